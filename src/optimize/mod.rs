//! Optimization: one evaluation interface, local and global solvers.
//!
//! A [`Problem`] returns, for a design `x`, the objective `f`, the constraints
//! `g_j(x) <= 0` and, when asked, all their gradients in one call (an
//! expensive simulation produces them together). Variables carry bounds and
//! may be periodic (ply angles repeat every 180°): a periodic variable is
//! wrapped into its box, never stopped by a bound.
//!
//! [`Counted`] wraps a problem and counts function and gradient evaluations
//! in one place, like argmin's `Problem`. Solvers report per-iteration
//! [`IterRecord`]s to [`Observer`]s and never write files themselves.

use crate::error::{Error, Result};
use std::sync::atomic::{AtomicUsize, Ordering};

pub mod cmaes;
pub mod driver;
pub mod indicators;
pub mod kkt;
pub mod local;
pub mod mmfd;
pub mod mo_testproblems;
pub mod multiobjective;
pub mod noise;
pub mod nsga2;
pub mod qp;
pub mod sampling;
pub mod sqp;
pub mod testproblems;

/// One design variable: bounds and optional period.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Name used in reports (e.g. `theta1_deg`).
    pub name: String,
    /// Lower bound.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
    /// `Some(p)`: the problem is p-periodic in this variable and `upper -
    /// lower == p`; the solver wraps instead of stopping at a bound.
    pub period: Option<f64>,
}

impl Variable {
    /// A bounded, non-periodic variable.
    pub fn bounded(name: impl Into<String>, lower: f64, upper: f64) -> Result<Variable> {
        let name = name.into();
        if !(lower.is_finite() && upper.is_finite() && lower < upper) {
            return Err(Error::input(
                format!("{name}.bounds"),
                format!("[{lower}, {upper}]"),
                "finite bounds with lower < upper",
            ));
        }
        Ok(Variable {
            name,
            lower,
            upper,
            period: None,
        })
    }

    /// A periodic variable on `[lower, lower + period)`.
    pub fn periodic(name: impl Into<String>, lower: f64, period: f64) -> Result<Variable> {
        let name = name.into();
        if !(lower.is_finite() && period.is_finite() && period > 0.0) {
            return Err(Error::input(
                format!("{name}.period"),
                period,
                "a finite period > 0 and a finite lower bound",
            ));
        }
        Ok(Variable {
            name,
            lower,
            upper: lower + period,
            period: Some(period),
        })
    }

    /// Bring `x` into the box: wrap into `[lower, upper)` if periodic, clamp
    /// to `[lower, upper]` otherwise.
    pub fn wrap(&self, x: f64) -> f64 {
        match self.period {
            Some(p) => {
                let y = self.lower + (x - self.lower).rem_euclid(p);
                // rem_euclid can round up to exactly p for tiny negatives.
                if y >= self.upper {
                    self.lower
                } else {
                    y
                }
            }
            None => x.clamp(self.lower, self.upper),
        }
    }

    /// Signed shortest difference `a - b` (on the circle if periodic).
    pub fn difference(&self, a: f64, b: f64) -> f64 {
        match self.period {
            Some(p) => {
                let d = (a - b).rem_euclid(p);
                if d > 0.5 * p {
                    d - p
                } else {
                    d
                }
            }
            None => a - b,
        }
    }
}

/// What one evaluation returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Objective value.
    pub f: f64,
    /// Constraint values, feasible when `g[j] <= 0`.
    pub g: Vec<f64>,
    /// Gradient of `f` (length n) when gradients were asked for.
    pub grad_f: Option<Vec<f64>>,
    /// Gradients of each `g[j]` (m rows of length n) when asked for.
    pub grad_g: Option<Vec<Vec<f64>>>,
}

