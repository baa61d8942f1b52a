//! The end of a local run, settled: certified, polished when it stopped
//! short, and (for comparisons) moved strictly inside the feasible set.
//!
//! A local solver stops by its own rules (DOT's relative and absolute
//! change exits, an iteration limit, a line search that found nothing), so
//! its end point is not yet an optimum. [`settle`] decides what it is:
//!
//! 1. The Kuhn–Tucker certificate at the end ([`kkt::certify_at`], one
//!    evaluation with gradients): `converged`, `stopped` or `infeasible`
//!    (see [`crate::optimize::kkt`] for the formulas and tolerances). When
//!    the solver hands over its curvature model (MMFD's) it also tests at
//!    the noise allowance [`EndPolicy::noise`]: converged when the
//!    decrease a step could still make on that model is within it.
//! 2. When the end is not converged and the polish is on: MMFD continued
//!    from the end with [`MmfdOptions::polish_for`] (the active set from the
//!    first iteration, CTMIN = the feasibility tolerance, change exits at
//!    round-off, the Kuhn–Tucker exit at half the certificate's tolerance),
//!    and the certificate again at its end. An infeasible end that is a
//!    stationary point of the violation is not polished: descent on the
//!    violation cannot leave it, which is the answer for that start. Nor
//!    is one where the solver's own moves toward the feasible set found no
//!    decrease (MMFD's `infeasible`, SQP's `line_search_failed`).
//!    The polish's result replaces the solver's unless it is worse
//!    (feasible before and not after, or higher f at equal feasibility by
//!    more than the noise allowance [`EndPolicy::noise`] of
//!    `max(|f|, 1)`).
//! 3. When the end is still infeasible and the rescue is on
//!    (`[multistart] rescue`, default true): the pure descent on the
//!    violation from the run's start ([`violation::descend`], the
//!    objective playing no part, the descent that `violation_checks.csv`
//!    runs on a sample). Where it reaches the feasible set, its end is
//!    settled by steps 1–2 (certified, polished from there) and becomes the
//!    run's result; else the run stays infeasible, now with the answer that
//!    neither the solver's feasibility moves nor the pure descent reach the
//!    feasible set from that start. A solver's feasibility phase trades the
//!    violation against the objective and may descend into another basin
//!    of the violation than the pure descent (on the SAR problem, 2 of 4
//!    sampled infeasible ends of the first sweep were such starts), so
//!    with the rescue every run reaches the feasible set wherever the pure
//!    descent from its start does. The descent's calls count with the run.
//!
//! 4. [`return_to_best`]: when the run visited a feasible design lower
//!    than its settled end by more than the noise allowance
//!    ([`EndPolicy::noise`]), or its end is infeasible while it visited a
//!    feasible design, it returns to the lowest feasible design it
//!    visited ([`BestFeasible`] keeps them from the run's records) that is
//!    no less feasible than the end ([`lowest_comparable`]), certified
//!    there.
//!
//! Every evaluation goes through the caller's problem, so a counting
//! wrapper counts the certificate and the polish with the run.
//!
//! [`strictly_feasible`] is the comparison's step: from a design, the
//! polish (when not converged), then [`kkt::nudge_inside`] when the design
//! stands on the tolerance (`0 < max g <= feasibility`), so that every
//! method is compared at `max g <= 0`.

use super::violation;
use crate::error::Result;
use crate::optimize::kkt::{self, Certificate, EndClass, KktTolerances};
use crate::optimize::local::LocalSolver;
use crate::optimize::mmfd::MmfdOptions;
use crate::optimize::{
    Counted, IterRecord, LocalOutcome, NoObserver, Observer, Problem, Termination,
};

/// What happens at the end of every local run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EndPolicy {
    /// The certificate's tolerances (`[multistart] feasibility_tolerance`,
    /// `active_tolerance`, `kt_tolerance`).
    pub tolerances: KktTolerances,
    /// Polish the ends that are not converged (`[multistart] polish`).
    pub polish: bool,
    /// Rescue infeasible ends by the pure descent on the violation from
    /// the run's start (`[multistart] rescue`; step 3 of the module doc).
    pub rescue: bool,
    /// The rise of f, relative to `max(|f|, 1)`, that designs within the
    /// evaluation's noise may show: the polish's slope search tolerates it,
    /// and the polish's end replaces the solver's unless it is higher by
    /// more (`[multistart] noise`: measured by ECNoise, see
    /// [`crate::optimize::noise::Measured::allowance`], or given).
    pub noise: f64,
    /// The constraints' noise, absolute (3σ of the noisiest,
    /// [`crate::optimize::noise::Measured::allowance_g`]; 0 when not
    /// measured): [`strictly_feasible`] nudges a design this far below
    /// `g = 0` (at least 1e-12), so that its `max g <= 0` is not a jump of
    /// the noise.
    pub noise_g: f64,
}

