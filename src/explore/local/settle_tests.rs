//! Tests of `settle`: the certificate, the polish, the rescue and step 4
//! on small analytic problems.

use super::*;
use crate::optimize::testproblems::islands;

const X_STAR: f64 = 2.109_381_364_946_409_5; // sqrt(2 + sqrt(6))

fn end(p: &dyn Problem, x: f64) -> LocalOutcome {
    let e = p.evaluate(&[x], false).unwrap();
    LocalOutcome {
        x: vec![x],
        f: e.f,
        g: e.g,
        iterations: 3,
        function_calls: 10,
        gradient_calls: 3,
        active_constraints: 0,
        active_side_constraints: 0,
        termination: Termination::RelativeChange,
        curvature: None,
    }
}

fn policy(polish: bool) -> EndPolicy {
    EndPolicy {
        tolerances: KktTolerances::default(),
        polish,
        rescue: false,
        noise: 1e-6,
        noise_g: 0.0,
    }
}

#[test]
fn a_stopped_end_is_polished_to_the_certified_optimum() {
    let p = islands();
    assert!((0.5 + X_STAR * X_STAR - 0.25 * X_STAR.powi(4)).abs() < 1e-12);
    // Without the polish: feasible, not stationary.
    let s = settle(&p, None, end(&p, 2.5), &policy(false), &mut NoObserver);
    let c = s.certificate.clone().unwrap();
    assert_eq!(c.class, EndClass::Stopped);
    assert_eq!(c.kt_residual, Some(1.0), "all of ∇f is left: {c:?}");
    assert_eq!((&s.polish, &s.rescue), (&PolishEnd::NotRun, &None));
    assert_eq!(s.note(), "");
    // With it: on the constraint, certified, the multiplier 1/|g'(x*)|.
    let s = settle(&p, None, end(&p, 2.5), &policy(true), &mut NoObserver);
    let c = s.certificate.as_ref().unwrap();
    assert_eq!(c.class, EndClass::Converged, "{s:?}");
    assert!((s.outcome.x[0] - X_STAR).abs() < 1e-6, "{s:?}");
    let lambda = 1.0 / (X_STAR.powi(3) - 2.0 * X_STAR);
    // The multiplier in scaled variables: ∂/∂y = 6 ∂/∂x for both, so
    // the ratio is the same.
    assert!(
        (c.multipliers[0].unwrap() - lambda).abs() < 1e-4 * lambda,
        "{c:?}"
    );
    // The solver's exit stays, the polish's is reported beside it.
    assert_eq!(s.outcome.termination, Termination::RelativeChange);
    assert!(matches!(s.polish, PolishEnd::Replaced(_)), "{s:?}");
    assert_eq!(s.note(), s.polish.text());
}

#[test]
fn an_end_at_a_local_minimum_of_the_violation_is_infeasible_and_stationary() {
    let p = islands();
    let s = settle(&p, None, end(&p, 0.0), &policy(true), &mut NoObserver);
    let c = s.certificate.unwrap();
    assert_eq!(c.class, EndClass::Infeasible);
    assert_eq!(c.violation_stationary, Some(true));
    assert_eq!(
        s.polish,
        PolishEnd::NotRun,
        "no polish from a stationary violation"
    );
    // Off the minimum of the violation: not stationary, and the polish
    // (MMFD's feasibility moves) reaches the feasible set.
    let s = settle(&p, None, end(&p, 1.9), &policy(false), &mut NoObserver);
    assert_eq!(s.certificate.unwrap().violation_stationary, Some(false));
    let s = settle(&p, None, end(&p, 1.9), &policy(true), &mut NoObserver);
    assert_eq!(
        s.certificate.unwrap().class,
        EndClass::Converged,
        "{:?}",
        s.polish
    );
    assert!((s.outcome.x[0] - X_STAR).abs() < 1e-6);
    // The same end left by a solver whose own moves toward the feasible
    // set failed there (SQP's failed line searches, MMFD's `infeasible`):
    // not polished, and the end stays the solver's.
    for t in [Termination::LineSearchFailed, Termination::Infeasible] {
        let stuck = LocalOutcome {
            termination: t.clone(),
            ..end(&p, 1.9)
        };
        let s = settle(&p, None, stuck, &policy(true), &mut NoObserver);
        assert_eq!(s.polish, PolishEnd::NotRun, "{t}");
        assert_eq!(s.certificate.unwrap().class, EndClass::Infeasible);
        assert_eq!((s.outcome.x, s.outcome.termination), (vec![1.9], t));
    }
}

