//! Exploration drivers: multistart, evolutionary comparison, design-space
//! maps, resumable and shardable tables (issue 5).
//!
//! A gradient-based local optimizer (MMFD) finds the optimum of the basin it
//! starts in; ply-angle problems have many basins. The drivers here answer
//! "how many optima are there, which is best, and how likely is one start to
//! find it?" by running the local optimizer from many seeded start points in
//! parallel ([`multistart`]), merging the results into distinct optima
//! ([`cluster`]), comparing with an evolutionary search on the same budget
//! ([`evolve`]) and drawing the landscape ([`map`]).
//!
//! Every table is reproducible from the study file: random choices come
//! from `[study] seed`, rows are sorted by start index, numbers round-trip
//! exactly, and `manifest.json` records the study text, seed, threads and
//! crate versions. `runs.csv` survives a kill (see [`tables`]); `--resume`
//! continues a stopped multistart and `--shard i/n` splits one over
//! machines, with `plyscape merge` putting the pieces back together.
//!
//! Study sections read here: `[problem]` ([`problems::ProblemSpec`]; with
//! `name = "scene"` also `[scene_problem]`, [`scene_problem`]),
//! `[multistart]` ([`MultistartSection`]), `[evolve]` ([`EvolveSection`]),
//! `[compare]` (no keys), `[map]` ([`MapSection`]), `[scaling]`
//! ([`scaling::ScalingSection`]) and `[optimum_report]`
//! ([`optimum_report`]: the run from the first start as the paper's
//! Table 5 and Figs. 10–12, written by the multistart).
//!
//! A problem from a study, evaluated with its gradient (Himmelblau's
//! function has a minimum f = 0 at (3, 2)):
//!
//! ```
//! use plyscape::optimize::Problem;
//! use plyscape::study::Study;
//!
//! let study = Study::parse("himmelblau.toml", "[problem]\nname = \"himmelblau\"\n")?;
//! let problem = plyscape::explore::problem(&study)?;
//! let e = problem.evaluate(&[3.0, 2.0], true)?;
//! assert!(e.f.abs() < 1e-12);
//! assert!(e.grad_f.unwrap().iter().all(|g| g.abs() < 1e-10));
//! # Ok::<(), plyscape::Error>(())
//! ```
//!
//! Where things go: a new optimizer goes in [`crate::optimize`] behind the
//! [`crate::optimize::Problem`] interface and is named in [`solvers`]; a
//! new driver (a sweep of another kind) is a file here with its section
//! struct, writing its tables through [`crate::report`].

pub mod cluster;
pub mod evolve;
pub mod map;
pub mod multistart;
pub mod optimum_report;
pub mod problems;
pub mod sampling;
pub mod scaling;
pub mod scene_problem;
pub mod solvers;
pub mod tables;

use crate::error::{Error, Result};
use crate::optimize::cmaes::{Regime, Restarts};
use crate::optimize::Problem;
use crate::study::Study;
use cluster::Tolerances;
use multistart::Shard;
use serde::Deserialize;
use serde_json::json;
use std::path::{Path, PathBuf};

/// The `[multistart]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultistartSection {
    /// Local optimizer (default `mmfd`).
    #[serde(default = "default_method")]
    pub method: String,
    /// Sampler of the start points: `lhs` (default), `sobol`, `uniform`.
    #[serde(default = "default_sampler")]
    pub sampler: String,
    /// Number of sampled start points.
    #[serde(default)]
    pub starts: usize,
    /// Listed start points (run first).
    #[serde(default)]
    pub points: Vec<Vec<f64>>,
    /// Keep only feasible starts.
    #[serde(default)]
    pub feasible_only: bool,
    /// Stop launching runs once this many function calls are used.
    pub max_evaluations: Option<usize>,
    /// Stop launching runs after this wall time \[s\].
    pub max_wall_seconds: Option<f64>,
    /// Same optimum: coordinates within this fraction of each range
    /// (default 1e-2: 1.8° on a 180° ply angle; MMFD with DOT's default
    /// DELOBJ = 1e-3 stops that far from the exact optimum on flat valleys).
    #[serde(default = "default_x_tol")]
    pub x_tolerance: f64,
    /// Same optimum: `|Δf| <= f_tolerance · max(1, |f|)` (default 1e-2:
    /// ten times DOT's DELOBJ, since runs that end on active constraints
    /// within CTMIN differ in f by that much; distinct optima are told apart
    /// by `x_tolerance`).
    #[serde(default = "default_f_tol")]
    pub f_tolerance: f64,
    /// Feasible: `max g <= feasibility_tolerance` (default 3e-3, DOT's
    /// CTMIN, the violation MMFD accepts at its optimum).
    #[serde(default = "default_feas_tol")]
    pub feasibility_tolerance: f64,
    /// MMFD convergence settings (`[multistart.mmfd]`; DOT defaults).
    #[serde(default)]
    pub mmfd: solvers::MmfdSettings,
}

fn default_method() -> String {
    "mmfd".into()
}
fn default_sampler() -> String {
    "lhs".into()
}
fn default_x_tol() -> f64 {
    1e-2
}
fn default_f_tol() -> f64 {
    1e-2
}
fn default_feas_tol() -> f64 {
    3e-3
}