/// The defaults of `[multistart]`: the certificate's default tolerances,
/// the polish and the rescue on, no noise allowance.
impl Default for EndPolicy {
    fn default() -> Self {
        EndPolicy {
            tolerances: KktTolerances::default(),
            polish: true,
            rescue: true,
            noise: 0.0,
            noise_g: 0.0,
        }
    }
}

/// A settled run end.
#[derive(Debug, Clone)]
pub struct Settled {
    /// The final outcome (the polish's when it was kept).
    pub outcome: LocalOutcome,
    /// Its certificate (`None` when it could not be computed; the reason is
    /// in `polish`).
    pub certificate: Option<Certificate>,
    /// How the polish of the solver's end went.
    pub polish: PolishEnd,
    /// What the rescue did (step 3 of the module doc); `None` when it did
    /// not run.
    pub rescue: Option<Rescue>,
    /// Step 4: the run went back to the lowest feasible design it visited;
    /// the f (and feasibility) of the end it left.
    pub returned: Option<Left>,
}

/// The end a run left for the lowest feasible design it visited (step 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Left {
    /// f at the end left.
    pub f: f64,
    /// `max_j g_j` at the end left.
    pub max_g: f64,
}

impl Settled {
    /// The `polish` column of `runs.csv`: the polish's text, then the
    /// certificate's test at the noise when it decided the class
    /// ([`kkt::AtNoise`]), the rescue's and step 4's after `; ` (empty
    /// when none ran).
    pub fn note(&self) -> String {
        let mut parts = vec![self.polish.text()];
        parts.extend(self.certificate.as_ref().and_then(|c| {
            let (left, allowance) = (c.decrease_left?, c.at_noise?);
            Some(format!(
                "converged at the noise: decrease left {left:.2e} <= allowance {allowance:.2e}"
            ))
        }));
        parts.extend(self.rescue.as_ref().map(Rescue::text));
        parts.extend(self.returned.map(|l| {
            format!(
                "returned to the lowest feasible design visited (the end left: f = {}, max g = {:.3e})",
                l.f, l.max_g
            )
        }));
        parts.retain(|p| !p.is_empty());
        parts.join("; ")
    }
}

/// Passes every record on and keeps the feasible ones (`max g <= tol`,
/// finite f): what step 4 may return to.
pub struct BestFeasible<'a> {
    inner: &'a mut dyn Observer,
    tol: f64,
    /// The feasible records so far, in the run's order.
    pub visited: Vec<IterRecord>,
}

impl<'a> BestFeasible<'a> {
    /// Watch the records passed to `inner` for feasibility within `tol`.
    pub fn new(inner: &'a mut dyn Observer, tol: f64) -> Self {
        BestFeasible {
            inner,
            tol,
            visited: Vec::new(),
        }
    }
}

impl Observer for BestFeasible<'_> {
    fn observe(&mut self, r: &IterRecord) {
        if r.max_g <= self.tol && r.f.is_finite() {
            self.visited.push(r.clone());
        }
        self.inner.observe(r);
    }
}

/// The lowest of the `visited` records that an end with largest
/// constraint `end_max_g` may return to: for a feasible end (`end_max_g <=
/// tol`) those no less feasible than it (`max g <= max(end_max_g, 0)`),
/// for an infeasible end every feasible one (`max g <= tol`).
///
/// Why not every design within the tolerance: at an active constraint a
/// design that uses more of the tolerance than the end buys f at the rate
/// of the multiplier (`Δf ≈ −λ Δg`), which is no better design. On HS 100
/// (16 starts, measured noise σ_f = 1e-13) comparing with every design
/// within 1e-6 sent all 16 runs from ends at `max g <= 2e-9` back to
/// designs at `max g` up to 9.8e-7 whose f was lower by up to 3.6e-5
/// (λ₁ = 145 on g₁ = c₁/127), 4 of them uncertified.
pub fn lowest_comparable(visited: &[IterRecord], end_max_g: f64, tol: f64) -> Option<&IterRecord> {
    let bound = if end_max_g <= tol {
        end_max_g.max(0.0)
    } else {
        tol
    };
    visited
        .iter()
        .filter(|r| r.max_g <= bound)
        .min_by(|a, b| a.f.total_cmp(&b.f))
}

