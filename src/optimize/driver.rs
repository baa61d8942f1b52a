//! The loop that runs an argmin [`Solver`] and hands its per-iteration
//! records to an [`Observer`].
//!
//! argmin's `Executor` wants `'static` observers; ours are borrowed
//! (`&mut dyn Observer`: CSV writers, progress bars, a test's `History`),
//! so the `minimize` functions run the same protocol themselves: `init`,
//! then `next_iter` until `terminate_internal` says stop, incrementing the
//! iteration counter like the executor does. The solvers hold the last
//! [`IterRecord`]; only this loop passes it on.

use super::{
    Counted, Evaluation, IterRecord, LocalOutcome, Observer, Problem, Termination, Variable,
};
use crate::error::{Error, Result};
use argmin::core::{IterState, Problem as ArgminProblem, Solver, State};

/// The argmin state both solvers use: parameters and cost are `Vec<f64>`
/// and `f64`; gradients and Hessians live inside the solvers.
pub type OptState = IterState<Vec<f64>, (), (), (), (), f64>;

/// A solver that exposes the record of its last iteration.
pub trait Recorded {
    /// The next record not yet taken (each is taken once; the loop takes
    /// until `None` after every step).
    fn take_record(&mut self) -> Option<IterRecord>;
}

/// Map an argmin error back to the crate error it wraps.
pub fn from_argmin(e: argmin::core::Error) -> Error {
    match e.downcast::<Error>() {
        Ok(err) => err,
        Err(other) => Error::numerical("optimize (argmin)", other.to_string()),
    }
}

/// The number of constraints of the problem an argmin solver is given (0
/// when argmin holds none).
pub fn constraint_count(problem: &ArgminProblem<Counted<'_>>) -> usize {
    problem.problem.as_ref().map_or(0, |c| c.n_constraints())
}

/// Check that an evaluation has the sizes the problem declared and finite
/// values: `g` of length m, `grad_f` of length n and `grad_g` m × n when
/// gradients were asked for. Violations are numerical errors at `place`.
pub fn check_evaluation(
    ev: &Evaluation,
    x: &[f64],
    m: usize,
    gradients: bool,
    place: &str,
) -> Result<()> {
    let n = x.len();
    let fail = |d: String| Err(Error::numerical(place, format!("{d} at x = {x:?}")));
    if ev.g.len() != m {
        return fail(format!("{} constraint values, expected {m}", ev.g.len()));
    }
    if !ev.f.is_finite() || ev.g.iter().any(|v| !v.is_finite()) {
        return fail(format!("non-finite f = {} or g = {:?}", ev.f, ev.g));
    }
    if gradients {
        match &ev.grad_f {
            Some(gf) if gf.len() == n && gf.iter().all(|v| v.is_finite()) => {}
            _ => return fail("missing, mis-sized or non-finite grad_f".into()),
        }
        let ok = match &ev.grad_g {
            Some(gg) => {
                gg.len() == m
                    && gg
                        .iter()
                        .all(|r| r.len() == n && r.iter().all(|v| v.is_finite()))
            }
            None => m == 0,
        };
        if !ok {
            return fail("missing, mis-sized or non-finite grad_g".into());
        }
    }
    Ok(())
}

/// Run `solver` from `state` to termination, feeding `observer`.
pub fn run<'a, S>(
    solver: &mut S,
    problem: &mut ArgminProblem<Counted<'a>>,
    state: OptState,
    observer: &mut dyn Observer,
) -> Result<OptState>
where
    S: Solver<Counted<'a>, OptState> + Recorded,
{
    let (mut state, _) = solver.init(problem, state).map_err(from_argmin)?;
    while let Some(r) = solver.take_record() {
        observer.observe(&r);
    }
    loop {
        if solver.terminate_internal(&state).terminated() {
            break;
        }
        let (next, _) = solver.next_iter(problem, state).map_err(from_argmin)?;
        state = next;
        state.increment_iter();
        while let Some(r) = solver.take_record() {
            observer.observe(&r);
        }
    }
    Ok(state)
}

/// The argmin problem the solvers of this crate step on.
pub type Ap<'a> = ArgminProblem<Counted<'a>>;

/// The design variables of the wrapped problem (none if argmin has taken
/// the problem out, which it does not while a solver step runs).
pub fn variables<'p>(problem: &'p Ap<'_>) -> &'p [Variable] {
    problem.problem.as_ref().map_or(&[], |c| c.variables())
}

/// Evaluate `x` through argmin's counting (`cost_count` or
/// `gradient_count`) and check the evaluation ([`check_evaluation`], its
/// failures numerical errors at `place`).
pub fn evaluate(
    problem: &mut Ap<'_>,
    x: &[f64],
    gradients: bool,
    place: &str,
) -> Result<Evaluation> {
    let key = if gradients {
        "gradient_count"
    } else {
        "cost_count"
    };
    let ev = problem
        .problem(key, |c| {
            c.evaluate(x, gradients).map_err(argmin::core::Error::from)
        })
        .map_err(from_argmin)?;
    let m = constraint_count(problem);
    check_evaluation(&ev, x, m, gradients, place)?;
    Ok(ev)
}

/// Function and gradient calls of the wrapped problem so far.
pub fn counts(problem: &Ap<'_>) -> (usize, usize) {
    problem
        .problem
        .as_ref()
        .map(|c| (c.function_calls(), c.gradient_calls()))
        .unwrap_or((0, 0))
}

/// The end of a local run at `(x, f, g)` after `iterations`, with the
/// calls of `problem`: constraints with `g_j >= active_from` and the
/// non-periodic variables on a bound are counted active; no termination
/// means the iteration limit.
pub fn local_outcome(
    problem: &Ap<'_>,
    (x, f, g): (Vec<f64>, f64, Vec<f64>),
    active_from: f64,
    iterations: usize,
    termination: Option<Termination>,
) -> LocalOutcome {
    let (function_calls, gradient_calls) = counts(problem);
    let active_side_constraints = variables(problem)
        .iter()
        .zip(&x)
        .filter(|(v, &xi)| v.period.is_none() && (xi <= v.lower || xi >= v.upper))
        .count();
    let active_constraints = g.iter().filter(|&&gj| gj >= active_from).count();
    LocalOutcome {
        x,
        f,
        g,
        iterations,
        function_calls,
        gradient_calls,
        active_constraints,
        active_side_constraints,
        termination: termination.unwrap_or(Termination::MaxIterations),
        curvature: None,
    }
}
