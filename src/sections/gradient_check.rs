//! `[gradient_check]`: what the fixed-mode approximation costs in gradient
//! accuracy against what it saves in time.
//!
//! The ply-angle gradients of a scene problem go through the mode
//! derivatives of its panels. The updated-mode approach (paper Eq. 18)
//! differentiates eigenvalues and eigenvectors, `Λ'` and `X'`; the
//! fixed-mode approach (Eq. 19) keeps the eigenvectors and differentiates
//! only `Λ`, which is cheaper and approximate. For each listed problem and
//! design this section computes:
//! - `∇f` and `∇g_j` with each approach (median time of `repeats` f+g
//!   evaluations after one untimed warm-up);
//! - the central differences `(h(x + δ e_i) − h(x − δ e_i)) / 2δ` of the
//!   f-only evaluation for every variable (δ = `step_deg`; their time is the
//!   sum of the 2n evaluations);
//! - with `optimize = true`, one MMFD run from the problem's start with each
//!   approach (DOT's default settings): optimum, calls, iterations, time.
//!
//! Output: `gradient_check.csv` (one row per approach, function and
//! variable; `central` for the differences) and, with `optimize`,
//! `gradient_optimize.csv`, in the study's output folder. Gradients are
//! per degree (the problem's variables are ply angles in degrees).