/// The `[evolve]` section.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct EvolveSection {
    /// Evaluation budget of each schedule. Default: under `compare`, the
    /// function calls the multistart used; alone, 100 per start of
    /// `[multistart]`, else 10 000.
    pub max_evaluations: Option<usize>,
    /// CMA-ES restart schedule ([`crate::optimize::cmaes::Restarts`]):
    /// `ipop` (default), `bipop`, or a list of distinct names
    /// (`["ipop", "bipop"]`), run one after another on the same budget and
    /// seed; read by [`schedules`].
    pub restarts: Option<toml::Value>,
    /// CMA-ES TolFun: a run restarts when its best f of the recent
    /// generations and every f of the current one lie within this range.
    /// Default 1e-12, for exact objectives; an objective from a simulation
    /// carries the integrator's noise (adaptive steps: about 1e-8 of f at
    /// rtol 1e-6), below which no progress is real, and a run whose f
    /// never settles within 1e-12 never restarts: set it above the noise.
    pub tol_fun: Option<f64>,
}

/// A checked `[evolve]`.
#[derive(Debug, Clone)]
pub struct EvolvePlan {
    /// The section.
    pub section: EvolveSection,
    /// The restart schedules, in the order they run (at least one).
    pub schedules: Vec<Restarts>,
}

/// Read and check `[evolve]` (absent: defaults). Errors name the file and
/// `evolve.<key>`.
pub fn evolve_plan(study: &Study) -> Result<EvolvePlan> {
    let section: EvolveSection = study.section("evolve")?.unwrap_or_default();
    if section.max_evaluations == Some(0) {
        return Err(study.error("evolve.max_evaluations", 0, "a budget >= 1"));
    }
    if let Some(t) = section.tol_fun {
        if !(t.is_finite() && t >= 0.0) {
            return Err(study.error("evolve.tol_fun", t, "a finite range >= 0"));
        }
    }
    let schedules = schedules(section.restarts.as_ref()).map_err(study.locate("evolve"))?;
    Ok(EvolvePlan { section, schedules })
}

/// The schedules of a `restarts` value: absent, IPOP; a name, that
/// schedule; a non-empty list of distinct names, those in order. Errors
/// name the key `restarts` (`restarts[k]` for the k-th list entry).
pub fn schedules(value: Option<&toml::Value>) -> Result<Vec<Restarts>> {
    let names = Restarts::NAMES;
    let list = match value {
        None => return Ok(vec![Restarts::default()]),
        Some(toml::Value::String(name)) => return Ok(vec![Restarts::parse(name)?]),
        Some(toml::Value::Array(list)) if !list.is_empty() => list,
        Some(other) => {
            return Err(Error::input(
                "restarts",
                other,
                format!(
                    "one of {names}, or a non-empty list of them (\"ipop\", [\"ipop\", \"bipop\"])"
                ),
            ))
        }
    };
    let mut out: Vec<Restarts> = Vec::new();
    for (k, v) in list.iter().enumerate() {
        let key = format!("restarts[{k}]");
        let r = v
            .as_str()
            .and_then(|name| Restarts::parse(name).ok())
            .ok_or_else(|| Error::input(&key, v, format!("one of {names}")))?;
        if let Some(j) = out.iter().position(|&earlier| earlier == r) {
            return Err(Error::input(
                key,
                v,
                format!("each schedule once (it is restarts[{j}] already)"),
            ));
        }
        out.push(r);
    }
    Ok(out)
}

/// The `[compare]` section (no keys).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CompareSection {}

/// The `[map]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSection {
    /// Grid points per axis (default 61).
    #[serde(default = "default_resolution")]
    pub resolution: usize,
    /// Variable pairs for more than two variables (default: consecutive
    /// pairs (0,1), (2,3), ...).
    pub pairs: Option<Vec<[usize; 2]>>,
}

fn default_resolution() -> usize {
    61
}

/// Flags of the driver commands beyond the common ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DriveFlags {
    /// Continue from an existing `runs.csv`.
    pub resume: bool,
    /// Which starts to run.
    pub shard: Shard,
    /// Without `resume`: discard an earlier `runs.csv` instead of keeping
    /// it under a timestamped name.
    pub force: bool,
}

impl Default for DriveFlags {
    fn default() -> Self {
        DriveFlags {
            resume: false,
            shard: Shard { index: 0, count: 1 },
            force: false,
        }
    }
}

/// What a driver command needs from the command line.
#[derive(Debug, Clone)]
pub struct Context<'a> {
    /// The study.
    pub study: &'a Study,
    /// Results root (`results/`).
    pub out: &'a Path,
    /// Worker threads.
    pub threads: usize,
    /// No progress bars or summaries.
    pub quiet: bool,
    /// Resume and shard.
    pub flags: DriveFlags,
}

impl Context<'_> {
    /// `out/<study>/`, or `out/<study>/shard-<i>-of-<n>/` for a shard.
    pub fn dir(&self) -> Result<PathBuf> {
        let base = self.study.output_dir(self.out)?;
        let s = self.flags.shard;
        if s.count == 1 {
            return Ok(base);
        }
        let dir = base.join(format!("shard-{}-of-{}", s.index, s.count));
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        Ok(dir)
    }

    /// Update `manifest.json` ([`crate::report::record_command`]) with the
    /// shard, the threads, the resume flag and `extra`.
    fn manifest(&self, dir: &Path, command: &str, extra: serde_json::Value) -> Result<()> {
        let mut entry = serde_json::Map::new();
        entry.insert("threads".into(), json!(self.threads));
        entry.insert("resume".into(), json!(self.flags.resume));
        if let serde_json::Value::Object(e) = extra {
            entry.extend(e);
        }
        let mut top = serde_json::Map::new();
        top.insert(
            "shard".into(),
            json!({"index": self.flags.shard.index, "count": self.flags.shard.count}),
        );
        crate::report::record_command(dir, self.study, self.threads, command, entry, top)
    }
}

