//! `[front]`: the Pareto front of two or three objectives, from the
//! gradient side ([`crate::explore::front::gradient`]: certified Tchebycheff
//! subproblems solved by MMFD or SQP, `method`) and from NSGA-II
//! ([`crate::optimize::nsga2`]), with their indicators.
//!
//! Budgets: the gradient side runs `subproblems` subproblems (plus one
//! anchor and one lexicographic anchor per objective); NSGA-II gets
//! `evaluations` function calls (default: as many as the gradient side
//! used, gradient calls not counted extra), in generations of
//! `population`.
//!
//! Outputs in the study's folder, all through [`crate::report`]:
//! Problems: the analytic ones (`zdt1`, `zdt2`, `zdt3`, `dtlz2`) or
//! `[problem] name = "scene"`, whose objectives are `[[scene.responses]]`
//! normalised at one design ([`crate::explore::problem::scene_front`]).
//!
//! With `grid = N` the box is also evaluated on a grid of `N` values per
//! variable ([`crate::explore::front::grid`]), after both methods; its
//! non-dominated feasible designs are a third method, `grid`.
//!
//! Outputs in the study's folder, all through [`crate::report`]
//! ([`super::outputs`]):
//! - `front.csv`: the non-dominated designs of each method (and of the
//!   grid); columns `method`, `x_<variable>` per variable, then one column
//!   per objective named as the objective, with its unit in brackets when
//!   the problem has one (`psi0 [J*s]`), in its own sign and unit (a
//!   maximized objective is written as its value, not negated; a
//!   normalised one in the response's unit).
//! - `front_summary.csv`: one row per method (`grid` last): `points`,
//!   `function_calls`, `gradient_calls`, `wall_seconds`, `certified_ends`
//!   (the gradient side's certified ends of all its runs), `hypervolume`
//!   with the reference point in `reference_<objective>` columns (own sign
//!   and unit), `igd_union` (IGD to the non-dominated union of all
//!   methods' fronts) and `igd_analytic` (IGD to the problem's analytic
//!   front when it has one). Hypervolume and IGD are computed on the
//!   objectives as evaluated, in the minimized orientation
//!   ([`crate::optimize::indicators`]): for the scene, the normalised
//!   objectives `R_i/|R_i(x_n)|` (dimensionless). The reference point is
//!   `[front] reference` (own sign and unit), `reference_relative` (a
//!   factor of each objective's value at the start design) or, by default,
//!   the union's nadir plus a tenth of its ideal-to-nadir range in each
//!   objective (`(1.1, 1.1)` on ZDT1).
//! - `front_ends.csv`: every run of the gradient side (label, class,
//!   exit, calls, Kuhn–Tucker residual, what became of the end in the
//!   front (`front`: `point`, `dominated by <run>`, `equal to <run>`,
//!   `not certified (<class>)`, `objectives not finite`, `anchor start`),
//!   end design, objectives of the certified ends), to see which ends were
//!   certified and why not, and why an end is not a point of the front.
//! - `grid.csv` (with `grid`): every grid design, its objectives (own
//!   sign and unit), `max_g`, and the error of a failed evaluation.
//! - `front.svg`: the first two objectives, every method's front, the
//!   start design and the analytic front (two objectives) when known;
//!   `front_design.svg` (two variables): the same designs in design space.