impl Evaluation {
    /// Largest constraint value (`-inf` when there are no constraints).
    pub fn max_g(&self) -> f64 {
        self.g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
}

/// An optimization problem: minimize `f(x)` subject to `g(x) <= 0` and the
/// variables' bounds. Implementations must be deterministic (same `x`, same
/// answer) and thread-safe: drivers evaluate many designs side by side.
pub trait Problem: Sync {
    /// The design variables.
    fn variables(&self) -> &[Variable];
    /// Number of inequality constraints `g_j <= 0`.
    fn n_constraints(&self) -> usize;
    /// Evaluate at `x`; with `gradients` also `grad_f` and `grad_g`.
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation>;
    /// Short name for reports.
    fn name(&self) -> &str {
        "problem"
    }
    /// What `f` is, with its unit, for plot axes (default: a dimensionless
    /// test function).
    fn objective_label(&self) -> String {
        "f [-]".into()
    }
    /// Variable `i` with its unit, for plot axes (default: its name, a
    /// dimensionless test variable).
    fn variable_label(&self, i: usize) -> String {
        format!("{} [-]", self.variables()[i].name)
    }
    /// The design of the last evaluation, when the problem keeps it (a
    /// [`Counted`] does): a counter wrapped around this one starts from it,
    /// so that nested counters count alike.
    fn last_evaluated(&self) -> Option<Vec<f64>> {
        None
    }
    /// The last evaluation with gradients and its design, when the problem
    /// keeps it (a [`Counted`] does): a certificate at that design needs no
    /// new evaluation.
    fn last_gradient(&self) -> Option<(Vec<f64>, Evaluation)> {
        None
    }
    /// What the evaluations so far need the user to know, one line each
    /// (e.g. a scene's mode count that split a repeated eigenvalue at some
    /// design; default: nothing).
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }
    /// The relative integration tolerance of a problem whose evaluation
    /// integrates a motion (`None`: a closed form, exact to rounding).
    fn tolerance(&self) -> Option<f64> {
        None
    }
    /// Integrate at the relative tolerance `rtol` from now on, the
    /// absolute tolerance following at the problem's own ratio atol/rtol;
    /// `false` (and nothing changed) for a problem that integrates nothing.
    fn set_tolerance(&mut self, _rtol: f64) -> bool {
        false
    }
}

/// Counts every evaluation of the wrapped problem, as DOT (the paper's
/// Table 5) and scipy's optimizers count: a function call is an
/// evaluation of f and g at a design not evaluated just before; a call
/// with gradients counts one gradient call, plus one function call unless
/// it is at the design of the evaluation just before (DOT asks for the
/// gradients of the design its line search has accepted, whose f and g it
/// already has; without its `speculative` option it evaluates no gradient
/// during the line search).
pub struct Counted<'a> {
    inner: &'a dyn Problem,
    function_calls: AtomicUsize,
    gradient_calls: AtomicUsize,
    /// The design of the last evaluation.
    last: std::sync::Mutex<Option<Vec<f64>>>,
    /// The last evaluation with gradients, with its design.
    last_gradient: std::sync::Mutex<Option<(Vec<f64>, Evaluation)>>,
}

impl<'a> Counted<'a> {
    /// Wrap `inner` with zeroed counters.
    pub fn new(inner: &'a dyn Problem) -> Self {
        Counted {
            inner,
            function_calls: AtomicUsize::new(0),
            gradient_calls: AtomicUsize::new(0),
            last: std::sync::Mutex::new(inner.last_evaluated()),
            last_gradient: std::sync::Mutex::new(inner.last_gradient()),
        }
    }
    /// Function evaluations so far.
    pub fn function_calls(&self) -> usize {
        self.function_calls.load(Ordering::Relaxed)
    }
    /// Gradient evaluations so far.
    pub fn gradient_calls(&self) -> usize {
        self.gradient_calls.load(Ordering::Relaxed)
    }
}

impl Problem for Counted<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        let known = match self.last.lock() {
            Ok(mut last) => {
                let known = last.as_deref() == Some(x);
                *last = Some(x.to_vec());
                known
            }
            Err(_) => false,
        };
        if !(gradients && known) {
            self.function_calls.fetch_add(1, Ordering::Relaxed);
        }
        if gradients {
            self.gradient_calls.fetch_add(1, Ordering::Relaxed);
        }
        let e = self.inner.evaluate(x, gradients)?;
        if gradients {
            if let Ok(mut last) = self.last_gradient.lock() {
                *last = Some((x.to_vec(), e.clone()));
            }
        }
        Ok(e)
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn objective_label(&self) -> String {
        self.inner.objective_label()
    }
    fn variable_label(&self, i: usize) -> String {
        self.inner.variable_label(i)
    }
    fn last_evaluated(&self) -> Option<Vec<f64>> {
        self.last.lock().ok().and_then(|l| l.clone())
    }
    fn last_gradient(&self) -> Option<(Vec<f64>, Evaluation)> {
        self.last_gradient.lock().ok().and_then(|l| l.clone())
    }
    fn notes(&self) -> Vec<String> {
        self.inner.notes()
    }
}

