//! Reference points placed where the front found so far has its largest
//! gaps (two objectives, `[front] refine`).
//!
//! The lattice of reference points is even along the segment between the
//! anchors, not along the front: where the front is disconnected (ZDT3's
//! five pieces) or bends sharply, many rays end at the same point (a
//! piece's end, the max-norm-nearest point of the front to a ray through a
//! gap) and whole pieces get few points. Refinement spends a budget of
//! further subproblems where the points found so far are furthest apart:
//!
//! 1. The certified non-dominated points so far, in normalized objectives
//!    `u_i = (f_i − z_i)/s_i`, sorted by `u_1`; the gaps between
//!    neighbours, measured by their Euclidean length in `u`.
//! 2. The [`ROUND`] largest gaps that are still open, longer than
//!    [`SHORTEST`], each get a subproblem whose ray `u_1 − u_2 = c` halves
//!    the gap (`c` the mean of its ends' `u_1 − u_2`; reference point
//!    `r = ((1 + c)/2, (1 − c)/2)`), started from the design halfway
//!    between its ends' designs (and once more from the start design when
//!    that run is not certified, as the lattice's subproblems). A gap that
//!    run does not fill (below) gets the same subproblem from each of its
//!    ends' designs: a piece of a disconnected front inside the gap (ZDT3's
//!    fourth, between the third's end and the fifth) is reached from a
//!    design on it, and a blend of two pieces' designs may lie in the basin
//!    of a third.
//! 3. A gap is filled by a new point strictly inside it: a certified end,
//!    further than [`SHORTEST`] from both ends of the gap, inside its
//!    `u_1` interval and dominated by neither end. A gap that none of its
//!    three runs fills is closed: the front has no point there that the
//!    ray reaches from those starts, as in a gap of a disconnected front.
//!    A new point splits its gap in two, which the next round measures
//!    again.
//! 4. Rounds go on until the budget is spent or no gap is open.
//!
//! The rounds are a fixed sequence of batches of [`ROUND`] subproblems,
//! each batch solved in parallel, so the result does not depend on the
//! number of threads. Every run is kept in the ends (labels `gap-<k>`),
//! certified or not, with its calls.

use super::gradient::{certified, non_dominated_ends, objectives, subproblem};
use super::gradient::{GradientSettings, Merge, SubproblemEnd};
use crate::error::Result;
use crate::explore::persist::tables::RunRecord;
use crate::optimize::multiobjective::{dominates, MultiProblem};
use rayon::prelude::*;

/// Subproblems per round.
pub const ROUND: usize = 4;
/// Gaps shorter than this (normalized objectives) are not refined, and an
/// end this close to a gap's end is no new point.
pub const SHORTEST: f64 = 1e-3;

/// A front point in normalized objectives, with its design and objectives.
struct Found {
    u: [f64; 2],
    x: Vec<f64>,
    f: Vec<f64>,
}

fn distance(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Objectives `f` normalized by `(ideal, scale)`: `u_i = (f_i − z_i)/s_i`.
fn normalized(f: &[f64], (ideal, scale): (&[f64], &[f64])) -> [f64; 2] {
    [(f[0] - ideal[0]) / scale[0], (f[1] - ideal[1]) / scale[1]]
}

/// The certified non-dominated points of `ends`, normalized by `norm`
/// and sorted by `u_1`.
fn front(n: usize, ends: &[SubproblemEnd], norm: (&[f64], &[f64])) -> Vec<Found> {
    let mut pts: Vec<Found> = non_dominated_ends(n, Merge::Objectives, ends)
        .into_iter()
        .map(|(x, f)| Found {
            u: normalized(&f, norm),
            x,
            f,
        })
        .collect();
    pts.sort_by(|a, b| a.u[0].total_cmp(&b.u[0]).then(a.u[1].total_cmp(&b.u[1])));
    pts
}

/// Is the gap between the objective vectors `a` and `b` closed?
fn is_closed(closed: &[(Vec<f64>, Vec<f64>)], a: &[f64], b: &[f64]) -> bool {
    closed.iter().any(|(p, q)| p == a && q == b)
}

/// Does the end `f_new` (normalized `u`) fill the gap `(a, b)`: strictly
/// inside its `u_1` interval, further than [`SHORTEST`] from both ends,
/// and dominated by neither?
fn fills(a: &Found, b: &Found, u: &[f64; 2]) -> bool {
    let inside = u[0] > a.u[0] && u[0] < b.u[0];
    let apart = distance(u, &a.u) > SHORTEST && distance(u, &b.u) > SHORTEST;
    inside && apart && !dominates(&a.u, u) && !dominates(&b.u, u)
}

/// The open gaps of `pts` longer than [`SHORTEST`], largest first (ties
/// by position), at most `k`: indices `i` of the gap `(pts[i], pts[i+1])`.
fn open_gaps(pts: &[Found], closed: &[(Vec<f64>, Vec<f64>)], k: usize) -> Vec<usize> {
    let mut gaps: Vec<(f64, usize)> = pts
        .windows(2)
        .enumerate()
        .filter(|(_, w)| !is_closed(closed, &w[0].f, &w[1].f))
        .map(|(i, w)| (distance(&w[0].u, &w[1].u), i))
        .filter(|(d, _)| *d > SHORTEST)
        .collect();
    gaps.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    gaps.into_iter().take(k).map(|(_, i)| i).collect()
}

/// The reference point of the ray that halves the gap `(a, b)`.
fn halving(a: &Found, b: &Found) -> Vec<f64> {
    let c = 0.5 * ((a.u[0] - a.u[1]) + (b.u[0] - b.u[1]));
    let l = (0.5 * (1.0 + c)).clamp(0.0, 1.0);
    vec![l, 1.0 - l]
}

/// The design halfway between `a`'s and `b`'s (wrapped into the box).
fn blend(problem: &dyn MultiProblem, a: &Found, b: &Found) -> Vec<f64> {
    (a.x.iter().zip(&b.x).zip(problem.variables()))
        .map(|((p, q), v)| v.wrap(p + 0.5 * v.difference(*q, *p)))
        .collect()
}

/// What every batch of gap subproblems shares.
struct Refiner<'a> {
    problem: &'a dyn MultiProblem,
    s: &'a GradientSettings,
    pool: &'a rayon::ThreadPool,
    norm: (&'a [f64], &'a [f64]),
    x0: &'a [f64],
    /// The number of ends before the first gap run (labels `gap-<k>`
    /// count from there).
    first: usize,
    /// Function calls not counted in the runs.
    extra: usize,
}

