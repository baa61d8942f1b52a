//! The three searches over a [`Lattice`] (module doc of
//! [`super`](crate::explore::discrete)): rounding of continuous optima with
//! a discrete coordinate descent, CMA-ES with integer handling, and
//! exhaustive enumeration. Designs are compared by Deb's feasibility rules
//! at the study's feasibility tolerance.

use super::lattice::{Cache, Lattice, OnSet};
use crate::error::Result;
use crate::optimize::cmaes::{self, CmaesOptions};
use crate::optimize::{NoObserver, Problem};

/// A design on the lattice with its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The design (every discrete coordinate a member of its set).
    pub x: Vec<f64>,
    /// Objective.
    pub f: f64,
    /// Constraints.
    pub g: Vec<f64>,
}

impl Candidate {
    /// Largest constraint (`-inf` without constraints).
    pub fn max_g(&self) -> f64 {
        self.g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
    /// `Σ_j max(0, g_j − tol)`.
    pub fn violation(&self, tol: f64) -> f64 {
        self.g.iter().map(|g| (g - tol).max(0.0)).sum()
    }
    /// Deb's order: feasible (to `tol`) by f before infeasible by violation.
    pub fn better_than(&self, other: &Candidate, tol: f64) -> bool {
        let (a, b) = (self.violation(tol), other.violation(tol));
        match (a <= 0.0, b <= 0.0) {
            (true, true) => self.f < other.f,
            (true, false) => true,
            (false, true) => false,
            (false, false) => a < b,
        }
    }
}

/// One method's result: its best design and what it cost.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// The best design.
    pub best: Candidate,
    /// Distinct designs the method asked for.
    pub evaluations: usize,
    /// Designs asked for, repeats included.
    pub samples: usize,
}

/// Evaluate `xs` (on the lattice) as one parallel batch through `on`.
fn batch(on: &OnSet, xs: &[Vec<f64>]) -> Result<Vec<Candidate>> {
    let evals = cmaes::evaluate_batch(on, xs)?;
    Ok(xs
        .iter()
        .zip(evals)
        .map(|(x, e)| Candidate {
            x: x.clone(),
            f: e.f,
            g: e.g,
        })
        .collect())
}

/// The best of `cands` by Deb's order (the first of equals).
fn best_of(cands: Vec<Candidate>, tol: f64) -> Option<Candidate> {
    cands
        .into_iter()
        .reduce(|b, c| if c.better_than(&b, tol) { c } else { b })
}

/// Every design of an all-discrete lattice, evaluated (in the order of
/// [`Lattice::enumerate`]), and the best of them at the feasibility
/// tolerance `tol`; `None` when a variable is continuous.
pub fn exhaustive(
    problem: &dyn Problem,
    lattice: &Lattice,
    cache: &Cache,
    tol: f64,
) -> Result<Option<(Vec<Candidate>, Found)>> {
    let Some(all) = lattice.enumerate() else {
        return Ok(None);
    };
    let on = OnSet::new(problem, lattice, cache);
    let cands = batch(&on, &all)?;
    let best = best_of(cands.clone(), tol).expect("a lattice has a design");
    Ok(Some((
        cands,
        Found {
            best,
            evaluations: on.evaluations(),
            samples: on.samples(),
        },
    )))
}

/// The gradient route's second half: the continuous optimum `x` rounded to
/// the lattice, then a discrete coordinate descent (evaluate the designs
/// one set member away in each discrete coordinate, move to the best if it
/// is better by Deb's order, repeat until none is). Returns the rounded
/// design and the polished one, with the cost of the whole route.
pub fn round_and_polish(
    problem: &dyn Problem,
    lattice: &Lattice,
    cache: &Cache,
    x: &[f64],
    tol: f64,
) -> Result<(Candidate, Found)> {
    let on = OnSet::new(problem, lattice, cache);
    let start = lattice.round(x);
    let rounded = batch(&on, std::slice::from_ref(&start))?.remove(0);
    let mut current = rounded.clone();
    loop {
        let around = batch(&on, &lattice.neighbours(&current.x))?;
        match best_of(around, tol) {
            Some(b) if b.better_than(&current, tol) => current = b,
            _ => break,
        }
    }
    Ok((
        rounded,
        Found {
            best: current,
            evaluations: on.evaluations(),
            samples: on.samples(),
        },
    ))
}

/// IPOP-CMA-ES on the lattice: every sample is evaluated at its rounding
/// (the distribution stays continuous), and the standard deviation of
/// each discrete coordinate is kept at or above `min_std` lattice steps
/// ([`CmaesOptions::min_std`]). `samples` is the budget of designs asked
/// for; the best design is returned rounded.
pub fn cmaes_on_set(
    problem: &dyn Problem,
    lattice: &Lattice,
    cache: &Cache,
    samples: usize,
    min_std: f64,
    seed: u64,
    tol: f64,
) -> Result<Found> {
    let on = OnSet::new(problem, lattice, cache);
    let n = lattice.variables().len();
    let options = CmaesOptions {
        seed,
        max_evaluations: samples,
        feasibility_tolerance: tol,
        min_std: (0..n).map(|i| min_std * lattice.step_fraction(i)).collect(),
        ..CmaesOptions::default()
    };
    let out = cmaes::minimize(&on, &options, &mut NoObserver)?;
    let x = lattice.round(&out.x);
    Ok(Found {
        best: Candidate {
            x,
            f: out.f,
            g: out.g,
        },
        evaluations: on.evaluations(),
        samples: on.samples(),
    })
}