/// Step 4 of the module doc: a run never ends above a feasible design it
/// visited by more than the noise. When the lowest comparable record of
/// the run ([`lowest_comparable`] of `visited`) lies lower than the
/// settled end by more than `policy.noise · max(|f|, 1)`, or the end is
/// infeasible, the run returns to it: certified there (one evaluation
/// with gradients, recorded to `observer` as the run's final check), and
/// taken unless that certificate cannot be computed or is worse than the
/// end's (a converged end is left only for a converged design).
pub fn return_to_best(
    problem: &dyn Problem,
    settled: Settled,
    visited: &[IterRecord],
    policy: &EndPolicy,
    observer: &mut dyn Observer,
) -> Settled {
    let tol = policy.tolerances.feasibility;
    let o = &settled.outcome;
    let max_g = o.g.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let end_max_g = if o.f.is_finite() {
        max_g
    } else {
        f64::INFINITY
    };
    let Some(b) = lowest_comparable(visited, end_max_g, tol) else {
        return settled;
    };
    let feasible_end = end_max_g <= tol;
    if feasible_end && o.f <= b.f + policy.noise * b.f.abs().max(1.0) {
        return settled;
    }
    let counted = Counted::new(problem);
    let there = LocalOutcome {
        x: b.x.clone(),
        f: b.f,
        g: b.g.clone(),
        // The solver's model is of its end, not of this design.
        curvature: None,
        ..o.clone()
    };
    let at = (o.function_calls, o.gradient_calls);
    let noisy = (at, policy.noise);
    let Ok((c, calls)) = certify_recorded(&counted, &there, noisy, &policy.tolerances, observer)
    else {
        let spent = (counted.function_calls(), counted.gradient_calls());
        return stay(settled, (at.0 + spent.0, at.1 + spent.1), observer);
    };
    let converged = |c: Option<&Certificate>| c.is_some_and(|c| c.class == EndClass::Converged);
    if converged(settled.certificate.as_ref()) && !converged(Some(&c)) {
        return stay(settled, calls, observer);
    }
    let left = Left { f: o.f, max_g };
    Settled {
        outcome: LocalOutcome {
            function_calls: calls.0,
            gradient_calls: calls.1,
            ..there
        },
        certificate: Some(c),
        returned: Some(left),
        ..settled
    }
}

/// The settled end stays the run's result after a look at a visited
/// design that spent `calls` in all: its counts become those, and it is
/// recorded once more, so that the history ends at the result with the
/// run's calls.
fn stay(settled: Settled, calls: (usize, usize), observer: &mut dyn Observer) -> Settled {
    let o = LocalOutcome {
        function_calls: calls.0,
        gradient_calls: calls.1,
        ..settled.outcome
    };
    observer.observe(&IterRecord {
        iteration: o.iterations,
        x: o.x.clone(),
        f: o.f,
        g: o.g.clone(),
        max_g: o.g.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ct: None,
        step: 0.0,
        function_calls: o.function_calls,
        gradient_calls: o.gradient_calls,
    });
    Settled {
        outcome: o,
        ..settled
    }
}

/// How the polish of a run's end went.
#[derive(Debug, Clone, PartialEq)]
pub enum PolishEnd {
    /// No polish ran: the end is converged, the polish is off, or descent
    /// on the violation cannot go on from an infeasible end.
    NotRun,
    /// The polish's end replaced the solver's; how the polish stopped.
    Replaced(Termination),
    /// The solver's end was kept: the polish ended worse (how it stopped,
    /// and its f).
    Kept(Termination, f64),
    /// The polish failed (the error's message).
    Failed(String),
    /// The certificate at the solver's end could not be computed (the
    /// error's message); no polish ran.
    CertificateFailed(String),
}

impl PolishEnd {
    /// Its text in `runs.csv` (empty for [`PolishEnd::NotRun`]).
    pub fn text(&self) -> String {
        match self {
            PolishEnd::NotRun => String::new(),
            PolishEnd::Replaced(t) => t.to_string(),
            PolishEnd::Kept(t, f) => format!("kept: the polish ended worse ({t}, f = {f})"),
            PolishEnd::Failed(e) => format!("error: {e}"),
            PolishEnd::CertificateFailed(e) => format!("error: certificate: {e}"),
        }
    }
}