/// One iteration (local solver) or generation (evolutionary solver).
///
/// Local solvers (MMFD, steepest descent) record the start design first
/// (`iteration` 0, `step` 0, the calls of its evaluation), then the design
/// after each iteration (`iteration` = iterations completed). A last
/// record with the same `iteration` as the one before is the final check
/// at the design the solver stopped at (the gradient evaluation that found
/// nothing better): it counts calls and does not move. The last record's
/// calls are the run's.
#[derive(Debug, Clone, PartialEq)]
pub struct IterRecord {
    /// Iterations completed (local) or generation number from 0 (global).
    pub iteration: usize,
    /// Current (local) or best-so-far (global) design.
    pub x: Vec<f64>,
    /// Its objective.
    pub f: f64,
    /// Its constraint values `g_j` (feasible when `<= 0`).
    pub g: Vec<f64>,
    /// Its largest constraint value.
    pub max_g: f64,
    /// The constraint thickness the solver applies at this design: `g_j >=
    /// ct` is active (MMFD's CT, negative, shrinking towards −CTMIN);
    /// `None` for solvers without an active set.
    pub ct: Option<f64>,
    /// Step length taken in this iteration (or σ for CMA-ES).
    pub step: f64,
    /// Function evaluations so far.
    pub function_calls: usize,
    /// Gradient evaluations so far.
    pub gradient_calls: usize,
}

impl IterRecord {
    /// Indices of the constraints active at this design (`g_j >= ct`;
    /// none without a constraint thickness).
    pub fn active(&self) -> Vec<usize> {
        match self.ct {
            Some(ct) => (0..self.g.len()).filter(|&j| self.g[j] >= ct).collect(),
            None => Vec::new(),
        }
    }
}

/// Receives iteration records; CSV writers and progress bars implement it.
pub trait Observer {
    /// Called once per iteration.
    fn observe(&mut self, record: &IterRecord);
}

/// An observer that ignores everything.
pub struct NoObserver;

impl Observer for NoObserver {
    fn observe(&mut self, _record: &IterRecord) {}
}

/// An observer that keeps every record (for tests and histories).
#[derive(Default, Debug, Clone)]
pub struct History(pub Vec<IterRecord>);

impl Observer for History {
    fn observe(&mut self, record: &IterRecord) {
        self.0.push(record.clone());
    }
}

/// An observer that keeps every record with the wall time \[s\] since the
/// observer was made (make it just before the solver starts).
#[derive(Debug, Clone)]
pub struct TimedHistory {
    started: std::time::Instant,
    /// Records in order, each with its wall time since the start \[s\].
    pub records: Vec<(IterRecord, f64)>,
}

impl TimedHistory {
    /// An empty history whose clock starts now.
    pub fn start() -> TimedHistory {
        TimedHistory {
            started: std::time::Instant::now(),
            records: Vec::new(),
        }
    }
}

impl Observer for TimedHistory {
    fn observe(&mut self, record: &IterRecord) {
        let t = self.started.elapsed().as_secs_f64();
        self.records.push((record.clone(), t));
    }
}

/// Why a solver stopped. Solvers may add variants; reports print `Display`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Termination {
    /// |Δf| < DABOBJ for ITRMOP consecutive iterations.
    AbsoluteChange,
    /// |Δf|/|f| < DELOBJ for ITRMOP consecutive iterations.
    RelativeChange,
    /// The Kuhn–Tucker conditions hold to tolerance.
    KuhnTucker,
    /// The decrease a step could still make, on the solver's curvature
    /// model, is within the noise allowance of f (MMFD with a measured
    /// noise; [`kkt`]'s test at the noise).
    AtNoise,
    /// No usable-feasible direction exists.
    NoFeasibleDirection,
    /// Iteration limit reached.
    MaxIterations,
    /// Evaluation budget exhausted.
    MaxEvaluations,
    /// Evolution: step size or fitness range collapsed.
    Stagnation,
    /// Could not reach the feasible region.
    Infeasible,
    /// A feasible design reached the requested target objective.
    TargetReached,
    /// The line search found no decrease of the merit function, twice in
    /// a row (SQP).
    LineSearchFailed,
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = match self {
            Termination::AbsoluteChange => "absolute_change",
            Termination::RelativeChange => "relative_change",
            Termination::KuhnTucker => "kuhn_tucker",
            Termination::AtNoise => "at_noise",
            Termination::NoFeasibleDirection => "no_feasible_direction",
            Termination::MaxIterations => "max_iterations",
            Termination::MaxEvaluations => "max_evaluations",
            Termination::Stagnation => "stagnation",
            Termination::Infeasible => "infeasible",
            Termination::TargetReached => "target_reached",
            Termination::LineSearchFailed => "line_search_failed",
        };
        f.write_str(s)
    }
}

