//! What `[front]` writes: `front.csv`, `front_summary.csv`, `grid.csv`,
//! `front.svg` and `front_design.svg` (see [`super::command`] for the
//! columns), all through [`crate::report`].
//!
//! Objectives are written in the study's sign and their own unit: the
//! evaluated (minimized, possibly normalised) value `f` becomes
//! `sign · scale · f` ([`MultiProblem::objective_scale`]), and a column is
//! named `<objective> [<unit>]` when the problem states a unit
//! ([`MultiProblem::objective_unit`]).

use super::gradient::SubproblemEnd;
use super::grid::GridFront;
use crate::error::Result;
use crate::explore::persist::tables::class_name;
use crate::optimize::multiobjective::MultiProblem;
use crate::report::csv::{num, write_table};
use crate::report::{scatter_plot, Axes, Scale, Series};
use std::path::Path;

/// One method's front and its indicators.
#[derive(Debug, Clone)]
pub struct MethodFront {
    /// `mmfd-tchebycheff`, `nsga2` or `grid`.
    pub method: String,
    /// Designs and objectives (minimized orientation, as evaluated).
    pub points: Vec<(Vec<f64>, Vec<f64>)>,
    /// Function calls.
    pub function_calls: usize,
    /// Gradient calls.
    pub gradient_calls: usize,
    /// Simulations run, for a problem that caches evaluations by design
    /// (the scene's); `None` where every call evaluates.
    pub simulations: Option<usize>,
    /// Wall time \[s\].
    pub wall_seconds: f64,
    /// Certified ends of all runs (`(certified, runs)`; gradient side).
    pub certified: Option<(usize, usize)>,
    /// Hypervolume to the reference point, in the evaluated objectives.
    pub hypervolume: f64,
    /// IGD to the union front.
    pub igd_union: Option<f64>,
    /// IGD to the analytic front, when known.
    pub igd_analytic: Option<f64>,
}

/// What `[front]` computed.
#[derive(Debug, Clone)]
pub struct FrontReport {
    /// The objectives' names.
    pub objectives: Vec<String>,
    /// The methods: gradient side, NSGA-II, then the grid when asked.
    pub methods: Vec<MethodFront>,
    /// The reference point (minimized orientation, as evaluated).
    pub reference: Vec<f64>,
    /// Evaluations served from the journal of a killed run (`run
    /// --resume`).
    pub replayed: usize,
}

/// How an evaluated objective vector is written: `sign · scale · f`.
struct Units {
    factor: Vec<f64>,
}

impl Units {
    fn new(problem: &dyn MultiProblem, signs: &[f64]) -> Units {
        Units {
            factor: (signs.iter().enumerate())
                .map(|(k, s)| s * problem.objective_scale(k))
                .collect(),
        }
    }
    fn of(&self, f: &[f64]) -> Vec<f64> {
        f.iter().zip(&self.factor).map(|(v, s)| v * s).collect()
    }
}

/// `psi0 [J*s]`, or the bare name without a unit.
fn column_name(problem: &dyn MultiProblem, names: &[String], k: usize) -> String {
    match problem.objective_unit(k) {
        Some(u) => format!("{} [{u}]", names[k]),
        None => names[k].clone(),
    }
}

fn field(v: Option<f64>) -> String {
    v.map(num).unwrap_or_default()
}