/// What the rescue of an infeasible end did; `calls` are the descent's
/// (function, gradient) calls.
#[derive(Debug, Clone, PartialEq)]
pub enum Rescue {
    /// The descent on the violation failed (the error's message).
    Failed(String),
    /// The descent ended infeasible too, at this largest constraint.
    StayedInfeasible {
        /// `max_j g_j` at the descent's end.
        max_g: f64,
        /// The descent's calls.
        calls: (usize, usize),
    },
    /// The descent reached the feasible set; its end was settled again.
    Reached {
        /// The descent's calls.
        calls: (usize, usize),
        /// The polish from the descent's end.
        then: PolishEnd,
    },
}

impl Rescue {
    /// Its text in `runs.csv`'s `polish` column.
    pub fn text(&self) -> String {
        match self {
            Rescue::Failed(e) => format!("rescue: error: {e}"),
            Rescue::StayedInfeasible { max_g, calls } => format!(
                "rescue: the descent on the violation from the start ended infeasible too \
                 (max g = {max_g:.3e}, {} f + {} g)",
                calls.0, calls.1
            ),
            Rescue::Reached { calls, then } => {
                let then = match then.text().as_str() {
                    "" => String::new(),
                    p => format!("; then {p}"),
                };
                format!(
                    "rescued: the descent on the violation from the start reached the feasible \
                     set ({} f + {} g){then}",
                    calls.0, calls.1
                )
            }
        }
    }
}

/// Passes the polish's records on as continuations of the run: iteration
/// numbers and call counts after the solver's.
struct Continued<'a> {
    inner: &'a mut dyn Observer,
    iterations: usize,
    function_calls: usize,
    gradient_calls: usize,
    /// The last iteration number passed on.
    last: usize,
}

impl Observer for Continued<'_> {
    fn observe(&mut self, r: &IterRecord) {
        if r.iteration == 0 {
            return; // the start of the polish is the solver's end
        }
        let mut r = r.clone();
        r.iteration += self.iterations;
        r.function_calls += self.function_calls;
        r.gradient_calls += self.gradient_calls;
        self.last = r.iteration;
        self.inner.observe(&r);
    }
}

/// Is outcome `b` no worse than `a`: feasible (to `tol`) beats infeasible,
/// then lower f among feasible ends, up to `noise` of `max(|f|, 1)` (the
/// polish's noise allowance: its certified end may sit that much above an
/// uncertified one that a jump of the evaluation's noise put lower), lower
/// largest violation among infeasible ones.
fn no_worse(b: &LocalOutcome, a: &LocalOutcome, tol: f64, noise: f64) -> bool {
    let max_g = |o: &LocalOutcome| o.g.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (fa, fb) = (max_g(a) <= tol, max_g(b) <= tol);
    match (fa, fb) {
        (true, false) => false,
        (false, true) => true,
        (true, true) => b.f <= a.f + noise * a.f.abs().max(1.0),
        (false, false) => max_g(b) <= max_g(a),
    }
}

/// The certificate at `o`'s design, recorded to `observer` as a check of
/// the run's last iteration (one evaluation with gradients through
/// `counted`, whose calls are added to `calls`; its active set
/// `g_j >= −active` as the record's CT). With the solver's curvature
/// model (`o.curvature`) and a noise allowance (`noise`, relative to
/// `max(|f|, 1)`) the certificate also tests at the noise
/// ([`kkt::AtNoise`]). Returns the certificate and the calls after it.
fn certify_recorded(
    counted: &Counted<'_>,
    o: &LocalOutcome,
    (calls, noise): ((usize, usize), f64),
    tol: &KktTolerances,
    observer: &mut dyn Observer,
) -> Result<(Certificate, (usize, usize))> {
    let before = (counted.function_calls(), counted.gradient_calls());
    let at_noise = o.curvature.as_deref().map(|hessian| kkt::AtNoise {
        hessian,
        allowance: noise * o.f.abs().max(1.0),
    });
    let (ev, c) = kkt::certify_at_with(counted, &o.x, tol, at_noise)?;
    let calls = (
        calls.0 + counted.function_calls() - before.0,
        calls.1 + counted.gradient_calls() - before.1,
    );
    observer.observe(&IterRecord {
        iteration: o.iterations,
        x: o.x.clone(),
        f: ev.f,
        g: ev.g.clone(),
        max_g: ev.max_g(),
        ct: Some(-tol.active),
        step: 0.0,
        function_calls: calls.0,
        gradient_calls: calls.1,
    });
    Ok((c, calls))
}

