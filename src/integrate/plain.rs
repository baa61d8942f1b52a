//! [`integrate`]: the states alone.

use super::legs::{lift_failure_cap, Legs};
use super::ode::OdeModel;
use super::options::{Method, Options, Stats};
use crate::error::{Error, Result};
use diffsol::{FaerLU, FaerMat, OdeBuilder};
use std::cell::RefCell;
use std::time::Instant;

/// Integrate `model` from `y0` (already consistent) and call
/// `observe(t, y)` at every output time.
pub fn integrate<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    mut observe: impl FnMut(f64, &[f64]) -> Result<()>,
) -> Result<Stats> {
    opts.validate()?;
    let n = y0.len();
    let ev = RefCell::new(model.events(opts.events, y0));
    let nroots = model.nroots(&ev.borrow());
    let work = RefCell::new(model.work(n));
    model.freeze(&ev.borrow(), &mut work.borrow_mut());
    let jvps = std::cell::Cell::new(0u64);
    let rhs_calls = std::cell::Cell::new(0u64);
    let observer_time = std::cell::Cell::new(0.0f64);
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
    let start = Instant::now();
    let mut observe = |t: f64, y: &[f64], _s: &[f64]| {
        let t0 = Instant::now();
        let r = observe(t, y);
        observer_time.set(observer_time.get() + t0.elapsed().as_secs_f64());
        r
    };
    let setup = |e: diffsol::error::DiffsolError| {
        Error::numerical("integrate: solver set-up", e.to_string())
    };
    let mut legs = Legs {
        opts,
        nsens: 0,
        fused: None,
        next: 0,
        model,
        events: &ev,
        work: &work,
        params: none,
    };
    let mut stats = Stats::default();
    loop {
        let (leg, event) = match opts.method {
            Method::Bdf => {
                legs.drive(problem.bdf::<FaerLU<f64>>().map_err(setup)?, &mut observe)?
            }
            Method::Esdirk34 => legs.drive(
                problem.esdirk34::<FaerLU<f64>>().map_err(setup)?,
                &mut observe,
            )?,
            Method::Tsit45 => legs.drive(problem.tsit45().map_err(setup)?, &mut observe)?,
        };
        let Some(e) = legs.end_leg(&mut stats, (leg, event), &mut observe)? else {
            break;
        };
        problem.t0 = e.t;
        *start_y.borrow_mut() = e.y;
    }
    Ok(stats.finish(start, observer_time.get(), (rhs_calls.get(), jvps.get())))
}
