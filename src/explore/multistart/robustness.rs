//! Robustness of each certified optimum under a manufacturing tolerance
//! (`[robustness]`): how much does an optimum lose when every
//! variable may be off by up to `±δ_i` (a ±2° lay-up tolerance on a ply
//! angle)?
//!
//! For an optimum `x*` with objective `f`, constraints `g_j` and their exact
//! gradients (one evaluation with gradients), the **first-order worst case**
//! over the box `|x_i − x*_i| <= δ_i` is
//!
//! ```text
//! f_worst     = f + Σ_i |∂f/∂x_i| δ_i
//! max_g_worst = max_j ( g_j + Σ_i |∂g_j/∂x_i| δ_i )
//! ```
//!
//! (the maximum of the linearisation over the box, attained at a corner).
//! It is **checked by evaluation**: with n <= [`MAX_CORNER_DIMENSION`]
//! variables at the 2ⁿ corners of the box, with more at a seeded
//! Latin-hypercube sample of `samples` points of the box (`[study] seed`);
//! the centre counts too. `f_worst_sampled` is the largest f and
//! `max_g_worst_sampled` the largest `max_j g_j` among those points. For a
//! linear function both agree to rounding; otherwise they differ by
//! `O(δ²)` (second derivatives times δ²), and where the function has a kink
//! or a local maximum inside the box the sample can exceed the first-order
//! value (or fall below it) by more. A corner outside a non-periodic
//! variable's box is moved onto the box (the design cannot go there); a
//! periodic variable wraps. Units: `δ_i` in the variable's own units
//! (degrees for ply angles).
//!
//! The study's spelling, for analytic and scene problems alike:
//!
//! ```toml
//! [robustness]
//! tolerance = [2.0, 2.0]   # δ_i, one per variable, in its units
//! samples = 64             # Latin-hypercube points when n > 6
//! ```
//!
//! The multistart (alone or under `[compare]`) then writes `optima.csv`
//! with the columns `f_worst`, `max_g_worst`, `f_worst_sampled`,
//! `max_g_worst_sampled` and `robustness_evaluations` (the evaluations of
//! the check: one with gradients plus the corners or samples). Without
//! constraints the `max_g` columns are empty. Tables merged from shards
//! (`plyscape merge`) do not carry them.

use super::cluster::Optimum;
use crate::error::{Error, Result};
use crate::explore::context::Context;
use crate::optimize::{Evaluation, Problem, Variable};
use crate::report::csv::num;
use crate::study::Study;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;
use std::path::Path;

/// Largest number of variables whose 2ⁿ box corners are evaluated; above
/// it a Latin-hypercube sample of the box is.
pub const MAX_CORNER_DIMENSION: usize = 6;

/// The `[robustness]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobustnessSection {
    /// Tolerance `δ_i >= 0` of each variable, in its units, one per
    /// variable in the problem's order.
    pub tolerance: Vec<f64>,
    /// Latin-hypercube points of the box when there are more than
    /// [`MAX_CORNER_DIMENSION`] variables (default 64).
    #[serde(default = "default_samples")]
    pub samples: usize,
}

fn default_samples() -> usize {
    64
}

/// Read and check `[robustness]` (values only; the length against the
/// problem is checked when it runs). It needs a `[multistart]`, whose
/// optima it assesses.
pub fn section(study: &Study) -> Result<Option<RobustnessSection>> {
    let Some(s) = study.section::<RobustnessSection>("robustness")? else {
        return Ok(None);
    };
    if !study.has("multistart") {
        return Err(study.error(
            "robustness",
            "(table)",
            "a [multistart] too: [robustness] assesses the optima it finds",
        ));
    }
    if s.tolerance.is_empty() {
        return Err(study.error(
            "robustness.tolerance",
            "[]",
            "one tolerance >= 0 per variable",
        ));
    }
    for (i, &d) in s.tolerance.iter().enumerate() {
        if !(d.is_finite() && d >= 0.0) {
            return Err(study.error(
                format!("robustness.tolerance[{i}]"),
                d,
                "a finite tolerance >= 0 in the variable's units",
            ));
        }
    }
    if s.samples == 0 {
        return Err(study.error("robustness.samples", 0, "a sample size >= 1"));
    }
    let n = crate::explore::problem::build::variables(study)?.len();
    if s.tolerance.len() != n {
        return Err(study.error(
            "robustness.tolerance",
            format!("(array of {})", s.tolerance.len()),
            format!("{n} tolerances, one per variable"),
        ));
    }
    Ok(Some(s))
}

