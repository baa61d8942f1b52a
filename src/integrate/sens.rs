//! [`integrate_sens`]: states and forward sensitivities.

use super::legs::{lift_failure_cap, Integrand, Legs};
use super::ode::OdeModel;
use super::options::{Options, SensitivityForm, Stats};
use super::step::StepWatch;
use crate::error::{Error, Result};
use diffsol::error::DiffsolError;
use diffsol::{
    FaerContext, FaerLU, FaerMat, FaerVec, OdeBuilder, OdeEquations, OdeEquationsImplicitSens,
    OdeSolverMethod, OdeSolverProblem, Tableau,
};
use std::cell::RefCell;

/// Integrate `model` from `y0` together with the forward sensitivities of
/// the state with respect to `params` (direct differentiation, paper Eqs.
/// 12–16): `ṡ_i = J s_i + ∂f/∂p_i`, both products exact
/// ([`OdeModel::rhs_dir`]). The initial state is taken as independent of
/// the parameters (`s_i(t0) = 0`). `observe(t, y, s)` gets `s`
/// lane-major: `s[i·n..(i+1)·n] = ∂y/∂p_i`. In the staggered form the
/// sensitivities are not error-controlled (diffsol includes them only when
/// sensitivity tolerances are set, which this integrator does not): the
/// steps, and so the states, are those of [`super::integrate`]; the
/// sensitivities inherit the accuracy of those steps. With [`Options::events`], `s` jumps at each change
/// of piece by `(f⁻ − f⁺) dt_e/dp` (module doc). [`Options::sensitivity`]
/// selects the staggered or the fused form (`super::fused`).
pub fn integrate_sens<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    params: &[M::Param],
    observe: impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
) -> Result<Stats> {
    integrate_sens_stepped(model, y0, opts, params, observe, &mut |_| Ok(()))
}

/// [`integrate_sens`], calling `within` with every accepted step and its
/// dense output (state and sensitivities, [`super::Step`]) besides.
pub fn integrate_sens_stepped<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    params: &[M::Param],
    observe: impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
    within: &mut StepWatch<'_>,
) -> Result<Stats> {
    opts.validate()?;
    let n = y0.len();
    let np = params.len();
    let mut p0 = Vec::with_capacity(np);
    for (k, p) in params.iter().enumerate() {
        let v = model.param_value(*p).ok_or_else(|| {
            Error::input(
                format!("params[{k}]"),
                format!("{p:?}"),
                "a parameter of the model",
            )
        })?;
        p0.push(v);
    }
    if opts.sensitivity == SensitivityForm::Fused && np > 0 {
        return super::fused::integrate_fused(model, y0, opts, (params, &p0), observe, within);
    }
    let ev = RefCell::new(model.events(opts.events, y0));
    let nroots = model.nroots(&ev.borrow());
    let work = RefCell::new(model.work(n));
    model.freeze(&ev.borrow(), &mut work.borrow_mut());
    let rhs_calls = std::cell::Cell::new(0u64);
    let jvps = std::cell::Cell::new(0u64);
    // Start of the current leg: state and sensitivities (lane-major).
    let start_y = RefCell::new(y0.to_vec());
    let start_s = RefCell::new(vec![0.0; n * np]);
    // One directional derivative: state seeds `vy`, parameter seeds `vp`.
    let dir =
        |x: &[f64], p: &[f64], t: f64, seeds: (Option<&[f64]>, Option<&[f64]>), out: &mut [f64]| {
            jvps.set(jvps.get() + 1);
            model.rhs_dir(&mut work.borrow_mut(), t, x, (params, p), seeds, out);
        };
    let mut problem = OdeBuilder::<FaerMat<f64>>::new()
        .t0(opts.t0)
        .rtol(opts.rtol)
        .atol([opts.atol])
        .h0(1e-6) // as in `integrate`
        .p(p0.clone())
        .rhs_sens_implicit(
            |x: &[f64], p: &[f64], t: f64, y: &mut [f64]| {
                rhs_calls.set(rhs_calls.get() + 1);
                model.rhs(&mut work.borrow_mut(), t, x, (params, p), y);
            },
            |x: &[f64], p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                dir(x, p, t, (Some(v), None), y)
            },
            |x: &[f64], p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                dir(x, p, t, (None, Some(v)), y)
            },
        )
        .init_sens(
            |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&start_y.borrow()),
            // S v with S = [s_1 .. s_np] at the start of the leg.
            |_p: &[f64], _t: f64, v: &[f64], y: &mut [f64]| {
                y.fill(0.0);
                for (lane, vi) in start_s.borrow().chunks(n).zip(v) {
                    for k in 0..n {
                        y[k] += vi * lane[k];
                    }
                }
            },
            n,
        )
        .root_sens_implicit(
            |x: &[f64], _p: &[f64], t: f64, g: &mut [f64]| {
                model.roots(&ev.borrow(), &mut work.borrow_mut(), t, x, g)
            },
            |x: &[f64], _p: &[f64], t: f64, v: &[f64], g: &mut [f64]| {
                model.roots_dir(&ev.borrow(), t, x, v, g)
            },
            // The switching surfaces do not depend on the parameters.
            |_x: &[f64], _p: &[f64], _t: f64, _v: &[f64], g: &mut [f64]| g.fill(0.0),
            nroots,
        )
        .build()
        .map_err(|e| Error::numerical("integrate_sens: problem set-up", e.to_string()))?;
    lift_failure_cap(&mut problem.ode_options);
    let mut states = WithSens {
        problem,
        np,
        start: (&start_y, &start_s),
    };
    let legs = Legs::new(opts, model, (&ev, &work), (params, &p0), &states);
    legs.run(&mut states, (&rhs_calls, &jvps), observe, within)
}

