//! Consistent initial conditions (projection onto the constraints) and
//! per-state outputs: joint angles and rates, reactions, energy and
//! constraint violation.

use super::dynamics::{angle_of, System, Workspace};
use super::linalg::Scalar;
use super::model::{Force, JointKind};
use crate::error::{Error, Result};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Sizes of the corrections made by [`System::project`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Largest position-level residual before the projection.
    pub phi_before: f64,
    /// Largest residual after it.
    pub phi_after: f64,
    /// Euclidean norm of the mass-weighted position correction
    /// (m and rad mixed; `[Δr, Δθ']` stacked).
    pub position_correction: f64,
    /// Euclidean norm of the velocity correction `[Δṙ, Δω']`.
    pub velocity_correction: f64,
    /// Newton iterations on positions.
    pub iterations: usize,
    /// Rank of the constraint Jacobian at the projected state.
    pub rank: usize,
    /// Number of equations.
    pub equations: usize,
}

/// Reaction of a joint: force (N) and torque (N·m, about the joint point)
/// exerted on the body of marker `j`, in global axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reaction {
    pub force: Vector3<f64>,
    pub torque: Vector3<f64>,
}

/// Tolerance of the position projection on `max |Φ|`.
pub const PROJECTION_TOL: f64 = 1e-12;

impl System {
    /// Project `y` onto the constraints at time `t`: Newton iterations with
    /// the mass-weighted minimum-norm step
    /// `Δx = −M⁻¹Gᵀ(GM⁻¹Gᵀ)⁺Φ` on positions, then the same projection of
    /// the velocities onto `G v = ν`. Inconsistent positions (redundant
    /// equations that contradict each other, or no convergence within 50
    /// iterations) are an input error.
    pub fn project(&self, t: f64, y: &mut [f64]) -> Result<Projection> {
        let mut ws = Workspace::<f64>::empty();
        let nb = self.nb();
        let vo = self.voff();
        let mut before = None;
        let mut poscorr = 0.0;
        let mut iterations = 0;
        let mut after = 0.0;
        for it in 0..=50 {
            self.load(t, y, &mut ws);
            let res = ws.rows.iter().fold(0.0f64, |m, r| m.max(r.phi.abs()));
            if !res.is_finite() {
                return Err(Error::input(
                    "initial state",
                    res,
                    "a configuration where the constraints are defined",
                ));
            }
            before.get_or_insert(res);
            after = res;
            if res <= PROJECTION_TOL || it == 50 {
                break;
            }
            iterations = it + 1;
            for r in ws.rows.iter_mut() {
                r.gamma = -r.phi;
            }
            let dx = self.correction(&mut ws);
            for (s, d) in dx.iter().enumerate() {
                poscorr += d.iter().map(|v| v * v).sum::<f64>();
                for c in 0..3 {
                    y[7 * s + c] += d[c];
                }
                let p = &y[7 * s + 3..7 * s + 7];
                let q = UnitQuaternion::from_quaternion(Quaternion::new(p[0], p[1], p[2], p[3]));
                let dq = UnitQuaternion::from_quaternion(Quaternion::new(
                    1.0,
                    0.5 * d[3],
                    0.5 * d[4],
                    0.5 * d[5],
                ));
                let n = q * dq;
                y[7 * s + 3..7 * s + 7].copy_from_slice(&[n.w, n.i, n.j, n.k]);
            }
        }
        let before = before.unwrap_or(0.0);
        if after > 1e-9 {
            return Err(Error::input(
                "joints",
                format!("max |Φ| = {after:.3e} after projection (was {before:.3e})"),
                "initial positions that satisfy the joints (consistent redundant constraints)",
            ));
        }
        // Velocities.
        self.load(t, y, &mut ws);
        for r in ws.rows.iter_mut() {
            r.gamma = -r.phidot;
        }
        let dv = self.correction(&mut ws);
        let mut velcorr = 0.0;
        for (s, d) in dv.iter().enumerate() {
            for c in 0..6 {
                y[vo + 6 * s + c] += d[c];
                velcorr += d[c] * d[c];
            }
        }
        let _ = nb;
        Ok(Projection {
            phi_before: before,
            phi_after: after,
            position_correction: poscorr.sqrt(),
            velocity_correction: velcorr.sqrt(),
            iterations,
            rank: ws.rank,
            equations: ws.rows.len(),
        })
    }

