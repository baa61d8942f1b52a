//! Forward sensitivities in the fused form, for explicit methods: the
//! sensitivities ride in the state, `z = [y; s_1; ..; s_np]`, and
//! `ż = [f; J s_1 + ∂f/∂p_1; ..]`, where lane `i` is the directional
//! derivative with the state seeded by `s_i` and parameter `p_i` seeded
//! by one. The model gives `f` and every lane at once
//! ([`OdeModel::rhs_lanes`]; the multibody system from one multi-lane
//! dual-number evaluation per stage), where the staggered form
//! ([`super::integrate_sens`] through diffsol's sensitivity equations)
//! makes two single-lane evaluations per lane and stage (`J s_i` and
//! `∂f/∂p_i` separately) besides `f`. As in the staggered
//! form, only the states are error-controlled (the lanes weigh nothing in
//! the norm and the states' tolerances are rescaled so that the norm is
//! the plain one): the steps are those of an integration without
//! sensitivities up to rounding. Events, jumps and restarts are those of
//! the other forms.

use super::legs::{lift_failure_cap, Legs};
use super::ode::OdeModel;
use super::options::{Options, Stats};
use crate::error::{Error, Result};
use diffsol::{FaerMat, OdeBuilder};
use std::cell::{Cell, RefCell};
use std::time::Instant;

/// [`super::integrate_sens`] in the fused form with tsit45 (the caller
/// checks the method). `p0`: the parameters' values.
pub(super) fn integrate_fused<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    (params, p0): (&[M::Param], &[f64]),
    mut observe: impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
) -> Result<Stats> {
    let n = y0.len();
    let np = params.len();
    let ev = RefCell::new(model.events(opts.events, y0));
    let nroots = model.nroots(&ev.borrow());
    let work = RefCell::new(model.work(n));
    model.freeze(&ev.borrow(), &mut work.borrow_mut());
    let (rhs_calls, jvps) = (Cell::new(0u64), Cell::new(0u64));
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
        .rhs(|z: &[f64], _p: &[f64], t: f64, dz: &mut [f64]| {
            let mut w = work.borrow_mut();
            let (y, lanes) = z.split_at(n);
            let (dy, dlanes) = dz.split_at_mut(n);
            rhs_calls.set(rhs_calls.get() + 1);
            let duals = model.rhs_lanes(&mut w, t, y, (params, p0), lanes, dy, dlanes);
            jvps.set(jvps.get() + duals as u64);
        })
        .init(
            |_p: &[f64], _t: f64, z: &mut [f64]| z.copy_from_slice(&start_z.borrow()),
            n * (1 + np),
        )
        .root(
            |z: &[f64], _p: &[f64], _t: f64, g: &mut [f64]| {
                model.roots(&ev.borrow(), &mut work.borrow_mut(), &z[..n], g)
            },
            nroots,
        )
        .build()
        .map_err(|e| Error::numerical("integrate_sens (fused): problem set-up", e.to_string()))?;
    lift_failure_cap(&mut problem.ode_options);
    let start = Instant::now();
    let observer_time = Cell::new(0.0f64);
    let mut observe = |t: f64, y: &[f64], s: &[f64]| {
        let t0 = Instant::now();
        let r = observe(t, y, s);
        observer_time.set(observer_time.get() + t0.elapsed().as_secs_f64());
        r
    };
    let mut legs = Legs {
        opts,
        nsens: 0,
        fused: Some(n),
        next: 0,
        model,
        events: &ev,
        work: &work,
        params: (params, p0),
    };
    let mut stats = Stats::default();
    loop {
        let solver = problem.tsit45().map_err(|e| {
            Error::numerical("integrate_sens (fused): solver set-up", e.to_string())
        })?;
        let (leg, event) = legs.drive(solver, &mut observe)?;
        let Some(e) = legs.end_leg(&mut stats, (leg, event), &mut observe)? else {
            break;
        };
        problem.t0 = e.t;
        *start_z.borrow_mut() = [e.y, e.s].concat();
    }
    Ok(stats.finish(start, observer_time.get(), (rhs_calls.get(), jvps.get())))
}
