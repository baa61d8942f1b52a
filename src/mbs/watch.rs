//! What the integrator watches besides the actuator segments
//! ([`super::segments`]): the constraint rows left out of the solve
//! ([`RowWatch`]) and the size of the flexible bodies' deformations
//! ([`Guard`]). Both are root functions of the model's events.
//!
//! ## Redundant rows followed through the run
//! Rows found dependent at the projected start are left out of the solve
//! ([`System::drop_rows`]): on the constraint manifold they are implied by
//! the others. A row that is dependent only at the start (a flexible
//! body whose undeformed shape makes two joints redundant, e.g. a panel
//! hinged by a revolute and a spherical joint on one line: the in-plane
//! rows of the spherical joint are implied by the hinge while the panel
//! is flat, not once it bends) then drifts unchecked. Each dropped row
//! `r` therefore has the root function
//!
//! ```text
//!   g_r(t, y) = τ − |Φ_r(t, y)|,      τ = 10 · atol  (m or rad),
//! ```
//!
//! evaluated by the integrator at every accepted step from the kinematics
//! and the rows of the joints concerned only
//! ([`System::row_values`]). At a sign change the rows are chosen anew
//! at the event state (an event like a segment change: the integrator
//! restarts there): every row is factored, rows at the regularisation
//! level are dependent ([`crate::mbs::system::RANK_TOL`]), and of those,
//! the ones whose violation has reached `τ / 2` *and* exceeds
//! [`IMPLIED_RATIO`] times the largest violation of the rows in the solve
//! stay in the solve (a row implied by the others cannot drift away from
//! them), as does every row that has re-entered once. A row that reached
//! its bound but drifts only with the solved rows (a truly redundant row
//! of an overconstrained linkage at a loose tolerance) stays out, its
//! bound doubled past its violation, so such a row causes few events. Baumgarte stabilisation then pulls the re-entered row back, so
//! the largest violation stays at `τ`. While no dropped row drifts, no
//! root changes sign and the run is unchanged step for step.
//!
//! With sensitivities, `g_y v = −sign(Φ_r) Φ_r,y v` (one dual-number
//! evaluation of the row) gives the jump of the state sensitivities at
//! the event ([`crate::integrate`]).
//!
//! ## Divergence guard
//! A linear floating frame is valid for small deformations only; a run
//! that leaves them (a body spun above its first frequency without
//! geometric stiffening, negative damping) grows without bound until the
//! step size underflows, minutes later. Each flexible body `b` has the
//! root function
//!
//! ```text
//!   g_b(y) = c · D_b − Σ_j |w_j| a_j,     a_j = max_k |(u_x, u_y, u_z)_kj|,
//! ```
//!
//! with `w` its modal coordinates, `a_j` the largest nodal displacement
//! of mode `j` per unit coordinate (so the sum bounds the largest nodal
//! deflection from above), `D_b` the largest side of the box around its
//! undeformed nodes and `c` the scene's `divergence_limit` (default 0.2).
//! A sign change ends the integration ([`crate::integrate::OdeModel::halt`])
//! with a numerical error naming the time, the body and the value; the
//! outputs up to that time are kept ([`crate::simulate`]).

use crate::mbs::system::{System, Workspace, RANK_REG, RANK_TOL};
use num_dual::Dual64;

/// The constraint rows left out of the solve, watched for drift (module
/// doc).
#[derive(Debug, Clone)]
pub struct RowWatch {
    /// Rows left out of the solve now (ascending).
    dropped: Vec<usize>,
    /// Rows that have re-entered the solve: never left out again.
    kept: Vec<bool>,
    /// Per row, the bound on `|Φ_r|` while it is left out (m or rad):
    /// `τ`, raised for a row found implied at an event.
    bound: Vec<f64>,
    /// Whether rows are watched (the system's [`System::row_bound`] is set).
    on: bool,
}

impl RowWatch {
    /// The rows `sys` leaves out at the start, watched with the system's
    /// bound (none watched without one).
    pub fn new(sys: &System) -> RowWatch {
        let m = sys.equations();
        let on = sys.row_bound.is_some();
        RowWatch {
            dropped: if on {
                (0..m).filter(|&r| sys.dropped(r)).collect()
            } else {
                Vec::new()
            },
            kept: vec![false; m],
            bound: vec![sys.row_bound.unwrap_or(f64::INFINITY); m],
            on,
        }
    }

    /// Number of root functions (one per dropped row).
    pub fn nroots(&self) -> usize {
        self.dropped.len()
    }

