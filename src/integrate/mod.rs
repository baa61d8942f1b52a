//! Time integration of a multibody [`System`] with `diffsol`.
//!
//! The paper (§3.1) integrates with a variable-step, variable-order
//! multistep method; diffsol's variable-order BDF ([`Method::Bdf`], the
//! default) is that family. The explicit Tsitouras 5(4) pair
//! ([`Method::Tsit45`]) and the ESDIRK 3(4) method ([`Method::Esdirk34`])
//! are selectable for comparison. Implicit methods need Jacobian-vector
//! products `J v`; they are exact, from one evaluation of the generic
//! right-hand side on `num_dual::Dual64` numbers `y + ε v`.
//!
//! Output is dense: the solver steps freely and the state is interpolated
//! at the requested times, handed to an observer.

use crate::error::{Error, Result};
use crate::mbs::{Param, System, Workspace};
use diffsol::{FaerLU, FaerMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason, Vector};
use num_dual::Dual64;
use std::cell::RefCell;
use std::time::Instant;

/// Integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Variable-order (1–5) BDF with exact Jacobian-vector products.
    Bdf,
    /// Explicit Tsitouras 5(4) Runge–Kutta.
    Tsit45,
    /// Explicit-first-stage SDIRK, order 3(4).
    Esdirk34,
}

impl Method {
    /// Name as written in study files.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Bdf => "bdf",
            Method::Tsit45 => "tsit45",
            Method::Esdirk34 => "esdirk34",
        }
    }
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub method: Method,
    /// Relative tolerance (0 < rtol < 1).
    pub rtol: f64,
    /// Absolute tolerance (> 0), the same for every state.
    pub atol: f64,
    /// Start time (s).
    pub t0: f64,
    /// Output times (s), increasing, all ≥ `t0`; the last is the end time.
    pub times: Vec<f64>,
}

impl Options {
    /// Check the ranges; errors name the key (`integrator.<field>`).
    pub fn validate(&self) -> Result<()> {
        if !(self.rtol > 1e-14 && self.rtol < 1.0) {
            return Err(Error::input(
                "integrator.rtol",
                self.rtol,
                "1e-14 < rtol < 1",
            ));
        }
        if !(self.atol > 0.0 && self.atol.is_finite()) {
            return Err(Error::input(
                "integrator.atol",
                self.atol,
                "a finite atol > 0",
            ));
        }
        let ok = !self.times.is_empty()
            && self.times.iter().all(|t| t.is_finite())
            && self.times[0] >= self.t0
            && self.times.windows(2).all(|w| w[1] > w[0])
            && self.times[self.times.len() - 1] > self.t0;
        if !ok {
            return Err(Error::input(
                "integrator.t_end",
                format!("t0 = {}, outputs {:?}..", self.t0, self.times.first()),
                "an end time > start time with increasing output times",
            ));
        }
        Ok(())
    }
}

/// Integrator statistics.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    pub steps: usize,
    /// Right-hand-side evaluations (f64), counted by the system.
    pub rhs_calls: u64,
    /// Jacobian-vector products (each one dual-number evaluation).
    pub jvp_calls: u64,
    /// Jacobian / LU set-ups.
    pub jacobians: usize,
    pub error_test_failures: usize,
    pub nonlinear_iterations: usize,
    pub nonlinear_failures: usize,
    /// Wall time of the integration without the observer (s).
    pub wall: f64,
    /// Wall time spent in the observer (output evaluation, s).
    pub observer_wall: f64,
}

