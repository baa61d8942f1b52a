//! `optimum_summary.csv`: the reported run in one row, as the paper's
//! Table 5 reports its MMFD run.
//!
//! Columns: `start` (index), `method`, `exit` (termination or `error:
//! ...`), `x0_<variable>` and `x_<variable>` (start and optimum, in the
//! variables' unit), `f_start` and `f_optimum` (the problem's objective,
//! normalized for a scene problem with `normalize_at`),
//! `objective_start [unit]` and `objective_optimum [unit]` (`f ×
//! divisor`: the response in its SI unit, e.g. Ψ₀ in J*s),
//! `reduction [%]` = `100 (f_start − f_optimum) / |f_start|`, `max_g`,
//! `feasibility_tolerance` (the multistart's), `active_constraints` and
//! `active` (constraints with `g_j >= −feasibility_tolerance` at the
//! optimum: on their limit within the tolerance, or beyond it), and
//! `active_side_constraints` (non-periodic variables on a bound),
//! `variables`, `constraints`, `function_calls`, `gradient_calls`,
//! `iterations`, `wall_seconds` (the run's, beside the other starts on
//! `threads` threads), `threads`, `load_1min` (the machine's 1-minute load
//! average when the row was written; empty where unknown). Fields of a
//! failed run's optimum are empty.

use super::labels::Labels;
use crate::error::Result;
use crate::explore::persist::tables::RunRecord;
use crate::optimize::Problem;
use crate::report::csv::{num, write_table};
use std::path::{Path, PathBuf};

/// What the row needs besides the run.
#[derive(Debug, Clone)]
pub struct Facts<'a> {
    /// The local method (`mmfd`).
    pub method: &'a str,
    /// f at the start design (the history's first record).
    pub f_start: Option<f64>,
    /// Feasibility tolerance of the multistart.
    pub tolerance: f64,
    /// Threads the multistart ran on.
    pub threads: usize,
    /// 1-minute load average.
    pub load: Option<f64>,
}

/// The header of `optimum_summary.csv`.
pub fn header(problem: &dyn Problem, labels: &Labels) -> Vec<String> {
    let vars = problem.variables();
    let mut h = vec!["start".to_string(), "method".into(), "exit".into()];
    h.extend(vars.iter().map(|v| format!("x0_{}", v.name)));
    h.extend(vars.iter().map(|v| format!("x_{}", v.name)));
    let u = &labels.unit;
    h.extend([
        "f_start".into(),
        "f_optimum".into(),
        format!("objective_start [{u}]"),
        format!("objective_optimum [{u}]"),
        "reduction [%]".into(),
    ]);
    h.extend(
        [
            "max_g",
            "feasibility_tolerance",
            "active_constraints",
            "active",
            "active_side_constraints",
            "variables",
            "constraints",
            "function_calls",
            "gradient_calls",
            "iterations",
            "wall_seconds",
            "threads",
            "load_1min",
        ]
        .map(String::from),
    );
    h
}

/// The constraints active at `g`: `g_j >= −tolerance`.
pub fn active(g: &[f64], tolerance: f64) -> Vec<usize> {
    (0..g.len()).filter(|&j| g[j] >= -tolerance).collect()
}

/// The row of `run`.
pub fn row(problem: &dyn Problem, labels: &Labels, run: &RunRecord, facts: &Facts) -> Vec<String> {
    let vars = problem.variables();
    let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
    let res = run.result.as_ref();
    let f_opt = res.map(|r| r.f);
    let mut row = vec![
        run.start.to_string(),
        facts.method.to_string(),
        run.exit.replace(['\n', '\r'], " "),
    ];
    row.extend(run.x0.iter().map(|&x| num(x)));
    match res {
        Some(r) => row.extend(r.x.iter().map(|&x| num(x))),
        None => row.extend(vars.iter().map(|_| String::new())),
    }
    let reduction = match (facts.f_start, f_opt) {
        (Some(a), Some(b)) if a != 0.0 => Some(100.0 * (a - b) / a.abs()),
        _ => None,
    };
    row.extend([
        opt(facts.f_start),
        opt(f_opt),
        opt(facts.f_start.map(|f| f * labels.divisor)),
        opt(f_opt.map(|f| f * labels.divisor)),
        opt(reduction),
    ]);
    let g = res.map(|r| r.g.as_slice()).unwrap_or(&[]);
    let act = active(g, facts.tolerance);
    let names: Vec<&str> = act
        .iter()
        .map(|&j| labels.constraints[j].as_str())
        .collect();
    let side = res.map(|r| {
        vars.iter()
            .zip(&r.x)
            .filter(|(v, &x)| v.period.is_none() && (x <= v.lower || x >= v.upper))
            .count()
    });
    row.extend([
        opt(res.filter(|r| !r.g.is_empty()).map(|r| r.max_g())),
        num(facts.tolerance),
        res.map(|_| act.len().to_string()).unwrap_or_default(),
        names.join("; "),
        side.map(|s| s.to_string()).unwrap_or_default(),
        vars.len().to_string(),
        problem.n_constraints().to_string(),
        run.function_calls.to_string(),
        run.gradient_calls.to_string(),
        run.iterations.to_string(),
        num(run.wall_seconds),
        facts.threads.to_string(),
        opt(facts.load),
    ]);
    row
}

/// Write `optimum_summary.csv` into `dir`.
pub fn write(
    dir: &Path,
    problem: &dyn Problem,
    labels: &Labels,
    run: &RunRecord,
    facts: &Facts,
) -> Result<PathBuf> {
    let path = dir.join("optimum_summary.csv");
    write_table(
        &path,
        &header(problem, labels),
        &[row(problem, labels, run, facts)],
    )?;
    Ok(path)
}
