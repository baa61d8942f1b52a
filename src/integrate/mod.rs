//! Time integration of an ODE system given by the [`OdeModel`] trait, with
//! `diffsol`. The integrator knows nothing of multibody dynamics: the
//! multibody system implements the trait in `crate::mbs::ode`.
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
//!
//! ## Events
//! A piecewise-smooth model (the Eq. 32 actuator laws of the multibody
//! system) describes its pieces as events through the trait: during one
//! integration leg every piece is frozen ([`OdeModel::freeze`]), so the
//! right-hand side is smooth; the model's root functions
//! ([`OdeModel::roots`]) are handed to diffsol, which locates a sign
//! change on the dense output of the accepted step; the model says whether
//! it is a genuine crossing ([`OdeModel::classify`]) and switches the piece
//! ([`OdeModel::switch`]); a fresh solver restarts from `(t_e, y(t_e))`, so
//! no multistep history and no Runge–Kutta stage crosses the
//! discontinuity. [`Options::events`] switches this off (the model then
//! picks its pieces by value).
//!
//! With the switching surface `g(y(t_e), p) = 0` the event time moves with
//! the parameters and the state sensitivities `s = ∂y/∂p` jump (Hiskens &
//! Pai, "Trajectory sensitivity analysis of hybrid systems", IEEE TCAS-I
//! 47(2), 2000, the switching-event case of their Eq. 13 family):
//! `dt_e/dp = −(g_y s⁻ + g_p)/(g_y f⁻)`, `s⁺ = s⁻ + (f⁻ − f⁺) dt_e/dp`,
//! with `f⁻`/`f⁺` the right-hand side with the old/new piece at the event.
//! The trait's switching surfaces do not depend on the parameters
//! (`g_p = 0`), and `g_y v` is [`OdeModel::crossing_dir`].

use crate::error::{Error, Result};
use diffsol::{FaerLU, FaerMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason, Vector};
use std::cell::RefCell;
use std::time::Instant;

/// An ODE system `ẏ = f(t, y; p)` as the integrator sees it: right-hand
/// side, exact directional derivatives (for implicit methods and forward
/// sensitivities), and the events that switch between its smooth pieces.
/// `n` is the state length; parameter lanes are named by
/// [`OdeModel::Param`] and carried with their values.
pub trait OdeModel {
    /// A parameter of the model (a sensitivity lane).
    type Param: Copy + std::fmt::Debug;
    /// Scratch reused by every evaluation of one integration.
    type Work;
    /// The state of the model's piece switching (which piece is frozen).
    type Events;
    /// An accepted change of piece.
    type Crossing: Copy;