/// The robustness of one optimum (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Robustness {
    /// First-order worst objective `f + Σ|∂f/∂x_i| δ_i`.
    pub f_worst: f64,
    /// First-order worst constraint `max_j (g_j + Σ|∂g_j/∂x_i| δ_i)`
    /// (`None` without constraints).
    pub max_g_worst: Option<f64>,
    /// Largest f at the centre and the corners (or samples) of the box.
    pub f_worst_sampled: f64,
    /// Largest `max_j g_j` there (`None` without constraints).
    pub max_g_worst_sampled: Option<f64>,
    /// Evaluations spent: one with gradients, then the corners or samples.
    pub evaluations: usize,
}

/// The first-order worst case of an evaluation with gradients: (`f_worst`,
/// `max_g_worst`).
pub fn first_order(e: &Evaluation, delta: &[f64]) -> Result<(f64, Option<f64>)> {
    let spread = |grad: &[f64]| -> f64 { grad.iter().zip(delta).map(|(d, t)| d.abs() * t).sum() };
    let gf = e.grad_f.as_ref().ok_or_else(|| {
        Error::numerical("explore::robustness", "the evaluation returned no gradient")
    })?;
    let f_worst = e.f + spread(gf);
    if e.g.is_empty() {
        return Ok((f_worst, None));
    }
    let gg = e.grad_g.as_ref().ok_or_else(|| {
        Error::numerical(
            "explore::robustness",
            "the evaluation returned no constraint gradients",
        )
    })?;
    let worst =
        e.g.iter()
            .zip(gg)
            .map(|(g, grad)| g + spread(grad))
            .fold(f64::NEG_INFINITY, f64::max);
    Ok((f_worst, Some(worst)))
}

/// The points that check the first-order worst case: the 2ⁿ corners of
/// the box `x ± δ` for n <= [`MAX_CORNER_DIMENSION`] (corner `k` takes
/// `+δ_i` where bit i of k is set), else `samples` Latin-hypercube points
/// of the box drawn with `seed`. Non-periodic coordinates are clamped to
/// their bounds, periodic ones wrapped.
pub fn box_points(
    vars: &[Variable],
    x: &[f64],
    delta: &[f64],
    samples: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let n = vars.len();
    let place = |i: usize, t: f64| vars[i].wrap(x[i] + (2.0 * t - 1.0) * delta[i]);
    if n <= MAX_CORNER_DIMENSION {
        (0..1usize << n)
            .map(|k| (0..n).map(|i| place(i, ((k >> i) & 1) as f64)).collect())
            .collect()
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        crate::optimize::sampling::latin_hypercube(samples, n, &mut rng)
            .into_iter()
            .map(|u| (0..n).map(|i| place(i, u[i])).collect())
            .collect()
    }
}

/// Assess one design: its first-order worst case from one evaluation with
/// gradients, checked at the corners (or samples) of the box, evaluated in
/// parallel on the current rayon pool.
pub fn assess(
    problem: &dyn Problem,
    x: &[f64],
    delta: &[f64],
    samples: usize,
    seed: u64,
) -> Result<Robustness> {
    let centre = problem.evaluate(x, true)?;
    let (f_worst, max_g_worst) = first_order(&centre, delta)?;
    let points = box_points(problem.variables(), x, delta, samples, seed);
    let evals = crate::optimize::cmaes::evaluate_batch(problem, &points)?;
    let mut f_sampled = centre.f;
    let mut g_sampled = centre.max_g();
    for (p, e) in points.iter().zip(&evals) {
        if !e.f.is_finite() || e.g.iter().any(|g| !g.is_finite()) {
            return Err(Error::numerical(
                "explore::robustness",
                format!("a non-finite value at the box point {p:?}: f = {}", e.f),
            ));
        }
        f_sampled = f_sampled.max(e.f);
        g_sampled = g_sampled.max(e.max_g());
    }
    Ok(Robustness {
        f_worst,
        max_g_worst,
        f_worst_sampled: f_sampled,
        max_g_worst_sampled: max_g_worst.map(|_| g_sampled),
        evaluations: 1 + points.len(),
    })
}

