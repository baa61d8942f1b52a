//! Thread scaling of the multistart (`[scaling]` section): the same
//! multistart with each listed thread count, timed, into `scaling.csv`.
//!
//! Columns, per thread count `t` over `R` runs with `E` function calls:
//! - `wall_seconds` `W_t` of the whole multistart and `speedup` `W_1 / W_t`;
//! - `run_seconds` `Σ w_r`, the summed wall time of the runs themselves;
//! - `driver_overhead_per_run_s` `(t · W_t − Σ w_r) / R`: thread time per
//!   run spent outside the local solver (pool start-up, scheduling, CSV
//!   appends, clustering, final tables; for `t > 1` also the idle time of
//!   threads that ran out of starts while the last runs finish), and
//!   `driver_overhead_fraction`, the same divided by the mean run time
//!   `Σ w_r / R`;
//! - with `cost_ms > 0`, `solver_overhead_fraction`
//!   `(Σ w_r − E · cost) / (E · cost)`: time inside the runs that is not
//!   evaluation.
//!
//! Wall times depend on the machine and its load (recorded as
//! `load_average_1min`); the tables of the runs do not (the `runs.csv` of each thread count are identical up to wall times).

use super::command::run_multistart;
use crate::error::{Error, Result};
use crate::explore::context::{Context, DriveFlags};
use serde::Deserialize;

/// The `[scaling]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalingSection {
    /// Thread counts to time (each >= 1), e.g. `[1, 2]`.
    pub threads: Vec<usize>,
}

/// One row of `scaling.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalingRow {
    /// Thread count.
    pub threads: usize,
    /// Runs.
    pub runs: usize,
    /// Function calls.
    pub function_calls: usize,
    /// Multistart wall time \[s\].
    pub wall_seconds: f64,
    /// Summed run wall time \[s\].
    pub run_seconds: f64,
    /// 1-minute load average of the machine after the run (Linux
    /// `/proc/loadavg`; empty elsewhere): other processes distort timings.
    pub load_average: Option<f64>,
}

/// Run `[scaling]`: the study's multistart once per thread count, each in
/// `out/<study>/threads-<t>/`, and `scaling.csv` in `out/<study>/`.
pub fn run_scaling(ctx: &Context) -> Result<Vec<ScalingRow>> {
    let sec = check(ctx.study)?;
    if sec.threads.is_empty() || sec.threads.contains(&0) {
        return Err(ctx.study.error(
            "scaling.threads",
            format!("{:?}", sec.threads),
            "a non-empty list of thread counts >= 1",
        ));
    }
    let spec: crate::explore::problem::problems::ProblemSpec =
        ctx.study.require_section("problem", "name = ...")?;
    let cost = spec.cost_ms * 1e-3;
    let base = ctx.study.output_dir(ctx.out)?;
    let mut rows = Vec::new();
    for &t in &sec.threads {
        let root = base.join(format!("threads-{t}"));
        std::fs::create_dir_all(&root).map_err(|e| Error::io(&root, e))?;
        let sub = Context {
            study: ctx.study,
            out: &root,
            threads: t,
            quiet: ctx.quiet,
            flags: DriveFlags::default(),
        };
        let r = run_multistart(&sub)?;
        rows.push(ScalingRow {
            threads: t,
            runs: r.runs.len(),
            function_calls: r.function_calls,
            wall_seconds: r.wall_seconds,
            run_seconds: r.runs.iter().map(|x| x.wall_seconds).sum(),
            load_average: crate::report::clock::load_average(),
        });
    }
    let w1 = rows.iter().find(|r| r.threads == 1).map(|r| r.wall_seconds);
    let mut table = vec![[
        "threads",
        "runs",
        "function_calls",
        "wall_seconds",
        "speedup",
        "run_seconds",
        "driver_overhead_per_run_s",
        "driver_overhead_fraction",
        "solver_overhead_fraction",
        "load_average_1min",
    ]
    .map(String::from)
    .to_vec()];
    for r in &rows {
        let n = r.runs.max(1) as f64;
        let overhead = (r.threads as f64 * r.wall_seconds - r.run_seconds) / n;
        let eval = r.function_calls as f64 * cost;
        table.push(vec![
            r.threads.to_string(),
            r.runs.to_string(),
            r.function_calls.to_string(),
            format!("{:.4}", r.wall_seconds),
            w1.map(|w| format!("{:.3}", w / r.wall_seconds))
                .unwrap_or_default(),
            format!("{:.4}", r.run_seconds),
            format!("{overhead:.3e}"),
            format!("{:.3e}", overhead / (r.run_seconds / n)),
            if cost > 0.0 {
                format!("{:.3e}", (r.run_seconds - eval) / eval)
            } else {
                String::new()
            },
            r.load_average
                .map(|l| format!("{l:.2}"))
                .unwrap_or_default(),
        ]);
    }
    crate::explore::persist::tables::write_atomic(&base.join("scaling.csv"), &table)?;
    if !ctx.quiet {
        for l in &table {
            println!("{}", l.join("  "));
        }
    }
    Ok(rows)
}

/// Read `[scaling]` (no work; `plyscape run` checks every section first).
pub fn check(study: &crate::study::Study) -> Result<ScalingSection> {
    study.require_section("scaling", "threads = [1, 2]")
}