    /// Scratch for states of length `n`.
    fn work(&self, n: usize) -> Self::Work;
    /// The model's value of parameter `p` (None: not a parameter of it).
    fn param_value(&self, p: Self::Param) -> Option<f64>;
    /// `dy = f(t, y)` with the parameters `params.0` set to the values
    /// `params.1` (both empty: the model's own values).
    fn rhs(
        &self,
        w: &mut Self::Work,
        t: f64,
        y: &[f64],
        params: (&[Self::Param], &[f64]),
        dy: &mut [f64],
    );
    /// The exact directional derivative `out = J v_y + (∂f/∂p) v_p` with
    /// the state seeds `seeds.0` and parameter seeds `seeds.1` (None: 0).
    fn rhs_dir(
        &self,
        w: &mut Self::Work,
        t: f64,
        y: &[f64],
        params: (&[Self::Param], &[f64]),
        seeds: (Option<&[f64]>, Option<&[f64]>),
        out: &mut [f64],
    );
    /// The event state at `y0` (every piece frozen where `y0` is); with
    /// `enabled = false`, no root function is active.
    fn events(&self, enabled: bool, y0: &[f64]) -> Self::Events;
    /// Make the right-hand side use the pieces frozen in `ev`.
    fn freeze(&self, ev: &Self::Events, w: &mut Self::Work);
    /// Number of root functions (≥ 1: diffsol needs one; a constant
    /// function where there are none).
    fn nroots(&self, ev: &Self::Events) -> usize;
    /// Root function values `g(y)` (sign change = a candidate crossing).
    fn roots(&self, ev: &Self::Events, w: &mut Self::Work, y: &[f64], g: &mut [f64]);
    /// `g_y v` of every root function.
    fn roots_dir(&self, ev: &Self::Events, y: &[f64], v: &[f64], g: &mut [f64]);
    /// Whether the sign change of root `idx` at `y` is a genuine crossing.
    fn classify(&self, ev: &Self::Events, idx: usize, y: &[f64]) -> Option<Self::Crossing>;
    /// Switch to the piece after crossing `c` at `y`.
    fn switch(&self, ev: &mut Self::Events, c: Self::Crossing, y: &[f64]);
    /// `g_y v` of the switching surface of crossing `c`.
    fn crossing_dir(&self, ev: &Self::Events, c: Self::Crossing, y: &[f64], v: &[f64]) -> f64;
    /// What switched, for messages (e.g. `actuator forces[3]`).
    fn crossing_label(&self, ev: &Self::Events, c: Self::Crossing) -> String;
}

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
    /// Treat segment changes of piecewise actuator laws (Eq. 32) as events
    /// (root finding and a restart at each crossing, module doc) instead of
    /// picking the segment by value inside the right-hand side. Scenes
    /// default to `true`, from the measurement on the rigid SAR scene over
    /// 0–10 s (three crossings; `studies/events.toml`,
    /// `results/events/events.csv`, rtol 1e-4/1e-6/1e-8 against a rtol
    /// 1e-12 reference): the sensitivities dθ/dp are right only with
    /// events (relative error 3e-4 / 5e-6 / 5e-7 with BDF, 4e-6 / 8e-9 /
    /// 2e-10 with tsit45; 7e-4 to 2e-1 by value, not converging with
    /// rtol, because direct differentiation of the by-value law misses the
    /// jump of `s` at the event); θ(10 s) is 2–5× (BDF, rtol ≤ 1e-6; at
    /// 1e-4 both are 1.2–1.4e-4) and 200–4000× (tsit45) more accurate,
    /// with fewer error-test failures. Cost (three runs on a shared 2-core
    /// VM): tsit45 the same wall time within noise; BDF restarts at order 1
    /// after each event, which costs extra steps and Jacobians (about 2×
    /// wall at rtol 1e-4, +10–25 % at 1e-6, −6 to +14 % at 1e-8). Scenes
    /// that cross no breakpoint (SAR 0–3 s) are bit-identical either way.
    pub events: bool,
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
    /// Accepted segment changes of piecewise laws (events).
    pub events: usize,
    /// Fresh solvers started after an event (≤ `events`).
    pub restarts: usize,
    /// Time of the last accepted segment change (s), if any.
    pub last_event: Option<f64>,
}

impl Stats {
    /// Add the counters of one integration leg.
    fn absorb(&mut self, leg: &Stats) {
        self.steps += leg.steps;
        self.jacobians += leg.jacobians;
        self.error_test_failures += leg.error_test_failures;
        self.nonlinear_iterations += leg.nonlinear_iterations;
        self.nonlinear_failures += leg.nonlinear_failures;
    }
}

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
            |x: &[f64], _p: &[f64], _t: f64, g: &mut [f64]| {
                model.roots(&ev.borrow(), &mut work.borrow_mut(), x, g)
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
    stats.wall = start.elapsed().as_secs_f64() - observer_time.get();
    stats.observer_wall = observer_time.get();
    stats.rhs_calls = rhs_calls.get();
    stats.jvp_calls = jvps.get();
    Ok(stats)
}

