//! NSGA-II (K. Deb, A. Pratap, S. Agarwal, T. Meyarivan, "A fast and
//! elitist multiobjective genetic algorithm: NSGA-II", *IEEE Trans.
//! Evolutionary Computation* 6(2), 2002, 182–197) on a [`MultiProblem`].
//!
//! One generation: `N` offspring are made from the population by binary
//! tournaments (lower rank wins, then larger crowding distance), simulated
//! binary crossover (SBX, distribution index `η_c`, probability `p_c`,
//! each variable exchanged with probability ½) and polynomial mutation
//! (index `η_m`, probability `p_m` per variable, default `1/n`), both in
//! the bounded forms of Deb's reference code; the `2N` parents and
//! offspring are sorted into fronts by the fast non-dominated sort, and
//! the next population is the first fronts that fit, the last one cut by
//! crowding distance (largest first; the ends of every front have an
//! infinite distance).
//!
//! Constraints by constraint-domination (Deb et al. 2002, §V): with the
//! violation `v = Σ_j max(0, g_j)`, a design with `v <= tol` beats one with
//! `v > tol`; of two infeasible designs the smaller `v` wins; of two
//! feasible ones Pareto dominance decides. A failed evaluation counts as
//! infinitely violated.
//!
//! Random numbers come from ChaCha8 seeded with [`Nsga2Options::seed`];
//! every draw happens on the calling thread in a fixed order and the
//! evaluations of a generation (parallel, rayon) are collected in order, so
//! a seed gives the same run on any thread count. Periodic variables are
//! wrapped into their box after crossover and mutation.

use super::multiobjective::{dominates, MultiProblem};
use crate::error::{Error, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// NSGA-II's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Nsga2Options {
    /// Population size `N` (even, >= 4).
    pub population: usize,
    /// Function-call budget: the initial population and whole generations
    /// that fit (`⌊(budget − N)/N⌋` generations).
    pub max_evaluations: usize,
    /// Seed of the random generator.
    pub seed: u64,
    /// SBX distribution index `η_c`.
    pub eta_crossover: f64,
    /// Polynomial-mutation distribution index `η_m`.
    pub eta_mutation: f64,
    /// Crossover probability per pair `p_c`.
    pub crossover_probability: f64,
    /// Mutation probability per variable (`None`: `1/n`).
    pub mutation_probability: Option<f64>,
    /// Feasible when the violation `Σ max(0, g_j)` is at most this.
    pub feasibility_tolerance: f64,
}

impl Default for Nsga2Options {
    /// Deb et al. (2002)'s settings for real variables: `η_c = η_m = 20`,
    /// `p_c = 0.9`, `p_m = 1/n`; 100 designs, 25 000 evaluations, seed 0,
    /// feasibility `v <= 0`.
    fn default() -> Self {
        Nsga2Options {
            population: 100,
            max_evaluations: 25_000,
            seed: 0,
            eta_crossover: 20.0,
            eta_mutation: 20.0,
            crossover_probability: 0.9,
            mutation_probability: None,
            feasibility_tolerance: 0.0,
        }
    }
}

/// One evaluated design.
#[derive(Debug, Clone, PartialEq)]
pub struct Individual {
    /// The design.
    pub x: Vec<f64>,
    /// Its objectives (minimized; `f64::MAX` each when the evaluation
    /// failed).
    pub f: Vec<f64>,
    /// Its constraints (empty when the evaluation failed).
    pub g: Vec<f64>,
    /// Violation `Σ max(0, g_j)` (`+∞` when the evaluation failed).
    pub violation: f64,
}

/// The end of a run.
#[derive(Debug, Clone)]
pub struct Nsga2Outcome {
    /// The final population's first front, feasible members only (no two
    /// with equal objectives).
    pub front: Vec<Individual>,
    /// The whole final population.
    pub population: Vec<Individual>,
    /// Function evaluations used.
    pub evaluations: usize,
    /// Generations run.
    pub generations: usize,
    /// Evaluations that failed (each counted as infinitely violated).
    pub failed: usize,
}

fn evaluate(problem: &dyn MultiProblem, x: Vec<f64>, k: usize) -> Individual {
    match problem.evaluate(&x, false) {
        Ok(e) if e.f.iter().chain(&e.g).all(|v| v.is_finite()) && e.f.len() == k => {
            let violation = e.g.iter().map(|g| g.max(0.0)).sum();
            Individual {
                x,
                f: e.f,
                g: e.g,
                violation,
            }
        }
        _ => Individual {
            x,
            f: vec![f64::MAX; k],
            g: vec![],
            violation: f64::INFINITY,
        },
    }
}

/// Does `a` constraint-dominate `b` (module doc) with tolerance `tol`?
pub fn constraint_dominates(a: &Individual, b: &Individual, tol: f64) -> bool {
    match (a.violation <= tol, b.violation <= tol) {
        (true, false) => true,
        (false, true) => false,
        (false, false) => a.violation < b.violation,
        (true, true) => dominates(&a.f, &b.f),
    }
}

