//! `[front]`: the Pareto front of two or three objectives, from the
//! gradient side ([`crate::explore::front`]: certified Tchebycheff
//! subproblems solved by MMFD) and from NSGA-II
//! ([`crate::optimize::nsga2`]), with their indicators.
//!
//! Budgets: the gradient side runs `subproblems` subproblems (plus one
//! anchor and one lexicographic anchor per objective); NSGA-II gets
//! `evaluations` function calls (default: as many as the gradient side
//! used, gradient calls not counted extra), in generations of
//! `population`.
//!
//! Outputs in the study's folder, all through [`crate::report`]:
//! - `front.csv`: the non-dominated designs of each method; columns
//!   `method`, `x_<variable>` per variable, then one column per objective
//!   named as the objective, in its own sign (a maximized objective is
//!   written as its value, not negated).
//! - `front_summary.csv`: one row per method: `points`, `function_calls`,
//!   `gradient_calls`, `wall_seconds`, `certified_ends` (the gradient
//!   side's certified ends of all its runs), `hypervolume` with the
//!   reference point in `reference_<objective>` columns, `igd_union` (IGD
//!   to the non-dominated union of both methods' fronts) and
//!   `igd_analytic` (IGD to the problem's analytic front when it has one).
//!   Hypervolume and IGD are computed in the minimized orientation
//!   ([`crate::optimize::indicators`]); the reference point is
//!   `[front] reference` or, by default, the union's nadir plus a tenth of
//!   its ideal-to-nadir range in each objective (`(1.1, 1.1)` on ZDT1).
//! - `front.svg`: the first two objectives, both methods' fronts, the start
//!   design and the analytic front (two objectives) when known.

use crate::error::{Error, Result};
use crate::explore::front::{gradient_front, GradientSettings};
use crate::explore::problems::ProblemSpec;
use crate::explore::settle::EndPolicy;
use crate::optimize::indicators::{hypervolume, igd};
use crate::optimize::kkt::KktTolerances;
use crate::optimize::mmfd::MmfdOptions;
use crate::optimize::multiobjective::{non_dominated, MultiProblem, Oriented};
use crate::optimize::nsga2::{self, Nsga2Options};
use crate::report::csv::{num, write_table};
use crate::report::{scatter_plot, Axes, Scale, Series};
use crate::study::Study;
use serde::Deserialize;
use std::path::Path;
use std::time::Instant;

/// Whether a study minimizes or maximizes an objective.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Goal {
    /// Smaller is better (default).
    #[default]
    Minimize,
    /// Larger is better.
    Maximize,
}

/// One objective of `[front]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectiveSpec {
    /// The problem's name of the objective (`f1`, …).
    pub name: String,
    /// `minimize` (default) or `maximize`.
    #[serde(default)]
    pub goal: Goal,
}

/// The `[front]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrontSection {
    /// Two or three objectives of the `[problem]`.
    pub objectives: Vec<ObjectiveSpec>,
    /// Subproblems of the gradient side (default 32).
    #[serde(default = "default_subproblems")]
    pub subproblems: usize,
    /// NSGA-II's population (even, >= 4; default 100).
    #[serde(default = "default_population")]
    pub population: usize,
    /// NSGA-II's function-call budget (default: the gradient side's
    /// function calls).
    pub evaluations: Option<usize>,
    /// Hypervolume reference point, one value per objective in its own
    /// sign (default: see the module doc).
    pub reference: Option<Vec<f64>>,
    /// Starts of each single-objective anchor of the gradient side: the
    /// start design and seeded random designs (default 1: the start design
    /// only).
    #[serde(default = "default_anchor_starts")]
    pub anchor_starts: usize,
    /// Feasible: `max g <= feasibility_tolerance` (default 1e-6), for the
    /// certificate, MMFD's CTMIN and NSGA-II's constraint-domination.
    pub feasibility_tolerance: Option<f64>,
}

fn default_subproblems() -> usize {
    32
}

fn default_anchor_starts() -> usize {
    1
}

fn default_population() -> usize {
    100
}

/// One method's front and its indicators.
#[derive(Debug, Clone)]
pub struct MethodFront {
    /// `mmfd-tchebycheff` or `nsga2`.
    pub method: String,
    /// Designs and objectives (minimized orientation).
    pub points: Vec<(Vec<f64>, Vec<f64>)>,
    /// Function calls.
    pub function_calls: usize,
    /// Gradient calls.
    pub gradient_calls: usize,
    /// Wall time \[s\].
    pub wall_seconds: f64,
    /// Certified ends of all runs (`(certified, runs)`; gradient side).
    pub certified: Option<(usize, usize)>,
    /// Hypervolume to the reference point.
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
    /// The methods, gradient side first.
    pub methods: Vec<MethodFront>,
    /// The reference point (minimized orientation).
    pub reference: Vec<f64>,
}