/// Integrate `model` from `y0` together with the forward sensitivities of
/// the state with respect to `params` (direct differentiation, paper Eqs.
/// 12–16): `ṡ_i = J s_i + ∂f/∂p_i`, both products exact
/// ([`OdeModel::rhs_dir`]). The initial state is taken as independent of
/// the parameters (`s_i(t0) = 0`). `observe(t, y, s)` gets `s`
/// lane-major: `s[i·n..(i+1)·n] = ∂y/∂p_i`. Sensitivities take part in
/// the error control. With [`Options::events`], `s` jumps at each change
/// of piece by `(f⁻ − f⁺) dt_e/dp` (module doc).
pub fn integrate_sens<M: OdeModel>(
    model: &M,
    y0: &[f64],
    opts: &Options,
    params: &[M::Param],
    mut observe: impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
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
            |x: &[f64], _p: &[f64], _t: f64, g: &mut [f64]| {
                model.roots(&ev.borrow(), &mut work.borrow_mut(), x, g)
            },
            |x: &[f64], _p: &[f64], _t: f64, v: &[f64], g: &mut [f64]| {
                model.roots_dir(&ev.borrow(), x, v, g)
            },
            // The switching surfaces do not depend on the parameters.
            |_x: &[f64], _p: &[f64], _t: f64, _v: &[f64], g: &mut [f64]| g.fill(0.0),
            nroots,
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
    let setup = |e: diffsol::error::DiffsolError| {
        Error::numerical("integrate_sens: solver set-up", e.to_string())
    };
    let mut legs = Legs {
        opts,
        nsens: np,
        next: 0,
        model,
        events: &ev,
        work: &work,
        params: (params, &p0),
    };
    let mut stats = Stats::default();
    loop {
        let (leg, event) = match opts.method {
            Method::Bdf => legs.drive(
                problem.bdf_sens::<FaerLU<f64>>().map_err(setup)?,
                &mut observe,
            )?,
            Method::Esdirk34 => legs.drive(
                problem.esdirk34_sens::<FaerLU<f64>>().map_err(setup)?,
                &mut observe,
            )?,
            Method::Tsit45 => legs.drive(problem.tsit45_sens().map_err(setup)?, &mut observe)?,
        };
        let Some(e) = legs.end_leg(&mut stats, (leg, event), &mut observe)? else {
            break;
        };
        problem.t0 = e.t;
        *start_y.borrow_mut() = e.y;
        *start_s.borrow_mut() = e.s;
    }
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

/// An accepted change of piece: time, state and sensitivities (before the
/// jump; [`Legs::jump`] applies it in place) and the crossing.
struct Event<C> {
    t: f64,
    y: Vec<f64>,
    s: Vec<f64>,
    crossing: C,
}

/// The legs of one integration: output bookkeeping across restarts.
struct Legs<'c, M: OdeModel> {
    opts: &'c Options,
    /// Sensitivity lanes (0 without sensitivities).
    nsens: usize,
    /// Next output time to emit.
    next: usize,
    model: &'c M,
    events: &'c RefCell<M::Events>,
    work: &'c RefCell<M::Work>,
    /// The sensitivity parameters and their values (empty without).
    params: (&'c [M::Param], &'c [f64]),
}

