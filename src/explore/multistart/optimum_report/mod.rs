//! `[optimum_report]`: the multistart's run from its first start (the
//! paper's start when it is listed first in `[multistart] points`)
//! reported the way the paper reports its MMFD run (Neto, Ambrósio, Leal
//! §6.3, Table 5, Figs. 10–14):
//! - `iterations.csv`, with `iterations.svg` (f per iteration, Fig. 10),
//!   `iterations_constraints.svg` (every g_j and the solver's CT) and
//!   `iterations_design.svg` (the design, Fig. 11): one row per record of
//!   the run ([`history`]);
//! - `optimum_summary.csv`: one row like Table 5 ([`summary`]);
//! - per listed scene output `q`, `start_optimum_<q>.csv` and `.svg`: `q(t)`
//!   simulated at the start and at the optimum (Fig. 12 for `R3.angle`,
//!   Figs. 13–14 for the panels' strain energies; [`curves`]).
//!
//! ```toml
//! [optimum_report]
//! quantities = ["R3.angle", "B2.strain_energy", "B3.strain_energy"]  # scene problems only
//! ```
//!
//! The history is recorded while the multistart runs that start (a
//! [`TimedHistory`] observer on the solver), so its last row's calls and f
//! are the ones in `runs.csv`: nothing is optimized twice. The outputs at
//! the start are simulated before the multistart (so a bad output name is
//! refused before the long part), those at the optimum after it.
//!
//! Not written by a sharded multistart (`--shard`), nor when the first
//! start was read back from `runs.csv` (`--resume`) instead of run: a note
//! on stderr says so.

pub mod curves;
pub mod history;
pub mod labels;
pub mod summary;

pub use labels::Labels;

use super::section::MultistartPlan;
use crate::error::{Error, Result};
use crate::explore::context::Context;
use crate::explore::persist::manifest::OptimumReportEntry;
use crate::explore::problem::problems::ProblemSpec;
use crate::explore::problem::scene_problem::SceneProblem;
use crate::optimize::{Problem, TimedHistory};
use crate::simulate::Simulation;
use crate::study::Study;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The section's name in study files.
pub const KEY: &str = "optimum_report";

/// The reported start: the first of `[multistart]` (listed points first).
pub const REPORTED_START: usize = 0;

/// The `[optimum_report]` section.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OptimumReportSection {
    /// One-column scene outputs (names as in `[scene.outputs]`) simulated
    /// at the start and at the optimum; scene problems only.
    #[serde(default)]
    pub quantities: Vec<String>,
}

/// Is the study's `[problem]` the scene problem?
fn is_scene(study: &Study) -> Result<bool> {
    Ok(study
        .section::<ProblemSpec>("problem")?
        .is_some_and(|p| p.name == "scene"))
}

/// Read and check `[optimum_report]` (no computation): the study has a
/// `[multistart]`, and quantities are one-column output names, each once,
/// of a scene problem. Output names are resolved when the start is
/// simulated, before the multistart.
pub fn check(study: &Study) -> Result<OptimumReportSection> {
    let sec: OptimumReportSection = study.section(KEY)?.unwrap_or_default();
    if !study.has("multistart") {
        return Err(study.error(
            KEY,
            "(table)",
            "a study with [multistart]: the report is of the multistart's run from its first start",
        ));
    }
    if !sec.quantities.is_empty() && !is_scene(study)? {
        return Err(study.error(
            format!("{KEY}.quantities"),
            format!("{:?}", sec.quantities),
            "no quantities: outputs are simulated only for [problem] name = \"scene\"",
        ));
    }
    for (k, q) in sec.quantities.iter().enumerate() {
        let key = format!("{KEY}.quantities[{k}]");
        if !crate::scene::quantity::scalar_output(q) {
            return Err(study.error(
                key,
                q,
                "a one-column scene output: <joint>.angle|rate|displacement|velocity, \
                 <body>.strain_energy|kinetic_energy, kinetic_energy, energy or violation",
            ));
        }
        if sec.quantities[..k].contains(q) {
            return Err(study.error(key, q, "each output once"));
        }
    }
    Ok(sec)
}

/// An error of the scene's output names raised while building with the
/// report's quantities, moved onto `[optimum_report] quantities`.
fn quantity_error(study: &Study, e: Error) -> Error {
    match e {
        Error::Input {
            key,
            value,
            expected,
            ..
        } if key.starts_with("scene.outputs.quantities") => study.error(
            key.replacen("scene.outputs.", &format!("{KEY}."), 1),
            value,
            expected,
        ),
        other => other,
    }
}