/// The fast non-dominated sort: the fronts (indices into `pop`), best
/// first, under constraint-domination.
pub fn fast_non_dominated_sort(pop: &[Individual], tol: f64) -> Vec<Vec<usize>> {
    let n = pop.len();
    let mut dominated: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut count = vec![0usize; n];
    for p in 0..n {
        for q in 0..n {
            if p == q {
                continue;
            }
            if constraint_dominates(&pop[p], &pop[q], tol) {
                dominated[p].push(q);
            } else if constraint_dominates(&pop[q], &pop[p], tol) {
                count[p] += 1;
            }
        }
    }
    let mut fronts = Vec::new();
    let mut current: Vec<usize> = (0..n).filter(|&p| count[p] == 0).collect();
    while !current.is_empty() {
        let mut next = Vec::new();
        for &p in &current {
            for &q in &dominated[p] {
                count[q] -= 1;
                if count[q] == 0 {
                    next.push(q);
                }
            }
        }
        next.sort_unstable();
        fronts.push(current);
        current = next;
    }
    fronts
}

/// Crowding distance of each member of `front` (indices into `pop`), in
/// the order of `front`: per objective, the members sorted by it, the two
/// ends `+∞`, the others the gap between their neighbours divided by the
/// objective's range over the front.
pub fn crowding_distance(pop: &[Individual], front: &[usize]) -> Vec<f64> {
    let l = front.len();
    let mut d = vec![0.0; l];
    if l == 0 {
        return d;
    }
    let k = pop[front[0]].f.len();
    for m in 0..k {
        let mut order: Vec<usize> = (0..l).collect();
        order.sort_by(|&a, &b| {
            pop[front[a]].f[m]
                .total_cmp(&pop[front[b]].f[m])
                .then(a.cmp(&b))
        });
        let fmin = pop[front[order[0]]].f[m];
        let fmax = pop[front[order[l - 1]]].f[m];
        d[order[0]] = f64::INFINITY;
        d[order[l - 1]] = f64::INFINITY;
        let range = fmax - fmin;
        if range <= 0.0 || !range.is_finite() {
            continue;
        }
        for w in 1..l.saturating_sub(1) {
            let gap = pop[front[order[w + 1]]].f[m] - pop[front[order[w - 1]]].f[m];
            d[order[w]] += gap / range;
        }
    }
    d
}

/// SBX of one variable pair in `[lo, hi]` (Deb's bounded form), with the
/// uniform draw `u`.
fn sbx_pair(x1: f64, x2: f64, (lo, hi): (f64, f64), eta: f64, u: f64) -> (f64, f64) {
    if (x1 - x2).abs() <= 1e-14 {
        return (x1, x2);
    }
    let (y1, y2) = (x1.min(x2), x1.max(x2));
    let betaq = |beta: f64| {
        let alpha = 2.0 - beta.powf(-(eta + 1.0));
        if u <= 1.0 / alpha {
            (u * alpha).powf(1.0 / (eta + 1.0))
        } else {
            (1.0 / (2.0 - u * alpha)).powf(1.0 / (eta + 1.0))
        }
    };
    let b1 = betaq(1.0 + 2.0 * (y1 - lo) / (y2 - y1));
    let c1 = 0.5 * ((y1 + y2) - b1 * (y2 - y1));
    let b2 = betaq(1.0 + 2.0 * (hi - y2) / (y2 - y1));
    let c2 = 0.5 * ((y1 + y2) + b2 * (y2 - y1));
    (c1.clamp(lo, hi), c2.clamp(lo, hi))
}

/// Polynomial mutation of `y` in `[lo, hi]` (Deb's bounded form), with the
/// uniform draw `u`.
fn poly_mutation(y: f64, (lo, hi): (f64, f64), eta: f64, u: f64) -> f64 {
    let d1 = (y - lo) / (hi - lo);
    let d2 = (hi - y) / (hi - lo);
    let p = 1.0 / (eta + 1.0);
    let dq = if u <= 0.5 {
        let v = 2.0 * u + (1.0 - 2.0 * u) * (1.0 - d1).powf(eta + 1.0);
        v.powf(p) - 1.0
    } else {
        let v = 2.0 * (1.0 - u) + 2.0 * (u - 0.5) * (1.0 - d2).powf(eta + 1.0);
        1.0 - v.powf(p)
    };
    (y + dq * (hi - lo)).clamp(lo, hi)
}

/// Check the options.
fn check(o: &Nsga2Options) -> Result<()> {
    if o.population < 4 || o.population % 2 == 1 {
        return Err(Error::input(
            "population",
            o.population,
            "an even population of at least 4",
        ));
    }
    if o.max_evaluations < o.population {
        return Err(Error::input(
            "max_evaluations",
            o.max_evaluations,
            format!("at least the population ({})", o.population),
        ));
    }
    for (k, v) in [
        ("eta_crossover", o.eta_crossover),
        ("eta_mutation", o.eta_mutation),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::input(k, v, "a finite index >= 0"));
        }
    }
    let p = o.mutation_probability.unwrap_or(0.0);
    if !(0.0..=1.0).contains(&o.crossover_probability) || !(0.0..=1.0).contains(&p) {
        return Err(Error::input(
            "crossover_probability / mutation_probability",
            format!("{} / {p}", o.crossover_probability),
            "probabilities in [0, 1]",
        ));
    }
    Ok(())
}