/// Settle the solver's `outcome` of a run from `start` (see the module
/// doc; `None` when there is no start to rescue from). Each certificate is
/// recorded to `observer` as a final check of the run, and the polish's
/// iterations as continuations of it; the returned outcome's counts
/// include the certificates, the polish and the rescue.
pub fn settle(
    problem: &dyn Problem,
    start: Option<&[f64]>,
    outcome: LocalOutcome,
    policy: &EndPolicy,
    observer: &mut dyn Observer,
) -> Settled {
    let settled = settle_end(problem, outcome, policy, observer);
    let infeasible = settled
        .certificate
        .as_ref()
        .is_some_and(|c| c.class == EndClass::Infeasible);
    match start {
        Some(x0) if policy.rescue && infeasible => rescue(problem, x0, settled, policy, observer),
        _ => settled,
    }
}

/// Step 3 of the module doc: the pure descent on the violation from the
/// run's start ([`violation::descend`]); where it reaches the feasible set
/// its end is settled (certified, polished) and replaces the infeasible
/// end. The calls of the descent count with the run's; `polish` says what
/// the rescue did.
fn rescue(
    problem: &dyn Problem,
    x0: &[f64],
    settled: Settled,
    policy: &EndPolicy,
    observer: &mut dyn Observer,
) -> Settled {
    let counted = Counted::new(problem);
    let tol = policy.tolerances.feasibility;
    let descent = violation::descend(&counted, x0, tol);
    let calls = (counted.function_calls(), counted.gradient_calls());
    let (x, e, iterations) = match descent {
        Ok(d) => d,
        Err(e) => {
            return Settled {
                rescue: Some(Rescue::Failed(e.to_string())),
                ..settled
            }
        }
    };
    let max_g = e.max_g();
    let o = &settled.outcome;
    let (f_calls, g_calls) = (o.function_calls + calls.0, o.gradient_calls + calls.1);
    if max_g > tol {
        return Settled {
            rescue: Some(Rescue::StayedInfeasible { max_g, calls }),
            outcome: LocalOutcome {
                function_calls: f_calls,
                gradient_calls: g_calls,
                ..settled.outcome
            },
            ..settled
        };
    }
    let reached = LocalOutcome {
        x,
        f: e.f,
        g: e.g,
        iterations: o.iterations + iterations,
        function_calls: f_calls,
        gradient_calls: g_calls,
        active_constraints: 0,
        active_side_constraints: 0,
        termination: o.termination.clone(),
        curvature: None,
    };
    let again = settle_end(problem, reached, policy, observer);
    Settled {
        polish: settled.polish,
        rescue: Some(Rescue::Reached {
            calls,
            then: again.polish,
        }),
        ..again
    }
}

