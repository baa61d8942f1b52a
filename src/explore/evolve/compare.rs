//! `plyscape compare`: the multistart and CMA-ES on the same budget, and
//! `comparison.csv`.

use super::command::run_evolve;
use super::convergence::convergence_plot;
use super::search;
use super::section::{compare_section, evolve_plan};
use crate::error::{Error, Result};
use crate::explore::context::Context;
use crate::explore::local::settle;
use crate::explore::multistart::command::{multistart_with, noise_allowance};
use crate::explore::multistart::section::multistart_plan;
use crate::explore::persist::tables;
use crate::explore::problem::build::problem;
use crate::optimize::{Counted, Problem};

/// Which of a method's designs a comparison row holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// The best design with `max g <= feasibility_tolerance` (for the
    /// multistart its best certified optimum; for an evolution its best
    /// design, marked infeasible when it is not within the tolerance).
    Tolerance,
    /// The best design with `max g <= 0`, reached from the method's best
    /// designs by the same polish and push inside for every method
    /// ([`settle::strictly_feasible`]).
    Strict,
}

impl Basis {
    /// The name in `comparison.csv`'s `basis` column.
    pub fn name(self) -> &'static str {
        match self {
            Basis::Tolerance => "tolerance",
            Basis::Strict => "strict",
        }
    }
}

/// One row of the comparison table.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonRow {
    /// `multistart-<method>`, or the evolutionary method of one schedule:
    /// [`search::global_method`] (`cmaes` for IPOP, `cmaes-bipop`).
    pub method: String,
    /// Which design of the method the row holds.
    pub basis: Basis,
    /// Best objective (`None`: the method has no design on this basis).
    pub best_f: Option<f64>,
    /// Best design (empty with `best_f = None`).
    pub best_x: Vec<f64>,
    /// Largest constraint value at the best design (`None`: no
    /// constraints, or no design).
    pub max_g: Option<f64>,
    /// Feasible: `max_g <= feasibility_tolerance` (`max_g <= 0` on the
    /// strict basis).
    pub feasible: bool,
    /// The study's one feasibility tolerance.
    pub feasibility_tolerance: f64,
    /// Function calls of the method.
    pub function_calls: usize,
    /// Gradient calls of the method.
    pub gradient_calls: usize,
    /// Function and gradient calls of the strict row's polish and push
    /// inside (0 on the tolerance basis).
    pub polish_calls: (usize, usize),
    /// Wall time \[s\].
    pub wall_seconds: f64,
    /// Distinct certified optima (multistart only).
    pub distinct_optima: Option<usize>,
    /// Probability that one start reaches a best optimum (multistart only;
    /// [`crate::explore::multistart::driver::Report::p_single_start`]).
    pub p_single_start: Option<f64>,
}

/// `plyscape compare`: multistart, then CMA-ES with each schedule of
/// `[evolve] restarts` on the same budget (the multistart's function
/// calls), then the comparison table (printed and `comparison.csv`): for
/// the multistart and each schedule, in the listed order, a row on each
/// [`Basis`]: the best design within the feasibility tolerance, and the
/// best strictly feasible design after the same polish for every method,
/// so that no method wins by standing on the tolerance.
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
    // The multistart's allowance; a multistart read back from complete
    // tables has none, and the first start's noise is measured again.
    let noise = match ms.noise {
        Some(n) => n,
        None => noise_allowance(ctx, problem.as_ref(), &plan)?.0,
    };
    let policy = plan.section.end_policy(noise);
    let tolerance = policy.tolerances.feasibility;
    let base = ComparisonRow {
        method: format!("multistart-{}", plan.section.method.name()),
        basis: Basis::Tolerance,
        best_f: None,
        best_x: vec![],
        max_g: None,
        feasible: false,
        feasibility_tolerance: tolerance,
        function_calls: budget,
        gradient_calls: ms.gradient_calls,
        polish_calls: (0, 0),
        wall_seconds: ms.wall_seconds,
        distinct_optima: Some(ms.optima.len()),
        p_single_start: ms.p_single_start(),
    };
    let mut rows = Vec::new();
    let mut tolerance_row = base.clone();
    if let Some(best) = ms.optima.first() {
        tolerance_row.best_f = Some(best.f);
        tolerance_row.best_x = best.x.clone();
        tolerance_row.max_g = best.g.iter().copied().reduce(f64::max);
        tolerance_row.feasible = best.feasible;
    }
    rows.push(tolerance_row);
    // The optima in order; the best strictly feasible among the first ten.
    let designs: Vec<Vec<f64>> = ms.optima.iter().take(10).map(|o| o.x.clone()).collect();
    rows.push(strict_row(problem.as_ref(), &designs, &policy, &base)?);
    for ev in &evs {
        let row = evolution_row(ev, tolerance);
        let strict = strict_row(
            problem.as_ref(),
            std::slice::from_ref(&ev.outcome.x),
            &policy,
            &row,
        )?;
        rows.push(row);
        rows.push(strict);
    }
    let table = comparison_table(problem.as_ref(), &rows);
    tables::write_atomic(&dir.join("comparison.csv"), &table)?;
    convergence_plot(problem.as_ref(), &dir, Some(&ms), &evs)?;
    if !ctx.quiet {
        print_table(&table);
    }
    Ok(rows)
}