/// The robustness columns' names, in `optima.csv`'s order.
pub const COLUMNS: [&str; 5] = [
    "f_worst",
    "max_g_worst",
    "f_worst_sampled",
    "max_g_worst_sampled",
    "robustness_evaluations",
];

/// `optima.csv` with the robustness columns appended (one [`Robustness`]
/// per optimum, in the table's order).
pub fn optima_table(
    vars: &[Variable],
    m: usize,
    optima: &[Optimum],
    robust: &[Robustness],
) -> Vec<Vec<String>> {
    let mut rows = super::driver::optima_table(vars, m, optima);
    rows[0].extend(COLUMNS.map(String::from));
    let opt = |v: Option<f64>| v.map(num).unwrap_or_default();
    for (row, r) in rows[1..].iter_mut().zip(robust) {
        row.extend([
            num(r.f_worst),
            opt(r.max_g_worst),
            num(r.f_worst_sampled),
            opt(r.max_g_worst_sampled),
            r.evaluations.to_string(),
        ]);
    }
    rows
}

/// When the study has `[robustness]`: assess every certified optimum of
/// the multistart `report` and rewrite `dir/optima.csv` with the columns;
/// prints one line per optimum unless quiet. Returns the assessments
/// (`None` without the section).
pub fn apply(
    ctx: &Context,
    problem: &dyn Problem,
    optima: &[Optimum],
    dir: &Path,
) -> Result<Option<Vec<Robustness>>> {
    let Some(s) = section(ctx.study)? else {
        return Ok(None);
    };
    // `section` checked the tolerances' count against the variables.
    let vars = problem.variables();
    let pool = crate::explore::context::thread_pool(ctx.threads)?;
    let seed = ctx.study.meta.seed;
    let bar = crate::report::Progress::new("robustness", optima.len() as u64, ctx.quiet);
    let robust: Vec<Robustness> = pool.install(|| {
        optima
            .iter()
            .map(|o| {
                let r = assess(problem, &o.x, &s.tolerance, s.samples, seed);
                bar.tick();
                r
            })
            .collect::<Result<_>>()
    })?;
    bar.finish();
    let m = problem.n_constraints();
    let table = optima_table(vars, m, optima, &robust);
    crate::explore::persist::tables::write_atomic(&dir.join("optima.csv"), &table)?;
    if !ctx.quiet {
        let g = |v: Option<f64>| v.map(|v| format!("{v:.6e}")).unwrap_or("-".into());
        for (o, r) in optima.iter().zip(&robust).take(10) {
            println!(
                "  robustness of optimum {:>3} (±{:?}): f {:.8e} -> worst {:.8e} (first order) / \
                 {:.8e} (sampled); max g worst {} / {} ({} evaluations)",
                o.id,
                s.tolerance,
                o.f,
                r.f_worst,
                r.f_worst_sampled,
                g(r.max_g_worst),
                g(r.max_g_worst_sampled),
                r.evaluations
            );
        }
    }
    Ok(Some(robust))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_of_two_variables_and_clamping() {
        let vars = vec![
            Variable::bounded("a", 0.0, 1.0).unwrap(),
            Variable::periodic("b", -90.0, 180.0).unwrap(),
        ];
        let p = box_points(&vars, &[0.95, 89.0], &[0.1, 2.0], 64, 1);
        assert_eq!(p.len(), 4);
        assert_eq!(p[0], [0.85, 87.0]);
        // 1.05 clamps to the bound; 91° wraps to −89°.
        assert_eq!(p[3], [1.0, -89.0]);
        let many: Vec<Variable> = (0..7)
            .map(|i| Variable::bounded(format!("x{i}"), -1.0, 1.0).unwrap())
            .collect();
        let q = box_points(&many, &[0.0; 7], &[0.5; 7], 10, 3);
        assert_eq!(q.len(), 10);
        assert!(q.iter().flatten().all(|v| v.abs() <= 0.5));
    }
}
