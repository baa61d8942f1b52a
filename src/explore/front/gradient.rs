//! The gradient side of a Pareto front: a parallel multistart of
//! scalarized subproblems, each solved by MMFD or SQP (`[front] method`)
//! with the objectives' exact gradients and settled (certified, polished)
//! as a multistart run is ([`crate::explore::local::settle`]).
//!
//! 1. **Anchors** (one per objective `i`, in parallel): minimize `f_i` from
//!    the problem's start design and `anchor_starts − 1` seeded uniform
//!    random designs, and keep the best end (certified first, then lowest
//!    `f_i`); then, lexicographically, minimize the sum
//!    of the other objectives subject to `f_i <= f_i* + τ·max(1, |f_i*|)`
//!    with `τ = 1e-4` (both [`EpsilonConstraint`] problems), from the first
//!    run's end, and once more from the start design when that run does not
//!    end certified (e.g. an end on ZDT1's `x1 = 0`, where `∂f2/∂x1` is
//!    unbounded); both runs are counted. The anchors give the ideal point `z_j = min_i f_j(a_i)`
//!    and the payoff-table nadir `N_j = max_i f_j(a_i)`; the ranges are
//!    `s_j = N_j − z_j` (1 where that vanishes).
//! 2. **Subproblems** (in parallel): the augmented reference-point
//!    Tchebycheff problem ([`Tchebycheff`], `ρ = 1e-4`) for reference
//!    points `r = (m − 1)·λ` on the simplex lattice of the `m`
//!    objectives (Das & Dennis 1998) in normalized objectives: for two
//!    objectives `λ = (k/(K+1), 1 − k/(K+1))`, `k = 1..K` (the segment
//!    between the anchors, whose ends are the anchors); for three the
//!    lattice with the most points `≤ K`, edges included, so that the
//!    front's corners beyond the anchors' triangle are reached. Each starts
//!    from the anchors' designs weighted by `λ` (wrapped into the box; the
//!    problem's start design when an anchor is not certified) with `t` at
//!    its smallest feasible value, `t ∈ [−m − 1, max(t0, 0) + 1]`, and
//!    once more from the start design when that run does not end
//!    certified (both counted).
//!    With `refine` (two objectives), further subproblems where the front
//!    found so far has its largest gaps ([`super::gaps`]).
//! 3. **The front**: the ends certified `converged` (feasible, Kuhn–Tucker)
//!    of the lexicographic anchors and the subproblems, evaluated once more
//!    for their objectives, and of those the non-dominated ones (equal
//!    points once).
//!
//! Every evaluation is counted: the anchors', the subproblems' (with their
//! certificates and polishes) and the final objective evaluations.

use super::anchors::{anchor_starts, best_first, design, lexicographic, minimize_one};
use crate::error::{Error, Result};
use crate::explore::local::settle::EndPolicy;
use crate::explore::local::solvers::LocalSolver;
use crate::explore::multistart::cluster::scaled_distance;
use crate::explore::multistart::driver::one_run;
use crate::explore::persist::tables::{class_name, RunRecord};
use crate::optimize::kkt::EndClass;
use crate::optimize::mo_testproblems::simplex_lattice;
use crate::optimize::multiobjective::{dominates, EpsilonConstraint, MultiProblem, Tchebycheff};
use crate::optimize::noise::{estimate, NoiseOptions};
use crate::optimize::{NoObserver, Problem, Variable};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

/// Relative cap `τ` of the lexicographic anchors.
pub const ANCHOR_CAP: f64 = 1e-4;
/// Augmentation `ρ` of the Tchebycheff subproblems.
pub const RHO: f64 = 1e-4;

