//! Does a panel reference condition change a flexible scene's answer or
//! its cost? `[support_compare]` runs one scene study with every
//! `[[panels]]` entry set to each support of a list and with each
//! integrator of a list, and writes per run the cost (integration wall
//! time, RHS calls, steps), the final joint angle and the responses, each
//! against the first support with the same integrator (the reference), and
//! whether the run is within the section's limits.
//!
//! ```toml
//! [support_compare]
//! scene = "sar_phase1_flexible.toml" # optional: default this study's [scene]
//! supports = ["free_free", "centre_clamp"] # the first is the reference
//! methods = ["bdf", "tsit45"]        # [scene.integrator] method per run
//! angle = "R3.angle"                 # output whose final value is compared
//! repeats = 3                        # median wall time of this many runs
//! divisions = 16                     # optional: set on every [[panels]]
//! modes = 14                         # optional: set on every flexible body
//! max_time_ratio = 3.0               # limits of the `within_limits` column
//! max_angle_diff = 1e-4              # [rad]
//! max_response_rel = 0.02
//! ```
//! The scene runs without its sensitivities (and its bases without
//! derivatives). Ratios and differences are against the reference support
//! with the same method: `time_ratio = wall / wall_ref`, `angle_diff =
//! |θ(t_end) − θ_ref(t_end)|` \[rad\], `<response>_rel = |ψ − ψ_ref| / |ψ_ref|`.
//! The modal bases drop modes that are almost rigid motions of the frame
//! ([`crate::panels::basis`]); the `dropped` column lists them per body.

use super::stats::median;
use crate::error::{Error, Result};
use crate::report::csv::Table;
use crate::scene::load_scene;
use crate::simulate::simulate;
use crate::study::Study;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The `[support_compare]` section (module doc).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompareSpec {
    /// Scene study, relative to this study's folder (default: this study).
    pub scene: Option<PathBuf>,
    /// Panel supports to run, set on every `[[panels]]` entry
    /// (`centre_clamp`, `central_patch`, `simply_supported`, `free_free`);
    /// the first is the reference. At least one.
    pub supports: Vec<String>,
    /// Integrators to run, set as `[scene.integrator] method` (`bdf`,
    /// `tsit45`, `esdirk34`). At least one.
    pub methods: Vec<String>,
    /// Scene output whose final value is compared, e.g. `R3.angle`.
    pub angle: String,
    /// Timed runs per support and method; the median wall time is reported
    /// (default 1, ≥ 1).
    #[serde(default = "one")]
    pub repeats: usize,
    /// Mesh density set on every `[[panels]]` entry (default: the scene's).
    pub divisions: Option<usize>,
    /// Modes set on every flexible body (default: the scene's).
    pub modes: Option<usize>,
    /// Largest accepted `time_ratio` for `within_limits` (default 3).
    #[serde(default = "three")]
    pub max_time_ratio: f64,
    /// Largest accepted `angle_diff` for `within_limits` \[rad\] (default 1e-4).
    #[serde(default = "angle_limit")]
    pub max_angle_diff: f64,
    /// Largest accepted relative response difference for `within_limits`
    /// (default 0.02).
    #[serde(default = "response_limit")]
    pub max_response_rel: f64,
}

fn one() -> usize {
    1
}
fn three() -> f64 {
    3.0
}
fn angle_limit() -> f64 {
    1e-4
}
fn response_limit() -> f64 {
    0.02
}

/// One run: a support and an integrator.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Panel support of the run.
    pub support: String,
    /// Integrator of the run.
    pub method: String,
    /// Modes kept per flexible body, `B2:11 B3:11`.
    pub modes: String,
    /// Dropped modes per flexible body, `B2:1,3,7` (empty if none).
    pub dropped: String,
    /// Building the scene (modal bases included), median \[ms\].
    pub build_ms: f64,
    /// Integration wall time, median \[ms\].
    pub integrate_ms: f64,
    /// f64 right-hand-side evaluations of the (last) integration.
    pub rhs_calls: usize,
    /// Accepted integration steps of the (last) integration.
    pub steps: usize,
    /// Final value of the compared output \[rad\].
    pub angle_end: f64,
    /// `(name, value)` of each response.
    pub responses: Vec<(String, f64)>,
}