/// Build the study's `[problem]`.
pub fn problem(study: &Study) -> Result<Box<dyn Problem>> {
    let spec: problems::ProblemSpec =
        study.require_section("problem", "the problem to explore (name = ...)")?;
    if spec.name == "scene" {
        // The study's own scene (`[scene_problem]`, scene_problem.rs).
        if spec.dimension.is_some() || spec.bounds.is_some() || spec.cost_ms != 0.0 {
            return Err(study.error(
                "problem",
                "(table)",
                "only `name = \"scene\"`: variables and bounds are in [scene_problem]",
            ));
        }
        return Ok(Box::new(scene_problem::SceneProblem::from_study(study)?));
    }
    spec.build().map_err(study.locate("problem"))
}

/// Validated `[multistart]` with its start points.
pub struct MultistartPlan {
    /// The section.
    pub section: MultistartSection,
    /// Start points (all shards).
    pub starts: sampling::Starts,
    /// Clustering tolerances.
    pub tolerances: Tolerances,
}

/// Read and check `[multistart]` (keys and values; no start generated).
pub fn multistart_section(study: &Study) -> Result<MultistartSection> {
    let s: MultistartSection =
        study.require_section("multistart", "starts = ..., sampler = ...")?;
    let loc = study.locate("multistart");
    solvers::check_local(&s.method).map_err(&loc)?;
    s.mmfd.check().map_err(study.locate("multistart.mmfd"))?;
    for (key, v) in [
        ("x_tolerance", s.x_tolerance),
        ("f_tolerance", s.f_tolerance),
    ] {
        crate::error::require_positive(key, v).map_err(&loc)?;
    }
    if !(s.feasibility_tolerance.is_finite() && s.feasibility_tolerance >= 0.0) {
        return Err(loc(Error::input(
            "feasibility_tolerance",
            s.feasibility_tolerance,
            "a finite value >= 0",
        )));
    }
    if let Some(w) = s.max_wall_seconds {
        crate::error::require_positive("max_wall_seconds", w).map_err(&loc)?;
    }
    if s.max_evaluations == Some(0) {
        return Err(loc(Error::input(
            "max_evaluations",
            0,
            "a budget >= 1 (or no key)",
        )));
    }
    Ok(s)
}

/// Read and check `[multistart]`, generate the starts.
pub fn multistart_plan(study: &Study, problem: &dyn Problem) -> Result<MultistartPlan> {
    let s = multistart_section(study)?;
    let loc = study.locate("multistart");
    let spec = sampling::StartsSpec {
        sampler: s.sampler.clone(),
        count: s.starts,
        points: s.points.clone(),
        feasible_only: s.feasible_only,
    };
    let starts = spec.generate(problem, study.meta.seed).map_err(|e| {
        // `count` is called `starts` in the study file.
        match e {
            Error::Input {
                key,
                value,
                expected,
                file,
            } if key == "count" => loc(Error::Input {
                key: "starts".into(),
                value,
                expected,
                file,
            }),
            e => loc(e),
        }
    })?;
    Ok(MultistartPlan {
        tolerances: Tolerances {
            x: s.x_tolerance,
            f: s.f_tolerance,
            feasibility: s.feasibility_tolerance,
        },
        section: s,
        starts,
    })
}

/// `plyscape multistart`: runs, optima, manifest.
pub fn run_multistart(ctx: &Context) -> Result<multistart::Report> {
    let problem = problem(ctx.study)?;
    let plan = multistart_plan(ctx.study, problem.as_ref())?;
    multistart_with(ctx, problem.as_ref(), &plan)
}

fn multistart_with(
    ctx: &Context,
    problem: &dyn Problem,
    plan: &MultistartPlan,
) -> Result<multistart::Report> {
    let dir = ctx.dir()?;
    if !ctx.flags.resume {
        keep_earlier_runs(&dir, ctx.flags.force, ctx.quiet)?;
    }
    ctx.manifest(&dir, "multistart", json!({"complete": false}))?;
    let solver = solvers::local(&plan.section.method, &plan.section.mmfd)?;
    let report_plan = optimum_report::prepare(ctx, problem, plan)?;
    let settings = multistart::Settings {
        threads: ctx.threads,
        max_evaluations: plan.section.max_evaluations,
        max_wall_seconds: plan.section.max_wall_seconds,
        tolerances: plan.tolerances,
        resume: ctx.flags.resume,
        shard: ctx.flags.shard,
        quiet: ctx.quiet,
        history_start: report_plan.as_ref().map(|_| optimum_report::REPORTED_START),
    };
    let report = multistart::run(
        problem,
        solver.as_ref(),
        &plan.starts.points,
        &settings,
        &dir,
    )?;
    let mine = (0..plan.starts.points.len())
        .filter(|&k| ctx.flags.shard.owns(k))
        .count();
    ctx.manifest(
        &dir,
        "multistart",
        json!({
            "complete": report.runs.len() == mine || plan.section.max_evaluations.is_some(),
            "starts": plan.starts.points.len(),
            "runs_in_tables": report.runs.len(),
            "runs_this_invocation": report.new_runs,
            "filter_evaluations": plan.starts.filter_evaluations,
            "wall_seconds": report.wall_seconds,
        }),
    )?;
    if !ctx.quiet {
        print_optima(problem, &report);
    }
    if let Some(p) = report_plan {
        p.finish(ctx, &dir, problem, plan, &report)?;
    }
    Ok(report)
}