/// What the report keeps from before the multistart.
pub struct Prepared {
    section: OptimumReportSection,
    labels: Labels,
    /// The scene problem and its outputs at the start (with quantities).
    scene: Option<(SceneProblem, Simulation)>,
}

/// Print a note on stderr unless quiet.
fn note(ctx: &Context, text: &str) {
    if !ctx.quiet {
        eprintln!("note: [{KEY}]: {text}");
    }
}

/// Before the multistart: read the section (None without one, or for a
/// shard), label the problem and simulate the outputs at the start.
pub fn prepare(
    ctx: &Context,
    problem: &dyn Problem,
    plan: &MultistartPlan,
) -> Result<Option<Prepared>> {
    if !ctx.study.has(KEY) {
        return Ok(None);
    }
    let section = check(ctx.study)?;
    if ctx.flags.shard.count > 1 {
        note(ctx, "not written by a shard (run the multistart unsharded)");
        return Ok(None);
    }
    let Some(x0) = plan.starts.points.get(REPORTED_START) else {
        note(ctx, "the multistart has no start");
        return Ok(None);
    };
    let (labels, scene) = if is_scene(ctx.study)? {
        let p = SceneProblem::from_study(ctx.study)?;
        let labels = Labels::scene(&p);
        let scene = if section.quantities.is_empty() {
            None
        } else {
            let sim = p
                .simulate_outputs(x0, &section.quantities)
                .map_err(|e| quantity_error(ctx.study, e))?;
            Some((p, sim))
        };
        (labels, scene)
    } else {
        (Labels::plain(problem.n_constraints()), None)
    };
    Ok(Some(Prepared {
        section,
        labels,
        scene,
    }))
}

impl Prepared {
    /// After the multistart: write the report's files into `dir` from the
    /// reported run's row and history; returns the files written.
    pub fn finish(
        self,
        ctx: &Context,
        dir: &Path,
        problem: &dyn Problem,
        plan: &MultistartPlan,
        report: &crate::explore::multistart::driver::Report,
    ) -> Result<Vec<PathBuf>> {
        let t0 = std::time::Instant::now();
        let run = report.runs.iter().find(|r| r.start == REPORTED_START);
        let (Some(history), Some(run)) = (&report.history, run) else {
            note(
                ctx,
                "the first start was not run by this invocation (read back from runs.csv); \
                 run the multistart without --resume to write the report",
            );
            return Ok(vec![]);
        };
        let mut files = history::write(dir, problem, &self.labels, &history.records)?;
        let facts = summary::Facts {
            method: plan.section.method.name(),
            f_start: history.records.first().map(|(r, _)| r.f),
            tolerance: plan.tolerances.feasibility,
            threads: ctx.threads,
            load: crate::report::clock::load_average(),
        };
        files.push(summary::write(dir, problem, &self.labels, run, &facts)?);
        if let (Some((p, at_start)), Some(res)) = (&self.scene, &run.result) {
            let at_optimum = p.simulate_outputs(&res.x, &self.section.quantities)?;
            let start = curves::Design {
                x: &run.x0,
                sim: at_start,
            };
            let optimum = curves::Design {
                x: &res.x,
                sim: &at_optimum,
            };
            files.extend(curves::write(
                dir,
                &self.section.quantities,
                &self.labels.x_unit,
                &start,
                &optimum,
            )?);
        }
        let names: Vec<String> = files
            .iter()
            .filter_map(|f| f.file_name()?.to_str().map(String::from))
            .collect();
        let entry = OptimumReportEntry {
            start: REPORTED_START,
            files: names.clone(),
            wall_seconds: t0.elapsed().as_secs_f64(),
        };
        ctx.manifest(dir, KEY, entry)?;
        if !ctx.quiet {
            print_summary(&history_rows_note(history), &names);
        }
        Ok(files)
    }
}

/// One line on the reported run's history.
fn history_rows_note(h: &TimedHistory) -> String {
    match h.records.last() {
        Some((r, t)) => format!(
            "start {REPORTED_START}: {} records, f {} -> {:.6e}, {} function + {} gradient calls, {t:.3} s",
            h.records.len(),
            h.records[0].0.f,
            r.f,
            r.function_calls,
            r.gradient_calls
        ),
        None => format!("start {REPORTED_START}: no records"),
    }
}

fn print_summary(line: &str, files: &[String]) {
    println!("optimum report, {line}; wrote {}", files.join(", "));
}