impl Refiner<'_> {
    /// Gap runs so far.
    fn used(&self, ends: &[SubproblemEnd]) -> usize {
        ends.len() - self.first
    }

    /// One batch of gap subproblems `(gap index, start)`, solved in
    /// parallel and appended to `ends`; returns the gaps the ends filled.
    fn batch(
        &mut self,
        pts: &[Found],
        jobs: Vec<(usize, Vec<f64>)>,
        ends: &mut Vec<SubproblemEnd>,
    ) -> Result<Vec<usize>> {
        let (problem, s, norm, x0) = (self.problem, self.s, self.norm, self.x0);
        let tol = s.end.tolerances.feasibility;
        let index = ends.len();
        let runs: Vec<Result<(RunRecord, usize)>> = self.pool.install(|| {
            jobs.par_iter()
                .enumerate()
                .map(|(j, (i, x))| {
                    let r = halving(&pts[*i], &pts[i + 1]);
                    subproblem(problem, s, (index + j, &r), norm, x, x0)
                })
                .collect()
        });
        let mut filled = Vec::new();
        for ((i, _), run) in jobs.iter().zip(runs) {
            let (run, probes) = run?;
            self.extra += probes;
            let f = objectives(problem, &run, tol, &mut self.extra)?;
            let u = f.as_ref().map(|f| normalized(f, norm));
            if u.is_some_and(|u| fills(&pts[*i], &pts[i + 1], &u)) {
                filled.push(*i);
            }
            ends.push(SubproblemEnd {
                label: format!("gap-{}", self.used(ends)),
                certified: certified(&run, tol),
                run,
                f,
            });
        }
        Ok(filled)
    }
}

/// Run the refinement of the module doc, appending its runs to `ends`;
/// returns the function calls not counted in the runs (the starts' probe
/// evaluations and the ends' objective evaluations).
pub fn refine(
    problem: &dyn MultiProblem,
    s: &GradientSettings,
    pool: &rayon::ThreadPool,
    norm: (&[f64], &[f64]),
    x0: &[f64],
    ends: &mut Vec<SubproblemEnd>,
) -> Result<usize> {
    let mut r = Refiner {
        problem,
        s,
        pool,
        norm,
        x0,
        first: ends.len(),
        extra: 0,
    };
    let mut closed: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    while r.used(ends) < s.refine {
        let pts = front(problem.variables().len(), ends, norm);
        let gaps = open_gaps(&pts, &closed, ROUND.min(s.refine - r.used(ends)));
        if gaps.is_empty() {
            break;
        }
        // From the blend of the gap's ends; where that fills nothing, from
        // each end's own design.
        let jobs = gaps
            .iter()
            .map(|&i| (i, blend(problem, &pts[i], &pts[i + 1])))
            .collect();
        let filled = r.batch(&pts, jobs, ends)?;
        let unfilled: Vec<usize> = gaps.into_iter().filter(|i| !filled.contains(i)).collect();
        let jobs: Vec<(usize, Vec<f64>)> = unfilled
            .iter()
            .flat_map(|&i| [(i, pts[i].x.clone()), (i, pts[i + 1].x.clone())])
            .take(s.refine - r.used(ends))
            .collect();
        let tried: Vec<usize> = jobs.iter().map(|j| j.0).collect();
        let again = r.batch(&pts, jobs, ends)?;
        for i in unfilled {
            if tried.contains(&i) && !again.contains(&i) {
                closed.push((pts[i].f.clone(), pts[i + 1].f.clone()));
            }
        }
    }
    Ok(r.extra)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(u0: f64, u1: f64) -> Found {
        Found {
            u: [u0, u1],
            x: vec![],
            f: vec![u0, u1],
        }
    }

    #[test]
    fn a_gap_is_filled_only_by_a_new_non_dominated_point_inside_it() {
        let (a, b) = (found(0.0, 1.0), found(1.0, 0.0));
        assert!(fills(&a, &b, &[0.5, 0.5]));
        // On an end, outside the interval, or dominated by an end.
        assert!(!fills(&a, &b, &[0.0, 1.0]));
        assert!(!fills(&a, &b, &[1.0005, 0.0]));
        assert!(!fills(&a, &b, &[1.5, -0.2]));
        assert!(!fills(&a, &b, &[0.5, 1.2]));
    }
}