/// A run without `--resume` starts a new `runs.csv`. An earlier one with
/// rows is kept as `runs-<UTC time>.csv` (and said so on stderr) unless
/// `force` is given, so that forgetting `--resume` never loses finished
/// runs. Returns the kept file, if any.
pub fn keep_earlier_runs(dir: &Path, force: bool, quiet: bool) -> Result<Option<PathBuf>> {
    let path = dir.join("runs.csv");
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Error::io(&path, e)),
    };
    let rows = text.lines().count().saturating_sub(1);
    if rows == 0 || force {
        std::fs::remove_file(&path).map_err(|e| Error::io(&path, e))?;
        if rows > 0 && !quiet {
            eprintln!(
                "note: --force: discarded {rows} earlier row(s) of {}",
                path.display()
            );
        }
        return Ok(None);
    }
    let stamp = crate::report::clock::compact_utc(std::time::SystemTime::now());
    let mut kept = dir.join(format!("runs-{stamp}.csv"));
    let mut k = 1;
    while kept.exists() {
        kept = dir.join(format!("runs-{stamp}-{k}.csv"));
        k += 1;
    }
    std::fs::rename(&path, &kept).map_err(|e| Error::io(&path, e))?;
    eprintln!(
        "note: {} held {rows} earlier run(s); kept as {} (use --resume to continue \
         them, --force to discard them)",
        path.display(),
        kept.display()
    );
    Ok(Some(kept))
}

fn print_optima(problem: &dyn Problem, r: &multistart::Report) {
    println!(
        "multistart on {}: {} runs, {} distinct optima, {} function + {} gradient calls, {:.3} s",
        problem.name(),
        r.runs.len(),
        r.optima.len(),
        r.function_calls,
        r.gradient_calls,
        r.wall_seconds
    );
    for o in r.optima.iter().take(10) {
        println!(
            "  optimum {:>3}: f = {:>14.8e}  x = {:?}  feasible = {}  basin share = {:.3}",
            o.id, o.f, o.x, o.feasible, o.basin_share
        );
    }
}

/// `plyscape evolve`: CMA-ES with each schedule of `[evolve] restarts` on
/// the same budget and seed, one after another; evolution.csv,
/// convergence.svg and the manifest entry. `budget` stands in for an
/// absent `[evolve] max_evaluations`.
pub fn run_evolve(ctx: &Context, budget: Option<usize>) -> Result<Vec<evolve::Report>> {
    let problem = problem(ctx.study)?;
    let plan = evolve_plan(ctx.study)?;
    let ms = ctx.study.section::<MultistartSection>("multistart")?;
    let starts = ms.as_ref().map(|m| m.starts + m.points.len());
    // One feasibility tolerance for both methods: the multistart's.
    let feasibility_tolerance = ms.as_ref().map_or(0.0, |m| m.feasibility_tolerance);
    let max_evaluations = plan
        .section
        .max_evaluations
        .or(budget)
        .or(starts.map(|s| 100 * s.max(1)))
        .unwrap_or(10_000);
    let dir = ctx.dir()?;
    let solver = solvers::global();
    let mut reports = Vec::new();
    for &restarts in &plan.schedules {
        let request = evolve::Request {
            seed: ctx.study.meta.seed,
            max_evaluations,
            restarts,
            feasibility_tolerance,
            tol_fun: plan.section.tol_fun.unwrap_or(1e-12),
        };
        let report = evolve::run(
            problem.as_ref(),
            solver.as_ref(),
            &request,
            ctx.threads,
            ctx.quiet,
        )?;
        if !ctx.quiet {
            print_evolution(problem.as_ref(), &report);
        }
        reports.push(report);
    }
    tables::write_atomic(
        &dir.join("evolution.csv"),
        &evolve::table(problem.as_ref(), &reports),
    )?;
    let tol_fun = plan.section.tol_fun.unwrap_or(1e-12);
    ctx.manifest(
        &dir,
        "evolve",
        evolve_entry((max_evaluations, tol_fun), &reports),
    )?;
    convergence_plot(problem.as_ref(), &dir, None, &reports)?;
    Ok(reports)
}

/// The manifest entry of `evolve`: the budget, and per schedule its
/// method, solver, `restarts` name, function calls, wall time, run counts
/// per regime and every CMA-ES run (regime, λ, σ0, evaluations,
/// generations). One schedule's keys stand at the top of the entry (as
/// before lists existed); several are under `schedules`, with `restarts`
/// listing their names and `wall_seconds` their total.
fn evolve_entry(
    (max_evaluations, tol_fun): (usize, f64),
    reports: &[evolve::Report],
) -> serde_json::Value {
    let mut entry = serde_json::Map::new();
    entry.insert("max_evaluations".into(), json!(max_evaluations));
    entry.insert("tol_fun".into(), json!(tol_fun));
    let schedules: Vec<serde_json::Value> = reports.iter().map(schedule_entry).collect();
    match schedules.as_slice() {
        [serde_json::Value::Object(one)] => entry.extend(one.clone()),
        _ => {
            let names: Vec<&str> = reports.iter().map(|r| r.restarts.name()).collect();
            let wall: f64 = reports.iter().map(|r| r.wall_seconds).sum();
            entry.insert("wall_seconds".into(), json!(wall));
            entry.insert("restarts".into(), json!(names));
            entry.insert("schedules".into(), json!(schedules));
        }
    }
    serde_json::Value::Object(entry)
}

