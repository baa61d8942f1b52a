//! `plyscape compare`: the multistart and CMA-ES on the same budget, and
//! `comparison.csv`.

use super::convergence::convergence_plot;
use super::evolve::run_evolve;
use super::multistart::multistart_with;
use crate::error::{Error, Result};
use crate::explore::config::{compare_section, evolve_plan, multistart_plan, problem};
use crate::explore::context::Context;
use crate::explore::{evolve, tables};
use crate::optimize::Problem;

/// One row of the comparison table.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonRow {
    /// `multistart-<method>`, or the evolutionary method of one schedule:
    /// [`evolve::global_method`] (`cmaes` for IPOP, `cmaes-bipop`).
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
    compare_section(ctx.study)?;
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
            method: format!("multistart-{}", plan.section.method.name()),
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
        method: evolve::global_method(ev.restarts).into(),
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