use super::gradient::{gradient_front, subproblem_noise, GradientSettings};
use super::grid::{evaluate_grid, grid_size, GridFront, MAX_GRID_DESIGNS};
use super::hybrid::{hybrid_front, HybridFront};
use super::outputs::write_outputs;
pub use super::outputs::{FrontReport, MethodFront};
use crate::error::{Error, Result};
use crate::explore::context::Context;
use crate::explore::local::settle::EndPolicy;
use crate::explore::local::solvers::{local, LocalMethod, MmfdPreset, MmfdSettings};
use crate::explore::persist::journal::{Journal, JournaledMulti};
use crate::explore::problem::problems::ProblemSpec;
use crate::explore::problem::scene_front::SceneFrontProblem;
use crate::optimize::indicators::{hypervolume, igd};
use crate::optimize::kkt::KktTolerances;
use crate::optimize::multiobjective::{non_dominated, MultiProblem, Oriented};
use crate::optimize::nsga2::{self, Nsga2Options};
use crate::report::csv::num;
use crate::report::Progress;
use crate::study::Study;
use serde::Deserialize;
use std::path::Path;
use std::sync::Arc;
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
    /// The problem's name of the objective (`f1`, …; for the scene a
    /// `[[scene.responses]]` name).
    pub name: String,
    /// `minimize` (default) or `maximize`.
    #[serde(default)]
    pub goal: Goal,
    /// For a minimized scene `peak` response (a maximum over time): how
    /// many of its critical time points, largest first, the gradient side
    /// takes as the smooth pieces of the objective (default 1, the peak
    /// alone; `optimize::multiobjective`'s module doc). NSGA-II and the
    /// grid read the peak.
    pub critical_points: Option<usize>,
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
    /// sign and unit (default: see the module doc).
    pub reference: Option<Vec<f64>>,
    /// Hypervolume reference point as factors of the objectives' values
    /// at the start design (`[1.2, 1.2]`: 1.2 × each start value, in its
    /// own sign); not with `reference`.
    pub reference_relative: Option<Vec<f64>>,
    /// Also evaluate a grid of this many values per variable (>= 2) and
    /// compare its non-dominated set (row `grid`).
    pub grid: Option<usize>,
    /// Starts of each single-objective anchor of the gradient side: the
    /// start design and seeded random designs (default 1: the start design
    /// only).
    #[serde(default = "default_anchor_starts")]
    pub anchor_starts: usize,
    /// The local solver of the gradient side's anchors and subproblems:
    /// `mmfd` (default) or `sqp`. Measured on the analytic fronts
    /// (docs/exploration.md, "Fronts"): SQP takes 3-30x fewer function
    /// calls on ZDT1-3, and reaches ZDT3's global f2 anchor where MMFD's
    /// runs stop at its iteration limit, but its DTLZ2 front misses the
    /// 5e-2 IGD bar that MMFD's meets.
    #[serde(default = "default_front_method")]
    pub method: LocalMethod,
    /// Subproblems placed in the largest gaps of the gradient side's front
    /// after the lattice's (two objectives; default 0;
    /// [`crate::explore::front::gaps`]).
    #[serde(default)]
    pub refine: usize,
    /// Feasible: `max g <= feasibility_tolerance` (default 1e-6), for the
    /// certificate, MMFD's CTMIN and NSGA-II's constraint-domination.
    pub feasibility_tolerance: Option<f64>,
    /// Also run the hybrid ([`super::hybrid`]): NSGA-II on this fraction
    /// of NSGA-II's budget (0 < φ < 1), then gradient subproblems seeded
    /// at its points and in the gaps of their front (row `hybrid`).
    pub hybrid: Option<f64>,
}

fn default_subproblems() -> usize {
    32
}

fn default_front_method() -> LocalMethod {
    LocalMethod::Mmfd
}

fn default_anchor_starts() -> usize {
    1
}

fn default_population() -> usize {
    100
}

/// The study's multi-objective problem with the section's objectives:
/// `[problem] name` `zdt1`, `zdt2`, `zdt3` or `dtlz2`, or `scene` (the
/// `[[scene.responses]]` named by the objectives).
pub fn multi_problem(study: &Study, section: &FrontSection) -> Result<Box<dyn MultiProblem>> {
    let spec: ProblemSpec = study.require_section("problem", "the problem to solve")?;
    if spec.name == "scene" {
        let names: Vec<String> = section.objectives.iter().map(|o| o.name.clone()).collect();
        let points: Vec<usize> = (section.objectives.iter())
            .map(|o| o.critical_points.unwrap_or(1))
            .collect();
        return Ok(Box::new(
            SceneFrontProblem::from_study(study, &names)?.with_points(points),
        ));
    }
    spec.build_multi().map_err(study.locate("problem"))
}