/// One schedule's part of [`evolve_entry`].
fn schedule_entry(report: &evolve::Report) -> serde_json::Value {
    let o = &report.outcome;
    let (large, small) = regime_counts(o);
    let runs: Vec<serde_json::Value> = o
        .runs
        .iter()
        .map(|r| {
            json!({"regime": r.regime.name(), "lambda": r.lambda, "sigma0": r.sigma0,
                   "evaluations": r.evaluations, "generations": r.generations})
        })
        .collect();
    let r = report.restarts;
    json!({"method": solvers::global_method(r), "solver": r.solver_name(),
           "restarts": r.name(), "function_calls": report.function_calls,
           "wall_seconds": report.wall_seconds, "large_runs": large,
           "small_runs": small, "runs": runs})
}

/// The summary line of one evolutionary search.
fn print_evolution(problem: &dyn Problem, report: &evolve::Report) {
    let o = &report.outcome;
    let (large, small) = regime_counts(o);
    println!(
        "evolution ({}) on {}: best f = {:.8e} at x = {:?} (feasible = {}), {} evaluations, \
         {} generations, {} restarts ({} large-population runs, {} small), {}",
        report.restarts.solver_name(),
        problem.name(),
        o.f,
        o.x,
        o.feasible,
        report.function_calls,
        o.generations,
        o.restarts,
        large,
        small,
        o.termination
    );
}

/// Runs of the (large, small) regimes in a CMA-ES outcome.
pub fn regime_counts(o: &crate::optimize::GlobalOutcome) -> (usize, usize) {
    let large = o.runs.iter().filter(|r| r.regime == Regime::Large).count();
    (large, o.runs.len() - large)
}

/// One row of the comparison table.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonRow {
    /// `multistart-<method>`, or the evolutionary method of one schedule:
    /// [`solvers::global_method`] (`cmaes` for IPOP, `cmaes-bipop`).
    pub method: String,
    /// Best objective.
    pub best_f: f64,
    /// Best design.
    pub best_x: Vec<f64>,
    /// Largest constraint value at the best design (`None`: no
    /// constraints).
    pub max_g: Option<f64>,
    /// Feasible: `max_g <= feasibility_tolerance`, the same for every row.
    pub feasible: bool,
    /// The tolerance of `feasible` (the multistart's, which the
    /// evolutionary search also used).
    pub feasibility_tolerance: f64,
    /// Function calls.
    pub function_calls: usize,
    /// Gradient calls.
    pub gradient_calls: usize,
    /// Wall time \[s\].
    pub wall_seconds: f64,
    /// Distinct optima (multistart only).
    pub distinct_optima: Option<usize>,
    /// Probability that one start reaches the best optimum (multistart only).
    pub p_single_start: Option<f64>,
}

/// `plyscape compare`: multistart, then CMA-ES with each schedule of
/// `[evolve] restarts` on the same budget (the multistart's function
/// calls), then the comparison table (printed and `comparison.csv`): one
/// row for the multistart and one per schedule, in the listed order.
///
/// Not sharded: run the shards with `plyscape multistart --shard`, merge
/// them, then `plyscape compare --resume` finds every run done and adds the
/// evolution and the table.
pub fn run_compare(ctx: &Context) -> Result<Vec<ComparisonRow>> {
    ctx.study.section::<CompareSection>("compare")?;
    let s = ctx.flags.shard;
    if s.count > 1 {
        return Err(Error::input(
            "--shard",
            format!("{}/{}", s.index, s.count),
            "no shard for compare: shard `plyscape multistart`, merge, then `plyscape compare --resume`",
        ));
    }
    let problem = problem(ctx.study)?;
    let plan = multistart_plan(ctx.study, problem.as_ref())?;
    // Check [evolve] before the (possibly long) multistart.
    evolve_plan(ctx.study)?;
    let ms = multistart_with(ctx, problem.as_ref(), &plan)?;
    let budget = ms.function_calls + plan.starts.filter_evaluations;
    let evs = run_evolve(ctx, Some(budget))?;
    let dir = ctx.dir()?;
    let tolerance = plan.tolerances.feasibility;
    let mut rows = Vec::new();
    if let Some(best) = ms.optima.first() {
        rows.push(ComparisonRow {
            method: format!("multistart-{}", plan.section.method),
            best_f: best.f,
            best_x: best.x.clone(),
            max_g: best.g.iter().copied().reduce(f64::max),
            feasible: best.feasible,
            feasibility_tolerance: tolerance,
            function_calls: budget,
            gradient_calls: ms.gradient_calls,
            wall_seconds: ms.wall_seconds,
            distinct_optima: Some(ms.optima.len()),
            p_single_start: ms.p_best(),
        });
    }
    rows.extend(evs.iter().map(|ev| evolution_row(ev, tolerance)));
    let table = comparison_table(problem.as_ref(), &rows);
    tables::write_atomic(&dir.join("comparison.csv"), &table)?;
    convergence_plot(problem.as_ref(), &dir, Some(&ms), &evs)?;
    if !ctx.quiet {
        print_table(&table);
    }
    Ok(rows)
}

/// The comparison row of one evolutionary search; feasible when every
/// constraint at its best design is `<= tolerance` (the multistart's).
fn evolution_row(ev: &evolve::Report, tolerance: f64) -> ComparisonRow {
    let o = &ev.outcome;
    ComparisonRow {
        method: solvers::global_method(ev.restarts).into(),
        best_f: o.f,
        best_x: o.x.clone(),
        max_g: o.g.iter().copied().reduce(f64::max),
        feasible: o.g.iter().all(|&g| g <= tolerance),
        feasibility_tolerance: tolerance,
        function_calls: ev.function_calls,
        gradient_calls: ev.gradient_calls,
        wall_seconds: ev.wall_seconds,
        distinct_optima: None,
        p_single_start: None,
    }
}

