//! Forward sensitivities in the fused form: the sensitivities ride in the
//! state, `z = [y; s_1; ..; s_np]`, and `ż = [f; J s_1 + ∂f/∂p_1; ..]`,
//! where lane `i` is the directional derivative with the state seeded by
//! `s_i` and parameter `p_i` seeded by one. The model gives `f` and every
//! lane at once ([`OdeModel::rhs_lanes`]; the multibody system from one
//! multi-lane dual-number evaluation per stage or Newton iterate), where
//! the staggered form ([`super::integrate_sens`] through diffsol's
//! sensitivity equations) makes two single-lane evaluations per lane and
//! stage (`J s_i` and `∂f/∂p_i` separately) besides `f`.
//!
//! As in the staggered form, only the states are error-controlled (the
//! lanes weigh nothing in the norm and the states' tolerances are rescaled
//! so that the norm is the plain one): the steps are those of an
//! integration without sensitivities up to rounding. Events, jumps and
//! restarts are those of the other forms.
//!
//! The implicit methods (BDF, ESDIRK 3(4)) see the block-diagonal part
//! `diag(J, .., J)` of the augmented Jacobian, so their Newton matrix is the
//! states' own, factored once and applied per block ([`super::block_lu`]);
//! `J`'s columns are computed once per point and shared by the blocks
//! ([`Columns`]). The lanes are not in the Newton convergence test (their
//! tolerance is infinite): they contract with the states, as the omitted
//! coupling `∂(J s)/∂y` acts through the state's increment, but their
//! remaining Newton error is not checked (`super::block_lu`: 9e-5
//! relative between the fused and staggered BDF gradients of the flexible
//! SAR at rtol 1e-6, both within 3e-4 of a tight reference).

use super::block_lu::{with_blocks, BlockLu};
use super::legs::{lift_failure_cap, Integrand, Legs};
use super::ode::OdeModel;
use super::options::{Options, Stats};
use super::step::StepWatch;
use crate::error::{Error, Result};
use diffsol::{
    FaerContext, FaerMat, FaerVec, OdeBuilder, OdeEquations, OdeEquationsImplicit, OdeSolverProblem,
};
use std::cell::{Cell, RefCell};

/// [`super::integrate_sens`] in the fused form. `p0`: the parameters'
/// values.
pub(super) fn integrate_fused<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    (params, p0): (&[M::Param], &[f64]),
    observe: impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
    within: &mut StepWatch<'_>,
) -> Result<Stats> {
    let n = y0.len();
    let np = params.len();
    let ev = RefCell::new(model.events(opts.events, y0));
    let nroots = model.nroots(&ev.borrow());
    let work = RefCell::new(model.work(n));
    model.freeze(&ev.borrow(), &mut work.borrow_mut());
    let (rhs_calls, jvps) = (Cell::new(0u64), Cell::new(0u64));
    let columns = RefCell::new(Columns::new(n));
    // Start of the current leg: state and lanes.
    let start_z = RefCell::new([y0, &vec![0.0; n * np]].concat());
    // Error control of the states alone, as in the staggered form: the
    // lanes get an absolute tolerance so large that they weigh nothing,
    // and the states' tolerances are divided by √(1 + np), so that the
    // mean over the n(1 + np) components of diffsol's norm equals the
    // plain mean over the n states (to rounding).
    let c = ((1 + np) as f64).sqrt();
    let mut atol = vec![opts.atol / c; n];
    atol.resize(n * (1 + np), 1e300);
    let mut problem = OdeBuilder::<FaerMat<f64>>::new()
        .t0(opts.t0)
        .rtol(opts.rtol / c)
        .atol(atol)
        .h0(1e-6) // as in `integrate`
        .rhs_implicit(
            |z: &[f64], _p: &[f64], t: f64, dz: &mut [f64]| {
                let mut w = work.borrow_mut();
                let (y, lanes) = z.split_at(n);
                let (dy, dlanes) = dz.split_at_mut(n);
                rhs_calls.set(rhs_calls.get() + 1);
                let duals = model.rhs_lanes(&mut w, t, y, (params, p0), lanes, dy, dlanes);
                jvps.set(jvps.get() + duals as u64);
            },
            // Ĵ v = [J v_0; J v_1; ..] (module doc), for the implicit methods.
            |z: &[f64], _p: &[f64], t: f64, v: &[f64], out: &mut [f64]| {
                let y = &z[..n];
                let mut cols = columns.borrow_mut();
                cols.at(t, y);
                for (vb, ob) in v.chunks(n).zip(out.chunks_mut(n)) {
                    cols.product(vb, ob, |vb, ob| {
                        jvps.set(jvps.get() + 1);
                        model.rhs_dir(
                            &mut work.borrow_mut(),
                            t,
                            y,
                            (params, p0),
                            (Some(vb), None),
                            ob,
                        );
                    });
                }
            },
        )
        .init(
            |_p: &[f64], _t: f64, z: &mut [f64]| z.copy_from_slice(&start_z.borrow()),
            n * (1 + np),
        )
        .root(
            |z: &[f64], _p: &[f64], t: f64, g: &mut [f64]| {
                model.roots(&ev.borrow(), &mut work.borrow_mut(), t, &z[..n], g)
            },
            nroots,
        )
        .build()
        .map_err(|e| Error::numerical("integrate_sens (fused): problem set-up", e.to_string()))?;
    lift_failure_cap(&mut problem.ode_options);
    let mut lanes = Lanes {
        problem,
        n,
        blocks: 1 + np,
        start_z: &start_z,
        columns: &columns,
    };
    let legs = Legs::new(opts, model, (&ev, &work), (params, p0), &lanes);
    legs.run(&mut lanes, (&rhs_calls, &jvps), observe, within)
}

