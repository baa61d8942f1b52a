//! [`integrate`]: the states alone.

use super::legs::{lift_failure_cap, Integrand, Legs};
use super::ode::OdeModel;
use super::options::{Options, Stats};
use super::step::StepWatch;
use crate::error::{Error, Result};
use diffsol::{
    FaerContext, FaerLU, FaerMat, FaerVec, OdeBuilder, OdeEquations, OdeEquationsImplicit,
    OdeSolverProblem,
};
use std::cell::RefCell;

/// Integrate `model` from `y0` (already consistent) and call
/// `observe(t, y)` at every output time.
pub fn integrate<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    observe: impl FnMut(f64, &[f64]) -> Result<()>,
) -> Result<Stats> {
    integrate_stepped(model, y0, opts, observe, &mut |_| Ok(()))
}

/// [`integrate`], calling `within` with every accepted step and its dense
/// output besides ([`super::Step`]; its sensitivities are empty).
pub fn integrate_stepped<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    mut observe: impl FnMut(f64, &[f64]) -> Result<()>,
    within: &mut StepWatch<'_>,
) -> Result<Stats> {
    opts.validate()?;
    let n = y0.len();
    let ev = RefCell::new(model.events(opts.events, y0));
    let nroots = model.nroots(&ev.borrow());
    let work = RefCell::new(model.work(n));
    model.freeze(&ev.borrow(), &mut work.borrow_mut());
    let jvps = std::cell::Cell::new(0u64);
    let rhs_calls = std::cell::Cell::new(0u64);
    let none: (&[M::Param], &[f64]) = (&[], &[]);
    // Start of the current leg (the initial state, then each event state).
    let start_y = RefCell::new(y0.to_vec());
    let mut problem = OdeBuilder::<FaerMat<f64>>::new()
        .t0(opts.t0)
        .rtol(opts.rtol)
        .atol([opts.atol])
        // First trial step: small enough for the fastest scene here
        // (Andrews, 0.03 s span); the controllers grow it within a few steps.
        .h0(1e-6)
        .rhs_implicit(
            |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| {
                rhs_calls.set(rhs_calls.get() + 1);
                model.rhs(&mut work.borrow_mut(), t, x, none, y);
            },
            |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                jvps.set(jvps.get() + 1);
                model.rhs_dir(&mut work.borrow_mut(), t, x, none, (Some(v), None), y);
            },
        )
        .init(
            |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&start_y.borrow()),
            n,
        )
        .root(
            |x: &[f64], _p: &[f64], t: f64, g: &mut [f64]| {
                model.roots(&ev.borrow(), &mut work.borrow_mut(), t, x, g)
            },
            nroots,
        )
        .build()
        .map_err(|e| Error::numerical("integrate: problem set-up", e.to_string()))?;
    lift_failure_cap(&mut problem.ode_options);
    let mut states = States {
        problem,
        start_y: &start_y,
    };
    let legs = Legs::new(opts, model, (&ev, &work), none, &states);
    legs.run(
        &mut states,
        (&rhs_calls, &jvps),
        |t, y, _s| observe(t, y),
        within,
    )
}

/// The states alone, on diffsol's plain solvers with its dense LU; a leg
/// starts from `start_y` (shared with the problem's initial condition).
struct States<'c, Eqn: OdeEquations> {
    problem: OdeSolverProblem<Eqn>,
    start_y: &'c RefCell<Vec<f64>>,
}

impl<Eqn> Integrand for States<'_, Eqn>
where
    Eqn: OdeEquationsImplicit<T = f64, V = FaerVec<f64>, M = FaerMat<f64>, C = FaerContext>,
{
    type Eqn = Eqn;
    type Lu = FaerLU<f64>;
    const PLACE: &'static str = "integrate";

    fn problem(&self) -> &OdeSolverProblem<Eqn> {
        &self.problem
    }

    fn restart(&mut self, t: f64, y: Vec<f64>, _s: Vec<f64>) {
        self.problem.t0 = t;
        *self.start_y.borrow_mut() = y;
    }
}