/// `comparison.csv`: header and rows.
pub fn comparison_table(problem: &dyn Problem, rows: &[ComparisonRow]) -> Vec<Vec<String>> {
    let mut h = vec!["method".to_string(), "best_f".into()];
    h.extend(problem.variables().iter().map(|v| format!("x_{}", v.name)));
    h.extend(
        [
            "max_g",
            "feasible",
            "feasibility_tolerance",
            "function_calls",
            "gradient_calls",
            "wall_seconds",
            "distinct_optima",
            "p_single_start",
        ]
        .map(String::from),
    );
    let mut out = vec![h];
    for r in rows {
        let mut v = vec![r.method.clone(), tables::num(r.best_f)];
        v.extend(r.best_x.iter().map(|&x| tables::num(x)));
        v.push(tables::field(r.max_g));
        v.push(r.feasible.to_string());
        v.push(tables::num(r.feasibility_tolerance));
        v.push(r.function_calls.to_string());
        v.push(r.gradient_calls.to_string());
        v.push(format!("{:.3}", r.wall_seconds));
        v.push(r.distinct_optima.map(|d| d.to_string()).unwrap_or_default());
        v.push(tables::field(r.p_single_start));
        out.push(v);
    }
    out
}

fn print_table(rows: &[Vec<String>]) {
    let widths: Vec<usize> = (0..rows[0].len())
        .map(|c| rows.iter().map(|r| r[c].len()).max().unwrap_or(0))
        .collect();
    for r in rows {
        let line: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(s, w)| format!("{s:>w$}"))
            .collect();
        println!("{}", line.join("  "));
    }
}

/// `convergence.svg`: multistart best-so-far over cumulative function calls
/// (runs in start order) and each evolution's best-so-far per generation.
fn convergence_plot(
    problem: &dyn Problem,
    dir: &Path,
    ms: Option<&multistart::Report>,
    evs: &[evolve::Report],
) -> Result<()> {
    let mut curves = Vec::new();
    if let Some(ms) = ms {
        let (mut calls, mut best) = (0usize, f64::INFINITY);
        let mut pts = Vec::new();
        for r in &ms.runs {
            calls += r.function_calls;
            if let Some(res) = &r.result {
                best = best.min(res.f);
            }
            if best.is_finite() {
                pts.push((calls as f64, best));
            }
        }
        curves.push(crate::report::Curve {
            label: "multistart (best so far)".into(),
            points: pts,
        });
    }
    for ev in evs {
        // One schedule keeps the labels it always had (IPOP as plain
        // CMA-ES); several are named in full.
        let name = match ev.restarts {
            Restarts::Ipop if evs.len() == 1 => "CMA-ES",
            r => r.solver_name(),
        };
        curves.push(crate::report::Curve {
            label: format!("{name} (best so far)"),
            points: ev
                .generations
                .iter()
                .filter(|g| g.best_f.is_finite())
                .map(|g| (g.function_calls as f64, g.best_f))
                .collect(),
        });
    }
    // Log–log: the gap of each best-so-far to the lowest f any method
    // found, raised to a floor (marked in the plot) so that a gap of zero,
    // the winner's final point, shows.
    let lowest = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.1))
        .fold(f64::INFINITY, f64::min);
    let floor = 1e-12 * lowest.abs().max(1.0);
    for c in &mut curves {
        for p in &mut c.points {
            p.1 = (p.1 - lowest).max(floor);
        }
    }
    let y = format!(
        "best f − lowest f found ({lowest:.6e}), {}",
        problem.objective_label()
    );
    crate::report::line_plot_floored(
        &dir.join("convergence.svg"),
        &crate::report::Axes {
            title: &format!(
                "{}: best objective vs function calls (log–log)",
                problem.name()
            ),
            x: "function calls [-]",
            y: &y,
            scale: crate::report::Scale::LogLog,
        },
        &curves,
        floor,
    )
}

/// `plyscape map`: the grid(s), marked with the optima in `optima.csv` and
/// each evolution's best in `evolution.csv` when those exist in the study's
/// output directory.
pub fn run_map(ctx: &Context) -> Result<Vec<map::Slice>> {
    let problem = problem(ctx.study)?;
    let sec = map_section(ctx.study)?;
    let loc = ctx.study.locate("map");
    let vars = problem.variables();
    let n = vars.len();
    let pairs: Vec<(usize, usize)> = match &sec.pairs {
        Some(p) => {
            for (k, &[a, b]) in p.iter().enumerate() {
                if a >= n || b >= n || a == b {
                    return Err(loc(Error::input(
                        format!("pairs[{k}]"),
                        format!("[{a}, {b}]"),
                        format!("two different variable indices < {n}"),
                    )));
                }
            }
            p.iter().map(|&[a, b]| (a, b)).collect()
        }
        None => (0..n / 2).map(|k| (2 * k, 2 * k + 1)).collect(),
    };
    let dir = ctx.dir()?;
    let optima: Vec<Vec<f64>> = read_points(&dir.join("optima.csv"), "x_", vars)?
        .into_iter()
        .map(|(_, x)| x)
        .collect();
    let evo = read_points(&dir.join("evolution.csv"), "best_x_", vars)?;
    let base = optima
        .first()
        .cloned()
        .unwrap_or_else(|| vars.iter().map(|v| 0.5 * (v.lower + v.upper)).collect());
    let mut marks = Vec::new();
    if !optima.is_empty() {
        marks.push(("local optima".to_string(), optima));
    }
    marks.extend(evolution_marks(evo));
    let req = map::MapRequest {
        resolution: sec.resolution,
        pairs,
        base,
        marks,
    };
    let slices = map::run(problem.as_ref(), &req, ctx.threads, &dir)?;
    let mut entry = json!({"resolution": sec.resolution});
    if n > 2 {
        // The design the slices pass through (the other variables' values).
        let base = vars
            .iter()
            .zip(&req.base)
            .map(|(v, &x)| (v.name.clone(), json!(x)));
        entry["slices_through"] = serde_json::Value::Object(base.collect());
    }
    ctx.manifest(&dir, "map", entry)?;
    if !ctx.quiet {
        println!(
            "map of {}: {} slice(s) of {}^2 points in {}",
            problem.name(),
            slices.len(),
            sec.resolution,
            dir.display()
        );
    }
    Ok(slices)
}

