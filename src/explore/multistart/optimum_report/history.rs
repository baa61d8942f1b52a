//! `iterations.csv`: one row per record of the reported run (the start,
//! each iteration, and a final check that did not move; see
//! [`crate::optimize::IterRecord`]), with `iterations.svg` (f against the
//! iteration: the paper's Fig. 10), `iterations_constraints.svg` (every
//! g_j, and the solver's CT above which a constraint is active) and
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

use super::labels::Labels;
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

/// Write `iterations.csv` and, with records, its plots into `dir`.
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
    files.push(plot_objective(dir, problem, records)?);
    if !labels.constraints.is_empty() {
        files.push(plot_constraints(dir, problem, labels, records)?);
    }
    files.push(plot_design(dir, problem, labels, records)?);
    Ok(files)
}

/// Points `(iteration, value(record))` of the records that have a value.
fn per_iteration(
    records: &[(IterRecord, f64)],
    value: &dyn Fn(&IterRecord) -> Option<f64>,
) -> Vec<(f64, f64)> {
    records
        .iter()
        .filter_map(|(r, _)| Some((r.iteration as f64, value(r)?)))
        .collect()
}

/// Draw `curves` against the iteration into `dir/<file>`.
fn plot(dir: &Path, file: &str, title: &str, y: &str, curves: &[Curve]) -> Result<PathBuf> {
    let path = dir.join(file);
    line_plot(
        &path,
        &Axes {
            title,
            x: "iterations completed [-]",
            y,
            scale: Scale::Linear,
        },
        curves,
    )?;
    Ok(path)
}

/// `iterations.svg`: f against the iteration.
fn plot_objective(
    dir: &Path,
    problem: &dyn Problem,
    records: &[(IterRecord, f64)],
) -> Result<PathBuf> {
    let curves = [Curve {
        label: "f".into(),
        points: per_iteration(records, &|r| Some(r.f)),
    }];
    let title = format!("{}: objective per iteration", problem.name());
    plot(
        dir,
        "iterations.svg",
        &title,
        &problem.objective_label(),
        &curves,
    )
}

/// `iterations_constraints.svg`: each g_j, and CT, against the iteration.
fn plot_constraints(
    dir: &Path,
    problem: &dyn Problem,
    labels: &Labels,
    records: &[(IterRecord, f64)],
) -> Result<PathBuf> {
    let mut curves: Vec<Curve> = labels
        .constraints
        .iter()
        .enumerate()
        .map(|(j, name)| Curve {
            label: name.clone(),
            points: per_iteration(records, &|r| r.g.get(j).copied()),
        })
        .collect();
    let ct = per_iteration(records, &|r| r.ct);
    if !ct.is_empty() {
        curves.push(Curve {
            label: "CT (g_j >= CT: active)".into(),
            points: ct,
        });
    }
    let title = format!("{}: constraints per iteration", problem.name());
    let file = "iterations_constraints.svg";
    plot(dir, file, &title, "g_j [-] (feasible <= 0)", &curves)
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
            points: per_iteration(records, &|r| r.x.get(i).copied()),
        })
        .collect();
    let title = format!("{}: design variables per iteration", problem.name());
    let y = format!("design variables [{}]", labels.x_unit);
    plot(dir, "iterations_design.svg", &title, &y, &curves)
}