    /// Kinematics and constraint rows of `y` at `t` into `ws`.
    pub fn load(&self, t: f64, y: &[f64], ws: &mut Workspace<f64>) {
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &mut kin);
        ws.kin = kin;
        self.constraints(t, ws);
    }

    /// `M⁻¹Gᵀ(GM⁻¹Gᵀ)⁺γ` with the rows' `gamma` as right-hand side.
    fn correction(&self, ws: &mut Workspace<f64>) -> Vec<[f64; 6]> {
        ws.q.clear();
        ws.q.resize(self.nb(), [0.0; 6]);
        self.solve(ws)
    }

    /// Largest `|Φ|` of the state.
    pub fn violation(&self, t: f64, y: &[f64], ws: &mut Workspace<f64>) -> f64 {
        self.load(t, y, ws);
        ws.rows.iter().fold(0.0f64, |m, r| m.max(r.phi.abs()))
    }

    /// Mechanical energy: kinetic + gravity potential + linear springs (J).
    pub fn energy(&self, y: &[f64], ws: &mut Workspace<f64>) -> f64 {
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &mut kin);
        let mut e = 0.0;
        for (s, &b) in self.moving.iter().enumerate() {
            let body = &self.model.bodies[b];
            let k = &kin[s];
            e += 0.5 * body.mass * k.v.norm_squared() + 0.5 * k.wb.dot(&(body.inertia * k.wb));
        }
        for f in &self.model.forces {
            match f {
                Force::Gravity { g } => {
                    for (s, &b) in self.moving.iter().enumerate() {
                        e -= self.model.bodies[b].mass * g.dot(&kin[s].r);
                    }
                }
                Force::SpringDamper {
                    i,
                    j,
                    stiffness,
                    length,
                    ..
                } => {
                    let l = (self.marker_kin(&kin, *j).x - self.marker_kin(&kin, *i).x).norm();
                    e += 0.5 * stiffness * (l - length).powi(2);
                }
                _ => {}
            }
        }
        ws.kin = kin;
        e
    }

    /// Whether [`System::energy`] is conserved by the exact flow: no
    /// dampers, actuators, loads or driven joints.
    pub fn conservative(&self) -> bool {
        let forces_ok = self.model.forces.iter().all(|f| match f {
            Force::Gravity { .. } => true,
            Force::SpringDamper { damping, .. } => *damping == 0.0,
            _ => false,
        });
        let joints_ok = self
            .model
            .joints
            .iter()
            .all(|j| !matches!(j.kind, JointKind::Driven(ref d) if d.coefficients.len() > 1));
        forces_ok && joints_ok
    }

    /// Angular momentum about the global origin (N·m·s), meaningful for
    /// free systems.
    pub fn angular_momentum(&self, y: &[f64], ws: &mut Workspace<f64>) -> Vector3<f64> {
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &mut kin);
        let mut h = Vector3::zeros();
        for (s, &b) in self.moving.iter().enumerate() {
            let body = &self.model.bodies[b];
            let k = &kin[s];
            h += k.r.cross(&(k.v * body.mass)) + k.a * (body.inertia * k.wb);
        }
        ws.kin = kin;
        h
    }

    /// Relative angle (rad) and rate (rad/s) of a revolute joint.
    pub fn angle(&self, y: &[f64], joint: usize, ws: &mut Workspace<f64>) -> (f64, f64) {
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &mut kin);
        let j = &self.model.joints[joint];
        let r = angle_of(&self.marker_kin(&kin, j.i), &self.marker_kin(&kin, j.j));
        ws.kin = kin;
        r
    }

    /// Reactions of every joint at `(t, y)` (one right-hand-side solve).
    pub fn reactions(&self, t: f64, y: &[f64], ws: &mut Workspace<f64>) -> Vec<Reaction> {
        let mut dy = vec![0.0; y.len()];
        self.rhs(t, y, &mut dy, ws);
        let mut out = Vec::with_capacity(self.model.joints.len());
        let mut r0 = 0;
        for joint in &self.model.joints {
            let ne = joint.kind.equations();
            let mj = self.marker_kin(&ws.kin, joint.j);
            let mi = self.marker_kin(&ws.kin, joint.i);
            // Use the moving side; the ground side gets the opposite.
            let (side, mk, sign) = if mj.slot.is_some() {
                (1, mj, 1.0)
            } else {
                (0, mi, -1.0)
            };
            let mut f = Vector3::zeros();
            let mut nb = Vector3::zeros();
            for r in r0..r0 + ne {
                let blk = ws.rows[r].blocks[side].1;
                let lam = ws.rhs[r];
                f += Vector3::new(blk[0], blk[1], blk[2]) * lam;
                nb += Vector3::new(blk[3], blk[4], blk[5]) * lam;
            }
            let torque_com = match mk.slot {
                Some(s) => ws.kin[s].a * nb,
                None => Vector3::zeros(),
            };
            let torque = torque_com - mk.s.cross(&f);
            out.push(Reaction {
                force: f * sign,
                torque: torque * sign,
            });
            r0 += ne;
        }
        out
    }
}

impl<T: Scalar> Workspace<T> {
    /// An empty workspace (buffers grow on first use).
    pub fn empty() -> Self {
        Workspace {
            rows: Vec::new(),
            a: Vec::new(),
            rhs: Vec::new(),
            scale: Vec::new(),
            tmp: Vec::new(),
            kin: Vec::new(),
            by_body: Vec::new(),
            inv_order: Vec::new(),
            col: Vec::new(),
            nz: Vec::new(),
            q: Vec::new(),
            rank: 0,
            params: Vec::new(),
        }
    }
}