/// Read and check `[front]` and the problem's objectives without running
/// (the scene is parsed and checked, not simulated).
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
    if s.method == LocalMethod::Steepest {
        return Err(study.error(
            "front.method",
            "steepest",
            "\"sqp\" or \"mmfd\" (the subproblems have constraints)",
        ));
    }
    if s.refine > 0 && k != 2 {
        return Err(study.error(
            "front.refine",
            s.refine,
            "0 with three objectives (the gaps are refined on two)",
        ));
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
    for (key, r) in [
        ("reference", &s.reference),
        ("reference_relative", &s.reference_relative),
    ] {
        if let Some(r) = r {
            if r.len() != k || r.iter().any(|v| !v.is_finite()) {
                return Err(study.error(
                    format!("front.{key}"),
                    format!("{r:?}"),
                    format!("{k} finite values, one per objective"),
                ));
            }
        }
    }
    if let Some(r) = s
        .reference_relative
        .as_ref()
        .filter(|r| r.iter().any(|&v| v <= 0.0))
    {
        return Err(study.error(
            "front.reference_relative",
            format!("{r:?}"),
            "positive factors of the start's objectives (a factor <= 0 moves the reference \
             point to the other side of 0, where it bounds no front: hypervolume 0)",
        ));
    }
    if s.reference.is_some() && s.reference_relative.is_some() {
        return Err(study.error(
            "front.reference_relative",
            "(given)",
            "either `reference` or `reference_relative`, not both",
        ));
    }
    if let Some(t) = s.feasibility_tolerance {
        crate::error::require_positive("feasibility_tolerance", t)
            .map_err(study.locate("front"))?;
    }
    if let Some(h) = s.hybrid.filter(|h| !(*h > 0.0 && *h < 1.0)) {
        return Err(study.error(
            "front.hybrid",
            h,
            "a fraction of NSGA-II's budget, 0 < hybrid < 1",
        ));
    }
    let spec: ProblemSpec = study.require_section("problem", "the problem to solve")?;
    let names: Vec<String> = s.objectives.iter().map(|o| o.name.clone()).collect();
    let variables = if spec.name == "scene" {
        SceneFrontProblem::check(study, &names)?;
        let points: Vec<(Option<usize>, bool)> = (s.objectives.iter())
            .map(|o| (o.critical_points, o.goal == Goal::Maximize))
            .collect();
        SceneFrontProblem::check_points(study, &names, &points)?;
        let sp: crate::explore::problem::scene_problem::SceneProblemSpec =
            study.require_section("scene_problem", "the scene problem")?;
        sp.variables.len()
    } else {
        if let Some(k) = s
            .objectives
            .iter()
            .position(|o| o.critical_points.is_some())
        {
            return Err(study.error(
                format!("front.objectives[{k}].critical_points"),
                s.objectives[k].critical_points.unwrap_or(0),
                "a scene problem's peak response (`[problem] name = \"scene\"`)",
            ));
        }
        let problem = spec.build_multi().map_err(study.locate("problem"))?;
        oriented(problem.as_ref(), &s).map_err(study.locate("front"))?;
        problem.variables().len()
    };
    duplicate_names(&s).map_err(study.locate("front"))?;
    if let Some(n) = s.grid {
        if n < 2 || grid_size(variables, n).is_none() {
            return Err(study.error(
                "front.grid",
                n,
                format!("at least 2 values per variable and at most {MAX_GRID_DESIGNS} designs ({variables} variables)"),
            ));
        }
    }
    Ok(s)
}

/// Each objective named once.
fn duplicate_names(s: &FrontSection) -> Result<()> {
    for (i, o) in s.objectives.iter().enumerate() {
        if s.objectives[..i].iter().any(|p| p.name == o.name) {
            return Err(Error::input(
                format!("objectives[{i}].name"),
                format!("\"{}\"", o.name),
                "each objective once",
            ));
        }
    }
    Ok(())
}

fn oriented<'a>(p: &'a dyn MultiProblem, s: &FrontSection) -> Result<Oriented<'a>> {
    duplicate_names(s)?;
    let names: Vec<(String, bool)> = s
        .objectives
        .iter()
        .map(|o| (o.name.clone(), o.goal == Goal::Maximize))
        .collect();
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

/// The reference point in the evaluated (minimized, possibly normalised)
/// objectives: `reference` (own sign and unit) turned into them,
/// `reference_relative` times the start design's objectives, or the
/// default.
fn reference_point(
    problem: &Oriented,
    section: &FrontSection,
    union: &[Vec<f64>],
) -> Result<Vec<f64>> {
    let m = section.objectives.len();
    if let Some(r) = &section.reference {
        return Ok((0..m)
            .map(|k| r[k] * problem.sign(k) / problem.objective_scale(k))
            .collect());
    }
    if let Some(r) = &section.reference_relative {
        // sign·scale·f is the start's value in its own unit; r times that,
        // turned back, is r·f.
        let start = problem.evaluate(&problem.start(), false)?;
        return Ok(r.iter().zip(&start.f).map(|(r, f)| r * f).collect());
    }
    if union.is_empty() {
        return Ok(vec![0.0; m]);
    }
    Ok(default_reference(union, m))
}

/// Simulations the problem ran since `before` (problems that count them).
fn since(problem: &dyn MultiProblem, before: Option<usize>) -> Option<usize> {
    Some(problem.simulations()? - before?)
}