/// Integrate `sys` from `y0` (already consistent) and call
/// `observe(t, y)` at every output time.
pub fn integrate(
    sys: &System,
    y0: &[f64],
    opts: &Options,
    mut observe: impl FnMut(f64, &[f64]) -> Result<()>,
) -> Result<Stats> {
    opts.validate()?;
    let n = y0.len();
    let ws = RefCell::new(Workspace::<f64>::empty());
    let wsd = RefCell::new(Workspace::<Dual64>::empty());
    let ydual = RefCell::new(vec![Dual64::from(0.0); n]);
    let dydual = RefCell::new(vec![Dual64::from(0.0); n]);
    let jvps = std::cell::Cell::new(0u64);
    let rhs_calls = std::cell::Cell::new(0u64);
    let observer_time = std::cell::Cell::new(0.0f64);
    let y0v = y0.to_vec();
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
                sys.rhs(t, x, y, &mut ws.borrow_mut());
            },
            |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                jvps.set(jvps.get() + 1);
                let mut yd = ydual.borrow_mut();
                let mut dyd = dydual.borrow_mut();
                for k in 0..x.len() {
                    yd[k] = Dual64::new(x[k], v[k]);
                }
                sys.rhs(t, &yd, &mut dyd, &mut wsd.borrow_mut());
                for k in 0..x.len() {
                    y[k] = dyd[k].eps;
                }
            },
        )
        .init(
            move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&y0v),
            n,
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
    let mut stats = match opts.method {
        Method::Bdf => {
            let s = problem
                .bdf::<FaerLU<f64>>()
                .map_err(|e| Error::numerical("integrate: bdf set-up", e.to_string()))?;
            drive(s, opts, 0, &mut observe)?
        }
        Method::Esdirk34 => {
            let s = problem
                .esdirk34::<FaerLU<f64>>()
                .map_err(|e| Error::numerical("integrate: esdirk34 set-up", e.to_string()))?;
            drive(s, opts, 0, &mut observe)?
        }
        Method::Tsit45 => {
            let s = problem
                .tsit45()
                .map_err(|e| Error::numerical("integrate: tsit45 set-up", e.to_string()))?;
            drive(s, opts, 0, &mut observe)?
        }
    };
    stats.wall = start.elapsed().as_secs_f64() - observer_time.get();
    stats.observer_wall = observer_time.get();
    stats.rhs_calls = rhs_calls.get();
    stats.jvp_calls = jvps.get();
    Ok(stats)
}

/// Integrate `sys` from `y0` together with the forward sensitivities of
/// the state with respect to `params` (direct differentiation, paper Eqs.
/// 12–16): `ṡ_i = J s_i + ∂f/∂p_i`, both products exact from dual-number
/// evaluations of the same right-hand side. The initial state is taken as
/// independent of the parameters (`s_i(t0) = 0`). `observe(t, y, s)` gets
/// `s` lane-major: `s[i·n..(i+1)·n] = ∂y/∂p_i`. Sensitivities take part in
/// the error control.
pub fn integrate_sens(
    sys: &System,
    y0: &[f64],
    opts: &Options,
    params: &[Param],
    mut observe: impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
) -> Result<Stats> {
    opts.validate()?;
    let n = y0.len();
    let mut p0 = Vec::with_capacity(params.len());
    for (k, p) in params.iter().enumerate() {
        let v = p.value(&sys.model).ok_or_else(|| {
            Error::input(
                format!("params[{k}]"),
                format!("{p:?}"),
                "a parameter of the model",
            )
        })?;
        p0.push(v);
    }
    let ws = RefCell::new(Workspace::<f64>::empty());
    let wsd = RefCell::new(Workspace::<Dual64>::empty());
    let yd = RefCell::new(vec![Dual64::from(0.0); n]);
    let dyd = RefCell::new(vec![Dual64::from(0.0); n]);
    let rhs_calls = std::cell::Cell::new(0u64);
    let jvps = std::cell::Cell::new(0u64);
    let y0v = y0.to_vec();
    // One dual evaluation: state seeds `vy`, parameter seeds `vp`.
    let dual_eval =
        |x: &[f64], p: &[f64], t: f64, vy: Option<&[f64]>, vp: Option<&[f64]>, out: &mut [f64]| {
            jvps.set(jvps.get() + 1);
            let mut w = wsd.borrow_mut();
            w.params.clear();
            for (k, par) in params.iter().enumerate() {
                w.params
                    .push((*par, Dual64::new(p[k], vp.map_or(0.0, |v| v[k]))));
            }
            let mut yv = yd.borrow_mut();
            let mut dy = dyd.borrow_mut();
            for k in 0..x.len() {
                yv[k] = Dual64::new(x[k], vy.map_or(0.0, |v| v[k]));
            }
            sys.rhs(t, &yv, &mut dy, &mut w);
            for k in 0..x.len() {
                out[k] = dy[k].eps;
            }
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
                let mut w = ws.borrow_mut();
                w.params.clear();
                w.params
                    .extend(params.iter().copied().zip(p.iter().copied()));
                sys.rhs(t, x, y, &mut w);
            },
            |x: &[f64], p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                dual_eval(x, p, t, Some(v), None, y)
            },
            |x: &[f64], p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                dual_eval(x, p, t, None, Some(v), y)
            },
        )
        .init_sens(
            move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&y0v),
            |_p: &[f64], _t: f64, _v: &[f64], y: &mut [f64]| y.fill(0.0),
            n,
        )
        .build()
        .map_err(|e| Error::numerical("integrate_sens: problem set-up", e.to_string()))?;
    lift_failure_cap(&mut problem.ode_options);
    let start = Instant::now();
    let observer_time = std::cell::Cell::new(0.0f64);
    let mut observe = |t: f64, y: &[f64], s: &[f64]| {
        let t0 = Instant::now();
        let r = observe(t, y, s);
        observer_time.set(observer_time.get() + t0.elapsed().as_secs_f64());
        r
    };
    let np = params.len();
    let setup = |e: diffsol::error::DiffsolError| {
        Error::numerical("integrate_sens: solver set-up", e.to_string())
    };
    let mut stats = match opts.method {
        Method::Bdf => drive(
            problem.bdf_sens::<FaerLU<f64>>().map_err(setup)?,
            opts,
            np,
            &mut observe,
        )?,
        Method::Esdirk34 => drive(
            problem.esdirk34_sens::<FaerLU<f64>>().map_err(setup)?,
            opts,
            np,
            &mut observe,
        )?,
        Method::Tsit45 => drive(
            problem.tsit45_sens().map_err(setup)?,
            opts,
            np,
            &mut observe,
        )?,
    };
    stats.wall = start.elapsed().as_secs_f64() - observer_time.get();
    stats.observer_wall = observer_time.get();
    stats.rhs_calls = rhs_calls.get();
    stats.jvp_calls = jvps.get();
    Ok(stats)
}