    /// The rows left out now, for [`Workspace::drop`] (`None` when rows
    /// are not watched: the system's set applies).
    pub fn mask(&self) -> Option<Vec<bool>> {
        self.on.then(|| {
            let mut d = vec![false; self.kept.len()];
            for &r in &self.dropped {
                d[r] = true;
            }
            d
        })
    }

    /// The row of root `k`.
    pub fn row(&self, k: usize) -> usize {
        self.dropped[k]
    }

    /// `τ − |Φ_r|` of every dropped row at `(t, y)` into `g`; `ws` is
    /// scratch.
    pub fn roots(&self, sys: &System, t: f64, y: &[f64], ws: &mut Workspace<f64>, g: &mut [f64]) {
        if self.dropped.is_empty() {
            return;
        }
        sys.kinematics(y, ws);
        let mut phi = Vec::with_capacity(self.dropped.len());
        sys.row_values(t, ws, &self.dropped, &mut phi);
        for ((gk, p), &r) in g.iter_mut().zip(&phi).zip(&self.dropped) {
            *gk = self.bound[r] - p.abs();
        }
    }

    /// `g_y v` of every root function at `(t, y)` into `g`.
    pub fn roots_dir(&self, sys: &System, t: f64, y: &[f64], v: &[f64], g: &mut [f64]) {
        if self.dropped.is_empty() {
            return;
        }
        let phi = dual_rows(sys, t, y, v, &self.dropped);
        for (gk, p) in g.iter_mut().zip(&phi) {
            *gk = -p.re.signum() * p.eps;
        }
    }

    /// `g_y v` of the root function of row `row` at `(t, y)`.
    pub fn crossing_dir(&self, sys: &System, row: usize, t: f64, y: &[f64], v: &[f64]) -> f64 {
        let p = dual_rows(sys, t, y, v, &[row])[0];
        -p.re.signum() * p.eps
    }

    /// Whether row `row` has genuinely reached the bound at `(t, y)`
    /// (not a round-off sign change).
    pub fn reached(&self, sys: &System, row: usize, t: f64, y: &[f64]) -> bool {
        let mut ws = Workspace::<f64>::empty();
        sys.kinematics(y, &mut ws);
        let mut phi = Vec::new();
        sys.row_values(t, &ws, &[row], &mut phi);
        phi[0].abs() >= self.bound[row] * (1.0 - 1e-6)
    }

    /// Choose the rows left out anew at `(t, y)` (module doc): the rows
    /// the factorization of all rows finds dependent, except those whose
    /// violation has reached `τ / 2` and those that have re-entered once.
    pub fn rechoose(&mut self, sys: &System, t: f64, y: &[f64]) {
        let m = self.kept.len();
        let mut ws = Workspace::<f64>::empty();
        ws.drop = Some(vec![false; m]);
        sys.load(t, y, &mut ws);
        let phi: Vec<f64> = ws.rows.iter().map(|r| r.phi.abs()).collect();
        // The largest violation of the rows in the solve: a row implied
        // by them drifts with them, at most a few times as far.
        let solved = (0..m)
            .filter(|r| !self.dropped.contains(r))
            .fold(0.0f64, |a, r| a.max(phi[r]));
        let mut far = vec![false; m];
        for &r in &self.dropped {
            if phi[r] >= 0.5 * self.bound[r] {
                if phi[r] > IMPLIED_RATIO * solved {
                    far[r] = true;
                    self.kept[r] = true;
                } else {
                    self.bound[r] = 2.0 * phi[r].max(self.bound[r]);
                }
            }
        }
        ws.q.clear();
        ws.q.resize(sys.nvel(), 0.0);
        sys.mass_factors(&mut ws);
        sys.solve(&mut ws);
        self.dropped = (0..m)
            .filter(|&r| {
                let k = ws.inv_order[r];
                let l = ws.a[k * m + k];
                l * l - RANK_REG <= RANK_TOL && !far[r] && !self.kept[r]
            })
            .collect();
        crate::mbs::system::bump(&sys.counters.row_events);
    }
}

/// A dropped row whose violation is at most this many times the largest
/// violation of the rows in the solve counts as implied by them at an
/// event (module doc).
pub const IMPLIED_RATIO: f64 = 10.0;

