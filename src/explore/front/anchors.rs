//! The anchors of the gradient side (step 1 of [`super::gradient`]'s
//! module doc): each objective minimized alone from several starts, the
//! best run kept, then refined lexicographically. An objective that is a
//! maximum of smooth pieces is minimized as its epigraph
//! (`optimize::multiobjective`'s module doc).

use super::gradient::{certified, solve, GradientSettings, ANCHOR_CAP};
use crate::error::Result;
use crate::explore::persist::tables::RunRecord;
use crate::optimize::multiobjective::{EpsilonConstraint, MultiProblem, Tchebycheff};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The anchors' starts: the problem's start design `x0`, then
/// `anchor_starts − 1` seeded uniform random designs.
pub(super) fn anchor_starts(
    problem: &dyn MultiProblem,
    s: &GradientSettings,
    x0: &[f64],
    i: usize,
) -> Vec<Vec<f64>> {
    let mut starts = vec![x0.to_vec()];
    if !s.seeds.is_empty() {
        let mut order: Vec<&(Vec<f64>, Vec<f64>)> = s.seeds.iter().collect();
        order.sort_by(|a, b| a.1[i].total_cmp(&b.1[i]));
        let best = order.iter().map(|p| p.0.clone());
        starts.extend(best.cycle().take(s.anchor_starts.max(2) - 1));
        return starts;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    for _ in 1..s.anchor_starts.max(1) {
        starts.push(
            (problem.variables().iter())
                .map(|v| v.wrap(v.lower + rng.random::<f64>() * (v.upper - v.lower)))
                .collect(),
        );
    }
    starts
}

/// The order of runs of one scalarization, better first: certified, then
/// feasible to `tol`, then lower f (a run without a result or with a NaN
/// f last).
fn better(a: &RunRecord, b: &RunRecord, tol: f64) -> std::cmp::Ordering {
    let key = |r: &RunRecord| {
        let feasible = r.result.as_ref().is_some_and(|e| e.max_g() <= tol);
        let f = r.result.as_ref().map_or(f64::INFINITY, |e| e.f);
        let f = if f.is_nan() { f64::INFINITY } else { f };
        ((!certified(r, tol), !feasible), f)
    };
    let (ka, kb) = (key(a), key(b));
    ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
}

/// The best of one objective's first anchor runs ([`better`]).
pub(super) fn best_first(runs: &[RunRecord], tol: f64) -> RunRecord {
    runs.iter()
        .min_by(|a, b| better(a, b, tol))
        .expect("at least one start")
        .clone()
}

/// The design of a run's end: the first `n` values of its result (a
/// scalarization over `(x, t)` appends `t`).
pub(super) fn design(run: &RunRecord, n: usize) -> Option<Vec<f64>> {
    run.result.as_ref().map(|r| r.x[..n].to_vec())
}

/// One settled run minimizing objective `i` subject to `caps` (as
/// [`EpsilonConstraint`]'s) from the design `x0`: the ε-constraint
/// problem, or, when `f_i` is a maximum of pieces, its epigraph
/// ([`Tchebycheff::only`] with ideal 0, range 1, reference 0 and no
/// augmentation: minimize `t` with every piece at most `t`, so that the
/// end's f is `f_i`), started at `(x0, f_i(x0))`, whose one evaluation
/// is counted with the run.
pub(super) fn minimize_one(
    problem: &dyn MultiProblem,
    s: &GradientSettings,
    (i, caps): (usize, Vec<(usize, f64, f64)>),
    index: usize,
    x0: &[f64],
) -> Result<RunRecord> {
    let m = problem.objective_names().len();
    if problem.objective_pieces(i) <= 1 {
        let mut w = vec![0.0; m];
        w[i] = 1.0;
        return Ok(solve(
            &EpsilonConstraint::new(problem, w, caps),
            s,
            index,
            x0,
        ));
    }
    // t0 = f_i(x0), the largest piece: every epigraph row met, one active.
    let f0 = problem.evaluate(x0, false)?.f[i];
    let span = f0.abs().max(1.0);
    let t_bounds = (f0.min(0.0) - 2.0 * span, f0 + span);
    let p = Tchebycheff::new(
        problem,
        (vec![0.0; m], vec![1.0; m]),
        vec![0.0; m],
        0.0,
        t_bounds,
    )?
    .only(i)
    .capped(caps);
    let start: Vec<f64> = x0.iter().copied().chain([f0]).collect();
    let mut run = solve(&p, s, index, &start);
    run.function_calls += 1;
    Ok(run)
}

/// The lexicographic anchor of objective `i`: the sum of the other
/// objectives subject to `f_i <= f_i* + τ·max(1, |f_i*|)` (with two
/// objectives, the other one by [`minimize_one`], so that an objective
/// that is a maximum of pieces is minimized as its epigraph), from the
/// end of `first`, and once more from `x0` (calls counted together) when
/// that run is not certified, the [`better`] of the two kept; `first`
/// itself when it has no finite `f_i*`.
pub(super) fn lexicographic(
    problem: &dyn MultiProblem,
    s: &GradientSettings,
    i: usize,
    first: &RunRecord,
    x0: &[f64],
) -> Result<RunRecord> {
    let tol = s.end.tolerances.feasibility;
    let m = problem.objective_names().len();
    let fi = first.result.as_ref().map(|r| r.f);
    let (Some(fi), Some(end)) = (fi, design(first, x0.len())) else {
        return Ok(first.clone());
    };
    if !fi.is_finite() {
        return Ok(first.clone());
    }
    let scale = fi.abs().max(1.0);
    let cap = vec![(i, fi + ANCHOR_CAP * scale, scale)];
    let run = |from: &[f64]| -> Result<RunRecord> {
        if m == 2 {
            return minimize_one(problem, s, (1 - i, cap.clone()), i, from);
        }
        let w = (0..m).map(|j| if j == i { 0.0 } else { 1.0 }).collect();
        Ok(solve(
            &EpsilonConstraint::new(problem, w, cap.clone()),
            s,
            i,
            from,
        ))
    };
    let from_end = run(&end)?;
    if certified(&from_end, tol) {
        return Ok(from_end);
    }
    let again = run(x0)?;
    let calls = (
        from_end.function_calls + again.function_calls,
        from_end.gradient_calls + again.gradient_calls,
    );
    let mut kept = if better(&from_end, &again, tol).is_le() {
        from_end
    } else {
        again
    };
    (kept.function_calls, kept.gradient_calls) = calls;
    Ok(kept)
}