/// What the gradient side needs besides the problem.
#[derive(Clone)]
pub struct GradientSettings {
    /// Number of subproblems `K` (at most; see the module doc).
    pub subproblems: usize,
    /// Worker threads.
    pub threads: usize,
    /// The local solver of every anchor and subproblem (`[front] method`,
    /// built by [`crate::explore::local::solvers::local`]).
    pub solver: Arc<dyn LocalSolver>,
    /// Subproblems placed in the largest gaps of the front found so far,
    /// after the lattice's (two objectives; [`super::gaps`]).
    pub refine: usize,
    /// Certificate and polish of every end.
    pub end: EndPolicy,
    /// Starts of each anchor's first run: the start design, then uniform
    /// random designs (>= 1).
    pub anchor_starts: usize,
    /// Seed of those random starts.
    pub seed: u64,
    /// The noise σ of each objective at the start (absolute, in its own
    /// units; 0 where ECNoise found it smooth): the Tchebycheff
    /// subproblems' allowance is taken from it once the ranges are known
    /// ([`tchebycheff_settings`]).
    pub objective_sigma: Vec<f64>,
    /// Designs with their objectives found by another method (the hybrid's
    /// NSGA-II, [`super::hybrid`]); empty for the pure gradient side. With
    /// seeds, the anchors start from the start design and the seeds best
    /// in their objective (instead of random designs; at least one), and
    /// each lattice
    /// subproblem from the seed nearest its ray (instead of the anchors'
    /// blend).
    pub seeds: Vec<(Vec<f64>, Vec<f64>)>,
}

impl GradientSettings {
    /// One subproblem on one thread by `solver`'s runs settled by `end`:
    /// no gap subproblems, one anchor start, seed 0, no noise, no seeds
    /// (the fields to change are then set by name).
    pub fn new(solver: Arc<dyn LocalSolver>, end: EndPolicy) -> GradientSettings {
        GradientSettings {
            subproblems: 1,
            threads: 1,
            solver,
            refine: 0,
            end,
            anchor_starts: 1,
            seed: 0,
            objective_sigma: vec![],
            seeds: vec![],
        }
    }
}

/// The settings of the Tchebycheff subproblems: their constraints
/// `u_i − r_i − t <= 0` with `u_i = (f_i − z_i)/s_i` carry each
/// objective's noise divided by its range, `3σ_i/s_i`, and so does their
/// objective `t + ρ Σ u_i`; the end policy's allowances (of f, relative to
/// `max(|t|, 1)`, and of g) are raised to the largest of these. On the
/// deployable panel's front the ranges are 0.06 J·s and 0.017 s, so the
/// allowance taken from the objectives themselves was 17–60× too small.
pub fn tchebycheff_settings(s: &GradientSettings, scale: &[f64]) -> GradientSettings {
    let a = s
        .objective_sigma
        .iter()
        .zip(scale)
        .map(|(sigma, range)| 3.0 * sigma / range)
        .fold(0.0, f64::max);
    let mut sub = s.clone();
    sub.end.noise = sub.end.noise.max(a);
    sub.end.noise_g = sub.end.noise_g.max(a);
    sub
}

/// One settled end of the gradient side.
#[derive(Debug, Clone)]
pub struct SubproblemEnd {
    /// `anchor-<objective>`, `lexicographic-<objective>` or
    /// `subproblem-<k>`.
    pub label: String,
    /// The run (its design includes `t` for a subproblem).
    pub run: RunRecord,
    /// The end is certified `converged` (feasible, Kuhn–Tucker).
    pub certified: bool,
    /// The objectives at the end's design (minimized orientation), for a
    /// certified end that enters the front (the lexicographic anchors and
    /// the subproblems).
    pub f: Option<Vec<f64>>,
}

/// The gradient side's result.
#[derive(Debug, Clone)]
pub struct GradientFront {
    /// Non-dominated certified designs and their objectives (minimized
    /// orientation), in the order of the ends.
    pub points: Vec<(Vec<f64>, Vec<f64>)>,
    /// Every end, anchors first.
    pub ends: Vec<SubproblemEnd>,
    /// Ideal point from the anchors.
    pub ideal: Vec<f64>,
    /// Payoff-table nadir from the anchors.
    pub nadir: Vec<f64>,
    /// Function calls, all included.
    pub function_calls: usize,
    /// Gradient calls, all included.
    pub gradient_calls: usize,
    /// Wall time \[s\].
    pub wall_seconds: f64,
}

