//! `[noise]`: the noise of the study's problem, measured, and what
//! accuracy costs.
//!
//! An evaluation that integrates a motion with adaptive steps is smooth
//! only piecewise: f and every constraint jump by a little wherever the
//! accepted step sequence changes. For every integration tolerance listed
//! in `rtol` (scene problems; default the scene's own; the absolute
//! tolerance follows at the scene's own ratio `atol/rtol`, since a fixed
//! atol floors the accuracy: on the SAR scene atol 1e-8 keeps the noise
//! of f at 4e-7 whatever rtol) and every design in
//! `designs` (default the problem's start), ECNoise
//! ([`crate::optimize::noise::estimate`]) measures the noise σ of f and of
//! each constraint from a difference table of `points` function-only
//! evaluations along a seeded random direction, widening or narrowing the
//! step by 100 up to `retries` times when the table cannot tell.
//!
//! Per tolerance it also times `timing_repeats` evaluations of f and of
//! f with gradients at the first design (the evaluating thread's CPU time,
//! median), and, with `solve = true`, runs the local search (`method`, at
//! `feasibility_tolerance`, certificate and polish as in `[multistart]`,
//! with the measured noise as the polish's allowance) from the first
//! design: its calls, wall time, class and optimum, and the distance of the
//! optimum and of its f from those of the tightest tolerance listed.
//!
//! Output, in the study's folder:
//! - `noise.csv`: one row per tolerance, design and function (f, then the
//!   constraints `g1`, `g2`, ...): its value, σ (absolute, and relative:
//!   to |f| for f, to max(|g|, 1) for a constraint, which is compared with
//!   the feasibility tolerance in absolute terms), the difference order
//!   that gave it, the step of the last
//!   table; a failed estimate is written as its reason (`h_too_small`,
//!   `h_too_large`) with σ left empty, never as a number.
//! - `accuracy.csv`: one row per tolerance (columns in [`ACCURACY`]), and
//!   the plots `accuracy.svg` (noise and error against rtol) and
//!   `accuracy_cost.svg` (CPU per evaluation and the run's wall time).

