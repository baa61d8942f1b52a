//! `[kernel_bench]`: cost and accuracy of the rigid multibody kernel over
//! scenes × methods × tolerances, with and without forward sensitivities.
//!
//! ## Method
//! Every case is a full [`simulate`] of the scene with the method and
//! relative tolerance replaced (the absolute tolerance is scaled with the
//! relative one, keeping the scene's ratio `atol/rtol`; sensitivities in
//! the default form of the method, fused for tsit45), repeated
//! `repeats` times; the wall time reported is the median of the
//! integrator's own clock ([`crate::integrate::Stats::wall`]: problem
//! set-up and stepping, output evaluation excluded). Cases run one after
//! another on one thread so that timings do not disturb each other.
//! Besides the per-call cost seen by the integrator (`wall / rhs_calls`,
//! which also carries the solver's linear algebra and, with sensitivities,
//! the sensitivity products), the bare kernel is timed in isolation: one
//! f64 right-hand side and one dual-number (Jacobian-vector product)
//! evaluation at the consistent initial state (fastest of 7 batches of
//! about 3 ms each, see [`time_rhs`]). `rhs_calls·rhs_us + jvp_calls·jvp_us` against the
//! wall time (`kernel_share`) then says whether the kernel or the
//! integrator (Jacobian assembly is counted as kernel: its columns are
//! dual-number products; the rest is LU, step control, interpolation)
//! dominates. A case whose integration fails numerically is a result, not
//! an abort: its row carries `status = failed: <message>` and empty
//! measured columns.
//!
//! Output: `kernel_bench.csv` in the study's output folder, one row per
//! case (columns in [`HEADERS`]).