impl<M: OdeModel> Legs<'_, M> {
    /// Step a solver through the output times until the end or an
    /// accepted segment change; with `nsens > 0` the sensitivities
    /// (`nsens` lanes of the state length, lane-major) are interpolated
    /// too and handed to `observe` after the state. Outputs after an
    /// event are not served by this leg (its law is extended past the
    /// breakpoint there).
    fn drive<'a, Eqn, S>(
        &mut self,
        mut solver: S,
        observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
    ) -> Result<(Stats, Option<Event<M::Crossing>>)>
    where
        Eqn: diffsol::OdeEquations<T = f64, V = diffsol::FaerVec<f64>> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let opts = self.opts;
        let times = &opts.times;
        let nsens = self.nsens;
        let t_end = times[times.len() - 1];
        solver
            .set_stop_time(t_end)
            .map_err(|e| Error::numerical("integrate: stop time", e.to_string()))?;
        // Output times at the start (first leg only: later legs start
        // after the outputs already served).
        while self.next < times.len() && times[self.next] <= opts.t0 {
            let y = solver.state().y.clone_as_vec();
            // Initial sensitivities are zero (the initial state is given).
            let s0 = vec![0.0; y.len() * nsens];
            emit(times[self.next], &y, &s0, observe)?;
            self.next += 1;
        }
        let mut event = None;
        loop {
            let t_before = solver.state().t;
            let reason = solver.step().map_err(|e| {
                Error::numerical_at(
                    format!("integrate: {} step", opts.method.name()),
                    t_before,
                    e.to_string(),
                )
            })?;
            let mut t = solver.state().t;
            if let OdeSolverStopReason::RootFound(tr, idx) = reason {
                let yr = solver
                    .interpolate(tr)
                    .map_err(|e| Error::numerical_at("integrate: event state", tr, e.to_string()))?
                    .clone_as_vec();
                let crossing = self.model.classify(&self.events.borrow(), idx, &yr);
                if let Some(crossing) = crossing {
                    let s = if nsens > 0 {
                        solver
                            .interpolate_sens(tr)
                            .map_err(|e| {
                                Error::numerical_at(
                                    "integrate: event sensitivities",
                                    tr,
                                    e.to_string(),
                                )
                            })?
                            .clone_as_vec()
                    } else {
                        Vec::new()
                    };
                    t = tr;
                    event = Some(Event {
                        t: tr,
                        y: yr,
                        s,
                        crossing,
                    });
                }
            }
            while self.next < times.len() && times[self.next] <= t {
                let tq = times[self.next];
                if let Some(e) = event.as_ref().filter(|e| e.t == tq) {
                    emit(tq, &e.y, &e.s, observe)?;
                    self.next += 1;
                    continue;
                }
                let y = if tq == solver.state().t {
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
                self.next += 1;
            }
            if event.is_some()
                || matches!(reason, OdeSolverStopReason::TstopReached)
                || self.next >= times.len()
            {
                break;
            }
        }
        let st = solver.get_statistics();
        let stats = Stats {
            steps: st.number_of_steps,
            jacobians: st.number_of_linear_solver_setups,
            error_test_failures: st.number_of_error_test_failures,
            nonlinear_iterations: st.number_of_nonlinear_solver_iterations,
            nonlinear_failures: st.number_of_nonlinear_solver_fails,
            ..Stats::default()
        };
        Ok((stats, event))
    }

    /// The end of a leg: count it; at an event, switch the piece (the
    /// sensitivities jump), refreeze the model's pieces, and return the
    /// event when a new leg must start from it.
    fn end_leg(
        &mut self,
        stats: &mut Stats,
        leg: (Stats, Option<Event<M::Crossing>>),
        observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
    ) -> Result<Option<Event<M::Crossing>>> {
        stats.absorb(&leg.0);
        let Some(mut e) = leg.1 else { return Ok(None) };
        stats.events += 1;
        stats.last_event = Some(e.t);
        self.jump(&mut e)?;
        self.model
            .freeze(&self.events.borrow(), &mut self.work.borrow_mut());
        if !self.restart_or_finish(&e, observe)? {
            return Ok(None);
        }
        stats.restarts += 1;
        Ok(Some(e))
    }

    /// Switch the piece at event `e` and, with sensitivity lanes, apply
    /// the jump `s⁺ = s⁻ + (f⁻ − f⁺) dt_e/dp` with
    /// `dt_e/dp = −g_y s⁻ / (g_y f⁻)` (module doc; `g_p = 0`) in place.
    fn jump(&mut self, e: &mut Event<M::Crossing>) -> Result<()> {
        let (model, c) = (self.model, e.crossing);
        let mut ev = self.events.borrow_mut();
        if self.nsens == 0 {
            model.switch(&mut ev, c, &e.y);
            return Ok(());
        }
        let n = e.y.len();
        let mut work = self.work.borrow_mut();
        let (mut fm, mut fp) = (vec![0.0; n], vec![0.0; n]);
        model.freeze(&ev, &mut work);
        model.rhs(&mut work, e.t, &e.y, self.params, &mut fm);
        model.switch(&mut ev, c, &e.y);
        model.freeze(&ev, &mut work);
        model.rhs(&mut work, e.t, &e.y, self.params, &mut fp);
        let den = model.crossing_dir(&ev, c, &e.y, &fm);
        if den.is_nan() || den.abs() <= 1e-12 {
            return Err(Error::numerical_at(
                "integrate: segment event",
                e.t,
                format!(
                    "{} grazes a breakpoint (dθ/dt = {den:e}): the event \
                     time is not differentiable",
                    model.crossing_label(&ev, c)
                ),
            ));
        }
        for lane in e.s.chunks_mut(n) {
            let tau = -model.crossing_dir(&ev, c, &e.y, lane) / den;
            for k in 0..n {
                lane[k] += (fm[k] - fp[k]) * tau;
            }
        }
        Ok(())
    }

    /// After the switch at event `e` (sensitivities already jumped):
    /// whether a new leg must start. An event at the end time, or so close
    /// to it that no step fits (`≤ 1e-12 (1 + |t_end|)`), serves the
    /// remaining outputs from the event state instead.
    fn restart_or_finish(
        &mut self,
        e: &Event<M::Crossing>,
        observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
    ) -> Result<bool> {
        let times = &self.opts.times;
        if self.next >= times.len() {
            return Ok(false);
        }
        let t_end = times[times.len() - 1];
        if t_end - e.t > 1e-12 * (1.0 + t_end.abs()) {
            return Ok(true);
        }
        while self.next < times.len() {
            emit(times[self.next], &e.y, &e.s, observe)?;
            self.next += 1;
        }
        Ok(false)
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `ẏ = p` below `y = 1`, `ẏ = 2p` above: a piecewise-smooth scalar
    /// model with one switching surface `g = y − 1`, independent of `p`.
    /// The event state is the piece (0, 1), frozen into the work.
    struct Ramp;

    impl OdeModel for Ramp {
        type Param = ();
        type Work = usize;
        type Events = usize;
        type Crossing = usize;
        fn work(&self, _n: usize) -> usize {
            0
        }
        fn param_value(&self, _p: ()) -> Option<f64> {
            Some(1.0)
        }
        fn rhs(&self, w: &mut usize, _t: f64, _y: &[f64], p: (&[()], &[f64]), dy: &mut [f64]) {
            let p = p.1.first().copied().unwrap_or(1.0);
            dy[0] = if *w == 0 { p } else { 2.0 * p };
        }
        fn rhs_dir(
            &self,
            w: &mut usize,
            _t: f64,
            _y: &[f64],
            _p: (&[()], &[f64]),
            seeds: (Option<&[f64]>, Option<&[f64]>),
            out: &mut [f64],
        ) {
            // f does not depend on y; ∂f/∂p = 1 or 2.
            let vp = seeds.1.map_or(0.0, |v| v[0]);
            out[0] = if *w == 0 { vp } else { 2.0 * vp };
        }
        fn events(&self, _enabled: bool, _y0: &[f64]) -> usize {
            0
        }
        fn freeze(&self, ev: &usize, w: &mut usize) {
            *w = *ev;
        }
        fn nroots(&self, _ev: &usize) -> usize {
            1
        }
        fn roots(&self, ev: &usize, _w: &mut usize, y: &[f64], g: &mut [f64]) {
            g[0] = if *ev == 0 { y[0] - 1.0 } else { -1.0 };
        }
        fn roots_dir(&self, ev: &usize, _y: &[f64], v: &[f64], g: &mut [f64]) {
            g[0] = if *ev == 0 { v[0] } else { 0.0 };
        }
        fn classify(&self, ev: &usize, _idx: usize, y: &[f64]) -> Option<usize> {
            (*ev == 0 && (y[0] - 1.0).abs() < 1e-8).then_some(1)
        }
        fn switch(&self, ev: &mut usize, c: usize, _y: &[f64]) {
            *ev = c;
        }
        fn crossing_dir(&self, _ev: &usize, _c: usize, _y: &[f64], v: &[f64]) -> f64 {
            v[0]
        }
        fn crossing_label(&self, _ev: &usize, _c: usize) -> String {
            "ramp".into()
        }
    }

    #[test]
    fn piecewise_ramp_and_its_sensitivity_through_the_trait() {
        // Closed form at p = 1 from y(0) = 0: y = p t until the crossing
        // t_e = 1/p, then y = 1 + 2p (t − 1/p) = 2 p t − 1; so y(2) = 3
        // and s = ∂y/∂p = 2t after the event, s(2) = 4 (the jump at t_e
        // takes s from t_e = 1 to 2 t_e = 2: Hiskens & Pai with
        // dt_e/dp = −s⁻/f⁻ = −1 and f⁻ − f⁺ = −1).
        for method in [Method::Tsit45, Method::Bdf] {
            let opts = Options {
                method,
                rtol: 1e-10,
                atol: 1e-12,
                t0: 0.0,
                times: vec![0.5, 1.5, 2.0],
                events: true,
            };
            let mut out = Vec::new();
            let stats = integrate_sens(&Ramp, &[0.0], &opts, &[()], |t, y, s| {
                out.push((t, y[0], s[0]));
                Ok(())
            })
            .unwrap();
            assert_eq!(stats.events, 1, "{method:?}");
            for (t, y, s) in out {
                let (ye, se) = if t < 1.0 {
                    (t, t)
                } else {
                    (2.0 * t - 1.0, 2.0 * t)
                };
                assert!((y - ye).abs() < 1e-8, "{method:?} y({t}) = {y}");
                assert!((s - se).abs() < 1e-7, "{method:?} s({t}) = {s}");
            }
            let mut end = 0.0;
            integrate(&Ramp, &[0.0], &opts, |_, y| {
                end = y[0];
                Ok(())
            })
            .unwrap();
            assert!((end - 3.0).abs() < 1e-8, "{method:?} y(2) = {end}");
        }
    }
}