/// The scene study with `support` on every panel, `method` as integrator,
/// the optional mesh and mode overrides, and no sensitivities.
fn variant(base: &Study, spec: &CompareSpec, support: &str, method: &str) -> Study {
    use toml::Value;
    let mut s = base.clone();
    if let Some(Value::Array(panels)) = s.table.get_mut("panels") {
        for p in panels.iter_mut() {
            if let Value::Table(t) = p {
                t.insert("support".into(), Value::String(support.into()));
                if let Some(d) = spec.divisions {
                    t.insert("divisions".into(), Value::Integer(d as i64));
                }
            }
        }
    }
    if let Some(Value::Table(scene)) = s.table.get_mut("scene") {
        scene.remove("sensitivities");
        if let Some(Value::Table(i)) = scene.get_mut("integrator") {
            i.insert("method".into(), Value::String(method.into()));
        }
        if let Some(Value::Array(bodies)) = scene.get_mut("bodies") {
            for b in bodies.iter_mut() {
                if let Some(Value::Table(f)) = b.get_mut("flexible") {
                    f.remove("derivatives");
                    if let Some(n) = spec.modes {
                        f.insert("modes".into(), Value::Integer(n as i64));
                    }
                }
            }
        }
    }
    s
}

/// Check the spec; the scene study it names (or `study` itself).
fn scene_study(study: &Study, spec: &CompareSpec) -> Result<Study> {
    let key = |k: &str| format!("support_compare.{k}");
    if spec.supports.is_empty() {
        return Err(study.error(key("supports"), "[]", "at least one support"));
    }
    if spec.methods.is_empty() {
        return Err(study.error(key("methods"), "[]", "at least one integrator"));
    }
    if spec.repeats == 0 {
        return Err(study.error(key("repeats"), 0, "at least 1"));
    }
    let base = match &spec.scene {
        None => study.clone(),
        Some(p) => {
            let path = study.path.parent().unwrap_or(Path::new(".")).join(p);
            Study::load(&path).map_err(|e| e.in_file(&study.path, &key("scene")))?
        }
    };
    if !base.has("panels") || !base.has("scene") {
        return Err(study.error(
            key("scene"),
            base.path.display(),
            "a scene study with [scene] and [[panels]]",
        ));
    }
    Ok(base)
}

/// Run every support × method (methods outer, supports inner, in the
/// order given); `report` sees each run as it finishes.
pub fn run_compare(
    study: &Study,
    spec: &CompareSpec,
    mut report: impl FnMut(&Run),
) -> Result<Vec<Run>> {
    let base = scene_study(study, spec)?;
    let mut out = Vec::new();
    for method in &spec.methods {
        for support in &spec.supports {
            let st = variant(&base, spec, support, method);
            let place = format!("support_compare ({support}, {method})");
            let (mut build, mut integ) = (Vec::new(), Vec::new());
            let mut last = None;
            for _ in 0..spec.repeats {
                let t0 = Instant::now();
                let scene = load_scene(&st).map_err(|e| e.at_place(&place))?;
                build.push(t0.elapsed().as_secs_f64() * 1e3);
                let (_, sim) = simulate(&scene).map_err(|e| e.at_place(&place))?;
                integ.push(sim.stats.wall * 1e3);
                last = Some((scene, sim));
            }
            let (scene, sim) = last.expect("repeats ≥ 1");
            let col = sim
                .headers
                .iter()
                .position(|h| h.split(' ').next() == Some(spec.angle.as_str()))
                .ok_or_else(|| {
                    study.error(
                        "support_compare.angle",
                        format!("\"{}\"", spec.angle),
                        format!("an output of the scene: {}", sim.headers.join(", ")),
                    )
                })?;
            let angle_end = sim.rows.last().map_or(f64::NAN, |r| r[col]);
            let (mut modes, mut dropped) = (Vec::new(), Vec::new());
            for b in &scene.model.bodies {
                if let Some(f) = &b.flex {
                    modes.push(format!("{}:{}", b.name, f.basis.n_modes));
                    let d: Vec<String> = f
                        .basis
                        .rigid
                        .dropped
                        .iter()
                        .map(|d| d.mode.to_string())
                        .collect();
                    if !d.is_empty() {
                        dropped.push(format!("{}:{}", b.name, d.join("/")));
                    }
                }
            }
            let run = Run {
                support: support.clone(),
                method: method.clone(),
                modes: modes.join(" "),
                dropped: dropped.join(" "),
                build_ms: median(build),
                integrate_ms: median(integ),
                rhs_calls: sim.stats.rhs_calls as usize,
                steps: sim.stats.steps,
                angle_end,
                responses: sim
                    .responses
                    .iter()
                    .map(|r| (r.name.clone(), r.value))
                    .collect(),
            };
            report(&run);
            out.push(run);
        }
    }
    Ok(out)
}