#[test]
fn an_infeasible_end_is_rescued_by_the_descent_from_its_start() {
    let p = islands();
    let rescuing = EndPolicy {
        rescue: true,
        ..policy(true)
    };
    // The solver ended at the violation's local minimum x = 0 (g = 0.5),
    // but its start 1.9 lies beyond the violation's maximum at √2: the
    // pure descent from there reaches the feasible island x >= x*, and
    // the polish from its end the constrained minimum x*.
    let s = settle(&p, Some(&[1.9]), end(&p, 0.0), &rescuing, &mut NoObserver);
    let c = s.certificate.as_ref().unwrap();
    assert_eq!(c.class, EndClass::Converged, "{s:?}");
    assert!((s.outcome.x[0] - X_STAR).abs() < 1e-6, "{s:?}");
    assert!(matches!(s.rescue, Some(Rescue::Reached { .. })), "{s:?}");
    assert!(s.note().starts_with("rescued: the descent"), "{}", s.note());
    // The descent's and the polish's calls count with the run's 10 + 3.
    assert!(s.outcome.function_calls > 10 && s.outcome.gradient_calls > 3);
    // From 0.3 the descent ends at x = 0 too: still infeasible, said so.
    let s = settle(&p, Some(&[0.3]), end(&p, 0.0), &rescuing, &mut NoObserver);
    assert_eq!(s.certificate.as_ref().unwrap().class, EndClass::Infeasible);
    assert_eq!(s.outcome.x, vec![0.0]);
    assert!(
        matches!(s.rescue, Some(Rescue::StayedInfeasible { .. })),
        "{s:?}"
    );
    assert!(s.note().contains("ended infeasible too"), "{}", s.note());
    // Without the rescue the end stays as the solver left it.
    let s = settle(
        &p,
        Some(&[1.9]),
        end(&p, 0.0),
        &policy(true),
        &mut NoObserver,
    );
    assert_eq!(s.certificate.unwrap().class, EndClass::Infeasible);
}

#[test]
fn strictly_feasible_moves_a_design_on_the_tolerance_inside() {
    let p = islands();
    // 1e-7 left of x*: g = |g'(x*)| 1e-7 = 5.2e-7, within the 1e-6
    // tolerance and certified, but not strictly feasible.
    let x = X_STAR - 1e-7;
    let (x2, f, max_g) = strictly_feasible(&p, &[x], &policy(true)).unwrap().unwrap();
    assert!(max_g <= 0.0 && f >= X_STAR && (x2[0] - X_STAR).abs() < 1e-9);
    // A design far inside the infeasible gap has none.
    assert!(strictly_feasible(&p, &[0.0], &policy(true))
        .unwrap()
        .is_none());
}

/// A record of the run at `x` (feasible where `|x| >= X_STAR`).
fn record(p: &dyn Problem, x: f64) -> IterRecord {
    let e = p.evaluate(&[x], false).unwrap();
    IterRecord {
        iteration: 2,
        x: vec![x],
        f: e.f,
        max_g: e.max_g(),
        g: e.g,
        ct: None,
        step: 0.0,
        function_calls: 5,
        gradient_calls: 2,
    }
}