/// The rows `rows` (ascending) at `(t, y + ε v)`.
fn dual_rows(sys: &System, t: f64, y: &[f64], v: &[f64], rows: &[usize]) -> Vec<Dual64> {
    let yd: Vec<Dual64> = y.iter().zip(v).map(|(&a, &b)| Dual64::new(a, b)).collect();
    let mut ws = Workspace::<Dual64>::empty();
    sys.kinematics(&yd, &mut ws);
    let mut phi = Vec::new();
    sys.row_values(t, &ws, rows, &mut phi);
    phi
}

/// One flexible body under the divergence guard.
#[derive(Debug, Clone)]
struct Watched {
    /// Model index of the body.
    body: usize,
    /// Offset of its modal coordinates in the state.
    off: usize,
    /// Per mode: the largest nodal displacement per unit coordinate (m).
    reach: Vec<f64>,
    /// Largest side of the box around the undeformed nodes (m).
    size: f64,
}

/// The divergence guard of the flexible bodies (module doc).
#[derive(Debug, Clone)]
pub struct Guard {
    bodies: Vec<Watched>,
    /// The scene's factor `c` of the body size.
    limit: f64,
}

impl Guard {
    /// The guard of every flexible body of `sys` with the model's
    /// `divergence_limit` (no body watched without a finite one).
    pub fn new(sys: &System) -> Guard {
        let limit = sys.model.divergence_limit.unwrap_or(f64::INFINITY);
        let mut bodies = Vec::new();
        if limit.is_finite() {
            for (s, &b) in sys.moving.iter().enumerate() {
                let Some(flex) = &sys.model.bodies[b].flex else {
                    continue;
                };
                let basis = &flex.basis;
                let n = basis.n_modes;
                if n == 0 || sys.modes[s] != n {
                    continue;
                }
                let reach = (0..n)
                    .map(|j| {
                        (0..basis.n_nodes())
                            .map(|k| {
                                let u = [0, 1, 2].map(|c| basis.shape(k, c, j));
                                (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()
                            })
                            .fold(0.0f64, f64::max)
                    })
                    .collect();
                let size = (0..3)
                    .map(|c| {
                        let (lo, hi) = basis
                            .nodes
                            .iter()
                            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                                (lo.min(p[c]), hi.max(p[c]))
                            });
                        hi - lo
                    })
                    .fold(0.0f64, f64::max);
                bodies.push(Watched {
                    body: b,
                    off: sys.pos_off(s) + 7,
                    reach,
                    size,
                });
            }
        }
        Guard { bodies, limit }
    }

    /// Number of root functions (one per watched body).
    pub fn nroots(&self) -> usize {
        self.bodies.len()
    }

    /// The deflection bound `Σ_j |w_j| a_j` of watched body `k` at `y` (m).
    fn deflection(&self, k: usize, y: &[f64]) -> f64 {
        let b = &self.bodies[k];
        b.reach
            .iter()
            .enumerate()
            .map(|(j, a)| y[b.off + j].abs() * a)
            .sum()
    }

    /// `c D_b − Σ_j |w_j| a_j` of every watched body into `g`.
    pub fn roots(&self, y: &[f64], g: &mut [f64]) {
        for (k, gk) in g.iter_mut().enumerate().take(self.bodies.len()) {
            *gk = self.limit * self.bodies[k].size - self.deflection(k, y);
        }
    }

    /// `g_y v` of every root function.
    pub fn roots_dir(&self, y: &[f64], v: &[f64], g: &mut [f64]) {
        for (k, gk) in g.iter_mut().enumerate().take(self.bodies.len()) {
            let b = &self.bodies[k];
            *gk = -b
                .reach
                .iter()
                .enumerate()
                .map(|(j, a)| y[b.off + j].signum() * v[b.off + j] * a)
                .sum::<f64>();
        }
    }

    /// Whether watched body `k` has passed its bound at `y`.
    pub fn passed(&self, k: usize, y: &[f64]) -> bool {
        let b = &self.bodies[k];
        self.deflection(k, y) >= self.limit * b.size * (1.0 - 1e-9)
    }

    /// The message of the numerical error that ends a run at `y` because
    /// watched body `k` passed its bound.
    pub fn message(&self, sys: &System, k: usize, y: &[f64]) -> String {
        let b = &self.bodies[k];
        format!(
            "body `{}` left small deformations: its modal deflection bound \
             Σ|w_j|·max|Φ_j| = {:.4e} m passed divergence_limit {} × its size {:.4e} m \
             (the linear floating frame does not hold; raise [scene] divergence_limit \
             to go on)",
            sys.model.bodies[b.body].name,
            self.deflection(k, y),
            self.limit,
            b.size
        )
    }
}