impl GradientFront {
    /// How many ends are certified `converged`.
    pub fn certified(&self) -> usize {
        self.ends.iter().filter(|e| e.certified).count()
    }
}

/// The normalized reference points of the module doc for `m` objectives
/// and at most `k` subproblems.
pub fn reference_points(m: usize, k: usize) -> Vec<Vec<f64>> {
    let scale = (m - 1) as f64;
    if m == 2 {
        return (1..=k)
            .map(|i| {
                let l = i as f64 / (k + 1) as f64;
                vec![scale * l, scale * (1.0 - l)]
            })
            .collect();
    }
    let mut h = 1;
    while simplex_lattice(m, h + 1).len() <= k {
        h += 1;
    }
    simplex_lattice(m, h)
        .into_iter()
        .map(|l| l.iter().map(|v| scale * v).collect())
        .collect()
}

/// The start of the subproblem with reference point `r`: the anchors'
/// designs weighted by `λ = r/(m − 1)` (wrapped into the box), when every
/// anchor is certified.
fn between_anchors(
    problem: &dyn MultiProblem,
    anchors: &[Option<Vec<f64>>],
    r: &[f64],
) -> Option<Vec<f64>> {
    let m = anchors.len();
    let xs: Vec<&Vec<f64>> = anchors.iter().map(|a| a.as_ref()).collect::<Option<_>>()?;
    let vars = problem.variables();
    Some(
        (0..vars.len())
            .map(|j| {
                let v: f64 = xs
                    .iter()
                    .zip(r)
                    .map(|(x, l)| x[j] * l / (m - 1) as f64)
                    .sum();
                vars[j].wrap(v)
            })
            .collect(),
    )
}

/// The design of the seed nearest the ray `r + t·1` in the objectives
/// normalized by `(ideal, scale)`: the seed whose `u − r` is closest to a
/// multiple of `1` (smallest `max_i − min_i` of `u_i − r_i`), or `None`
/// without seeds.
fn nearest_seed(
    seeds: &[(Vec<f64>, Vec<f64>)],
    r: &[f64],
    (ideal, scale): (&[f64], &[f64]),
) -> Option<Vec<f64>> {
    let off = |f: &[f64]| {
        let d: Vec<f64> = (0..r.len())
            .map(|i| (f[i] - ideal[i]) / scale[i] - r[i])
            .collect();
        let hi = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let lo = d.iter().copied().fold(f64::INFINITY, f64::min);
        hi - lo
    };
    seeds
        .iter()
        .min_by(|a, b| off(&a.1).total_cmp(&off(&b.1)))
        .map(|p| p.0.clone())
}

/// One settled run of `p` from `x0` by the settings' solver.
pub(super) fn solve(p: &dyn Problem, s: &GradientSettings, index: usize, x0: &[f64]) -> RunRecord {
    one_run(p, s.solver.as_ref(), &s.end, index, x0, &mut NoObserver)
}

/// Is the run's end certified (converged and feasible to the tolerance)?
pub(super) fn certified(run: &RunRecord, tol: f64) -> bool {
    run.certificate
        .as_ref()
        .is_some_and(|c| c.class == EndClass::Converged && c.max_g <= tol)
        && run.result.is_some()
}

/// The objectives at a certified end's design (its first `n` values),
/// counted into `calls`.
pub(super) fn objectives(
    problem: &dyn MultiProblem,
    run: &RunRecord,
    tol: f64,
    calls: &mut usize,
) -> Result<Option<Vec<f64>>> {
    if !certified(run, tol) {
        return Ok(None);
    }
    let n = problem.variables().len();
    let x = &run.result.as_ref().expect("certified runs have a result").x[..n];
    *calls += 1;
    let e = problem.evaluate(x, false)?;
    Ok(e.f.iter().all(|v| v.is_finite()).then_some(e.f))
}