/// The gradient side's settings: the study's local method and
/// tolerances, and the objectives' noise measured at the start (for the
/// subproblems' stop tests).
fn gradient_settings(
    study: &Study,
    section: &FrontSection,
    problem: &Oriented,
    threads: usize,
    quiet: bool,
) -> Result<GradientSettings> {
    let tol = section.feasibility_tolerance.unwrap_or(1e-6);
    let tolerances = KktTolerances {
        feasibility: tol,
        ..KktTolerances::default()
    };
    let (noise, noise_g, objective_sigma, noise_calls) =
        subproblem_noise(problem, study.meta.seed).map_err(study.locate("front"))?;
    if !quiet {
        println!(
            "  noise of the objectives at the start: allowance {noise:.2e} ({noise_calls} function calls)"
        );
    }
    Ok(GradientSettings {
        subproblems: section.subproblems,
        threads,
        solver: Arc::from(local(
            section.method,
            &MmfdSettings::default(),
            MmfdPreset::Standard,
            (tol, 0.0),
        )?),
        refine: section.refine,
        end: EndPolicy {
            tolerances,
            polish: true,
            rescue: true,
            noise,
            noise_g,
        },
        anchor_starts: section.anchor_starts,
        seed: study.meta.seed,
        objective_sigma,
        seeds: vec![],
    })
}

/// The `n`-per-variable grid's front as a method row, with the grid
/// (a warning names the designs that failed to evaluate).
fn grid_front(
    problem: &Oriented,
    n: usize,
    threads: usize,
    quiet: bool,
    tol: f64,
) -> Result<(MethodFront, GridFront)> {
    let sims = problem.simulations();
    let g = evaluate_grid(problem, n, threads, quiet, tol)?;
    let row = MethodFront {
        method: "grid".into(),
        points: g.front.clone(),
        function_calls: g.points.len(),
        gradient_calls: 0,
        simulations: since(problem, sims),
        wall_seconds: g.wall_seconds,
        certified: None,
        hypervolume: 0.0,
        igd_union: None,
        igd_analytic: None,
    };
    if g.failures() > 0 && !quiet {
        eprintln!(
            "warning: {} of {} grid designs failed to evaluate (grid.csv, column error)",
            g.failures(),
            g.points.len()
        );
    }
    Ok((row, g))
}

/// Run `[front]`: both methods (and the grid), the indicators, the tables
/// and the plots in `dir`.
pub fn run_front(ctx: &Context) -> Result<FrontReport> {
    let (study, threads, quiet) = (ctx.study, ctx.threads, ctx.quiet);
    let dir = &ctx.dir()?;
    let section = check(study)?;
    let built = multi_problem(study, &section)?;
    let scope: Vec<&str> = section.objectives.iter().map(|o| o.name.as_str()).collect();
    let journal = ctx.journal("front", &scope.join(","))?;
    let inner = JournaledMulti::new(built.as_ref(), &journal)?;
    let problem = oriented(&inner, &section).map_err(study.locate("front"))?;
    let m = section.objectives.len();
    let tol = section.feasibility_tolerance.unwrap_or(1e-6);
    let settings = gradient_settings(study, &section, &problem, threads, quiet)?;
    let sims = problem.simulations();
    journal.watch(Some(Progress::counter(
        "front (gradient)",
        "evaluations",
        quiet,
    )));
    let grad = gradient_front(&problem, &settings)?;
    let grad_sims = since(&problem, sims);
    let budget = section.evaluations.unwrap_or(grad.function_calls);
    let options = Nsga2Options {
        population: section.population,
        max_evaluations: budget.max(section.population),
        seed: study.meta.seed,
        feasibility_tolerance: tol,
        ..Nsga2Options::default()
    };
    let pool = crate::explore::context::thread_pool(threads)?;
    let t = Instant::now();
    let sims = problem.simulations();
    journal.watch(Some(Progress::new(
        "front (NSGA-II)",
        options.max_evaluations as u64,
        quiet,
    )));
    let evo = pool
        .install(|| nsga2::minimize(&problem, &options))
        .map_err(study.locate("front"))?;
    journal.watch(None);
    let evo_seconds = t.elapsed().as_secs_f64();
    let evo_sims = since(&problem, sims);
    let mut methods = vec![
        MethodFront {
            method: format!("{}-tchebycheff", settings.solver.name()),
            points: grad.points.clone(),
            function_calls: grad.function_calls,
            gradient_calls: grad.gradient_calls,
            simulations: grad_sims,
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
            simulations: evo_sims,
            wall_seconds: evo_seconds,
            certified: None,
            hypervolume: 0.0,
            igd_union: None,
            igd_analytic: None,
        },
    ];
    let hybrid = match section.hybrid {
        Some(_) => {
            let h = hybrid_row(&problem, (&section, &options), &settings, &journal, quiet)?;
            methods.push(h.0);
            Some(h.1)
        }
        None => None,
    };
    let grid = match section.grid {
        Some(n) => {
            let (row, g) = grid_front(&problem, n, threads, quiet, tol)?;
            methods.push(row);
            Some(g)
        }
        None => None,
    };
    let signs: Vec<f64> = (0..m).map(|k| problem.sign(k)).collect();
    let analytic = problem.known_front();
    let reference = score(&problem, &section, analytic.as_deref(), &mut methods)?;
    let report = FrontReport {
        objectives: problem.objective_names(),
        methods,
        reference,
        replayed: journal.replayed(),
    };
    write_outputs(
        &problem,
        &report,
        &signs,
        analytic.as_deref(),
        grid.as_ref(),
        (
            &grad.ends,
            hybrid.as_ref().map(|h| h.gradient.ends.as_slice()),
        ),
        dir,
    )?;
    if !quiet {
        print_methods(&report, dir);
    }
    journal.report("front", quiet);
    Ok(report)
}