use super::stats::median;
use crate::error::{Error, Result};
use crate::explore::local::settle::EndPolicy;
use crate::explore::local::solvers::{self, LocalMethod, MmfdPreset, MmfdSettings};
use crate::explore::multistart::driver::one_run;
use crate::explore::persist::tables::{class_name, RunRecord};
use crate::optimize::kkt::KktTolerances;
use crate::optimize::noise::{estimate, Measured, Noise, NoiseOptions};
use crate::optimize::{NoObserver, Problem};
use crate::report::csv::{num, write_table};
use crate::report::plot::{line_plot, Axes, Curve, Scale};
use crate::study::Study;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The `[noise]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Designs to measure at, in the variables' units (default: the scene
    /// problem's start; required for a test problem).
    pub designs: Option<Vec<Vec<f64>>>,
    /// Integration tolerances (scene problems only; default the scene's
    /// own `[scene.integrator] rtol`); atol follows at the scene's ratio
    /// atol/rtol.
    pub rtol: Option<Vec<f64>>,
    /// Evaluations per difference table (4–20, default 8).
    #[serde(default = "default_points")]
    pub points: usize,
    /// First scaled step (a step of 1 spans a variable's range; default
    /// 1e-4).
    #[serde(default = "default_step")]
    pub step: f64,
    /// Tables after a failed one (0–4, default 2).
    #[serde(default = "default_retries")]
    pub retries: usize,
    /// Timed evaluations of f and of f+g per tolerance (default 3; 0: no
    /// timing).
    #[serde(default = "default_repeats")]
    pub timing_repeats: usize,
    /// Run the certified local search from the first design at every
    /// tolerance (default false).
    #[serde(default)]
    pub solve: bool,
    /// The local search's method (as `[multistart] method`; default sqp).
    #[serde(default)]
    pub method: LocalMethod,
    /// The local search's feasibility tolerance (default 1e-6).
    #[serde(default = "default_feasibility")]
    pub feasibility_tolerance: f64,
}

fn default_points() -> usize {
    NoiseOptions::default().points
}
fn default_step() -> f64 {
    NoiseOptions::default().step
}
fn default_retries() -> usize {
    NoiseOptions::default().retries
}
fn default_repeats() -> usize {
    3
}
fn default_feasibility() -> f64 {
    1e-6
}

/// Columns of `accuracy.csv`, before the optimum's variables.
pub const ACCURACY: [&str; 14] = [
    "rtol",
    "noise_f",
    "noise_f_relative",
    "noise_g_max",
    "f_cpu_seconds",
    "fg_cpu_seconds",
    "class",
    "function_calls",
    "gradient_calls",
    "run_wall_seconds",
    "f",
    "max_g",
    "f_error_relative",
    "x_distance",
];

/// Read and check `[noise]` without evaluating anything.
pub fn check(study: &Study) -> Result<NoiseSpec> {
    let spec: NoiseSpec = study.require_section("noise", "what to measure (designs, rtol)")?;
    if !(4..=20).contains(&spec.points) {
        return Err(study.error("noise.points", spec.points, "4 <= points <= 20"));
    }
    if !(spec.step.is_finite() && (1e-12..=0.01).contains(&spec.step)) {
        return Err(study.error(
            "noise.step",
            format!("{:?}", spec.step),
            "a scaled step with 1e-12 <= step <= 0.01 (1 spans a variable's range; \
             below 1e-12 the points differ by rounding only)",
        ));
    }
    if spec.retries > 4 {
        return Err(study.error("noise.retries", spec.retries, "0 <= retries <= 4"));
    }
    let scene = is_scene(study)?;
    if let Some(rtols) = &spec.rtol {
        if !scene {
            return Err(study.error(
                "noise.rtol",
                format!("{rtols:?}"),
                "no tolerances: only a scene problem ([problem] name = \"scene\") integrates",
            ));
        }
        if rtols.is_empty()
            || rtols
                .iter()
                .any(|r| !(r.is_finite() && *r > 0.0 && *r <= 1e-2))
        {
            return Err(study.error(
                "noise.rtol",
                format!("{rtols:?}"),
                "a non-empty list of tolerances with 0 < rtol <= 1e-2",
            ));
        }
    }
    if spec.designs.is_none() && !scene {
        return Err(study.error(
            "noise.designs",
            "(none)",
            "the designs to measure at (a test problem has no start)",
        ));
    }
    if !(spec.feasibility_tolerance.is_finite() && spec.feasibility_tolerance >= 0.0) {
        return Err(study.error(
            "noise.feasibility_tolerance",
            spec.feasibility_tolerance,
            "a finite value >= 0",
        ));
    }
    Ok(spec)
}

/// Is the study's `[problem]` its scene?
fn is_scene(study: &Study) -> Result<bool> {
    let p: crate::explore::problem::problems::ProblemSpec =
        study.require_section("problem", "the problem to measure (name = ...)")?;
    Ok(p.name == "scene")
}

/// One tolerance's measurements.
struct Row {
    rtol: Option<f64>,
    measured: Vec<Measured>,
    f_cpu: Option<f64>,
    fg_cpu: Option<f64>,
    run: Option<RunRecord>,
}

/// Run `[noise]`: measure, time, solve, write the tables and plots.
pub fn run_noise(study: &Study, out: &Path, quiet: bool) -> Result<Vec<PathBuf>> {
    let spec = check(study)?;
    let t0 = Instant::now();
    let mut problem = crate::explore::problem(study)?;
    let designs = match &spec.designs {
        Some(d) => d.clone(),
        None => {
            let sp: crate::explore::problem::scene_problem::SceneProblemSpec =
                study.require_section("scene_problem", "the scene problem's start")?;
            vec![sp.start]
        }
    };
    let n = problem.variables().len();
    for (i, d) in designs.iter().enumerate() {
        if d.len() != n || d.iter().any(|v| !v.is_finite()) {
            return Err(study.error(
                format!("noise.designs[{i}]"),
                format!("{d:?}"),
                format!("{n} finite values, one per variable"),
            ));
        }
    }
    let rtols: Vec<Option<f64>> = match &spec.rtol {
        Some(r) => r.iter().map(|&v| Some(v)).collect(),
        None => vec![problem.tolerance()],
    };
    let options = NoiseOptions {
        points: spec.points,
        step: spec.step,
        retries: spec.retries,
    };
    let mut rows = Vec::new();
    for rtol in rtols {
        if let Some(r) = rtol {
            // Checked: only a scene problem lists tolerances.
            problem.set_tolerance(r);
        }
        let row = measure_at(study, &spec, &options, problem.as_ref(), &designs, rtol)?;
        if !quiet {
            println!("{}", summary(&row));
        }
        rows.push(row);
    }
    let dir = study.output_dir(out)?;
    let files = write(&dir, problem.as_ref(), &rows)?;
    let mut entry = serde_json::Map::new();
    entry.insert("wall_seconds".into(), t0.elapsed().as_secs_f64().into());
    entry.insert(
        "evaluations".into(),
        rows.iter()
            .flat_map(|r| r.measured.iter().map(|m| m.evaluations))
            .sum::<usize>()
            .into(),
    );
    crate::report::record_command(&dir, study, 1, "noise", entry, None)?;
    if !quiet {
        for f in &files {
            println!("wrote {}", f.display());
        }
    }
    Ok(files)
}

/// Measure, time and (with `solve`) run at one tolerance.
fn measure_at(
    study: &Study,
    spec: &NoiseSpec,
    options: &NoiseOptions,
    problem: &dyn Problem,
    designs: &[Vec<f64>],
    rtol: Option<f64>,
) -> Result<Row> {
    let measured = designs
        .iter()
        .enumerate()
        .map(|(i, d)| estimate(problem, d, study.meta.seed.wrapping_add(i as u64), options))
        .collect::<Result<Vec<_>>>()
        .map_err(study.locate(""))?;
    let f_cpu = time(problem, &designs[0], false, spec.timing_repeats)?;
    let fg_cpu = time(problem, &designs[0], true, spec.timing_repeats)?;
    let run = if spec.solve {
        let solver = solvers::local(
            spec.method,
            &MmfdSettings::default(),
            MmfdPreset::default(),
            (spec.feasibility_tolerance, measured[0].allowance()),
        )?;
        let end = EndPolicy {
            tolerances: KktTolerances {
                feasibility: spec.feasibility_tolerance,
                ..KktTolerances::default()
            },
            polish: true,
            rescue: true,
            noise: measured[0].allowance(),
            noise_g: measured[0].allowance_g(),
        };
        let row = one_run(
            problem,
            solver.as_ref(),
            &end,
            0,
            &designs[0],
            &mut NoObserver,
        );
        if row.result.is_none() {
            return Err(Error::numerical(
                "noise.solve",
                format!("the run at rtol {rtol:?} failed: {}", row.exit),
            ));
        }
        Some(row)
    } else {
        None
    };
    Ok(Row {
        rtol,
        measured,
        f_cpu,
        fg_cpu,
        run,
    })
}

/// The median CPU time of `repeats` evaluations at `x` (the evaluating
/// thread's own; wall time where the platform has no thread clock).
fn time(problem: &dyn Problem, x: &[f64], gradients: bool, repeats: usize) -> Result<Option<f64>> {
    if repeats == 0 {
        return Ok(None);
    }
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let (c0, w0) = (crate::report::clock::thread_cpu_seconds(), Instant::now());
        problem.evaluate(x, gradients)?;
        let cpu = crate::report::clock::thread_cpu_seconds()
            .zip(c0)
            .map(|(c1, c0)| c1 - c0);
        times.push(cpu.unwrap_or_else(|| w0.elapsed().as_secs_f64()));
    }
    Ok(Some(median(times)))
}

/// One line per tolerance for the terminal.
fn summary(row: &Row) -> String {
    let m = &row.measured[0];
    let rel = m
        .relative_f()
        .map(|v| format!("{v:.2e}"))
        .unwrap_or_else(|| m.noise_f.failure().unwrap_or("").into());
    let mut s = format!("rtol {:?}: noise of f {rel} (relative)", row.rtol);
    if let Some(r) = &row.run {
        s += &format!(
            ", run {} in {} f + {} g",
            class_name(r),
            r.function_calls,
            r.gradient_calls
        );
    }
    s
}

/// σ as a cell: the number, or empty when the estimate failed.
fn sigma_cell(n: Noise) -> String {
    n.sigma().map(num).unwrap_or_default()
}

/// What the estimate says: `level`, or why it failed.
fn status(n: Noise) -> &'static str {
    n.failure().unwrap_or("level")
}

/// Write `noise.csv`, `accuracy.csv` and the plots.
fn write(dir: &Path, problem: &dyn Problem, rows: &[Row]) -> Result<Vec<PathBuf>> {
    let vars = problem.variables();
    let mut header: Vec<String> = vec!["rtol".into(), "design".into()];
    header.extend(vars.iter().map(|v| v.name.clone()));
    header.extend(
        [
            "function",
            "value",
            "noise",
            "noise_relative",
            "order",
            "status",
            "step",
        ]
        .map(String::from),
    );
    let mut table = Vec::new();
    for row in rows {
        for (i, m) in row.measured.iter().enumerate() {
            let functions = std::iter::once(("f".to_string(), m.f, m.noise_f)).chain(
                m.g.iter()
                    .zip(&m.noise_g)
                    .enumerate()
                    .map(|(j, (&g, &n))| (format!("g{}", j + 1), g, n)),
            );
            for (k, (name, value, n)) in functions.enumerate() {
                let mut cells = vec![row.rtol.map(num).unwrap_or_default(), i.to_string()];
                cells.extend(m.x.iter().map(|&v| num(v)));
                // f relative to |f|; a constraint, judged in absolute terms
                // against the feasibility tolerance, relative to max(|g|, 1).
                let scale = if k == 0 {
                    value.abs()
                } else {
                    value.abs().max(1.0)
                };
                let (order, relative) = match n {
                    Noise::Level { sigma, order } if scale > 0.0 => {
                        (order.to_string(), num(sigma / scale))
                    }
                    Noise::Level { order, .. } => (order.to_string(), String::new()),
                    _ => (String::new(), String::new()),
                };
                cells.extend([
                    name,
                    num(value),
                    sigma_cell(n),
                    relative,
                    order,
                    status(n).to_string(),
                    num(*m.steps.last().unwrap_or(&f64::NAN)),
                ]);
                table.push(cells);
            }
        }
    }
    let noise_csv = dir.join("noise.csv");
    write_table(&noise_csv, &header, &table)?;
    let accuracy_csv = dir.join("accuracy.csv");
    write_table(
        &accuracy_csv,
        &accuracy_header(vars),
        &accuracy_rows(vars, rows),
    )?;
    let mut files = vec![noise_csv, accuracy_csv];
    if rows.iter().filter(|r| r.rtol.is_some()).count() >= 2 {
        files.extend(plots(dir, rows)?);
    }
    Ok(files)
}

fn accuracy_header(vars: &[crate::optimize::Variable]) -> Vec<String> {
    let mut h: Vec<String> = ACCURACY.iter().map(|s| s.to_string()).collect();
    h.extend(vars.iter().map(|v| v.name.clone()));
    h
}

/// The reference of the distances: the run at the tightest tolerance.
fn reference(rows: &[Row]) -> Option<&RunRecord> {
    rows.iter()
        .filter(|r| r.run.is_some())
        .min_by(|a, b| a.rtol.unwrap_or(0.0).total_cmp(&b.rtol.unwrap_or(0.0)))
        .and_then(|r| r.run.as_ref())
}

/// The largest distance of two designs over the variables, in their units
/// (across the period for periodic ones).
fn distance(vars: &[crate::optimize::Variable], a: &[f64], b: &[f64]) -> f64 {
    vars.iter()
        .zip(a.iter().zip(b))
        .map(|(v, (x, y))| {
            let d = (x - y).abs();
            v.period
                .map_or(d, |p| d.rem_euclid(p).min(p - d.rem_euclid(p)))
        })
        .fold(0.0, f64::max)
}

fn accuracy_rows(vars: &[crate::optimize::Variable], rows: &[Row]) -> Vec<Vec<String>> {
    let opt = |v: Option<f64>| v.map(num).unwrap_or_default();
    let reference = reference(rows).and_then(|r| r.result.clone());
    rows.iter()
        .map(|row| {
            let m = &row.measured[0];
            let mut cells = vec![
                opt(row.rtol),
                m.noise_f
                    .sigma()
                    .map(num)
                    .unwrap_or_else(|| status(m.noise_f).into()),
                opt(m.relative_f()),
                match (m.noise_g.is_empty(), m.max_g()) {
                    (true, _) => String::new(),
                    (false, Some(v)) => num(v),
                    (false, None) => "failed".into(),
                },
                opt(row.f_cpu),
                opt(row.fg_cpu),
            ];
            match row
                .run
                .as_ref()
                .zip(row.run.as_ref().and_then(|r| r.result.as_ref()))
            {
                Some((r, res)) => {
                    let max_g = res.g.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    let (df, dx) = match &reference {
                        Some(x) => (
                            opt(Some((res.f - x.f).abs() / x.f.abs().max(f64::MIN_POSITIVE))),
                            opt(Some(distance(vars, &res.x, &x.x))),
                        ),
                        None => (String::new(), String::new()),
                    };
                    cells.extend([
                        class_name(r).to_string(),
                        r.function_calls.to_string(),
                        r.gradient_calls.to_string(),
                        num(r.wall_seconds),
                        num(res.f),
                        if res.g.is_empty() {
                            String::new()
                        } else {
                            num(max_g)
                        },
                        df,
                        dx,
                    ]);
                    cells.extend(res.x.iter().map(|&v| num(v)));
                }
                None => cells.extend(std::iter::repeat_n(String::new(), 8 + vars.len())),
            }
            cells
        })
        .collect()
}

/// `accuracy.svg` (noise of f and g, error of f against rtol) and
/// `accuracy_cost.svg` (CPU per evaluation, wall time of the run).
fn plots(dir: &Path, rows: &[Row]) -> Result<Vec<PathBuf>> {
    let curve = |label: &str, value: &dyn Fn(&Row) -> Option<f64>| Curve {
        label: label.into(),
        points: rows
            .iter()
            .filter_map(|r| Some((r.rtol?, value(r)?)))
            .filter(|(_, v)| v.is_finite() && *v > 0.0)
            .collect(),
    };
    let reference = reference(rows).and_then(|r| r.result.clone());
    let error = |r: &Row| {
        let (res, x) = (r.run.as_ref()?.result.as_ref()?, reference.as_ref()?);
        Some((res.f - x.f).abs() / x.f.abs().max(f64::MIN_POSITIVE))
    };
    let noise = vec![
        curve("noise of f / |f|", &|r| r.measured[0].relative_f()),
        curve("largest noise of g", &|r| r.measured[0].max_g()),
        curve("error of the optimum's f / |f|", &error),
    ];
    let path = dir.join("accuracy.svg");
    line_plot(
        &path,
        &Axes {
            title: "Noise and error against the integration tolerance",
            x: "rtol",
            y: "relative noise / error",
            scale: Scale::LogLog,
        },
        &noise,
    )?;
    let cost = vec![
        curve("CPU per f [s]", &|r| r.f_cpu),
        curve("CPU per f+g [s]", &|r| r.fg_cpu),
        curve("certified run, wall [s]", &|r| {
            r.run.as_ref().map(|x| x.wall_seconds)
        }),
    ];
    let cost_path = dir.join("accuracy_cost.svg");
    line_plot(
        &cost_path,
        &Axes {
            title: "What accuracy costs",
            x: "rtol",
            y: "seconds",
            scale: Scale::LogLog,
        },
        &cost,
    )?;
    Ok(vec![path, cost_path])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn study(text: &str) -> Study {
        Study::parse("noise.toml", text).unwrap()
    }

    #[test]
    fn bad_settings_name_their_key() {
        let base = "[problem]\nname = \"himmelblau\"\n[noise]\ndesigns = [[1.0, 1.0]]\n";
        for (extra, key) in [
            ("points = 3\n", "noise.points"),
            ("step = 0.5\n", "noise.step"),
            ("step = 1e-300\n", "`noise.step` = 1e-300"),
            ("retries = 9\n", "noise.retries"),
            ("rtol = [1e-6]\n", "noise.rtol"),
            (
                "feasibility_tolerance = -1.0\n",
                "noise.feasibility_tolerance",
            ),
        ] {
            let e = check(&study(&format!("{base}{extra}")))
                .unwrap_err()
                .to_string();
            assert!(e.contains(key), "{extra}: {e}");
        }
        let e = check(&study("[problem]\nname = \"himmelblau\"\n[noise]\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("noise.designs") && e.contains("no start"), "{e}");
        assert!(check(&study(base)).is_ok());
    }

    #[test]
    fn periodic_distance_goes_the_short_way() {
        let vars = vec![crate::optimize::Variable::periodic("t", -90.0, 180.0).unwrap()];
        assert_eq!(distance(&vars, &[89.0], &[-89.0]), 2.0);
        assert_eq!(distance(&vars, &[10.0], &[-5.0]), 15.0);
    }
}