/// The study's multi-objective problem (`[problem] name`: `zdt1`,
/// `zdt2`, `zdt3` or `dtlz2`).
pub fn multi_problem(study: &Study) -> Result<Box<dyn MultiProblem>> {
    let spec: ProblemSpec = study.require_section("problem", "the problem to solve")?;
    spec.build_multi().map_err(study.locate("problem"))
}

/// Read and check `[front]` and the problem's objectives without running.
pub fn check(study: &Study) -> Result<FrontSection> {
    let s: FrontSection = study.require_section("front", "the Pareto front")?;
    let k = s.objectives.len();
    if !(2..=3).contains(&k) {
        return Err(study.error("front.objectives", format!("({k} objectives)"), "2 or 3"));
    }
    if s.anchor_starts == 0 {
        return Err(study.error("front.anchor_starts", 0, "at least 1 start"));
    }
    if s.subproblems == 0 {
        return Err(study.error("front.subproblems", 0, "at least 1 subproblem"));
    }
    if s.population < 4 || s.population % 2 == 1 {
        return Err(study.error("front.population", s.population, "an even count >= 4"));
    }
    if let Some(e) = s.evaluations.filter(|&e| e < s.population) {
        return Err(study.error(
            "front.evaluations",
            e,
            format!("at least the population ({})", s.population),
        ));
    }
    if let Some(r) = &s.reference {
        if r.len() != k || r.iter().any(|v| !v.is_finite()) {
            return Err(study.error(
                "front.reference",
                format!("{r:?}"),
                format!("{k} finite values, one per objective"),
            ));
        }
    }
    if let Some(t) = s.feasibility_tolerance {
        crate::error::require_positive("feasibility_tolerance", t)
            .map_err(study.locate("front"))?;
    }
    let problem = multi_problem(study)?;
    oriented(problem.as_ref(), &s).map_err(study.locate("front"))?;
    Ok(s)
}

fn oriented<'a>(p: &'a dyn MultiProblem, s: &FrontSection) -> Result<Oriented<'a>> {
    let names: Vec<(String, bool)> = s
        .objectives
        .iter()
        .map(|o| (o.name.clone(), o.goal == Goal::Maximize))
        .collect();
    for (i, (n, _)) in names.iter().enumerate() {
        if names[..i].iter().any(|(m, _)| m == n) {
            return Err(Error::input(
                format!("objectives[{i}].name"),
                format!("\"{n}\""),
                "each objective once",
            ));
        }
    }
    Oriented::new(p, &names)
}

/// The default reference point: the union's nadir plus a tenth of its
/// ideal-to-nadir range (of `max(1, |nadir|)` where the range vanishes).
fn default_reference(union: &[Vec<f64>], m: usize) -> Vec<f64> {
    (0..m)
        .map(|j| {
            let lo = union.iter().map(|p| p[j]).fold(f64::INFINITY, f64::min);
            let hi = union.iter().map(|p| p[j]).fold(f64::NEG_INFINITY, f64::max);
            let range = if hi > lo { hi - lo } else { hi.abs().max(1.0) };
            hi + 0.1 * range
        })
        .collect()
}