/// The noise allowance of the subproblems' ends (`EndPolicy::noise`):
/// the largest over the objectives of ECNoise's allowance at the start
/// design (3σ of the objective relative to `max(|f_i|, 1)`,
/// [`crate::optimize::noise::Measured::allowance`]; 0 for an objective
/// smooth at every step tried, as a closed form is); the constraints'
/// allowance (absolute, [`crate::optimize::noise::Measured::allowance_g`])
/// over the problem's constraints and the objectives themselves, which
/// the ε-constraint subproblems bound; each objective's σ (absolute, for
/// [`tchebycheff_settings`]); and the function calls it took. A weighted
/// sum of the objectives has a noise relative to its own value of at most
/// about the largest of theirs.
pub fn subproblem_noise(
    problem: &dyn MultiProblem,
    seed: u64,
) -> Result<(f64, f64, Vec<f64>, usize)> {
    let x0 = problem.start();
    let m = problem.objective_names().len();
    let (mut allowance, mut allowance_g): (f64, f64) = (0.0, 0.0);
    let mut sigmas = Vec::new();
    let mut calls = 0;
    for i in 0..m {
        let mut w = vec![0.0; m];
        w[i] = 1.0;
        let one = EpsilonConstraint::new(problem, w, vec![]);
        let measured = estimate(&one, &x0, seed, &NoiseOptions::default())?;
        allowance = allowance.max(measured.allowance());
        let sigma_f = measured.noise_f.sigma().unwrap_or(0.0);
        allowance_g = allowance_g.max(measured.allowance_g()).max(3.0 * sigma_f);
        sigmas.push(sigma_f);
        calls += measured.evaluations;
    }
    Ok((allowance, allowance_g, sigmas, calls))
}