/// Step 4: min x on the islands problem. A run that visited the
/// feasible x = −3 (f = −3, the bound optimum) and ended at the
/// feasible x = 2.5 returns to −3, certified there (one gradient
/// call); an end within the noise allowance of the best is kept; the
/// observer keeps the lowest feasible record only.
#[test]
fn a_run_returns_to_the_lowest_feasible_design_it_visited() {
    let p = islands();
    let settled = |x: f64| settle(&p, None, end(&p, x), &policy(false), &mut NoObserver);
    let best = record(&p, -3.0);
    let s = return_to_best(
        &p,
        settled(2.5),
        std::slice::from_ref(&best),
        &policy(false),
        &mut NoObserver,
    );
    assert_eq!(s.outcome.x, vec![-3.0]);
    assert_eq!(s.outcome.f, -3.0);
    assert_eq!(
        s.certificate.as_ref().map(|c| c.class),
        Some(EndClass::Converged)
    );
    assert_eq!(s.returned.map(|l| l.f), Some(2.5));
    assert!(
        s.note().contains("returned to the lowest feasible design"),
        "{}",
        s.note()
    );
    assert_eq!(
        s.outcome.gradient_calls,
        settled(2.5).outcome.gradient_calls + 1
    );
    // Within the noise: x = −3 + 1e-7 against a best 1e-6 · 3 lower.
    let near = -3.0 + 1e-7;
    let kept = return_to_best(
        &p,
        settled(near),
        std::slice::from_ref(&best),
        &policy(false),
        &mut NoObserver,
    );
    assert_eq!(kept.outcome.x, vec![near]);
    assert!(kept.returned.is_none());
    let mut none = NoObserver;
    let mut watch = BestFeasible::new(&mut none, 0.0);
    for x in [2.5, 0.0, -3.0, 2.2] {
        watch.observe(&record(&p, x));
    }
    let lowest = lowest_comparable(&watch.visited, 0.0, 0.0);
    assert_eq!(lowest.map(|b| b.x.clone()), Some(vec![-3.0]));
}

/// The islands problem, failing when gradients are asked below
/// x = −2.9 (a design-dependent failure, as a modal basis whose
/// retained modes split a cluster).
struct FailsLow(crate::optimize::testproblems::Analytic);

impl Problem for FailsLow {
    fn variables(&self) -> &[crate::optimize::Variable] {
        self.0.variables()
    }
    fn n_constraints(&self) -> usize {
        self.0.n_constraints()
    }
    fn evaluate(
        &self,
        x: &[f64],
        gradients: bool,
    ) -> crate::error::Result<crate::optimize::Evaluation> {
        if gradients && x[0] < -2.9 {
            return Err(crate::error::Error::numerical("test", "no gradient here"));
        }
        self.0.evaluate(x, gradients)
    }
}

/// Step 4 that cannot certify the visited design (its evaluation
/// fails) keeps the end, counts the failed call, and records the end
/// once more with the run's calls, so that the history ends at the
/// result with the counts of `runs.csv`.
#[test]
fn a_failed_look_back_keeps_the_end_and_counts_its_call() {
    let p = FailsLow(islands());
    let s = settle(&p, None, end(&p, 2.5), &policy(false), &mut NoObserver);
    let before = (s.outcome.function_calls, s.outcome.gradient_calls);
    let mut history = crate::optimize::History::default();
    let kept = return_to_best(&p, s, &[record(&p, -3.0)], &policy(false), &mut history);
    assert_eq!(kept.outcome.x, vec![2.5]);
    assert!(kept.returned.is_none());
    let calls = (kept.outcome.function_calls, kept.outcome.gradient_calls);
    assert_eq!(calls, (before.0 + 1, before.1 + 1));
    let last = history.0.last().unwrap();
    assert_eq!(last.x, vec![2.5]);
    assert_eq!((last.function_calls, last.gradient_calls), calls);
}

/// Step 4 compares a feasible end only with designs no less feasible
/// than it: on `min x` s.t. `x >= 1` (g = 1 − x) with the tolerance
/// 1e-3, a visited x = 0.9995 (g = 5e-4, f lower by 5e-4) is no
/// better than the end x = 1 (g = 0); an end at g = 8e-4 may return
/// to it, and an infeasible end to any design within the tolerance.
#[test]
fn step_4_compares_designs_no_less_feasible_than_the_end() {
    let rec = |x: f64| IterRecord {
        iteration: 1,
        x: vec![x],
        f: x,
        g: vec![1.0 - x],
        max_g: 1.0 - x,
        ct: None,
        step: 0.0,
        function_calls: 1,
        gradient_calls: 1,
    };
    let visited = vec![rec(1.2), rec(0.9995), rec(1.0)];
    let x = |r: Option<&IterRecord>| r.map(|r| r.x[0]);
    assert_eq!(x(lowest_comparable(&visited, 0.0, 1e-3)), Some(1.0));
    assert_eq!(x(lowest_comparable(&visited, -0.1, 1e-3)), Some(1.0));
    assert_eq!(x(lowest_comparable(&visited, 8e-4, 1e-3)), Some(0.9995));
    assert_eq!(x(lowest_comparable(&visited, 0.5, 1e-3)), Some(0.9995));
    assert_eq!(x(lowest_comparable(&visited[1..2], -0.1, 1e-3)), None);
}