/// The strict row of a method: from each of `designs`, the polish and the
/// push inside; the lowest f with `max g <= 0`, or no design. Counts and
/// other fields from `like`.
fn strict_row(
    problem: &dyn Problem,
    designs: &[Vec<f64>],
    policy: &settle::EndPolicy,
    like: &ComparisonRow,
) -> Result<ComparisonRow> {
    let counted = Counted::new(problem);
    let mut best: Option<(Vec<f64>, f64, f64)> = None;
    for x in designs {
        if let Some(d) = settle::strictly_feasible(&counted, x, policy)? {
            if best.as_ref().is_none_or(|b| d.1 < b.1) {
                best = Some(d);
            }
        }
    }
    let m = problem.n_constraints();
    let mut row = ComparisonRow {
        basis: Basis::Strict,
        polish_calls: (counted.function_calls(), counted.gradient_calls()),
        best_f: None,
        best_x: vec![],
        max_g: None,
        feasible: false,
        ..like.clone()
    };
    if let Some((x, f, max_g)) = best {
        row.best_f = Some(f);
        row.best_x = x;
        row.max_g = (m > 0).then_some(max_g);
        row.feasible = true;
    }
    Ok(row)
}

/// The tolerance row of one evolutionary search; feasible when every
/// constraint at its best design is `<= tolerance` (the study's).
fn evolution_row(ev: &search::Report, tolerance: f64) -> ComparisonRow {
    let o = &ev.outcome;
    ComparisonRow {
        method: search::global_method(ev.restarts).into(),
        basis: Basis::Tolerance,
        best_f: Some(o.f),
        best_x: o.x.clone(),
        max_g: o.g.iter().copied().reduce(f64::max),
        feasible: o.g.iter().all(|&g| g <= tolerance),
        feasibility_tolerance: tolerance,
        function_calls: ev.function_calls,
        gradient_calls: ev.gradient_calls,
        polish_calls: (0, 0),
        wall_seconds: ev.wall_seconds,
        distinct_optima: None,
        p_single_start: None,
    }
}

/// `comparison.csv`: header and rows.
pub fn comparison_table(problem: &dyn Problem, rows: &[ComparisonRow]) -> Vec<Vec<String>> {
    let n = problem.variables().len();
    let mut h = vec!["method".to_string(), "basis".into(), "best_f".into()];
    h.extend(problem.variables().iter().map(|v| format!("x_{}", v.name)));
    h.extend(
        [
            "max_g",
            "feasible",
            "feasibility_tolerance",
            "function_calls",
            "gradient_calls",
            "polish_function_calls",
            "polish_gradient_calls",
            "wall_seconds",
            "distinct_optima",
            "p_single_start",
        ]
        .map(String::from),
    );
    let mut out = vec![h];
    for r in rows {
        let mut v = vec![
            r.method.clone(),
            r.basis.name().into(),
            tables::field(r.best_f),
        ];
        if r.best_x.is_empty() {
            v.extend(std::iter::repeat_n(String::new(), n));
        } else {
            v.extend(r.best_x.iter().map(|&x| tables::num(x)));
        }
        v.push(tables::field(r.max_g));
        v.push(r.feasible.to_string());
        v.push(tables::num(r.feasibility_tolerance));
        v.push(r.function_calls.to_string());
        v.push(r.gradient_calls.to_string());
        v.push(r.polish_calls.0.to_string());
        v.push(r.polish_calls.1.to_string());
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