/// Build the front's gradient side (see the module doc).
pub fn gradient_front(problem: &dyn MultiProblem, s: &GradientSettings) -> Result<GradientFront> {
    let t0 = Instant::now();
    let tol = s.end.tolerances.feasibility;
    let m = problem.objective_names().len();
    if !(2..=3).contains(&m) {
        return Err(Error::input(
            "objectives",
            format!("({m} objectives)"),
            "2 or 3 objectives",
        ));
    }
    let x0 = problem.start();
    let pool = crate::explore::context::thread_pool(s.threads)?;
    let names = problem.objective_names();
    // 1. Anchors from every start, the best of each objective, and its
    // lexicographic refinement.
    let starts: Vec<Vec<Vec<f64>>> = (0..m).map(|i| anchor_starts(problem, s, &x0, i)).collect();
    let per = starts[0].len();
    let pairs: Vec<(usize, usize)> = (0..m).flat_map(|i| (0..per).map(move |k| (i, k))).collect();
    let firsts: Vec<RunRecord> = pool.install(|| {
        pairs
            .par_iter()
            .map(|&(i, k)| minimize_one(problem, s, (i, vec![]), i, &starts[i][k]))
            .collect::<Result<_>>()
    })?;
    let best: Vec<RunRecord> = (0..m)
        .map(|i| best_first(&firsts[i * per..(i + 1) * per], tol))
        .collect();
    let anchors: Vec<RunRecord> = pool.install(|| {
        (0..m)
            .into_par_iter()
            .map(|i| lexicographic(problem, s, i, &best[i], &x0))
            .collect::<Result<_>>()
    })?;
    let mut extra_calls = 0;
    let mut ends = Vec::new();
    for ((i, k), first) in pairs.iter().zip(firsts) {
        ends.push(SubproblemEnd {
            label: format!("anchor-{}-start-{k}", names[*i]),
            certified: certified(&first, tol),
            run: first,
            f: None,
        });
    }
    let mut anchor_x: Vec<Option<Vec<f64>>> = vec![None; m];
    for (i, second) in anchors.into_iter().enumerate() {
        let f = objectives(problem, &second, tol, &mut extra_calls)?;
        if f.is_some() {
            anchor_x[i] = design(&second, x0.len());
        }
        ends.push(SubproblemEnd {
            label: format!("lexicographic-{}", names[i]),
            certified: certified(&second, tol),
            run: second,
            f,
        });
    }
    let anchor_f: Vec<&Vec<f64>> = ends.iter().filter_map(|e| e.f.as_ref()).collect();
    if anchor_f.is_empty() {
        return Err(Error::numerical(
            "explore::front",
            format!(
                "no anchor (single-objective optimum) was certified: {}",
                ends.iter()
                    .map(|e| format!("{} {} ({})", e.label, class_name(&e.run), e.run.exit))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        ));
    }
    let (ideal, nadir, scale) = ideal_and_nadir(&anchor_f, m);
    let s = &tchebycheff_settings(s, &scale);
    // 2. The subproblems.
    let refs = reference_points(m, s.subproblems);
    let runs: Vec<Result<(RunRecord, usize)>> = pool.install(|| {
        refs.par_iter()
            .enumerate()
            .map(|(k, r)| {
                let start = match nearest_seed(&s.seeds, r, (&ideal, &scale)) {
                    Some(x) => x,
                    None => between_anchors(problem, &anchor_x, r).unwrap_or_else(|| x0.clone()),
                };
                subproblem(problem, s, (k, r), (&ideal, &scale), &start, &x0)
            })
            .collect()
    });
    for (k, run) in runs.into_iter().enumerate() {
        let (run, probes) = run?;
        extra_calls += probes;
        let f = objectives(problem, &run, tol, &mut extra_calls)?;
        ends.push(SubproblemEnd {
            label: format!("subproblem-{k}"),
            certified: certified(&run, tol),
            run,
            f,
        });
    }
    // Subproblems in the largest gaps of the front found so far.
    if m == 2 && s.refine > 0 {
        let norm = (ideal.as_slice(), scale.as_slice());
        extra_calls += super::gaps::refine(problem, s, &pool, norm, &x0, &mut ends)?;
    }
    // 3. The non-dominated certified ends.
    let vars = problem.variables();
    let points = non_dominated_ends(vars.len(), Merge::Designs(vars), &ends);
    // Extra calls: the subproblems' start evaluations and the final
    // objective evaluations.
    let function_calls = ends.iter().map(|e| e.run.function_calls).sum::<usize>() + extra_calls;
    let gradient_calls = ends.iter().map(|e| e.run.gradient_calls).sum();
    Ok(GradientFront {
        points,
        ends,
        ideal,
        nadir,
        function_calls,
        gradient_calls,
        wall_seconds: t0.elapsed().as_secs_f64(),
    })
}

/// The ideal point `z_j = min_i f_j(a_i)`, the payoff-table nadir
/// `N_j = max_i f_j(a_i)` of the anchors' objectives, and the ranges
/// `N_j − z_j` (1 where a range is below `1e-12 max(1, |z_j|)`).
fn ideal_and_nadir(anchor_f: &[&Vec<f64>], m: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let ideal: Vec<f64> = (0..m)
        .map(|j| anchor_f.iter().map(|f| f[j]).fold(f64::INFINITY, f64::min))
        .collect();
    let nadir: Vec<f64> = (0..m)
        .map(|j| {
            anchor_f
                .iter()
                .map(|f| f[j])
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .collect();
    let scale: Vec<f64> = ideal
        .iter()
        .zip(&nadir)
        .map(|(z, n)| {
            let s = n - z;
            if s > 1e-12 * z.abs().max(1.0) {
                s
            } else {
                1.0
            }
        })
        .collect();
    (ideal, nadir, scale)
}

/// Subproblem `k` with reference weights `r`: the Tchebycheff problem
/// normalised by `(ideal, scale)`, from `x_start` (the anchors' blend, or
/// a point of the front found so far) and once more from `x0` when that
/// run is not certified; with the 2 probe evaluations of its start.
pub(super) fn subproblem(
    problem: &dyn MultiProblem,
    s: &GradientSettings,
    (k, r): (usize, &Vec<f64>),
    (ideal, scale): (&[f64], &[f64]),
    x_start: &[f64],
    x0: &[f64],
) -> Result<(RunRecord, usize)> {
    let tol = s.end.tolerances.feasibility;
    let m = problem.objective_names().len();
    let t_probe = Tchebycheff::new(
        problem,
        (ideal.to_vec(), scale.to_vec()),
        r.clone(),
        RHO,
        (-(m as f64) - 1.0, f64::MAX / 4.0),
    )?;
    // (x, t0) from the anchors' blend and from the start design
    // (one evaluation each, counted); t's upper bound admits both.
    let from_blend = t_probe.start(x_start)?;
    let from_x0 = t_probe.start(x0)?;
    let t_hi = from_blend[x0.len()].max(from_x0[x0.len()]).max(0.0) + 1.0;
    let p = Tchebycheff::new(
        problem,
        (ideal.to_vec(), scale.to_vec()),
        r.clone(),
        RHO,
        (-(m as f64) - 1.0, t_hi),
    )?;
    let run = solve(&p, s, m + k, &from_blend);
    if certified(&run, tol) || x_start == x0 {
        return Ok((run, 2));
    }
    // Once more from the start design (counted together).
    let mut again = solve(&p, s, m + k, &from_x0);
    again.function_calls += run.function_calls;
    again.gradient_calls += run.gradient_calls;
    Ok((again, 2))
}

/// What became of an end in the front (`front_ends.csv`'s `front`).
#[derive(Debug, Clone, PartialEq)]
pub enum FrontRole {
    /// A point of the gradient side's front.
    Point,
    /// Dominated by the end with this label.
    DominatedBy(String),
    /// The same objectives as the earlier end with this label, or the same
    /// design (every coordinate within [`SAME_DESIGN`] of its range).
    EqualTo(String),
    /// Not certified; its class.
    NotCertified(&'static str),
    /// Certified, but its objectives are not finite.
    NotFinite,
    /// A first anchor run, whose end enters the front only through its
    /// lexicographic refinement.
    AnchorStart,
}

impl std::fmt::Display for FrontRole {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FrontRole::Point => f.write_str("point"),
            FrontRole::DominatedBy(l) => write!(f, "dominated by {l}"),
            FrontRole::EqualTo(l) => write!(f, "equal to {l}"),
            FrontRole::NotCertified(c) => write!(f, "not certified ({c})"),
            FrontRole::NotFinite => f.write_str("objectives not finite"),
            FrontRole::AnchorStart => f.write_str("anchor start"),
        }
    }
}

/// Which ends [`front_roles`] takes as one point.
#[derive(Debug, Clone, Copy)]
pub enum Merge<'a> {
    /// Equal objectives, or the same design ([`SAME_DESIGN`]) with nearly
    /// equal objectives, over these variables (the first coordinates of
    /// each end's design): the front's points.
    Designs(&'a [Variable]),
    /// Equal objectives only: the gap search ([`super::gaps`]) keeps an end
    /// that reached a point again, so that the gap beside it, whose ends
    /// are compared by their objectives, is tried again from that end's
    /// design (the refinement as it was before the front's points were
    /// merged by design).
    Objectives,
}

/// Two certified ends whose designs agree to this fraction of every
/// variable's range (1.8e-3° on a 180° ply angle) and whose objectives
/// agree to [`SAME_OBJECTIVES`] are one point of the front. Two
/// subproblems that converge to the same Pareto point end there to their
/// stop tests, about 1e-7 of the range apart on the deployable panel's
/// front, with objectives that differ by the evaluation's noise (4e-9 of
/// max(|f|, 1)), so that neither dominates.
pub const SAME_DESIGN: f64 = 1e-5;
/// The objectives' agreement for [`SAME_DESIGN`]: `|Δf_i| <= 1e-6 ·
/// max(|f_i|, 1)`. Designs that close can still be distinct points where
/// an objective is steep: ZDT3's `f2` moves by `√Δx1` near `x1 = 0`.
pub const SAME_OBJECTIVES: f64 = 1e-6;

/// What became of each end: dominated by any other end with objectives,
/// equal to an earlier one (the same objectives, or the same design and
/// nearly the same objectives, [`SAME_DESIGN`]), or a point of the front (the non-dominated filter of
/// [`crate::optimize::multiobjective::non_dominated`], equal points once).
/// `merge`: whether ends at one design are merged (the front's points) or
/// only ends with equal objectives (the gap search's view, [`Merge`]).
pub fn front_roles(merge: Merge<'_>, ends: &[SubproblemEnd]) -> Vec<FrontRole> {
    let point = representatives(merge, ends);
    ends.iter()
        .enumerate()
        .map(|(i, e)| {
            let Some(f) = &e.f else {
                return if e.label.starts_with("anchor-") {
                    FrontRole::AnchorStart
                } else if !e.certified {
                    FrontRole::NotCertified(class_name(&e.run))
                } else {
                    FrontRole::NotFinite
                };
            };
            let by = ends
                .iter()
                .enumerate()
                .find(|(j, o)| *j != i && o.f.as_ref().is_some_and(|g| dominates(g, f)));
            match by {
                Some((_, o)) => FrontRole::DominatedBy(o.label.clone()),
                None if point[i] != i => FrontRole::EqualTo(ends[point[i]].label.clone()),
                None => FrontRole::Point,
            }
        })
        .collect()
}

/// Are the ends `a` and `b` (both with objectives) one point by `merge`?
fn one_point(merge: Merge<'_>, a: &SubproblemEnd, b: &SubproblemEnd) -> bool {
    let (Some(fa), Some(fb)) = (&a.f, &b.f) else {
        return false;
    };
    if fa == fb {
        return true;
    }
    let Merge::Designs(vars) = merge else {
        return false;
    };
    let near = fa
        .iter()
        .zip(fb)
        .all(|(u, v)| (u - v).abs() <= SAME_OBJECTIVES * v.abs().max(1.0));
    let n = vars.len();
    match (&a.run.result, &b.run.result) {
        (Some(ra), Some(rb)) => {
            near && scaled_distance(vars, &ra.x[..n], &rb.x[..n]) <= SAME_DESIGN
        }
        _ => false,
    }
}

/// For each end with objectives, the end that stands for its point of the
/// front (itself when it does; ends without objectives: themselves). Ends
/// that are one point with an earlier cluster's first member join that
/// cluster; the cluster's point is its first member that no other member
/// dominates, so that a cluster whose members differ by noise keeps one
/// point and never none.
fn representatives(merge: Merge<'_>, ends: &[SubproblemEnd]) -> Vec<usize> {
    let n = ends.len();
    let mut cluster: Vec<usize> = (0..n).collect();
    for i in 0..n {
        if let Some(c) = (0..i).find(|&c| cluster[c] == c && one_point(merge, &ends[c], &ends[i])) {
            cluster[i] = c;
        }
    }
    let mut point = cluster.clone();
    for c in (0..n).filter(|&c| cluster[c] == c) {
        let members: Vec<usize> = (c..n).filter(|&i| cluster[i] == c).collect();
        let objectives = |i: usize| ends[i].f.as_deref().unwrap_or(&[]);
        let first = members.iter().copied().find(|&i| {
            !members
                .iter()
                .any(|&j| dominates(objectives(j), objectives(i)))
        });
        for &i in &members {
            point[i] = first.unwrap_or(c);
        }
    }
    point
}

/// The non-dominated certified ends (the [`FrontRole::Point`]s):
/// (design, objectives), the first `n` coordinates of each design.
pub(super) fn non_dominated_ends(
    n: usize,
    merge: Merge<'_>,
    ends: &[SubproblemEnd],
) -> Vec<(Vec<f64>, Vec<f64>)> {
    ends.iter()
        .zip(front_roles(merge, ends))
        .filter(|(_, role)| *role == FrontRole::Point)
        .filter_map(|(e, _)| Some((e.run.result.as_ref()?.x[..n].to_vec(), e.f.clone()?)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_points_cover_the_simplex() {
        let r = reference_points(2, 3);
        assert_eq!(r, vec![vec![0.25, 0.75], vec![0.5, 0.5], vec![0.75, 0.25]]);
        // Three objectives, at most 20 points: the lattice with h = 4 has
        // C(6, 2) = 15 points (h = 5 would have 21), each summing to 2.
        let r = reference_points(3, 20);
        assert_eq!(r.len(), 15);
        assert!(r
            .iter()
            .all(|p| (p.iter().sum::<f64>() - 2.0).abs() < 1e-12));
    }

    /// The Tchebycheff subproblems' allowance is 3σ_i/s_i at its largest
    /// (here 3 · 2e-6 / 0.01 = 6e-4), raised from the objectives' own;
    /// an allowance already larger stays.
    #[test]
    fn the_subproblems_allowance_is_the_noise_over_the_range() {
        use crate::explore::local::solvers::{local, LocalMethod, MmfdPreset};
        let solver = local(
            LocalMethod::Sqp,
            &Default::default(),
            MmfdPreset::Standard,
            (1e-6, 0.0),
        );
        let end = EndPolicy {
            noise: 1e-6,
            noise_g: 2e-6,
            ..EndPolicy::default()
        };
        let mut s = GradientSettings {
            objective_sigma: vec![1e-6, 2e-6],
            ..GradientSettings::new(Arc::from(solver.unwrap()), end)
        };
        let sub = tchebycheff_settings(&s, &[0.1, 0.01]);
        assert!((sub.end.noise - 6e-4).abs() < 1e-15 && (sub.end.noise_g - 6e-4).abs() < 1e-15);
        s.end.noise = 1e-3;
        assert_eq!(tchebycheff_settings(&s, &[0.1, 0.01]).end.noise, 1e-3);
    }

    /// A certified end at `x` (with `t` appended, as a subproblem's design
    /// is) with objectives `f`.
    fn end(label: &str, x: &[f64], f: [f64; 2]) -> SubproblemEnd {
        let mut design = x.to_vec();
        design.push(0.0);
        SubproblemEnd {
            label: label.into(),
            run: RunRecord {
                start: 0,
                x0: design.clone(),
                result: Some(crate::explore::persist::tables::RunResult {
                    x: design,
                    f: 0.0,
                    g: vec![],
                }),
                exit: String::new(),
                iterations: 1,
                function_calls: 1,
                gradient_calls: 1,
                wall_seconds: 0.0,
                optimum: None,
                certificate: None,
                polish: String::new(),
            },
            certified: true,
            f: Some(f.to_vec()),
        }
    }

    /// Two ends at one design (1e-7 of the range apart, the periodic
    /// variable across its seam) whose objectives differ by noise so that
    /// neither dominates are one point of the front; a design 1e-4 of the
    /// range away is another point, and so is one 1e-6 away whose
    /// objectives differ by 0.1 (a steep objective). Where a later end at a
    /// design dominates an earlier one by noise, the later one is the
    /// point (the cluster keeps one point, never none).
    #[test]
    fn one_design_reached_twice_is_one_point() {
        let vars = [
            Variable::periodic("a", -90.0, 180.0).unwrap(),
            Variable::bounded("b", 0.0, 1.0).unwrap(),
        ];
        let ends = [
            end("subproblem-0", &[89.99999, 0.5], [1.0, 2.0]),
            end("subproblem-1", &[-89.99999, 0.5], [1.0 + 1e-9, 2.0 - 1e-9]),
            end("subproblem-2", &[89.99999, 0.5001], [0.9, 2.1]),
            end("subproblem-3", &[89.99999, 0.500001], [1.1, 1.9]),
            end(
                "subproblem-4",
                &[89.99999, 0.5001],
                [0.9 - 1e-9, 2.1 - 1e-9],
            ),
        ];
        let roles = front_roles(Merge::Designs(&vars), &ends);
        assert_eq!(
            roles,
            [
                FrontRole::Point,
                FrontRole::EqualTo("subproblem-0".into()),
                FrontRole::DominatedBy("subproblem-4".into()),
                FrontRole::Point,
                FrontRole::Point
            ]
        );
        assert_eq!(non_dominated_ends(2, Merge::Designs(&vars), &ends).len(), 3);
        assert_eq!(non_dominated_ends(2, Merge::Objectives, &ends).len(), 4);
    }
}
