//! Integration settings ([`Options`], [`Method`]) and statistics
//! ([`Stats`]).

use super::pair::Pair;
use crate::error::{Error, Result};
use diffsol::Tableau;

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
    /// Verner's explicit 6(5) pair (9 stages, FSAL) with its order-5
    /// continuous extension (one more stage per step whose dense output
    /// is read), stepped here (`super::erk`); sensitivities in the fused
    /// form only.
    Vern65,
}

impl Method {
    /// Name as written in study files.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Bdf => "bdf",
            Method::Tsit45 => "tsit45",
            Method::Esdirk34 => "esdirk34",
            Method::Vern65 => "vern65",
        }
    }

    /// The family of diffsol solvers the method belongs to, with its
    /// Butcher tableau; every form of integration (`super::legs`) builds
    /// its solver from this.
    pub(super) fn scheme(&self) -> Scheme {
        match self {
            Method::Bdf => Scheme::Bdf,
            Method::Tsit45 => Scheme::ExplicitRk(Tableau::tsit45()),
            Method::Esdirk34 => Scheme::Sdirk(Tableau::esdirk34()),
            Method::Vern65 => Scheme::Pair(Pair::vern65()),
        }
    }
}

/// A family of diffsol solvers ([`Method::scheme`]).
pub(super) enum Scheme {
    /// Variable-order BDF (implicit: needs a Newton matrix).
    Bdf,
    /// A singly diagonally implicit Runge–Kutta method with this tableau
    /// (implicit).
    Sdirk(Tableau<f64>),
    /// An explicit Runge–Kutta method with this tableau.
    ExplicitRk(Tableau<f64>),
    /// An explicit Runge–Kutta pair with more stages than diffsol's
    /// tableaus hold, stepped here (`super::erk`).
    Pair(Pair),
}

/// How forward sensitivities are integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SensitivityForm {
    /// diffsol's sensitivity equations: `J s_i` and `∂f/∂p_i` as two
    /// directional derivatives per lane and stage; every method.
    Staggered,
    /// The lanes ride in the state and `J s_i + ∂f/∂p_i` is one
    /// directional derivative per lane and stage (or Newton iterate);
    /// every method (implicit ones with the block-diagonal Newton matrix of
    /// `super::block_lu`).
    Fused,
}

impl SensitivityForm {
    /// The default form for `method`: fused, for every method (cheaper:
    /// one multi-lane evaluation per stage or Newton iterate, against two
    /// single-lane ones per lane for the staggered form; the same steps).
    pub fn default_for(method: Method) -> SensitivityForm {
        match method {
            Method::Tsit45 | Method::Bdf | Method::Esdirk34 | Method::Vern65 => {
                SensitivityForm::Fused
            }
        }
    }

    /// Name as written in study files.
    pub fn name(&self) -> &'static str {
        match self {
            SensitivityForm::Staggered => "staggered",
            SensitivityForm::Fused => "fused",
        }
    }
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The integration method.
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
    /// The form of forward sensitivities ([`SensitivityForm`]).
    pub sensitivity: SensitivityForm,
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
            let (first, last) = match (self.times.first(), self.times.last()) {
                (Some(a), Some(b)) => (a.to_string(), b.to_string()),
                _ => ("none".into(), "none".into()),
            };
            return Err(Error::input(
                "integrator.t_end",
                format!(
                    "t0 = {} s, {} output times from {first} s to {last} s",
                    self.t0,
                    self.times.len()
                ),
                "an end time > start time with increasing output times",
            ));
        }
        Ok(())
    }
}

/// Integrator statistics.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations (f64), counted by the system.
    pub rhs_calls: u64,
    /// Jacobian-vector products (each one dual-number evaluation).
    pub jvp_calls: u64,
    /// Jacobian / LU set-ups.
    pub jacobians: usize,
    /// Steps rejected by the local error test (retried smaller).
    pub error_test_failures: usize,
    /// Nonlinear-solver (Newton) iterations, as diffsol counts them.
    pub nonlinear_iterations: usize,
    /// Nonlinear-solver failures, as diffsol counts them (each retried
    /// with a smaller step).
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
    /// Close the counts of a whole integration started at `start`: wall
    /// time without the observer's `observer` seconds, and the calls.
    pub(super) fn finish(
        mut self,
        start: std::time::Instant,
        observer: f64,
        (rhs_calls, jvp_calls): (u64, u64),
    ) -> Stats {
        self.wall = start.elapsed().as_secs_f64() - observer;
        self.observer_wall = observer;
        self.rhs_calls = rhs_calls;
        self.jvp_calls = jvp_calls;
        self
    }

    pub(super) fn absorb(&mut self, leg: &Stats) {
        self.steps += leg.steps;
        self.jacobians += leg.jacobians;
        self.error_test_failures += leg.error_test_failures;
        self.nonlinear_iterations += leg.nonlinear_iterations;
        self.nonlinear_failures += leg.nonlinear_failures;
    }
}