/// The states with the lanes in the state, `z = [y; s_1; ..; s_np]`, on
/// diffsol's plain solvers; the implicit ones factor the states' own
/// Newton matrix once for the `blocks = 1 + np` blocks ([`BlockLu`]). A
/// leg starts from `start_z` (shared with the problem's initial
/// condition) with the columns of `J` forgotten ([`Columns`]: a new leg
/// may have a new piece frozen at the same point).
struct Lanes<'c, Eqn: OdeEquations> {
    problem: OdeSolverProblem<Eqn>,
    n: usize,
    blocks: usize,
    start_z: &'c RefCell<Vec<f64>>,
    columns: &'c RefCell<Columns>,
}

impl<Eqn> Integrand for Lanes<'_, Eqn>
where
    Eqn: OdeEquationsImplicit<T = f64, V = FaerVec<f64>, M = FaerMat<f64>, C = FaerContext>,
{
    type Eqn = Eqn;
    type Lu = BlockLu;
    const PLACE: &'static str = "integrate_sens (fused)";

    fn problem(&self) -> &OdeSolverProblem<Eqn> {
        &self.problem
    }

    fn fused(&self) -> Option<usize> {
        Some(self.n)
    }

    fn implicit<R>(&self, leg: impl FnOnce() -> R) -> R {
        with_blocks(self.blocks, leg)
    }

    fn restart(&mut self, t: f64, y: Vec<f64>, s: Vec<f64>) {
        *self.columns.borrow_mut() = Columns::new(self.n);
        self.problem.t0 = t;
        *self.start_z.borrow_mut() = [y, s].concat();
    }
}

/// Columns of `J` at one point `(t, y)`: the implicit methods build their
/// Newton matrix column by column (`Ĵ e_j`), and every lane block asks for
/// the same unit vectors as the state block; each column is computed once
/// per point and copied to the blocks.
struct Columns {
    t: f64,
    y: Vec<f64>,
    /// `J e_j` where computed at `(t, y)`.
    cols: Vec<Option<Vec<f64>>>,
}

impl Columns {
    fn new(n: usize) -> Self {
        Columns {
            t: f64::NAN,
            y: vec![f64::NAN; n],
            cols: vec![None; n],
        }
    }

    /// Move to the point `(t, y)`, forgetting the columns of another one.
    fn at(&mut self, t: f64, y: &[f64]) {
        let same = t.to_bits() == self.t.to_bits()
            && y.iter()
                .zip(&self.y)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            self.t = t;
            self.y.copy_from_slice(y);
            self.cols.iter_mut().for_each(|c| *c = None);
        }
    }

    /// `out = J v` for one block: zero for `v = 0`, the stored column for a
    /// unit vector (computed by `jv` and stored the first time), else `jv`.
    fn product(&mut self, v: &[f64], out: &mut [f64], jv: impl FnOnce(&[f64], &mut [f64])) {
        let mut nonzero = v.iter().enumerate().filter(|(_, x)| **x != 0.0);
        let (first, second) = (nonzero.next(), nonzero.next());
        match (first, second) {
            (None, _) => out.fill(0.0),
            (Some((j, &1.0)), None) => match &self.cols[j] {
                Some(c) => out.copy_from_slice(c),
                None => {
                    jv(v, out);
                    self.cols[j] = Some(out.to_vec());
                }
            },
            _ => jv(v, out),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Columns;

    /// The cache gives `J e_j` computed once per point, zero for a zero
    /// block, and computes anything else (or at a new point) afresh.
    #[test]
    fn columns_are_shared_per_point_only() {
        let mut cols = Columns::new(3);
        let calls = std::cell::Cell::new(0);
        // "J" = diag(1, 2, 3) scaled by the point's first entry.
        let jv = |c: &mut Columns, y: &[f64], v: &[f64]| {
            let mut out = [0.0; 3];
            c.at(0.5, y);
            c.product(v, &mut out, |v, o| {
                calls.set(calls.get() + 1);
                for k in 0..3 {
                    o[k] = y[0] * (k + 1) as f64 * v[k];
                }
            });
            out
        };
        let e1 = [0.0, 1.0, 0.0];
        assert_eq!(jv(&mut cols, &[1.0, 0.0, 0.0], &e1), [0.0, 2.0, 0.0]);
        assert_eq!(jv(&mut cols, &[1.0, 0.0, 0.0], &e1), [0.0, 2.0, 0.0]);
        assert_eq!(calls.get(), 1, "the second block copies the column");
        assert_eq!(jv(&mut cols, &[1.0, 0.0, 0.0], &[0.0; 3]), [0.0; 3]);
        assert_eq!(
            jv(&mut cols, &[1.0, 0.0, 0.0], &[0.0, 2.0, 0.0]),
            [0.0, 4.0, 0.0]
        );
        assert_eq!(calls.get(), 2, "a non-unit vector is computed");
        assert_eq!(jv(&mut cols, &[3.0, 0.0, 0.0], &e1), [0.0, 6.0, 0.0]);
        assert_eq!(calls.get(), 3, "a new point forgets the columns");
    }
}