/// Every output of `[front]` in `dir`; `ends` are the gradient side's
/// runs and, with `[front] hybrid`, the hybrid's subproblems.
pub fn write_outputs(
    problem: &dyn MultiProblem,
    report: &FrontReport,
    signs: &[f64],
    analytic: Option<&[Vec<f64>]>,
    grid: Option<&GridFront>,
    (ends, hybrid): (&[SubproblemEnd], Option<&[SubproblemEnd]>),
    dir: &Path,
) -> Result<()> {
    let units = Units::new(problem, signs);
    let names = &report.objectives;
    let columns: Vec<String> = (0..names.len())
        .map(|k| column_name(problem, names, k))
        .collect();
    let xcols = problem.variables().iter().map(|v| format!("x_{}", v.name));
    let mut header = vec!["method".to_string()];
    header.extend(xcols.clone());
    header.extend(columns.iter().cloned());
    let mut rows = Vec::new();
    for mf in &report.methods {
        for (x, f) in &mf.points {
            let mut r = vec![mf.method.clone()];
            r.extend(x.iter().map(|&v| num(v)));
            r.extend(units.of(f).into_iter().map(num));
            rows.push(r);
        }
    }
    write_table(&dir.join("front.csv"), &header, &rows)?;
    write_summary(report, &units, dir)?;
    write_ends(problem, ends, &columns, &units, &dir.join("front_ends.csv"))?;
    if let Some(hybrid) = hybrid {
        write_ends(
            problem,
            hybrid,
            &columns,
            &units,
            &dir.join("hybrid_ends.csv"),
        )?;
    }
    if let Some(grid) = grid {
        let mut header: Vec<String> = xcols.collect();
        header.extend(columns.iter().cloned());
        header.extend(["max_g".to_string(), "error".into()]);
        let width = names.len() + 1;
        let rows: Vec<Vec<String>> = (grid.points.iter())
            .map(|p| {
                let mut r: Vec<String> = p.x.iter().map(|&v| num(v)).collect();
                match &p.result {
                    Ok(e) => {
                        r.extend(units.of(&e.f).into_iter().map(num));
                        r.push(if e.g.is_empty() {
                            String::new()
                        } else {
                            num(e.max_g())
                        });
                        r.push(String::new());
                    }
                    Err(msg) => {
                        r.extend(std::iter::repeat_n(String::new(), width));
                        r.push(msg.replace(['\n', ','], " "));
                    }
                }
                r
            })
            .collect();
        write_table(&dir.join("grid.csv"), &header, &rows)?;
    }
    write_plots(problem, report, &units, analytic, dir)
}

/// `front_ends.csv`: every run of the gradient side, in order (anchors
/// from each start, lexicographic anchors, subproblems): its label, class
/// (`converged` ends are certified), the solver's exit, calls, the
/// Kuhn–Tucker residual, what became of the end in the front
/// ([`super::gradient::front_roles`]: `point`, `dominated by <run>`, `equal
/// to <run>`, `not certified (<class>)`, `anchor start`), the end design
/// (without the subproblem's `t`) and, for the certified ends, the
/// objectives in their units. `hybrid_ends.csv`: the same for the
/// hybrid's subproblems.
fn write_ends(
    problem: &dyn MultiProblem,
    ends: &[SubproblemEnd],
    columns: &[String],
    units: &Units,
    path: &Path,
) -> Result<()> {
    let vars = problem.variables();
    let mut header: Vec<String> = [
        "run",
        "class",
        "exit",
        "function_calls",
        "gradient_calls",
        "kt_residual",
        "front",
    ]
    .map(String::from)
    .to_vec();
    header.extend(vars.iter().map(|v| format!("x_{}", v.name)));
    header.extend(columns.iter().cloned());
    let roles = super::gradient::front_roles(super::gradient::Merge::Designs(vars), ends);
    let rows: Vec<Vec<String>> = ends
        .iter()
        .zip(roles)
        .map(|(e, role)| {
            let mut r = vec![
                e.label.clone(),
                class_name(&e.run).to_string(),
                e.run.exit.replace(['\n', ','], " "),
                e.run.function_calls.to_string(),
                e.run.gradient_calls.to_string(),
                field(e.run.certificate.as_ref().and_then(|c| c.kt_residual)),
                role.to_string(),
            ];
            match &e.run.result {
                Some(end) => r.extend(end.x[..vars.len()].iter().map(|&v| num(v))),
                None => r.extend(std::iter::repeat_n(String::new(), vars.len())),
            }
            match &e.f {
                Some(f) => r.extend(units.of(f).into_iter().map(num)),
                None => r.extend(std::iter::repeat_n(String::new(), columns.len())),
            }
            r
        })
        .collect();
    write_table(path, &header, &rows)
}