/// Read and check `[map]` (default: 61 points per axis, consecutive pairs).
pub fn map_section(study: &Study) -> Result<MapSection> {
    let sec: MapSection = study.section("map")?.unwrap_or(MapSection {
        resolution: default_resolution(),
        pairs: None,
    });
    if !(2..=2001).contains(&sec.resolution) {
        return Err(study.error("map.resolution", sec.resolution, "2 <= resolution <= 2001"));
    }
    Ok(sec)
}

/// Check the exploration section `key` of `study` without doing any work
/// (`plyscape run` checks every section before the first one runs). A
/// `scene` problem is only parsed here: building it evaluates a design.
pub fn check(study: &Study, key: &str) -> Result<()> {
    match key {
        "problem" => {
            let spec: problems::ProblemSpec =
                study.require_section("problem", "the problem to explore (name = ...)")?;
            if spec.name == "scene" {
                scene_problem::SceneProblem::check(study)
            } else {
                problem(study).map(|_| ())
            }
        }
        "multistart" => multistart_section(study).map(|_| ()),
        "evolve" => evolve_plan(study).map(|_| ()),
        "compare" => study.section::<CompareSection>("compare").map(|_| ()),
        "map" => map_section(study).map(|_| ()),
        optimum_report::KEY => optimum_report::check(study).map(|_| ()),
        "scaling" => study
            .require_section::<scaling::ScalingSection>("scaling", "threads = [1, 2]")
            .map(|_| ()),
        _ => Ok(()),
    }
}

/// The marks of the evolutions' bests: the last row (best so far) of each
/// method of `evolution.csv` rows from [`read_points`], labelled
/// `CMA-ES best` for a table of one schedule and `<solver> best`
/// (`IPOP-CMA-ES best`, `BIPOP-CMA-ES best`) for each schedule of a table
/// with a `method` column.
fn evolution_marks(rows: Vec<(String, Vec<f64>)>) -> Vec<(String, Vec<Vec<f64>>)> {
    let mut out: Vec<(String, Vec<Vec<f64>>)> = Vec::new();
    for (method, x) in rows {
        let label = if method.is_empty() {
            "CMA-ES best".to_string()
        } else {
            match solvers::global_schedule(&method) {
                Some(r) => format!("{} best", r.solver_name()),
                None => format!("{method} best"),
            }
        };
        match out.iter_mut().find(|(l, _)| *l == label) {
            Some(mark) => mark.1 = vec![x],
            None => out.push((label, vec![x])),
        }
    }
    out
}

/// Designs from the `<prefix><name>` columns of a CSV, if the file exists,
/// each with its `method` field (empty when there is no such column).
fn read_points(
    path: &Path,
    prefix: &str,
    vars: &[crate::optimize::Variable],
) -> Result<Vec<(String, Vec<f64>)>> {
    if !path.exists() {
        return Ok(vec![]);
    }
    let mut rd = csv::Reader::from_path(path).map_err(|e| Error::csv(path, e))?;
    let headers = rd.headers().map_err(|e| Error::csv(path, e))?.clone();
    let cols: Option<Vec<usize>> = vars
        .iter()
        .map(|v| {
            headers
                .iter()
                .position(|h| h == format!("{prefix}{}", v.name))
        })
        .collect();
    let Some(cols) = cols else { return Ok(vec![]) };
    let method = headers.iter().position(|h| h == "method");
    let mut out = Vec::new();
    for r in rd.records() {
        let r = r.map_err(|e| Error::csv(path, e))?;
        let x: Option<Vec<f64>> = cols.iter().map(|&c| r.get(c)?.parse().ok()).collect();
        let tag = method.and_then(|c| r.get(c)).unwrap_or_default();
        if let Some(x) = x {
            out.push((tag.to_string(), x));
        }
    }
    Ok(out)
}