use super::stats::median;
use crate::error::Result;
use crate::explore::problem::scene_problem::SceneProblem;
use crate::modal::ModeUpdate;
use crate::optimize::{Evaluation, Problem};
use crate::report::csv::{num, Table};
use crate::study::Study;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The `[gradient_check]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GradientCheckSpec {
    /// Study files with a scene problem (paths relative to this study).
    pub problems: Vec<PathBuf>,
    /// Designs \[deg\] (default: each problem's start).
    #[serde(default)]
    pub designs: Vec<Vec<f64>>,
    /// Central-difference step δ \[deg\] (default 1e-3).
    #[serde(default = "default_step")]
    pub step_deg: f64,
    /// Timed f+g evaluations per approach (median reported; default 3).
    #[serde(default = "default_repeats")]
    pub repeats: usize,
    /// Also run MMFD from the start with each approach (default false).
    #[serde(default)]
    pub optimize: bool,
}

fn default_step() -> f64 {
    1e-3
}
fn default_repeats() -> usize {
    3
}

/// Read and check `[gradient_check]` without running anything.
pub fn check(study: &Study) -> Result<GradientCheckSpec> {
    let spec: GradientCheckSpec =
        study.require_section("gradient_check", "problems = [\"<study>.toml\"]")?;
    if spec.problems.is_empty() {
        return Err(study.error("gradient_check.problems", "[]", "at least one study file"));
    }
    if !(spec.step_deg.is_finite() && spec.step_deg > 0.0 && spec.step_deg < 1.0) {
        return Err(study.error(
            "gradient_check.step_deg",
            spec.step_deg,
            "a step 0 < δ < 1 deg",
        ));
    }
    if spec.repeats == 0 {
        return Err(study.error("gradient_check.repeats", 0, "at least 1 repetition"));
    }
    Ok(spec)
}

/// `gradient_check.csv` headers.
pub const HEADERS: [&str; 10] = [
    "problem",
    "design [deg]",
    "derivatives",
    "function",
    "variable",
    "gradient [1/deg]",
    "central_difference [1/deg]",
    "abs_error [1/deg]",
    "rel_error",
    "time [ms]",
];

/// The values `[f, g_1, ..]` of an evaluation.
fn values(e: &Evaluation) -> Vec<f64> {
    std::iter::once(e.f).chain(e.g.iter().copied()).collect()
}

/// Gradient rows `[function][variable]` of an evaluation.
fn gradients(e: &Evaluation) -> Vec<Vec<f64>> {
    let mut out = vec![e.grad_f.clone().unwrap_or_default()];
    out.extend(e.grad_g.clone().unwrap_or_default());
    out
}

/// Central differences of every function by every variable at `x`, and
/// their wall time \[s\].
fn central(p: &SceneProblem, x: &[f64], step: f64) -> Result<(Vec<Vec<f64>>, f64)> {
    let t = Instant::now();
    let m = 1 + p.n_constraints();
    let mut d = vec![vec![0.0; x.len()]; m];
    for i in 0..x.len() {
        let at = |s: f64| {
            let mut y = x.to_vec();
            y[i] += s;
            p.evaluate(&y, false).map(|e| values(&e))
        };
        let (plus, minus) = (at(step)?, at(-step)?);
        for (k, row) in d.iter_mut().enumerate() {
            row[i] = (plus[k] - minus[k]) / (2.0 * step);
        }
    }
    Ok((d, t.elapsed().as_secs_f64()))
}

/// Gradients by `update` at `x`: the last evaluation and the median time
/// \[s\] of `repeats` after a warm-up.
fn timed_gradient(
    p: &mut SceneProblem,
    update: ModeUpdate,
    x: &[f64],
    repeats: usize,
) -> Result<(Vec<Vec<f64>>, f64)> {
    p.set_mode_update(update);
    let mut e = p.evaluate(x, true)?;
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let t = Instant::now();
        e = p.evaluate(x, true)?;
        times.push(t.elapsed().as_secs_f64());
    }
    Ok((gradients(&e), median(times)))
}

/// The rows of one problem and design.
fn design_rows(
    name: &str,
    p: &mut SceneProblem,
    x: &[f64],
    spec: &GradientCheckSpec,
) -> Result<Vec<Vec<String>>> {
    let (cd, cd_time) = central(p, x, spec.step_deg)?;
    let design: Vec<String> = x.iter().map(|v| num(*v)).collect();
    let vars: Vec<String> = p.variables().iter().map(|v| v.name.clone()).collect();
    let function = |k: usize| {
        if k == 0 {
            "f".to_string()
        } else {
            format!("g{k}")
        }
    };
    let mut rows = Vec::new();
    for (k, row) in cd.iter().enumerate() {
        for (i, v) in row.iter().enumerate() {
            rows.push(vec![
                name.to_string(),
                design.join(" "),
                "central".into(),
                function(k),
                vars[i].clone(),
                String::new(),
                num(*v),
                String::new(),
                String::new(),
                format!("{:.3}", 1e3 * cd_time),
            ]);
        }
    }
    for update in [ModeUpdate::Updated, ModeUpdate::Fixed] {
        let (grad, time) = timed_gradient(p, update, x, spec.repeats)?;
        for (k, row) in grad.iter().enumerate() {
            let scale = cd[k].iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
            for (i, g) in row.iter().enumerate() {
                let err = (g - cd[k][i]).abs();
                rows.push(vec![
                    name.to_string(),
                    design.join(" "),
                    update.name().into(),
                    function(k),
                    vars[i].clone(),
                    num(*g),
                    num(cd[k][i]),
                    num(err),
                    num(err / scale),
                    format!("{:.3}", 1e3 * time),
                ]);
            }
        }
    }
    Ok(rows)
}

/// `gradient_optimize.csv` headers.
pub const OPTIMIZE_HEADERS: [&str; 10] = [
    "problem",
    "derivatives",
    "start [deg]",
    "optimum [deg]",
    "f",
    "max_g",
    "function_calls",
    "gradient_calls",
    "iterations",
    "wall [s]",
];

/// One MMFD run from the start per approach.
fn optimize_rows(name: &str, p: &mut SceneProblem) -> Result<Vec<Vec<String>>> {
    // DOT's settings as they are, CTMIN included (the paper's runs).
    let solver = crate::explore::local::solvers::local(
        crate::explore::local::solvers::LocalMethod::Mmfd,
        &Default::default(),
        crate::explore::local::solvers::MmfdPreset::Dot,
        (crate::optimize::mmfd::MmfdOptions::dot().ctmin, 0.0),
    )?;
    let start = p.start().to_vec();
    let mut rows = Vec::new();
    for update in [ModeUpdate::Updated, ModeUpdate::Fixed] {
        p.set_mode_update(update);
        let t = Instant::now();
        let o = solver.minimize(p, &start, &mut crate::optimize::NoObserver)?;
        let wall = t.elapsed().as_secs_f64();
        let text = |x: &[f64]| x.iter().map(|v| num(*v)).collect::<Vec<_>>().join(" ");
        rows.push(vec![
            name.to_string(),
            update.name().into(),
            text(&start),
            text(&o.x),
            num(o.f),
            o.g.iter()
                .copied()
                .reduce(f64::max)
                .map_or(String::new(), num),
            o.function_calls.to_string(),
            o.gradient_calls.to_string(),
            o.iterations.to_string(),
            format!("{wall:.3}"),
        ]);
    }
    Ok(rows)
}

/// The `[gradient_check]` handler: every problem and design, then the
/// tables.
pub fn run_gradient_check(study: &Study, out: &Path, quiet: bool) -> Result<Vec<PathBuf>> {
    let spec = check(study)?;
    let base = study.path.parent().unwrap_or(Path::new("."));
    let (mut rows, mut opt) = (Vec::new(), Vec::new());
    for (k, file) in spec.problems.iter().enumerate() {
        let at = format!("gradient_check.problems[{k}]");
        let inner = Study::load(base.join(file)).map_err(|e| e.in_file(&study.path, &at))?;
        let mut p = SceneProblem::from_study(&inner)?;
        let designs = if spec.designs.is_empty() {
            vec![p.start().to_vec()]
        } else {
            spec.designs.clone()
        };
        let name = inner.name().to_string();
        for (j, x) in designs.iter().enumerate() {
            if x.len() != p.variables().len() {
                return Err(study.error(
                    format!("gradient_check.designs[{j}]"),
                    format!("{x:?}"),
                    format!("{} angles [deg]", p.variables().len()),
                ));
            }
            rows.extend(design_rows(&name, &mut p, x, &spec)?);
        }
        if spec.optimize {
            opt.extend(optimize_rows(&name, &mut p)?);
        }
    }
    let dir = study.output_dir(out)?;
    let mut files = vec![write(&dir.join("gradient_check.csv"), &HEADERS, &rows)?];
    if spec.optimize {
        files.push(write(
            &dir.join("gradient_optimize.csv"),
            &OPTIMIZE_HEADERS,
            &opt,
        )?);
    }
    if !quiet {
        for r in rows.iter().chain(&opt) {
            println!("{}", r.join("  "));
        }
    }
    Ok(files)
}

fn write(path: &Path, headers: &[&str], rows: &[Vec<String>]) -> Result<PathBuf> {
    let mut t = Table::new(path);
    t.row(headers)?;
    for r in rows {
        t.row(r)?;
    }
    t.finish()
}