/// `front_summary.csv`: one row per method.
fn write_summary(report: &FrontReport, units: &Units, dir: &Path) -> Result<()> {
    let names = &report.objectives;
    let mut header: Vec<String> = [
        "method",
        "points",
        "function_calls",
        "gradient_calls",
        "wall_seconds",
        "certified_ends",
        "hypervolume",
    ]
    .map(String::from)
    .to_vec();
    header.extend(names.iter().map(|n| format!("reference_{n}")));
    header.extend(["igd_union".to_string(), "igd_analytic".into()]);
    let reference = units.of(&report.reference);
    let rows: Vec<Vec<String>> = report
        .methods
        .iter()
        .map(|mf| {
            let mut r = vec![
                mf.method.clone(),
                mf.points.len().to_string(),
                mf.function_calls.to_string(),
                mf.gradient_calls.to_string(),
                format!("{:.3}", mf.wall_seconds),
                mf.certified
                    .map(|(c, n)| format!("{c}/{n}"))
                    .unwrap_or_default(),
                num(mf.hypervolume),
            ];
            r.extend(reference.iter().map(|&v| num(v)));
            r.push(field(mf.igd_union));
            r.push(field(mf.igd_analytic));
            r
        })
        .collect();
    write_table(&dir.join("front_summary.csv"), &header, &rows)
}

/// `front.svg` (objective space) and, for two variables,
/// `front_design.svg` (the front's designs in design space).
fn write_plots(
    problem: &dyn MultiProblem,
    report: &FrontReport,
    units: &Units,
    analytic: Option<&[Vec<f64>]>,
    dir: &Path,
) -> Result<()> {
    let names = &report.objectives;
    let pair = |f: &[f64]| {
        let v = units.of(f);
        (v[0], v[1])
    };
    let mut series = Vec::new();
    if let (Some(a), 2) = (analytic, names.len()) {
        series.push(Series {
            label: "analytic front".into(),
            points: a.iter().map(|f| pair(f)).collect(),
            line: true,
        });
    }
    for mf in &report.methods {
        series.push(Series {
            label: format!("{} ({} points)", mf.method, mf.points.len()),
            points: mf.points.iter().map(|p| pair(&p.1)).collect(),
            line: false,
        });
    }
    let x0 = problem.start();
    let start = problem.evaluate(&x0, false)?;
    series.push(Series {
        label: "start design".into(),
        points: vec![pair(&start.f)],
        line: false,
    });
    let title = if names.len() == 3 {
        format!(
            "{}: front, {} against {} (projection)",
            problem.name(),
            names[1],
            names[0]
        )
    } else {
        format!("{}: Pareto front", problem.name())
    };
    let (x, y) = (problem.objective_label(0), problem.objective_label(1));
    let axes = Axes {
        title: &title,
        x: &x,
        y: &y,
        scale: Scale::Linear,
    };
    scatter_plot(&dir.join("front.svg"), &axes, &series)?;
    if problem.variables().len() != 2 {
        return Ok(());
    }
    let mut series: Vec<Series> = (report.methods.iter())
        .map(|mf| Series {
            label: format!("{} ({} points)", mf.method, mf.points.len()),
            points: mf.points.iter().map(|p| (p.0[0], p.0[1])).collect(),
            line: false,
        })
        .collect();
    series.push(Series {
        label: "start design".into(),
        points: vec![(x0[0], x0[1])],
        line: false,
    });
    let title = format!("{}: designs along the front", problem.name());
    let (x, y) = (problem.variable_label(0), problem.variable_label(1));
    let axes = Axes {
        title: &title,
        x: &x,
        y: &y,
        scale: Scale::Linear,
    };
    scatter_plot(&dir.join("front_design.svg"), &axes, &series)
}