/// [`settle`] without the rescue.
fn settle_end(
    problem: &dyn Problem,
    outcome: LocalOutcome,
    policy: &EndPolicy,
    observer: &mut dyn Observer,
) -> Settled {
    let tol = &policy.tolerances;
    // One counter for the certificates and the polish: it starts from the
    // caller's last design when the caller counts (`Counted`), so that a
    // certificate at the design the solver has just evaluated counts as
    // the caller's counter counts it.
    let counted = Counted::new(problem);
    let calls = (outcome.function_calls, outcome.gradient_calls);
    let (first, calls) =
        match certify_recorded(&counted, &outcome, (calls, policy.noise), tol, observer) {
            Ok(c) => c,
            Err(e) => {
                return Settled {
                    outcome,
                    certificate: None,
                    polish: PolishEnd::CertificateFailed(e.to_string()),
                    rescue: None,
                    returned: None,
                }
            }
        };
    // No polish from an infeasible end where descent on the violation
    // cannot go on: a stationary point of the violation, or an end where
    // the solver's own moves toward the feasible set found no decrease
    // (MMFD's restoration, `infeasible`; SQP's elastic steps on the ℓ1
    // merit, `line_search_failed`): a kink of a peak constraint, which the
    // gradient test cannot see. The polish would repeat that restoration.
    let stuck = first.violation_stationary == Some(true)
        || (first.class == EndClass::Infeasible && stuck_exit(&outcome.termination));
    if !policy.polish || first.class == EndClass::Converged || stuck {
        return Settled {
            outcome: LocalOutcome {
                function_calls: calls.0,
                gradient_calls: calls.1,
                ..outcome
            },
            certificate: Some(first),
            polish: PolishEnd::NotRun,
            rescue: None,
            returned: None,
        };
    }
    let before = (counted.function_calls(), counted.gradient_calls());
    let mut continued = Continued {
        inner: observer,
        iterations: outcome.iterations,
        function_calls: calls.0,
        gradient_calls: calls.1,
        last: outcome.iterations,
    };
    let options = MmfdOptions::polish_for(tol).with_noise(policy.noise);
    let polished = LocalSolver::minimize(&options, &counted, &outcome.x, &mut continued);
    let last = continued.last;
    let polished = polished.and_then(|p| {
        let o = LocalOutcome {
            iterations: outcome.iterations + p.iterations,
            function_calls: calls.0 + p.function_calls,
            gradient_calls: calls.1 + p.gradient_calls,
            termination: outcome.termination.clone(),
            ..p.clone()
        };
        let at = (o.function_calls, o.gradient_calls);
        let (c, after) = certify_recorded(&counted, &o, (at, policy.noise), tol, observer)?;
        Ok((p.termination, o, c, after))
    });
    let (polish, c) = match polished {
        Ok((t, o, c, after)) if no_worse(&o, &outcome, tol.feasibility, options.noise) => {
            return Settled {
                polish: PolishEnd::Replaced(t),
                rescue: None,
                returned: None,
                outcome: LocalOutcome {
                    function_calls: after.0,
                    gradient_calls: after.1,
                    ..o
                },
                certificate: Some(c),
            }
        }
        Ok((t, o, _, _)) => (PolishEnd::Kept(t, o.f), o.iterations),
        Err(e) => (PolishEnd::Failed(e.to_string()), last),
    };
    // The solver's end stays the result: recorded once more after the
    // polish's iterations, so that the history ends at the result.
    let kept = Settled {
        outcome: LocalOutcome {
            iterations: c,
            ..outcome
        },
        certificate: Some(first),
        polish,
        rescue: None,
        returned: None,
    };
    let spent = (
        calls.0 + counted.function_calls() - before.0,
        calls.1 + counted.gradient_calls() - before.1,
    );
    stay(kept, spent, observer)
}

/// The solver exits that, at an infeasible end, say its own moves toward
/// the feasible set found no decrease there (step 2 of the module doc).
///
/// SQP's `line_search_failed` counts since 2026-12-02: on the 64-start SAR
/// sweep (`studies/sar_sweep64.toml`) the polish from its 22 infeasible
/// such ends cost 1016 f + 188 g in all (46 f + 9 g each) and reached the
/// feasible set from 2 of them, each by one long first restoration step,
/// not by descent; a new start of that sweep converges three times in
/// four for a median of 24.5 f + 19 g. The rescue from the run's start
/// stays (4 of those 22 runs converge by it).
fn stuck_exit(t: &Termination) -> bool {
    matches!(t, Termination::Infeasible | Termination::LineSearchFailed)
}

/// A design with `max g <= 0`, reached from `x` by the polish (when `x` is
/// not converged) and [`kkt::nudge_inside`]: the design, its objective and
/// largest constraint, or `None` when neither reaches `max g <= 0`.
pub fn strictly_feasible(
    problem: &dyn Problem,
    x: &[f64],
    policy: &EndPolicy,
) -> Result<Option<(Vec<f64>, f64, f64)>> {
    let start = problem.evaluate(x, false)?;
    let outcome = LocalOutcome {
        x: x.to_vec(),
        f: start.f,
        g: start.g.clone(),
        iterations: 0,
        function_calls: 0,
        gradient_calls: 0,
        active_constraints: 0,
        active_side_constraints: 0,
        termination: crate::optimize::Termination::MaxIterations,
        curvature: None,
    };
    let s = settle_end(problem, outcome, policy, &mut NoObserver);
    let end = s.outcome;
    let max_g = end.g.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max_g <= 0.0 {
        return Ok(Some((end.x, end.f, max_g)));
    }
    if max_g > policy.tolerances.feasibility {
        return Ok(None);
    }
    let ev = problem.evaluate(&end.x, true)?;
    let margin = policy.noise_g.max(1e-12);
    Ok(
        kkt::nudge_inside(problem, &end.x, &ev, margin)?.map(|(x, e)| {
            let m = e.max_g();
            (x, e.f, m)
        }),
    )
}

#[cfg(test)]
#[path = "settle_tests.rs"]
mod tests;