/// Run NSGA-II (see the module doc).
pub fn minimize(problem: &dyn MultiProblem, options: &Nsga2Options) -> Result<Nsga2Outcome> {
    check(options)?;
    let vars = problem.variables();
    let n = vars.len();
    let k = problem.objective_names().len();
    let np = options.population;
    let tol = options.feasibility_tolerance;
    let pm = options.mutation_probability.unwrap_or(1.0 / n as f64);
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let initial: Vec<Vec<f64>> = (0..np)
        .map(|_| {
            vars.iter()
                .map(|v| v.wrap(v.lower + rng.random::<f64>() * (v.upper - v.lower)))
                .collect()
        })
        .collect();
    let eval_all = |xs: Vec<Vec<f64>>| -> Vec<Individual> {
        xs.into_par_iter()
            .map(|x| evaluate(problem, x, k))
            .collect()
    };
    let mut pop = eval_all(initial);
    let mut evaluations = np;
    let mut generations = 0;
    let mut rank_crowd = ranks(&pop, tol);
    while evaluations + np <= options.max_evaluations {
        let mut children = Vec::with_capacity(np);
        while children.len() < np {
            let mut pick = || {
                let (a, b) = (rng.random_range(0..np), rng.random_range(0..np));
                let better = |a: usize, b: usize| {
                    let (ra, rb) = (rank_crowd[a], rank_crowd[b]);
                    ra.0 < rb.0 || (ra.0 == rb.0 && ra.1 > rb.1)
                };
                if better(b, a) {
                    b
                } else {
                    a
                }
            };
            let (p1, p2) = (pick(), pick());
            let (mut c1, mut c2) = (pop[p1].x.clone(), pop[p2].x.clone());
            if rng.random::<f64>() <= options.crossover_probability {
                for i in 0..n {
                    let (swap, u) = (rng.random::<f64>(), rng.random::<f64>());
                    if swap <= 0.5 {
                        let bounds = (vars[i].lower, vars[i].upper);
                        let (a, b) = sbx_pair(c1[i], c2[i], bounds, options.eta_crossover, u);
                        let flip = rng.random::<f64>() <= 0.5;
                        (c1[i], c2[i]) = if flip { (b, a) } else { (a, b) };
                    }
                }
            }
            for c in [&mut c1, &mut c2] {
                for i in 0..n {
                    if rng.random::<f64>() < pm {
                        let bounds = (vars[i].lower, vars[i].upper);
                        let u = rng.random::<f64>();
                        c[i] = poly_mutation(c[i], bounds, options.eta_mutation, u);
                    }
                    c[i] = vars[i].wrap(c[i]);
                }
            }
            children.push(c1);
            children.push(c2);
        }
        let mut all = pop;
        all.extend(eval_all(children));
        evaluations += np;
        generations += 1;
        pop = select(all, np, tol);
        rank_crowd = ranks(&pop, tol);
    }
    let failed = pop.iter().filter(|i| i.violation.is_infinite()).count();
    let fronts = fast_non_dominated_sort(&pop, tol);
    let mut front: Vec<Individual> = Vec::new();
    for &i in fronts.first().map(Vec::as_slice).unwrap_or(&[]) {
        let p = &pop[i];
        if p.violation <= tol && !front.iter().any(|q| q.f == p.f) {
            front.push(p.clone());
        }
    }
    Ok(Nsga2Outcome {
        front,
        population: pop,
        evaluations,
        generations,
        failed,
    })
}

/// `(rank, crowding distance)` of every member.
fn ranks(pop: &[Individual], tol: f64) -> Vec<(usize, f64)> {
    let mut out = vec![(0, 0.0); pop.len()];
    for (r, front) in fast_non_dominated_sort(pop, tol).iter().enumerate() {
        for (&i, d) in front.iter().zip(crowding_distance(pop, front)) {
            out[i] = (r, d);
        }
    }
    out
}

/// The `np` best of `all`: whole fronts while they fit, then the last
/// front's members by decreasing crowding distance (ties by index).
fn select(all: Vec<Individual>, np: usize, tol: f64) -> Vec<Individual> {
    let mut keep: Vec<usize> = Vec::with_capacity(np);
    for front in fast_non_dominated_sort(&all, tol) {
        if keep.len() + front.len() <= np {
            keep.extend(&front);
            continue;
        }
        let d = crowding_distance(&all, &front);
        let mut order: Vec<usize> = (0..front.len()).collect();
        order.sort_by(|&a, &b| d[b].total_cmp(&d[a]).then(front[a].cmp(&front[b])));
        keep.extend(order.iter().take(np - keep.len()).map(|&j| front[j]));
        break;
    }
    keep.sort_unstable();
    keep.into_iter().map(|i| all[i].clone()).collect()
}

#[cfg(test)]
#[path = "nsga2_tests.rs"]
mod tests;
