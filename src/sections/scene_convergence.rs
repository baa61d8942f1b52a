//! What accuracy costs in a flexible scene: `[scene_convergence]` runs a
//! scene study over a grid of panel mesh densities × numbers of modes and
//! writes, per variant, the responses (`[[scene.responses]]`), their
//! relative error against the finest variant, and the time spent building
//! the modal bases and integrating (median of `repeats`).
//!
//! ```toml
//! [scene_convergence]
//! scene = "main.toml"        # a study with [scene], [[panels]], [[scene.responses]]
//! divisions = [16, 24, 32]   # set on every [[panels]] entry
//! modes = [6, 10, 14]        # set on every flexible body
//! repeats = 3
//! ```
//! The scene runs without its sensitivities (and its bases without
//! design derivatives): the table is about the values. The finest variant
//! (largest divisions, then most modes) is the reference; the errors are
//! therefore self-convergence, which the mesh study of the panel modes
//! (`panel_convergence.toml`) complements with the frequencies.

use super::stats::median;
use crate::error::{Error, Result};
use crate::report::csv::Table;
use crate::scene::load_scene;
use crate::simulate::simulate;
use crate::study::Study;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The `[scene_convergence]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceSpec {
    /// Scene study, relative to this study's folder.
    pub scene: PathBuf,
    /// Panel mesh densities (cells along the length, each ≥ 1), set on
    /// every `[[panels]]` entry.
    pub divisions: Vec<usize>,
    /// Numbers of modes (each ≥ 1), set on every flexible body.
    pub modes: Vec<usize>,
    /// Timed runs per variant; the median is reported (default 1, ≥ 1).
    #[serde(default = "one")]
    pub repeats: usize,
}

fn one() -> usize {
    1
}

/// One variant's results.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Panel mesh density of the variant (cells along the length).
    pub divisions: usize,
    /// Modes per flexible body of the variant.
    pub modes: usize,
    /// Building the scene (modal bases included), median (ms).
    pub build_ms: f64,
    /// Integration (diffsol wall time), median (ms).
    pub integrate_ms: f64,
    /// f64 right-hand-side evaluations of the (last) integration.
    pub rhs_calls: usize,
    /// Accepted integration steps of the (last) integration.
    pub steps: usize,
    /// `(name, value)` of each response.
    pub responses: Vec<(String, f64)>,
    /// SI unit of each response (`J*s`, `J`), in the same order.
    pub units: Vec<String>,
}

/// The scene study with `divisions` on every panel, `modes` on every
/// flexible body, and no sensitivities or design derivatives.
fn variant(base: &Study, divisions: usize, modes: usize) -> Study {
    let mut s = base.clone();
    if let Some(toml::Value::Array(panels)) = s.table.get_mut("panels") {
        for p in panels.iter_mut() {
            if let toml::Value::Table(t) = p {
                t.insert("divisions".into(), toml::Value::Integer(divisions as i64));
            }
        }
    }
    if let Some(toml::Value::Table(scene)) = s.table.get_mut("scene") {
        scene.remove("sensitivities");
        if let Some(toml::Value::Array(bodies)) = scene.get_mut("bodies") {
            for b in bodies.iter_mut() {
                if let Some(toml::Value::Table(f)) = b.get_mut("flexible") {
                    f.insert("modes".into(), toml::Value::Integer(modes as i64));
                    f.remove("derivatives");
                }
            }
        }
    }
    s
}

/// Run the grid (coarse to fine, in the order given).
pub fn run_grid(
    study: &Study,
    spec: &ConvergenceSpec,
    mut report: impl FnMut(&Variant),
) -> Result<Vec<Variant>> {
    let key = |k: &str| format!("scene_convergence.{k}");
    if spec.divisions.is_empty() || spec.divisions.contains(&0) {
        return Err(study.error(
            key("divisions"),
            format!("{:?}", spec.divisions),
            "mesh divisions ≥ 1",
        ));
    }
    if spec.modes.is_empty() || spec.modes.contains(&0) {
        return Err(study.error(
            key("modes"),
            format!("{:?}", spec.modes),
            "numbers of modes ≥ 1",
        ));
    }
    if spec.repeats == 0 {
        return Err(study.error(key("repeats"), 0, "at least 1"));
    }
    let path = study
        .path
        .parent()
        .unwrap_or(Path::new("."))
        .join(&spec.scene);
    let base = Study::load(&path).map_err(|e| e.in_file(&study.path, &key("scene")))?;
    if !base.has("panels") {
        return Err(study.error(
            key("scene"),
            path.display(),
            "a scene study with [[panels]]",
        ));
    }
    let mut out = Vec::new();
    for &d in &spec.divisions {
        for &n in &spec.modes {
            let st = variant(&base, d, n);
            let (mut build, mut integ) = (Vec::new(), Vec::new());
            let mut last = None;
            for _ in 0..spec.repeats {
                let t0 = Instant::now();
                let scene = load_scene(&st)?;
                build.push(t0.elapsed().as_secs_f64() * 1e3);
                let (_, sim) = simulate(&scene).map_err(|e| {
                    e.at_place(&format!("scene_convergence ({d} divisions, {n} modes)"))
                })?;
                integ.push(sim.stats.wall * 1e3);
                last = Some(sim);
            }
            let sim = last.expect("repeats ≥ 1");
            if sim.responses.is_empty() {
                return Err(study.error(
                    key("scene"),
                    path.display(),
                    "a scene with [[scene.responses]]",
                ));
            }
            let v = Variant {
                divisions: d,
                modes: n,
                build_ms: median(build),
                integrate_ms: median(integ),
                rhs_calls: sim.stats.rhs_calls as usize,
                steps: sim.stats.steps,
                responses: sim
                    .responses
                    .iter()
                    .map(|r| (r.name.clone(), r.value))
                    .collect(),
                units: sim.responses.iter().map(|r| r.unit.clone()).collect(),
            };
            report(&v);
            out.push(v);
        }
    }
    Ok(out)
}

/// The finest variant: most divisions, then most modes.
pub fn reference(rows: &[Variant]) -> Option<&Variant> {
    rows.iter().max_by_key(|v| (v.divisions, v.modes))
}

/// Write `scene_convergence.csv` into `dir`.
pub fn write_csv(rows: &[Variant], dir: &Path) -> Result<PathBuf> {
    let path = dir.join("scene_convergence.csv");
    let reference =
        reference(rows).ok_or_else(|| Error::numerical("scene_convergence", "no variants"))?;
    let mut w = Table::new(&path);
    let mut head: Vec<String> = [
        "divisions",
        "modes",
        "build_ms",
        "integrate_ms",
        "rhs_calls",
        "steps",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for ((name, _), unit) in reference.responses.iter().zip(&reference.units) {
        head.push(format!("{name} [{unit}]"));
        head.push(format!("{name}_rel_error"));
    }
    w.row(&head)?;
    for v in rows {
        let mut rec = vec![
            v.divisions.to_string(),
            v.modes.to_string(),
            format!("{:.3}", v.build_ms),
            format!("{:.3}", v.integrate_ms),
            v.rhs_calls.to_string(),
            v.steps.to_string(),
        ];
        for ((_, value), (_, r)) in v.responses.iter().zip(&reference.responses) {
            rec.push(format!("{value:.10e}"));
            rec.push(format!("{:.3e}", (value - r).abs() / r.abs().max(1e-300)));
        }
        w.row(&rec)?;
    }
    w.finish()?;
    Ok(path)
}

/// Read `[scene_convergence]` without running anything.
pub fn check(study: &Study) -> Result<ConvergenceSpec> {
    study.require_section("scene_convergence", "the flexible-scene accuracy/cost grid")
}

/// The `[scene_convergence]` handler.
pub fn run_scene_convergence(study: &Study, out: &Path, quiet: bool) -> Result<PathBuf> {
    let spec = check(study)?;
    let rows = run_grid(study, &spec, |v| {
        if !quiet {
            let r: Vec<String> = v
                .responses
                .iter()
                .map(|(n, x)| format!("{n} {x:.6e}"))
                .collect();
            println!(
                "{:>3} divisions {:>3} modes: build {:8.1} ms, integrate {:8.1} ms, {:>6} rhs; {}",
                v.divisions,
                v.modes,
                v.build_ms,
                v.integrate_ms,
                v.rhs_calls,
                r.join(", ")
            );
        }
    })?;
    let dir = study.output_dir(out)?;
    let path = write_csv(&rows, &dir)?;
    if !quiet {
        println!("wrote {}", path.display());
    }
    Ok(path)
}