/// diffsol counts nonlinear-solver failures over the WHOLE integration
/// (`max_nonlinear_solver_failures`, default 50) and aborts past the cap,
/// so a long, healthy BDF run whose Newton iteration occasionally fails
/// (each failure just refreshes the Jacobian and cuts the step, as in
/// CVODE, whose cap is per step) ends in an error: the Bricard linkage at
/// rtol 1e-4 did at t = 0.45 s. The cap is lifted; a genuine divergence
/// still ends, with its time, when the step falls below `min_timestep`
/// (1e-13 s; each failure cuts the step by 0.3, so after about 30
/// consecutive failures from a 1e-3 s step).
fn lift_failure_cap(o: &mut diffsol::OdeSolverOptions<f64>) {
    o.max_nonlinear_solver_failures = usize::MAX / 2;
}

/// Step a solver through the output times; with `nsens > 0` the
/// sensitivities (`nsens` lanes of the state length, lane-major) are
/// interpolated too and handed to `observe` after the state.
fn drive<'a, Eqn, S>(
    mut solver: S,
    opts: &Options,
    nsens: usize,
    observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
) -> Result<Stats>
where
    Eqn: diffsol::OdeEquations<T = f64, V = diffsol::FaerVec<f64>> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    let t_end = opts.times[opts.times.len() - 1];
    solver
        .set_stop_time(t_end)
        .map_err(|e| Error::numerical("integrate: stop time", e.to_string()))?;
    let mut next = 0;
    // Output times at the start.
    while next < opts.times.len() && opts.times[next] <= opts.t0 {
        let y = solver.state().y.clone_as_vec();
        // Initial sensitivities are zero (the initial state is given).
        let s0 = vec![0.0; y.len() * nsens];
        emit(opts.times[next], &y, &s0, observe)?;
        next += 1;
    }
    loop {
        let t_before = solver.state().t;
        let reason = solver.step().map_err(|e| {
            Error::numerical_at(
                format!("integrate: {} step", opts.method.name()),
                t_before,
                e.to_string(),
            )
        })?;
        let t = solver.state().t;
        while next < opts.times.len() && opts.times[next] <= t {
            let tq = opts.times[next];
            let y = if tq == t {
                solver.state().y.clone()
            } else {
                solver.interpolate(tq).map_err(|e| {
                    Error::numerical_at("integrate: dense output", tq, e.to_string())
                })?
            };
            let sens = if nsens > 0 {
                solver
                    .interpolate_sens(tq)
                    .map_err(|e| {
                        Error::numerical_at("integrate: sensitivity output", tq, e.to_string())
                    })?
                    .clone_as_vec()
            } else {
                Vec::new()
            };
            emit(tq, &y.clone_as_vec(), &sens, observe)?;
            next += 1;
        }
        if matches!(reason, OdeSolverStopReason::TstopReached) || next >= opts.times.len() {
            break;
        }
    }
    let st = solver.get_statistics();
    Ok(Stats {
        steps: st.number_of_steps,
        jacobians: st.number_of_linear_solver_setups,
        error_test_failures: st.number_of_error_test_failures,
        nonlinear_iterations: st.number_of_nonlinear_solver_iterations,
        nonlinear_failures: st.number_of_nonlinear_solver_fails,
        ..Stats::default()
    })
}

fn emit(
    t: f64,
    y: &[f64],
    sens: &[f64],
    observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
) -> Result<()> {
    if let Some(k) = y.iter().chain(sens).position(|v| !v.is_finite()) {
        return Err(Error::numerical_at(
            "integrate: state",
            t,
            format!("component {k} of the state/sensitivities is not finite"),
        ));
    }
    observe(t, y, sens)
}