/// The end of a local (gradient-based) run, as the paper's Table 5 reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalOutcome {
    /// Final design (periodic variables wrapped into their box).
    pub x: Vec<f64>,
    /// Objective at `x`.
    pub f: f64,
    /// Constraints at `x`.
    pub g: Vec<f64>,
    /// Iterations performed.
    pub iterations: usize,
    /// Function evaluations used by this run.
    pub function_calls: usize,
    /// Gradient evaluations used by this run.
    pub gradient_calls: usize,
    /// Constraints active at the end (g >= CT).
    pub active_constraints: usize,
    /// Side constraints (bounds of non-periodic variables) active at the end.
    pub active_side_constraints: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// The solver's curvature model of the Lagrangian at `x`, in the
    /// range-scaled variables of [`kkt`] (`n × n`, row-major), when it
    /// keeps one (MMFD's damped BFGS model): the certificate's test at the
    /// noise reads it ([`kkt::AtNoise`]).
    pub curvature: Option<Vec<f64>>,
}

/// The end of a global (evolutionary) run.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalOutcome {
    /// Best design found (best feasible if any was feasible).
    pub x: Vec<f64>,
    /// Its objective.
    pub f: f64,
    /// Its constraints.
    pub g: Vec<f64>,
    /// Whether `x` satisfies every constraint (to the solver's tolerance).
    pub feasible: bool,
    /// Function evaluations used.
    pub function_calls: usize,
    /// Generations run (over all restarts).
    pub generations: usize,
    /// Restarts performed.
    pub restarts: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// One record per run (`restarts + 1`): regime, λ, σ0, evaluations.
    pub runs: Vec<cmaes::RunRecord>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_wrap_and_difference() {
        let v = Variable::periodic("theta", -90.0, 180.0).unwrap();
        assert_eq!(v.wrap(95.0), -85.0);
        assert_eq!(v.wrap(-90.0), -90.0);
        assert_eq!(v.wrap(90.0), -90.0);
        assert!((v.difference(89.9, -89.9) + 0.2).abs() < 1e-9);
        let b = Variable::bounded("x", -1.0, 1.0).unwrap();
        assert_eq!(b.wrap(3.0), 1.0);
        assert_eq!(b.difference(0.5, -0.5), 1.0);
        assert!(Variable::bounded("x", 1.0, -1.0).is_err());
    }

    /// DOT's and scipy's counting: gradients at the design evaluated just
    /// before add a gradient call only; anywhere else a function call too.
    #[test]
    fn gradients_of_the_last_design_count_no_function_call() {
        let p = testproblems::hs21();
        let c = Counted::new(&p);
        c.evaluate(&[2.0, 1.0], false).unwrap();
        c.evaluate(&[2.0, 1.0], true).unwrap();
        assert_eq!((c.function_calls(), c.gradient_calls()), (1, 1));
        c.evaluate(&[3.0, 1.0], true).unwrap();
        assert_eq!((c.function_calls(), c.gradient_calls()), (2, 2));
        c.evaluate(&[2.0, 0.0], false).unwrap();
        c.evaluate(&[3.0, 1.0], true).unwrap();
        assert_eq!((c.function_calls(), c.gradient_calls()), (4, 3));
        // A counter around this one knows its last design.
        let inner = Counted::new(&c);
        inner.evaluate(&[3.0, 1.0], true).unwrap();
        assert_eq!((inner.function_calls(), inner.gradient_calls()), (0, 1));
        assert_eq!((c.function_calls(), c.gradient_calls()), (4, 4));
    }
}