/// A run's comparison with its reference (first support, same method):
/// time ratio, angle difference \[rad\], relative response differences,
/// and whether all are within the spec's limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Integration wall time over the reference's (median times).
    pub time_ratio: f64,
    /// `|θ(t_end) − θ_ref(t_end)|` of the compared output \[rad\].
    pub angle_diff: f64,
    /// `|ψ − ψ_ref| / |ψ_ref|` per response, in the run's order.
    pub response_rel: Vec<f64>,
    /// Whether all three are within the spec's limits.
    pub within_limits: bool,
}

/// Compare `run` with `reference` under `spec`'s limits.
pub fn compare(run: &Run, reference: &Run, spec: &CompareSpec) -> Comparison {
    let time_ratio = run.integrate_ms / reference.integrate_ms.max(1e-300);
    let angle_diff = (run.angle_end - reference.angle_end).abs();
    let response_rel: Vec<f64> = run
        .responses
        .iter()
        .zip(&reference.responses)
        .map(|((_, v), (_, r))| (v - r).abs() / r.abs().max(1e-300))
        .collect();
    let within_limits = time_ratio <= spec.max_time_ratio
        && angle_diff <= spec.max_angle_diff
        && response_rel.iter().all(|&e| e <= spec.max_response_rel);
    Comparison {
        time_ratio,
        angle_diff,
        response_rel,
        within_limits,
    }
}

/// The reference of `run`: the first support's run with the same method.
pub fn reference_of<'a>(runs: &'a [Run], run: &Run, spec: &CompareSpec) -> Option<&'a Run> {
    runs.iter()
        .find(|r| r.method == run.method && r.support == spec.supports[0])
}

/// Write `support_compare.csv` into `dir` (module doc for the columns).
pub fn write_csv(runs: &[Run], spec: &CompareSpec, dir: &Path) -> Result<PathBuf> {
    let path = dir.join("support_compare.csv");
    let first = runs
        .first()
        .ok_or_else(|| Error::numerical("support_compare", "no runs"))?;
    let mut head: Vec<String> = [
        "method",
        "support",
        "modes",
        "dropped",
        "build_ms",
        "integrate_ms",
        "time_ratio",
        "rhs_calls",
        "steps",
        "angle_end_rad",
        "angle_diff_rad",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for (name, _) in &first.responses {
        head.push(name.clone());
        head.push(format!("{name}_rel"));
    }
    head.push("within_limits".into());
    let mut w = Table::new(&path);
    w.row(&head)?;
    for run in runs {
        let reference = reference_of(runs, run, spec).unwrap_or(run);
        let c = compare(run, reference, spec);
        let mut rec = vec![
            run.method.clone(),
            run.support.clone(),
            run.modes.clone(),
            run.dropped.clone(),
            format!("{:.3}", run.build_ms),
            format!("{:.3}", run.integrate_ms),
            format!("{:.3}", c.time_ratio),
            run.rhs_calls.to_string(),
            run.steps.to_string(),
            format!("{:.10}", run.angle_end),
            format!("{:.3e}", c.angle_diff),
        ];
        for ((_, v), e) in run.responses.iter().zip(&c.response_rel) {
            rec.push(format!("{v:.6e}"));
            rec.push(format!("{e:.3e}"));
        }
        rec.push(c.within_limits.to_string());
        w.row(&rec)?;
    }
    w.finish()?;
    Ok(path)
}

/// Read `[support_compare]` without running anything.
pub fn check(study: &Study) -> Result<CompareSpec> {
    study.require_section(
        "support_compare",
        "the panel reference-condition comparison of a flexible scene",
    )
}

/// The `[support_compare]` handler.
pub fn run_support_compare(study: &Study, out: &Path, quiet: bool) -> Result<PathBuf> {
    let spec = check(study)?;
    let runs = run_compare(study, &spec, |r| {
        if !quiet {
            let resp: Vec<String> = r
                .responses
                .iter()
                .map(|(n, x)| format!("{n} {x:.6e}"))
                .collect();
            println!(
                "{:>7} {:>13}: integrate {:9.1} ms, {:>6} rhs, {:>5} steps, angle {:.9}; {} [{}]",
                r.method,
                r.support,
                r.integrate_ms,
                r.rhs_calls,
                r.steps,
                r.angle_end,
                resp.join(", "),
                if r.dropped.is_empty() {
                    "no modes dropped".to_string()
                } else {
                    format!("dropped {}", r.dropped)
                }
            );
        }
    })?;
    let dir = study.output_dir(out)?;
    let path = write_csv(&runs, &spec, &dir)?;
    if !quiet {
        println!("wrote {}", path.display());
    }
    Ok(path)
}