/// `plyscape merge`: combine the shard directories of one multistart into
/// the tables an unsharded run gives, in `out/<study>/`.
///
/// Strict by design: shards are only read, never modified (a torn last
/// line is refused, not repaired: finish that shard with `--resume`); a
/// directory of an unsharded run is not a shard; every start a shard owns
/// must have its row unless the study's `max_evaluations` budget stopped
/// the shard early (the missing starts are named).
pub fn merge(dirs: &[PathBuf], out: &Path, quiet: bool) -> Result<multistart::Report> {
    if dirs.is_empty() {
        return Err(Error::input(
            "dirs",
            "(none)",
            "at least one shard directory",
        ));
    }
    let (text, file, n, indices) = shard_manifests(dirs)?;
    let study = Study::parse(&file, &text)?;
    let problem = problem(&study)?;
    let plan = multistart_plan(&study, problem.as_ref())?;
    let vars = problem.variables();
    let m = problem.n_constraints();
    let mut rows = Vec::new();
    for (d, &index) in dirs.iter().zip(&indices) {
        let shard = Shard { index, count: n };
        rows.extend(shard_rows(d, shard, &plan, vars, m)?);
    }
    let dir = study.output_dir(out)?;
    let _lock = crate::report::lock::DirLock::acquire(&dir, "merge")?;
    let wall = dirs
        .iter()
        .filter_map(|d| {
            crate::report::read_manifest(d).ok()?["commands"]["multistart"]["wall_seconds"].as_f64()
        })
        .fold(0.0, f64::max);
    let report = multistart::finish(vars, m, rows, plan.tolerances, &dir, wall)?;
    // The manifest's thread count: the largest any shard used.
    let threads = dirs
        .iter()
        .filter_map(|d| crate::report::read_manifest(d).ok()?["threads"].as_u64())
        .max()
        .unwrap_or(1) as usize;
    let ctx = Context {
        study: &study,
        out,
        threads,
        quiet,
        flags: DriveFlags::default(),
    };
    ctx.manifest(
        &dir,
        "merge",
        json!({
            "complete": true,
            "merged_from": dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>(),
            "wall_seconds": wall,
        }),
    )?;
    if !quiet {
        print_optima(problem.as_ref(), &report);
    }
    Ok(report)
}

/// The study text, study file name and shard count shared by the shard
/// directories `dirs`, and their shard indices; refuses a directory that
/// is not a finished shard, shards of different studies, and a set that
/// does not hold each shard exactly once.
fn shard_manifests(dirs: &[PathBuf]) -> Result<(String, String, usize, Vec<usize>)> {
    let mut first: Option<(String, String, usize)> = None;
    let mut seen = Vec::new();
    for d in dirs {
        let m = crate::report::read_manifest(d)?;
        let t = m["study_text"].as_str().unwrap_or_default().to_string();
        let shard = (m["shard"]["index"].as_u64(), m["shard"]["count"].as_u64());
        let (Some(i), Some(n)) = shard else {
            return Err(Error::input(
                d.display().to_string(),
                "manifest.json",
                "a shard manifest",
            ));
        };
        if n < 2 {
            return Err(Error::input(
                d.display().to_string(),
                "an unsharded run (shard 0/1)",
                "a shard directory written by `plyscape multistart --shard I/N` with N >= 2",
            ));
        }
        if m["commands"]["multistart"]["complete"].as_bool() != Some(true) {
            return Err(Error::input(
                d.display().to_string(),
                format!("shard {i}/{n} (incomplete)"),
                "a finished shard (finish it with --resume first)",
            ));
        }
        match &first {
            None => {
                let file = m["study_file"].as_str().unwrap_or("study").to_string();
                first = Some((t, file, n as usize));
            }
            Some((t0, _, n0)) if *t0 == t && *n0 == n as usize => {}
            Some(_) => {
                return Err(Error::input(
                    d.display().to_string(),
                    format!("shard {i}/{n}"),
                    "shards of the same study text and shard count",
                ))
            }
        }
        seen.push(i as usize);
    }
    let (text, file, n) = first.expect("dirs is not empty");
    let mut sorted = seen.clone();
    sorted.sort_unstable();
    if sorted != (0..n).collect::<Vec<_>>() {
        return Err(Error::input(
            "dirs",
            format!("shards {seen:?}"),
            format!("each of the shards 0..{n} exactly once"),
        ));
    }
    Ok((text, file, n, seen))
}

/// The rows of one shard's `runs.csv`, read without modifying it: each row
/// must be a start of the study that this shard owns, and every start it
/// owns must be there unless the study's function-call budget stopped it.
fn shard_rows(
    d: &Path,
    shard: Shard,
    plan: &MultistartPlan,
    vars: &[crate::optimize::Variable],
    m: usize,
) -> Result<Vec<tables::RunRecord>> {
    let path = d.join("runs.csv");
    let (read, _) = tables::scan_runs(&path, vars, m)?;
    if read.repaired_bytes > 0 {
        return Err(Error::csv(
            &path,
            format!(
                "torn last line ({} bytes) in a finished shard; the shard is left as it is: \
                 run it again with --resume to finish it, then merge",
                read.repaired_bytes
            ),
        ));
    }
    let starts = &plan.starts.points;
    for row in &read.rows {
        let ok = shard.owns(row.start)
            && starts.get(row.start).is_some_and(|x0| {
                x0.iter()
                    .zip(&row.x0)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            });
        if !ok {
            return Err(Error::csv(
                &path,
                format!(
                    "row for start {} does not match the study or is not shard {}/{}'s",
                    row.start, shard.index, shard.count
                ),
            ));
        }
    }
    let have: std::collections::BTreeSet<usize> = read.rows.iter().map(|r| r.start).collect();
    let missing: Vec<usize> = (0..starts.len())
        .filter(|&k| shard.owns(k) && !have.contains(&k))
        .collect();
    if !missing.is_empty() && plan.section.max_evaluations.is_none() {
        return Err(Error::csv(
            &path,
            format!(
                "shard {}/{} lacks the rows of starts {missing:?}; run it again with --resume",
                shard.index, shard.count
            ),
        ));
    }
    Ok(read.rows)
}
