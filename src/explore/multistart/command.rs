//! `plyscape multistart`: the local optimizer from every start of
//! `[multistart]` ([`crate::explore::multistart::driver`] runs them), the optima
//! printed, the manifest entry, and the `[optimum_report]` of the first
//! start when the study asks for it.

use super::section::{multistart_plan, MultistartPlan, NoiseAllowance};
use super::{driver, optimum_report, robustness};
use crate::error::{Error, Result};
use crate::explore::context::Context;
use crate::explore::local::{solvers, violation};
use crate::explore::persist::fingerprint;
use crate::explore::persist::journal::Journaled;
use crate::explore::persist::manifest::{MultistartCounts, MultistartEntry, NoiseRecord};
use crate::explore::problem::build::problem;
use crate::optimize::noise::{estimate, Measured, NoiseOptions};
use crate::optimize::Problem;
use crate::report::Progress;
use std::path::{Path, PathBuf};

/// `plyscape multistart`: runs, optima, manifest.
pub fn run_multistart(ctx: &Context) -> Result<driver::Report> {
    let problem = problem(ctx.study)?;
    let plan = multistart_plan(ctx.study, problem.as_ref())?;
    multistart_with(ctx, problem.as_ref(), &plan)
}

/// The multistart of a checked plan on a built problem (`compare` runs it
/// before its evolution).
pub fn multistart_with(
    ctx: &Context,
    problem: &dyn Problem,
    plan: &MultistartPlan,
) -> Result<driver::Report> {
    let dir = ctx.dir()?;
    if ctx.flags.resume {
        // Same evaluations as the rows read back (fingerprint, spot check).
        let checks = plan.section.resume_checks;
        fingerprint::check_runs(ctx.study, &dir, problem, checks, ctx.quiet)?;
    } else {
        keep_earlier_runs(&dir, ctx.flags.force, ctx.quiet)?;
    }
    let started = MultistartEntry {
        complete: false,
        counts: None,
    };
    ctx.manifest(&dir, "multistart", started)?;
    let section = &plan.section;
    let noise = noise_allowance(ctx, problem, plan)?;
    let solver = solvers::local(
        section.method,
        &section.mmfd,
        section.preset,
        (section.feasibility_tolerance, noise.0 .0),
    )?;
    let report_plan = optimum_report::prepare(ctx, problem, plan)?;
    let settings = driver::Settings {
        threads: ctx.threads,
        max_evaluations: plan.section.max_evaluations,
        max_wall_seconds: plan.section.max_wall_seconds,
        tolerances: plan.tolerances,
        resume: ctx.flags.resume,
        shard: ctx.flags.shard,
        quiet: ctx.quiet,
        history_start: report_plan.as_ref().map(|_| optimum_report::REPORTED_START),
        end: section.end_policy(noise.0),
    };
    let mut report = driver::run(
        problem,
        solver.as_ref(),
        &plan.starts.points,
        &settings,
        &dir,
    )?;
    if noise.1.is_some() {
        noise_at_optima(ctx, problem, &mut report, &dir)?;
    }
    let checks = violation_checks(ctx, problem, &report, section.violation_checks, &dir)?;
    let mine = (0..plan.starts.points.len())
        .filter(|&k| ctx.flags.shard.owns(k))
        .count();
    let done = MultistartEntry {
        complete: report.runs.len() == mine || plan.section.max_evaluations.is_some(),
        counts: Some(MultistartCounts {
            starts: plan.starts.points.len(),
            runs_in_tables: report.runs.len(),
            runs_this_invocation: report.new_runs,
            filter_evaluations: plan.starts.filter_evaluations,
            wall_seconds: report.wall_seconds,
            classes: report.classes,
            feasibility_tolerance: section.feasibility_tolerance,
            violation_checks: checks,
            rtol: problem.tolerance(),
            noise: noise.1.as_ref().map(NoiseRecord::of),
            notes: problem.notes(),
        }),
    };
    ctx.manifest(&dir, "multistart", done)?;
    every_run_failed(&report)?;
    if !ctx.quiet {
        print_optima(problem, &report);
        for n in problem.notes() {
            eprintln!("note: {n}");
        }
    }
    // `[robustness]`: optima.csv again, with the worst-case columns.
    robustness::apply(ctx, problem, &report.optima, &dir)?;
    if let Some(p) = report_plan {
        p.finish(ctx, &dir, problem, plan, &report)?;
    }
    Ok(report)
}

/// A multistart none of whose runs gave a result is a numerical failure
/// (exit 3), with the first run's reason; its tables are written first.
fn every_run_failed(report: &driver::Report) -> Result<()> {
    if report.runs.is_empty() || report.runs.iter().any(|r| r.result.is_some()) {
        return Ok(());
    }
    let first = &report.runs[0];
    Err(Error::numerical(
        "explore::multistart",
        format!(
            "every one of the {} runs failed (runs.csv); start {}: {}",
            report.runs.len(),
            first.start,
            first.exit
        ),
    ))
}