/// The hybrid ([`super::hybrid`]) on `⌈φ·B⌉` NSGA-II evaluations (`B`:
/// `options`' budget, at least one population) as a method row, with its
/// subproblems' ends.
fn hybrid_row(
    problem: &Oriented,
    (section, options): (&FrontSection, &Nsga2Options),
    settings: &GradientSettings,
    journal: &Journal,
    quiet: bool,
) -> Result<(MethodFront, HybridFront)> {
    let phi = section.hybrid.unwrap_or(1.0);
    let budget = ((phi * options.max_evaluations as f64).ceil() as usize).max(options.population);
    let opts = Nsga2Options {
        max_evaluations: budget,
        ..options.clone()
    };
    journal.watch(Some(Progress::counter(
        "front (hybrid)",
        "evaluations",
        quiet,
    )));
    let sims = problem.simulations();
    let h = hybrid_front(problem, &opts, settings)?;
    journal.watch(None);
    let row = MethodFront {
        method: format!("hybrid-nsga2-{}", settings.solver.name()),
        points: h.points.clone(),
        function_calls: h.function_calls,
        gradient_calls: h.gradient.gradient_calls,
        simulations: since(problem, sims),
        wall_seconds: h.wall_seconds,
        certified: Some((h.gradient.certified(), h.gradient.ends.len())),
        hypervolume: 0.0,
        igd_union: None,
        igd_analytic: None,
    };
    Ok((row, h))
}

/// The indicators of every method's front: the hypervolume to the
/// reference point, the IGD to the union of all methods' non-dominated
/// points and to the `analytic` front (when the problem knows it).
/// Returns the reference point.
fn score(
    problem: &Oriented,
    section: &FrontSection,
    analytic: Option<&[Vec<f64>]>,
    methods: &mut [MethodFront],
) -> Result<Vec<f64>> {
    let all: Vec<Vec<f64>> = methods
        .iter()
        .flat_map(|mf| mf.points.iter().map(|p| p.1.clone()))
        .collect();
    let union: Vec<Vec<f64>> = non_dominated(&all)
        .into_iter()
        .map(|i| all[i].clone())
        .collect();
    let reference = reference_point(problem, section, &union)?;
    for mf in methods.iter_mut() {
        let f: Vec<Vec<f64>> = mf.points.iter().map(|p| p.1.clone()).collect();
        mf.hypervolume = hypervolume(&f, &reference)?;
        mf.igd_union = igd(&f, &union);
        mf.igd_analytic = analytic.and_then(|a| igd(&f, a));
    }
    Ok(reference)
}

/// One line per method on stdout, and where `front.csv` went.
fn print_methods(report: &FrontReport, dir: &Path) {
    for mf in &report.methods {
        println!(
            "{}: {} points, {} function + {} gradient calls{}, {:.2} s, hypervolume {}, IGD to the union {}, to the analytic front {}",
            mf.method,
            mf.points.len(),
            mf.function_calls,
            mf.gradient_calls,
            mf.simulations.map(|s| format!(" ({s} simulations)")).unwrap_or_default(),
            mf.wall_seconds,
            num(mf.hypervolume),
            field(mf.igd_union),
            field(mf.igd_analytic),
        );
    }
    println!("wrote {}", dir.join("front.csv").display());
}

fn field(v: Option<f64>) -> String {
    v.map(num).unwrap_or_default()
}