use crate::error::{Error, Result};
use crate::integrate::{Method, SensitivityForm};
use crate::mbs::{System, Workspace};
use crate::report::csv::Table;
use crate::scene::{load_scene, Scene};
use crate::simulate::simulate;
use crate::study::Study;
use num_dual::Dual64;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The `[kernel_bench]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchSpec {
    /// Scene study files (paths relative to the bench study's folder).
    pub scenes: Vec<PathBuf>,
    /// Integration methods.
    pub methods: Vec<Method>,
    /// Relative tolerances (0 < rtol < 1).
    pub rtols: Vec<f64>,
    /// Timed repetitions of each case (≥ 1); the median is reported.
    pub repeats: usize,
    /// Also run each scene that lists `sensitivities` with them (default
    /// true); every scene always runs without.
    #[serde(default = "yes")]
    pub sensitivities: bool,
    /// Integrate at most this many of a scene's sensitivity parameters
    /// (its first ones in `scene.sensitivities`); default: all.
    #[serde(default)]
    pub max_sensitivities: Option<usize>,
}

fn yes() -> bool {
    true
}

/// Column headers of `kernel_bench.csv` (SI units / as named). The
/// measured columns are empty when the case failed (`status` says why).
pub const HEADERS: [&str; 17] = [
    "scene",
    "method",
    "rtol",
    "n_sens",
    "status",
    "wall_ms",
    "rhs_calls",
    "jvp_calls",
    "us_per_rhs",
    "steps",
    "jacobians",
    "rhs_us",
    "jvp_us",
    "kernel_share",
    "max_violation",
    "first_output",
    "first_output_final",
];

/// What identifies a case, and the bare kernel timings of its scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Name of the scene study.
    pub scene: String,
    /// Integrator of the case.
    pub method: Method,
    /// Relative tolerance of the case (`atol` scaled with it, keeping the
    /// scene's `atol / rtol`).
    pub rtol: f64,
    /// Number of sensitivity parameters integrated.
    pub n_sens: usize,
    /// One f64 right-hand side in isolation (µs).
    pub rhs_us: f64,
    /// One dual-number right-hand side in isolation (µs).
    pub jvp_us: f64,
}

impl Case {
    fn with(self, outcome: std::result::Result<Measured, String>) -> BenchRow {
        BenchRow {
            case: self,
            outcome,
        }
    }
}

/// Measurements of one successful case.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Median integration wall time over the repeats (ms).
    pub wall_ms: f64,
    /// f64 right-hand-side evaluations by the integrator.
    pub rhs_calls: u64,
    /// Dual-number evaluations (Jacobian-vector and sensitivity products).
    pub jvp_calls: u64,
    /// Accepted integration steps.
    pub steps: usize,
    /// Jacobian / LU set-ups.
    pub jacobians: usize,
    /// Largest `|Φ|` over the output times.
    pub max_violation: f64,
    /// Header of the first output column.
    pub first_output: String,
    /// Its value at the end time.
    pub first_output_final: f64,
}

/// One row of the table: the case and its measurements or failure message.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchRow {
    /// The case that was run.
    pub case: Case,
    /// Its measurements, or the error message of the failed run.
    pub outcome: std::result::Result<Measured, String>,
}

impl BenchRow {
    /// `wall / rhs_calls` (µs): the cost per f64 right-hand side seen by
    /// the integrator (linear algebra and dual products included).
    pub fn us_per_rhs(&self) -> Option<f64> {
        let m = self.outcome.as_ref().ok()?;
        Some(m.wall_ms * 1e3 / m.rhs_calls.max(1) as f64)
    }

    /// Share of the wall time spent in the kernel, estimated from the
    /// bare timings: `(rhs_calls·rhs_us + jvp_calls·jvp_us) / wall`.
    pub fn kernel_share(&self) -> Option<f64> {
        let m = self.outcome.as_ref().ok()?;
        let c = &self.case;
        Some((m.rhs_calls as f64 * c.rhs_us + m.jvp_calls as f64 * c.jvp_us) / (m.wall_ms * 1e3))
    }

    fn record(&self) -> Vec<String> {
        let c = &self.case;
        let mut r = vec![
            c.scene.clone(),
            c.method.name().to_string(),
            format!("{:e}", c.rtol),
            c.n_sens.to_string(),
        ];
        let (status, measured) = match &self.outcome {
            Ok(m) => ("ok".to_string(), Some(m)),
            Err(e) => (format!("failed: {e}"), None),
        };
        r.push(status);
        let opt = |v: Option<String>| v.unwrap_or_default();
        r.push(opt(measured.map(|m| format!("{:.4}", m.wall_ms))));
        r.push(opt(measured.map(|m| m.rhs_calls.to_string())));
        r.push(opt(measured.map(|m| m.jvp_calls.to_string())));
        r.push(opt(self.us_per_rhs().map(|v| format!("{v:.3}"))));
        r.push(opt(measured.map(|m| m.steps.to_string())));
        r.push(opt(measured.map(|m| m.jacobians.to_string())));
        r.push(format!("{:.3}", c.rhs_us));
        r.push(format!("{:.3}", c.jvp_us));
        r.push(opt(self.kernel_share().map(|v| format!("{v:.3}"))));
        r.push(opt(measured.map(|m| format!("{:.3e}", m.max_violation))));
        r.push(opt(measured.map(|m| m.first_output.clone())));
        r.push(opt(
            measured.map(|m| format!("{:.12e}", m.first_output_final))
        ));
        r
    }

    /// One line for the terminal.
    pub fn line(&self) -> String {
        let c = &self.case;
        let head = format!(
            "{:<17} {:<6} rtol {:<5e} sens {}",
            c.scene,
            c.method.name(),
            c.rtol,
            c.n_sens
        );
        match &self.outcome {
            Ok(m) => format!(
                "{head}: {:>8.3} ms, {:>6} rhs, {:>5} jvp, {:>6.1} µs/rhs (bare {:.1}/{:.1} µs, kernel {:>3.0}%), viol {:.1e}, {} = {:.9}",
                m.wall_ms,
                m.rhs_calls,
                m.jvp_calls,
                self.us_per_rhs().unwrap_or(0.0),
                c.rhs_us,
                c.jvp_us,
                100.0 * self.kernel_share().unwrap_or(0.0),
                m.max_violation,
                m.first_output,
                m.first_output_final
            ),
            Err(e) => format!("{head}: FAILED ({e})"),
        }
    }
}

/// Simulate `scene` `repeats` times; the median wall time and the last
/// run's counts and outputs.
fn measure(scene: &Scene, repeats: usize) -> Result<Measured> {
    let mut walls = Vec::with_capacity(repeats);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let (_, sim) = simulate(scene)?;
        walls.push(sim.stats.wall);
        last = Some(sim);
    }
    let Some(sim) = last else {
        return Err(Error::numerical("kernel_bench", "no repeat ran"));
    };
    walls.sort_by(f64::total_cmp);
    let s = &sim.stats;
    let (first_output, first_output_final) = match (sim.headers.get(1), sim.rows.last()) {
        (Some(h), Some(r)) => (h.clone(), r[1]),
        _ => ("none".to_string(), 0.0),
    };
    Ok(Measured {
        wall_ms: walls[walls.len() / 2] * 1e3,
        rhs_calls: s.rhs_calls,
        jvp_calls: s.jvp_calls,
        steps: s.steps,
        jacobians: s.jacobians,
        max_violation: sim.max_violation,
        first_output,
        first_output_final,
    })
}

/// Time (µs) of one f64 and one dual-number right-hand side of `sys` at
/// `(t, y)`: the fastest of 7 batches, each averaging the calls that fill
/// about 3 ms (at least 10). The minimum over batches is the estimator of
/// a kernel's own cost that other processes on a shared machine disturb
/// least (they only ever add time).
pub fn time_rhs(sys: &System, t: f64, y: &[f64]) -> (f64, f64) {
    let n = y.len();
    let mut ws = Workspace::<f64>::empty();
    let mut dy = vec![0.0; n];
    let budget = 0.003;
    let time = |f: &mut dyn FnMut()| {
        f();
        (0..7)
            .map(|_| {
                let start = Instant::now();
                let mut calls = 0u32;
                while calls < 10 || start.elapsed().as_secs_f64() < budget {
                    f();
                    calls += 1;
                }
                start.elapsed().as_secs_f64() / f64::from(calls) * 1e6
            })
            .fold(f64::INFINITY, f64::min)
    };
    let rhs_us = time(&mut || sys.rhs(t, y, &mut dy, &mut ws));
    let mut wsd = Workspace::<Dual64>::empty();
    // Direction: a unit vector spread over all states (a generic product).
    let scale = 1.0 / (n as f64).sqrt();
    let yd: Vec<Dual64> = y.iter().map(|&v| Dual64::new(v, scale)).collect();
    let mut dyd = vec![Dual64::from(0.0); n];
    let jvp_us = time(&mut || sys.rhs(t, &yd, &mut dyd, &mut wsd));
    (rhs_us, jvp_us)
}

/// Fastest of 7 batches of `f`, each averaging the calls that fill about
/// 3 ms (at least 10), in µs per call (as in [`time_rhs`]).
fn fastest_us(f: &mut dyn FnMut()) -> f64 {
    f();
    (0..7)
        .map(|_| {
            let start = Instant::now();
            let mut calls = 0u32;
            while calls < 10 || start.elapsed().as_secs_f64() < 0.003 {
                f();
                calls += 1;
            }
            start.elapsed().as_secs_f64() / f64::from(calls) * 1e6
        })
        .fold(f64::INFINITY, f64::min)
}

/// Names of the pieces timed by [`rhs_pieces`], in order.
pub const PIECES: [&str; 7] = [
    "rhs (whole)",
    "kinematics: bodies + markers",
    "  of which node shapes",
    "constraints: rows + Jacobian blocks",
    "applied: forces + flexible terms",
    "  of which flexible mass matrices + Cholesky",
    "solve: G M^-1 G^T, Cholesky, accelerations",
];

/// Cost (µs, `fastest_us`) of the pieces of one right-hand side of
/// `sys` at `(t, y)`, in the order of [`PIECES`], evaluated in the scalar
/// type of `y` (`f64` for a plain call, `Dual64` for a Jacobian-vector
/// product). Each piece runs on a workspace prepared by the pieces before
/// it, so the pieces (without the "of which" lines) add up to the whole.
/// "node shapes" is every node marker's `(Φ_k, Ψ_k)` rows once (the
/// kinematics, constraint and force pieces each fetch them).
pub fn rhs_pieces<T: crate::mbs::math::Scalar>(sys: &System, t: f64, y: &[T]) -> Vec<f64> {
    let mut ws = Workspace::<T>::empty();
    let mut dy = vec![T::zero(); y.len()];
    let whole = fastest_us(&mut || sys.rhs(t, y, &mut dy, &mut ws));
    let kin = fastest_us(&mut || sys.kinematics(y, &mut ws));
    let nodes: Vec<(usize, usize, usize)> = sys
        .model
        .markers
        .iter()
        .filter_map(|m| {
            let (b, node) = (m.body?, m.node?);
            Some((sys.slot[b]?, b, node))
        })
        .collect();
    let shapes = fastest_us(&mut || {
        for &(s, b, node) in &nodes {
            std::hint::black_box(sys.node_shapes(&ws.kin[s], b, node));
        }
    });
    let rows = fastest_us(&mut || sys.constraints(t, &mut ws));
    let applied = fastest_us(&mut || sys.applied(t, &mut ws));
    let mass = fastest_us(&mut || sys.mass_factors(&mut ws));
    sys.applied(t, &mut ws);
    let solve = fastest_us(&mut || {
        std::hint::black_box(sys.solve(&mut ws));
    });
    vec![whole, kin, shapes, rows, applied, mass, solve]
}

/// Run every case of the section; `progress` gets each finished row.
pub fn run_bench(
    study: &Study,
    spec: &BenchSpec,
    mut progress: impl FnMut(&BenchRow),
) -> Result<Vec<BenchRow>> {
    validate(study, spec)?;
    let base = study.path.parent().unwrap_or(Path::new("."));
    let mut rows = Vec::new();
    for (k, file) in spec.scenes.iter().enumerate() {
        let path = base.join(file);
        let scene_study = Study::load(&path)
            .map_err(|e| e.in_file(&study.path, &format!("kernel_bench.scenes[{k}]")))?;
        let mut scene = load_scene(&scene_study)?;
        let name = scene_study.name();
        let sys = System::new(scene.model.clone());
        let mut y0 = sys.initial_state();
        sys.project(scene.options.t0, &mut y0)
            .map_err(scene_study.locate("scene"))?;
        let (rhs_us, jvp_us) = time_rhs(&sys, scene.options.t0, &y0);
        let mut params = std::mem::take(&mut scene.params);
        params.truncate(spec.max_sensitivities.unwrap_or(usize::MAX));
        let mut sens_sets = vec![Vec::new()];
        if spec.sensitivities && !params.is_empty() {
            sens_sets.push(params);
        }
        let ratio = scene.options.atol / scene.options.rtol;
        for &method in &spec.methods {
            for &rtol in &spec.rtols {
                for set in &sens_sets {
                    scene.options.method = method;
                    scene.options.sensitivity = SensitivityForm::default_for(method);
                    scene.options.rtol = rtol;
                    scene.options.atol = rtol * ratio;
                    scene.params = set.clone();
                    let case = Case {
                        scene: name.clone(),
                        method,
                        rtol,
                        n_sens: set.len(),
                        rhs_us,
                        jvp_us,
                    };
                    let row = match measure(&scene, spec.repeats) {
                        Ok(m) => case.with(Ok(m)),
                        // A solver failure is a result of the benchmark
                        // (reported in the CSV), not a reason to stop it.
                        Err(e @ Error::Numerical { .. }) => case.with(Err(e.to_string())),
                        Err(e) => return Err(e.in_file(&scene_study.path, "scene")),
                    };
                    progress(&row);
                    rows.push(row);
                }
            }
        }
    }
    Ok(rows)
}

fn validate(study: &Study, spec: &BenchSpec) -> Result<()> {
    if spec.scenes.is_empty() {
        return Err(study.error("kernel_bench.scenes", "[]", "at least one scene file"));
    }
    if spec.methods.is_empty() {
        return Err(study.error("kernel_bench.methods", "[]", "at least one method"));
    }
    if spec.rtols.is_empty() {
        return Err(study.error("kernel_bench.rtols", "[]", "at least one rtol"));
    }
    for (k, &r) in spec.rtols.iter().enumerate() {
        if !(r > 1e-14 && r < 1.0) {
            return Err(study.error(format!("kernel_bench.rtols[{k}]"), r, "1e-14 < rtol < 1"));
        }
    }
    if spec.max_sensitivities == Some(0) {
        return Err(study.error(
            "kernel_bench.max_sensitivities",
            0,
            "≥ 1 (set sensitivities = false to run without)",
        ));
    }
    if spec.repeats == 0 {
        return Err(study.error("kernel_bench.repeats", 0, "repeats ≥ 1"));
    }
    Ok(())
}

/// Write `kernel_bench.csv` into `dir`.
pub fn write_csv(rows: &[BenchRow], dir: &Path) -> Result<PathBuf> {
    let path = dir.join("kernel_bench.csv");
    let mut w = Table::new(&path);
    w.row(HEADERS)?;
    for r in rows {
        w.row(r.record())?;
    }
    w.finish()?;
    Ok(path)
}

/// Read and check `[kernel_bench]` without running anything.
pub fn check(study: &Study) -> Result<BenchSpec> {
    let spec: BenchSpec = study.require_section("kernel_bench", "the kernel benchmark")?;
    validate(study, &spec)?;
    Ok(spec)
}

/// The `[kernel_bench]` handler: run the section and write the CSV.
pub fn run_kernel_bench(study: &Study, out: &Path, quiet: bool) -> Result<PathBuf> {
    let spec = check(study)?;
    let rows = run_bench(study, &spec, |r| {
        if !quiet {
            println!("{}", r.line());
        }
    })?;
    let dir = study.output_dir(out)?;
    let path = write_csv(&rows, &dir)?;
    if !quiet {
        println!("wrote {}", path.display());
    }
    Ok(path)
}