/// `[multistart] noise`: the allowances of f and of g (see
/// [`super::section::MultistartSection::end_policy`]): f's given (g's
/// then 0), or ECNoise's at the first start (3σ;
/// [`crate::optimize::noise::Measured::allowance`] and `allowance_g`) with
/// the measurement (0 without starts: no run uses them).
pub(crate) fn noise_allowance(
    ctx: &Context,
    problem: &dyn Problem,
    plan: &MultistartPlan,
) -> Result<((f64, f64), Option<Measured>)> {
    let x0 = match (plan.section.noise, plan.starts.points.first()) {
        (NoiseAllowance::Given(v), _) => return Ok(((v, 0.0), None)),
        (NoiseAllowance::Measured(_), None) => return Ok(((0.0, 0.0), None)),
        (NoiseAllowance::Measured(_), Some(x0)) => x0,
    };
    let m = estimate(problem, x0, ctx.study.meta.seed, &NoiseOptions::default())?;
    if !ctx.quiet {
        println!(
            "  noise at the first start: {}; allowance {:.2e} ({} function calls)",
            level(&m),
            m.allowance(),
            m.evaluations
        );
    }
    Ok(((m.allowance(), m.allowance_g()), Some(m)))
}

/// The noise of f for the terminal: relative to |f|, or why it was not
/// measured.
fn level(m: &Measured) -> String {
    match m.relative_f() {
        Some(r) => format!("{r:.2e} of f"),
        None => format!("not measured ({})", m.noise_f.failure().unwrap_or("")),
    }
}

/// With `[multistart] noise = "measured"`: ECNoise at every certified
/// optimum (the same options and seed as at the first start), written to
/// `optima.csv`'s noise columns ([`driver::NOISE_COLUMNS`]) and printed
/// (also by `plyscape merge`, at the merged optima).
pub(crate) fn noise_at_optima(
    ctx: &Context,
    problem: &dyn Problem,
    report: &mut driver::Report,
    dir: &Path,
) -> Result<()> {
    let pool = crate::explore::context::thread_pool(ctx.threads)?;
    let seed = ctx.study.meta.seed;
    let measured: Vec<Measured> = pool.install(|| {
        use rayon::prelude::*;
        report
            .optima
            .par_iter()
            .map(|o| estimate(problem, &o.x, seed, &NoiseOptions::default()))
            .collect::<Result<_>>()
    })?;
    for (o, m) in report.optima.iter_mut().zip(measured) {
        if !ctx.quiet {
            println!("  noise at optimum {}: {}", o.id, level(&m));
        }
        o.noise = Some(m);
    }
    let (vars, m) = (problem.variables(), problem.n_constraints());
    crate::explore::persist::tables::write_atomic(
        &dir.join("optima.csv"),
        &driver::optima_table(vars, m, &report.optima),
    )
}

/// `[multistart] violation_checks`: the pure descent on the violation from
/// the starts of a sample of infeasible runs ([`violation`]), written to
/// `violation_checks.csv`; returns (checked, reached the feasible set).
fn violation_checks(
    ctx: &Context,
    problem: &dyn Problem,
    report: &driver::Report,
    count: usize,
    dir: &Path,
) -> Result<(usize, usize)> {
    let sample = violation::sample(&report.runs, count);
    if sample.is_empty() {
        return Ok((0, 0));
    }
    let tol = report.tolerances.feasibility;
    // The descents run for minutes on a scene: journaled (resumable) and
    // counted on stderr.
    let journal = ctx.journal("violation_checks", "")?;
    let journaled = Journaled::new(problem, &journal)?;
    journal.watch(Some(Progress::counter(
        "violation checks",
        "evaluations",
        ctx.quiet,
    )));
    let checks = violation::check(&journaled, &sample, tol);
    journal.watch(None);
    journal.report("violation checks", ctx.quiet);
    let table = violation::table(problem, &checks, tol);
    crate::explore::persist::tables::write_atomic(&dir.join("violation_checks.csv"), &table)?;
    let reached = checks.iter().filter(|c| c.reached(tol)).count();
    if !ctx.quiet {
        println!(
            "  violation check: from {} infeasible runs' starts, pure descent on the violation \
             reached the feasible set {} times (violation_checks.csv)",
            checks.len(),
            reached
        );
    }
    Ok((checks.len(), reached))
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

/// The summary of a multistart: counts, classes and the ten best optima.
pub fn print_optima(problem: &dyn Problem, r: &driver::Report) {
    println!(
        "multistart on {}: {} runs, {} distinct certified optima, {} function + {} gradient calls, {:.3} s",
        problem.name(),
        r.runs.len(),
        r.optima.len(),
        r.function_calls,
        r.gradient_calls,
        r.wall_seconds
    );
    println!("  runs: {}", r.classes.summary());
    if let Some(p) = r.p_single_start() {
        println!("  p_single_start (a start reaches a best optimum): {p:.3}");
    }
    for o in r.optima.iter().take(10) {
        println!(
            "  optimum {:>3}: f = {:>14.8e}  x = {:?}  feasible = {}  basin share = {:.3}",
            o.id, o.f, o.x, o.feasible, o.basin_share
        );
    }
}