/// The states and `np` lanes of forward sensitivities in diffsol's
/// sensitivity equations (the staggered form), on its sensitivity solvers
/// with its dense LU; a leg starts from `start` (state, lanes), shared
/// with the problem's initial conditions.
struct WithSens<'c, Eqn: OdeEquations> {
    problem: OdeSolverProblem<Eqn>,
    np: usize,
    start: (&'c RefCell<Vec<f64>>, &'c RefCell<Vec<f64>>),
}

impl<Eqn> Integrand for WithSens<'_, Eqn>
where
    Eqn: OdeEquationsImplicitSens<T = f64, V = FaerVec<f64>, M = FaerMat<f64>, C = FaerContext>,
{
    type Eqn = Eqn;
    type Lu = FaerLU<f64>;
    const PLACE: &'static str = "integrate_sens";

    fn problem(&self) -> &OdeSolverProblem<Eqn> {
        &self.problem
    }

    fn nsens(&self) -> usize {
        self.np
    }

    fn bdf<'s>(&'s self) -> std::result::Result<impl OdeSolverMethod<'s, Eqn>, DiffsolError>
    where
        Eqn: 's,
    {
        self.problem.bdf_sens::<FaerLU<f64>>()
    }

    fn sdirk<'s>(
        &'s self,
        tableau: Tableau<f64>,
    ) -> std::result::Result<impl OdeSolverMethod<'s, Eqn>, DiffsolError>
    where
        Eqn: 's,
    {
        let state = self
            .problem
            .rk_state_sens_and_consistent::<FaerLU<f64>>(&tableau)?;
        self.problem
            .sdirk_solver_sens::<FaerLU<f64>, _>(state, tableau)
    }

    fn explicit_rk<'s>(
        &'s self,
        tableau: Tableau<f64>,
    ) -> std::result::Result<impl OdeSolverMethod<'s, Eqn>, DiffsolError>
    where
        Eqn: 's,
    {
        let state = self.problem.rk_state_sens(&tableau)?;
        self.problem.explicit_rk_solver_sens(state, tableau)
    }

    fn erk(&self, _pair: super::pair::Pair) -> Result<super::erk::Erk<'_, Eqn>> {
        Err(Error::input(
            "integrator.sensitivity",
            "staggered",
            "the fused form with an explicit pair stepped here (vern65)",
        ))
    }

    fn restart(&mut self, t: f64, y: Vec<f64>, s: Vec<f64>) {
        self.problem.t0 = t;
        *self.start.0.borrow_mut() = y;
        *self.start.1.borrow_mut() = s;
    }
}
