//! `plyscape evolve`: CMA-ES with each schedule of `[evolve] restarts`
//! ([`crate::explore::evolve::search`] runs one), `evolution.csv`,
//! `convergence.svg` and the manifest entry.

use super::convergence::convergence_plot;
use super::search;
use super::section::evolve_plan;
use crate::error::Result;
use crate::explore::context::Context;
use crate::explore::multistart::section::MultistartSection;
use crate::explore::persist::journal::Journaled;
use crate::explore::persist::manifest::{
    CmaesRunEntry, EvolveEntry, EvolveSchedules, ScheduleEntry,
};
use crate::explore::persist::tables;
use crate::explore::problem::build::problem;
use crate::optimize::cmaes::Regime;
use crate::optimize::Problem;

/// `plyscape evolve`: CMA-ES with each schedule of `[evolve] restarts` on
/// the same budget and seed, one after another; evolution.csv,
/// convergence.svg and the manifest entry. `budget` stands in for an
/// absent `[evolve] max_evaluations`.
pub fn run_evolve(ctx: &Context, budget: Option<usize>) -> Result<Vec<search::Report>> {
    let built = problem(ctx.study)?;
    let plan = evolve_plan(ctx.study)?;
    let journal = ctx.journal("evolve", "")?;
    let problem = Journaled::new(built.as_ref(), &journal)?;
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
    let solver = search::global();
    let mut reports = Vec::new();
    for &restarts in &plan.schedules {
        let request = search::Request {
            seed: ctx.study.meta.seed,
            max_evaluations,
            restarts,
            feasibility_tolerance,
            tol_fun: plan.section.tol_fun.unwrap_or(1e-12),
            target: plan.section.target,
            active: plan.section.active,
        };
        let report = search::run(&problem, solver.as_ref(), &request, ctx.threads, ctx.quiet)?;
        if !ctx.quiet {
            print_evolution(&problem, &report);
        }
        reports.push(report);
    }
    tables::write_atomic(
        &dir.join("evolution.csv"),
        &search::table(&problem, &reports),
    )?;
    let tol_fun = plan.section.tol_fun.unwrap_or(1e-12);
    ctx.manifest(
        &dir,
        "evolve",
        EvolveEntry {
            replayed: (journal.replayed() > 0).then(|| journal.replayed()),
            ..evolve_entry((max_evaluations, tol_fun), &reports)
        },
    )?;
    convergence_plot(&problem, &dir, None, &reports)?;
    journal.report("evolve", ctx.quiet);
    Ok(reports)
}

/// The manifest entry of `evolve`: the budget, and per schedule its
/// method, solver, `restarts` name, function calls, wall time, run counts
/// per regime and every CMA-ES run (regime, λ, σ0, evaluations,
/// generations). One schedule's keys stand at the top of the entry (as
/// before lists existed); several are under `schedules`, with `restarts`
/// listing their names and `wall_seconds` their total.
pub fn evolve_entry(
    (max_evaluations, tol_fun): (usize, f64),
    reports: &[search::Report],
) -> EvolveEntry {
    let mut schedules: Vec<ScheduleEntry> = reports.iter().map(schedule_entry).collect();
    let schedules = if schedules.len() == 1 {
        EvolveSchedules::One(schedules.remove(0))
    } else {
        EvolveSchedules::Many {
            wall_seconds: reports.iter().map(|r| r.wall_seconds).sum(),
            restarts: reports.iter().map(|r| r.restarts.name().into()).collect(),
            schedules,
        }
    };
    EvolveEntry {
        max_evaluations,
        tol_fun,
        replayed: None,
        schedules,
    }
}

/// One schedule's part of [`evolve_entry`].
fn schedule_entry(report: &search::Report) -> ScheduleEntry {
    let o = &report.outcome;
    let (large_runs, small_runs) = regime_counts(o);
    let runs = o
        .runs
        .iter()
        .map(|r| CmaesRunEntry {
            regime: r.regime.name().into(),
            lambda: r.lambda,
            sigma0: r.sigma0,
            evaluations: r.evaluations,
            generations: r.generations,
        })
        .collect();
    let r = report.restarts;
    ScheduleEntry {
        method: search::global_method(r).into(),
        solver: r.solver_name().into(),
        restarts: r.name().into(),
        function_calls: report.function_calls,
        wall_seconds: report.wall_seconds,
        large_runs,
        small_runs,
        runs,
    }
}

/// The summary line of one evolutionary search.
fn print_evolution(problem: &dyn Problem, report: &search::Report) {
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