/// Run `[front]`: both methods, the indicators, the tables and the plot
/// in `dir`.
pub fn run_front(study: &Study, dir: &Path, threads: usize, quiet: bool) -> Result<FrontReport> {
    let section = check(study)?;
    let inner = multi_problem(study)?;
    let problem = oriented(inner.as_ref(), &section).map_err(study.locate("front"))?;
    let m = section.objectives.len();
    let tol = section.feasibility_tolerance.unwrap_or(1e-6);
    let tolerances = KktTolerances {
        feasibility: tol,
        ..KktTolerances::default()
    };
    let settings = GradientSettings {
        subproblems: section.subproblems,
        threads,
        mmfd: MmfdOptions::standard().with_feasibility(tol),
        end: EndPolicy {
            tolerances,
            polish: true,
        },
        anchor_starts: section.anchor_starts,
        seed: study.meta.seed,
    };
    let grad = gradient_front(&problem, &settings)?;
    let budget = section.evaluations.unwrap_or(grad.function_calls);
    let options = Nsga2Options {
        population: section.population,
        max_evaluations: budget.max(section.population),
        seed: study.meta.seed,
        feasibility_tolerance: tol,
        ..Nsga2Options::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::input("threads", threads, format!("a usable count ({e})")))?;
    let t = Instant::now();
    let evo = pool
        .install(|| nsga2::minimize(&problem, &options))
        .map_err(study.locate("front"))?;
    let evo_seconds = t.elapsed().as_secs_f64();
    let mut methods = vec![
        MethodFront {
            method: "mmfd-tchebycheff".into(),
            points: grad.points.clone(),
            function_calls: grad.function_calls,
            gradient_calls: grad.gradient_calls,
            wall_seconds: grad.wall_seconds,
            certified: Some((grad.certified(), grad.ends.len())),
            hypervolume: 0.0,
            igd_union: None,
            igd_analytic: None,
        },
        MethodFront {
            method: "nsga2".into(),
            points: evo
                .front
                .iter()
                .map(|i| (i.x.clone(), i.f.clone()))
                .collect(),
            function_calls: evo.evaluations,
            gradient_calls: 0,
            wall_seconds: evo_seconds,
            certified: None,
            hypervolume: 0.0,
            igd_union: None,
            igd_analytic: None,
        },
    ];
    let all: Vec<Vec<f64>> = methods
        .iter()
        .flat_map(|mf| mf.points.iter().map(|p| p.1.clone()))
        .collect();
    let union: Vec<Vec<f64>> = non_dominated(&all)
        .into_iter()
        .map(|i| all[i].clone())
        .collect();
    let signs: Vec<f64> = (0..m).map(|k| problem.sign(k)).collect();
    let reference = match &section.reference {
        Some(r) => r.iter().zip(&signs).map(|(v, s)| v * s).collect(),
        None if union.is_empty() => vec![0.0; m],
        None => default_reference(&union, m),
    };
    let analytic = problem.known_front();
    for mf in &mut methods {
        let f: Vec<Vec<f64>> = mf.points.iter().map(|p| p.1.clone()).collect();
        mf.hypervolume = hypervolume(&f, &reference)?;
        mf.igd_union = igd(&f, &union);
        mf.igd_analytic = analytic.as_ref().and_then(|a| igd(&f, a));
    }
    let report = FrontReport {
        objectives: problem.objective_names(),
        methods,
        reference,
    };
    write_outputs(&problem, &report, &signs, analytic.as_deref(), dir)?;
    if !quiet {
        for mf in &report.methods {
            println!(
                "{}: {} points, {} function + {} gradient calls, {:.2} s, hypervolume {}, IGD to the union {}, to the analytic front {}",
                mf.method,
                mf.points.len(),
                mf.function_calls,
                mf.gradient_calls,
                mf.wall_seconds,
                num(mf.hypervolume),
                field(mf.igd_union),
                field(mf.igd_analytic),
            );
        }
        println!("wrote {}", dir.join("front.csv").display());
    }
    Ok(report)
}

fn field(v: Option<f64>) -> String {
    v.map(num).unwrap_or_default()
}

/// `front.csv`, `front_summary.csv` and `front.svg`.
fn write_outputs(
    problem: &Oriented,
    report: &FrontReport,
    signs: &[f64],
    analytic: Option<&[Vec<f64>]>,
    dir: &Path,
) -> Result<()> {
    let names = &report.objectives;
    let mut header = vec!["method".to_string()];
    header.extend(problem.variables().iter().map(|v| format!("x_{}", v.name)));
    header.extend(names.iter().cloned());
    let mut rows = Vec::new();
    for mf in &report.methods {
        for (x, f) in &mf.points {
            let mut r = vec![mf.method.clone()];
            r.extend(x.iter().map(|&v| num(v)));
            r.extend(f.iter().zip(signs).map(|(v, s)| num(v * s)));
            rows.push(r);
        }
    }
    write_table(&dir.join("front.csv"), &header, &rows)?;
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
            r.extend(report.reference.iter().zip(signs).map(|(v, s)| num(v * s)));
            r.push(field(mf.igd_union));
            r.push(field(mf.igd_analytic));
            r
        })
        .collect();
    write_table(&dir.join("front_summary.csv"), &header, &rows)?;
    let pair = |f: &[f64]| (f[0] * signs[0], f[1] * signs[1]);
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
    let start = problem.evaluate(&problem.start(), false)?;
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
    scatter_plot(&dir.join("front.svg"), &axes, &series)
}
