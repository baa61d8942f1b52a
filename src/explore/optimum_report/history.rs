//! `iterations.csv`: one row per record of the reported run (the start,
//! each iteration, and a final check that did not move; see
//! [`crate::optimize::IterRecord`]), with `iterations.svg` (f and every
//! g_j against the iteration: the paper's Fig. 10 with its constraint) and
//! `iterations_design.svg` (the design variables: Fig. 11).
//!
//! Columns: `iteration` (iterations completed), `record` (`start`,
//! `iteration`, `final_check`), `f` (the problem's objective, normalized
//! for a scene problem with `normalize_at`), `objective [unit]` (`f ×
//! divisor`, the response in its SI unit, e.g. Ψ₀ in J*s), `g1..gm`,
//! `max_g`, `ct` (the solver's constraint thickness at this design; empty
//! without one), `active` (the constraints with `g_j >= ct`), `step`
//! (scaled step length of the iteration), `function_calls` and
//! `gradient_calls` (cumulative, as DOT counts them), `wall [s]` (since
//! the run started), `x_<variable>` (in the variables' unit, degrees for
//! a scene problem).

use super::Labels;
use crate::error::Result;
use crate::optimize::{IterRecord, Problem};
use crate::report::csv::{num, write_table};
use crate::report::{line_plot, Axes, Curve, Scale};
use std::path::{Path, PathBuf};

/// The kind of record `k` of `records`.
pub fn record_kind(records: &[(IterRecord, f64)], k: usize) -> &'static str {
    if k == 0 {
        "start"
    } else if records[k].0.iteration == records[k - 1].0.iteration {
        "final_check"
    } else {
        "iteration"
    }
}

/// The header of `iterations.csv`.
pub fn header(problem: &dyn Problem, labels: &Labels) -> Vec<String> {
    let mut h = vec![
        "iteration".to_string(),
        "record".into(),
        "f".into(),
        format!("objective [{}]", labels.unit),
    ];
    h.extend((1..=labels.constraints.len()).map(|j| format!("g{j}")));
    h.extend(
        [
            "max_g",
            "ct",
            "active",
            "step",
            "function_calls",
            "gradient_calls",
            "wall [s]",
        ]
        .map(String::from),
    );
    h.extend(problem.variables().iter().map(|v| format!("x_{}", v.name)));
    h
}

/// The row of record `k` (with its wall time).
fn row(records: &[(IterRecord, f64)], k: usize, labels: &Labels) -> Vec<String> {
    let (r, wall) = &records[k];
    let mut row = vec![
        r.iteration.to_string(),
        record_kind(records, k).into(),
        num(r.f),
        num(r.f * labels.divisor),
    ];
    row.extend(r.g.iter().map(|&g| num(g)));
    row.push(if r.g.is_empty() {
        String::new()
    } else {
        num(r.max_g)
    });
    row.push(r.ct.map(num).unwrap_or_default());
    let active: Vec<&str> = r
        .active()
        .iter()
        .map(|&j| labels.constraints[j].as_str())
        .collect();
    row.push(active.join("; "));
    row.push(num(r.step));
    row.push(r.function_calls.to_string());
    row.push(r.gradient_calls.to_string());
    row.push(num(*wall));
    row.extend(r.x.iter().map(|&x| num(x)));
    row
}

/// Write `iterations.csv` and, with records, its two plots into `dir`.
pub fn write(
    dir: &Path,
    problem: &dyn Problem,
    labels: &Labels,
    records: &[(IterRecord, f64)],
) -> Result<Vec<PathBuf>> {
    let path = dir.join("iterations.csv");
    let rows: Vec<Vec<String>> = (0..records.len())
        .map(|k| row(records, k, labels))
        .collect();
    write_table(&path, &header(problem, labels), &rows)?;
    let mut files = vec![path];
    if records.is_empty() {
        return Ok(files);
    }
    files.push(plot_values(dir, problem, labels, records)?);
    files.push(plot_design(dir, problem, labels, records)?);
    Ok(files)
}

/// `iterations.svg`: f and each g_j against the iteration.
fn plot_values(
    dir: &Path,
    problem: &dyn Problem,
    labels: &Labels,
    records: &[(IterRecord, f64)],
) -> Result<PathBuf> {
    let at = |value: &dyn Fn(&IterRecord) -> f64| -> Vec<(f64, f64)> {
        records
            .iter()
            .map(|(r, _)| (r.iteration as f64, value(r)))
            .collect()
    };
    let mut curves = vec![Curve {
        label: "f".into(),
        points: at(&|r| r.f),
    }];
    for (j, name) in labels.constraints.iter().enumerate() {
        curves.push(Curve {
            label: name.clone(),
            points: at(&|r| r.g[j]),
        });
    }
    let path = dir.join("iterations.svg");
    line_plot(
        &path,
        &Axes {
            title: &format!(
                "{}: objective and constraints per iteration",
                problem.name()
            ),
            x: "iterations completed [-]",
            y: &format!("{}; g_j [-]", problem.objective_label()),
            scale: Scale::Linear,
        },
        &curves,
    )?;
    Ok(path)
}

/// `iterations_design.svg`: each design variable against the iteration.
fn plot_design(
    dir: &Path,
    problem: &dyn Problem,
    labels: &Labels,
    records: &[(IterRecord, f64)],
) -> Result<PathBuf> {
    let curves: Vec<Curve> = problem
        .variables()
        .iter()
        .enumerate()
        .map(|(i, v)| Curve {
            label: v.name.clone(),
            points: records
                .iter()
                .map(|(r, _)| (r.iteration as f64, r.x[i]))
                .collect(),
        })
        .collect();
    let path = dir.join("iterations_design.svg");
    line_plot(
        &path,
        &Axes {
            title: &format!("{}: design variables per iteration", problem.name()),
            x: "iterations completed [-]",
            y: &format!("design variables [{}]", labels.x_unit),
            scale: Scale::Linear,
        },
        &curves,
    )?;
    Ok(path)
}
