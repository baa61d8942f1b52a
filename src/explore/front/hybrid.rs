//! The hybrid front (`[front] hybrid = φ`): NSGA-II on a fraction `φ` of
//! NSGA-II's budget, then the gradient side seeded by what it found.
//!
//! 1. **NSGA-II** ([`crate::optimize::nsga2`]) with the section's population
//!    and seed and `⌈φ·B⌉` function calls (`B`: the pure NSGA-II row's
//!    budget, at least one population). Its feasible first front `P` are
//!    the seeds.
//! 2. **The gradient side** ([`super::gradient`]) with the section's
//!    settings, seeded by `P`: each objective's anchor runs start from the
//!    start design and from the points of `P` best in that objective
//!    (instead of random designs), each lattice subproblem from the point
//!    of `P` nearest its ray in the anchors' normalized objectives (instead
//!    of the blend of the anchors' designs), and the gaps of the certified
//!    front are refined as in the pure gradient side. Every end is settled
//!    (certified, polished) as there; `hybrid_ends.csv` lists them.
//! 3. **The front**: the non-dominated set of `P` and the gradient side's
//!    points. Its cost is NSGA-II's evaluations plus every call of the
//!    gradient side.

use super::gradient::{gradient_front, GradientFront, GradientSettings};
use crate::error::{Error, Result};
use crate::optimize::multiobjective::{non_dominated_pairs, MultiProblem};
use crate::optimize::nsga2::{self, Nsga2Options};
use std::time::Instant;

/// What the hybrid found and spent.
#[derive(Debug, Clone)]
pub struct HybridFront {
    /// The non-dominated designs and objectives of NSGA-II's front and the
    /// seeded gradient side's points (minimized orientation).
    pub points: Vec<(Vec<f64>, Vec<f64>)>,
    /// The seeded gradient side.
    pub gradient: GradientFront,
    /// NSGA-II's function calls.
    pub nsga2_calls: usize,
    /// Function calls, all included (NSGA-II's and the gradient side's).
    pub function_calls: usize,
    /// Wall time \[s\].
    pub wall_seconds: f64,
}

/// Run the hybrid (module doc) on `problem` with NSGA-II's options
/// `options` (their `max_evaluations` is the hybrid's NSGA-II budget) and
/// the gradient side's settings `s`.
pub fn hybrid_front(
    problem: &dyn MultiProblem,
    options: &Nsga2Options,
    s: &GradientSettings,
) -> Result<HybridFront> {
    let t0 = Instant::now();
    let pool = crate::explore::context::thread_pool(s.threads)?;
    let evo = pool.install(|| nsga2::minimize(problem, options))?;
    if evo.front.is_empty() {
        return Err(Error::numerical(
            "explore::front::hybrid",
            format!(
                "NSGA-II found no feasible design in {} evaluations: nothing to seed the gradient side",
                evo.evaluations
            ),
        ));
    }
    let seeds: Vec<(Vec<f64>, Vec<f64>)> = evo
        .front
        .iter()
        .map(|i| (i.x.clone(), i.f.clone()))
        .collect();
    let seeded = GradientSettings {
        seeds: seeds.clone(),
        ..s.clone()
    };
    let gradient = gradient_front(problem, &seeded)?;
    let mut all = seeds;
    all.extend(gradient.points.iter().cloned());
    let points = non_dominated_pairs(&all);
    Ok(HybridFront {
        points,
        nsga2_calls: evo.evaluations,
        function_calls: evo.evaluations + gradient.function_calls,
        gradient,
        wall_seconds: t0.elapsed().as_secs_f64(),
    })
}
