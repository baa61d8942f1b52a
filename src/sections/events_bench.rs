//! `[events_bench]`: is it worth treating the segment changes of Eq. 32 as
//! integration events? Accuracy and cost with and without
//! [`crate::integrate::Options::events`].
//!
//! ## Method
//! One scene (the rigid SAR antenna, run long enough for θ to cross the
//! breakpoints 3.08, 3.02 and 2.63 rad) is integrated to `t_end` with each
//! method × rtol × events on/off (atol = rtol × the scene's atol/rtol).
//! Each case runs twice: without sensitivities (`repeats` times, median
//! integrator wall time, counts of the last run) and once with the
//! scene's sensitivity parameters. The errors of θ(t_end) of the scene's
//! first actuator joint and of dθ(t_end)/dp for each parameter are taken
//! against a reference: BDF, events on, rtol `reference_rtol`; a second
//! reference with tsit45 at the same rtol gives the reference's own error
//! (`reference_spread` in the CSV).
//!
//! Output: `events.csv` in the study's output folder (columns in
//! [`headers`]); a failed case is a row with `status = failed: …`.

use crate::error::{Error, Result};
use crate::integrate::{integrate, integrate_sens, Method, Options, SensitivityForm, Stats};
use crate::mbs::System;
use crate::mbs::{Force, Param};
use crate::report::csv::Table;
use crate::scene::load_scene;
use crate::study::Study;
use num_dual::Dual64;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The `[events_bench]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventsSpec {
    /// Scene study file (relative to this study's folder); its actuator
    /// law must have breakpoints inside the run.
    pub scene: PathBuf,
    /// End time (s), replacing the scene's.
    pub t_end: f64,
    /// Integrators to compare (`bdf`, `tsit45`, `esdirk34`), each run with
    /// and without events at every `rtols` entry.
    pub methods: Vec<Method>,
    /// Relative tolerances (0 < rtol < 1).
    pub rtols: Vec<f64>,
    /// rtol of the reference runs (BDF and tsit45, events on).
    pub reference_rtol: f64,
    /// Timed repetitions of the runs without sensitivities (≥ 1).
    pub repeats: usize,
}

/// Final θ, dθ/dp (per parameter) and statistics of one run.
#[derive(Debug, Clone)]
struct Run {
    theta: f64,
    dtheta: Vec<f64>,
    stats: Stats,
}

/// One integration to `opts.times[0]` (the only output time); with
/// `params` non-empty, with sensitivities.
fn run(sys: &System, y0: &[f64], opts: &Options, joint: usize, params: &[Param]) -> Result<Run> {
    let mut out = None;
    let n = y0.len();
    let final_values = |y: &[f64], s: &[f64]| {
        let mut ws = crate::mbs::Workspace::empty();
        let theta = sys.angle(y, joint, &mut ws).0;
        let dtheta = s
            .chunks(n)
            .map(|lane| {
                let yd: Vec<Dual64> = y
                    .iter()
                    .zip(lane)
                    .map(|(&a, &b)| Dual64::new(a, b))
                    .collect();
                let mut kin = Vec::new();
                sys.body_kin(&yd, &[], &mut kin);
                sys.joint_angle(&kin, joint).0.eps
            })
            .collect::<Vec<f64>>();
        (theta, dtheta)
    };
    let stats = if params.is_empty() {
        integrate(sys, y0, opts, |_, y| {
            out = Some(final_values(y, &[]));
            Ok(())
        })?
    } else {
        integrate_sens(sys, y0, opts, params, |_, y, s| {
            out = Some(final_values(y, s));
            Ok(())
        })?
    };
    let (theta, dtheta) =
        out.ok_or_else(|| Error::numerical("events_bench", "no output at the end time"))?;
    Ok(Run {
        theta,
        dtheta,
        stats,
    })
}

/// CSV headers: fixed columns, then one relative sensitivity error per
/// parameter (named as in the scene).
pub fn headers(param_names: &[String]) -> Vec<String> {
    let mut h: Vec<String> = [
        "method",
        "rtol",
        "events",
        "status",
        "wall_ms",
        "rhs_calls",
        "jvp_calls",
        "jacobians",
        "steps",
        "error_test_failures",
        "segment_events",
        "restarts",
        "theta_end_rad",
        "theta_abs_error_rad",
        "sens_wall_ms",
        "sens_rhs_calls",
        "sens_error_test_failures",
        "sens_rel_error_max",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    h.extend(
        param_names
            .iter()
            .map(|p| format!("dtheta_d({p})_rel_error")),
    );
    h.push("reference_spread_theta_rad".into());
    h.push("reference_spread_sens_rel".into());
    h
}

/// Read and check `[events_bench]` without running anything.
pub fn check(study: &Study) -> Result<EventsSpec> {
    let spec: EventsSpec = study.require_section("events_bench", "the events benchmark")?;
    validate(study, &spec)?;
    Ok(spec)
}

/// The `[events_bench]` handler: run all cases, write `events.csv`.
pub fn run_events_bench(study: &Study, out: &Path, quiet: bool) -> Result<PathBuf> {
    let spec = check(study)?;
    let base = study.path.parent().unwrap_or(Path::new("."));
    let path = base.join(&spec.scene);
    let scene_study =
        Study::load(&path).map_err(|e| e.in_file(&study.path, "events_bench.scene"))?;
    let scene = load_scene(&scene_study)?;
    let joint = scene
        .model
        .forces
        .iter()
        .find_map(|f| match f {
            Force::Rotational { joint, .. } => Some(*joint),
            _ => None,
        })
        .ok_or_else(|| {
            study.error(
                "events_bench.scene",
                spec.scene.display(),
                "a scene with an actuator (type = \"actuator\")",
            )
        })?;
    let names: Vec<String> = scene.params.iter().map(|(n, _)| n.clone()).collect();
    let params: Vec<Param> = scene.params.iter().map(|(_, p)| *p).collect();
    let sys = System::new(scene.model.clone());
    let mut y0 = sys.initial_state();
    sys.project(0.0, &mut y0)
        .map_err(scene_study.locate("scene"))?;
    let ratio = scene.options.atol / scene.options.rtol;
    let options = |method: Method, rtol: f64, events: bool| Options {
        method,
        rtol,
        atol: rtol * ratio,
        t0: 0.0,
        times: vec![spec.t_end],
        events,
        sensitivity: SensitivityForm::Staggered,
    };
    let r = spec.reference_rtol;
    let reference = run(&sys, &y0, &options(Method::Bdf, r, true), joint, &params)?;
    let check = run(&sys, &y0, &options(Method::Tsit45, r, true), joint, &params)?;
    let rel = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs() / y.abs().max(1e-300))
            .collect()
    };
    let spread_theta = (check.theta - reference.theta).abs();
    let spread_sens = rel(&check.dtheta, &reference.dtheta)
        .into_iter()
        .fold(0.0, f64::max);
    if !quiet {
        println!(
            "reference (bdf, rtol {r:e}, events): θ({}) = {:.12} rad, dθ/dp = {:?}; {} events; \
             tsit45 spread {:.1e} rad, sens {:.1e} (relative)",
            spec.t_end,
            reference.theta,
            reference.dtheta,
            reference.stats.events,
            spread_theta,
            spread_sens
        );
    }
    let mut rows = Vec::new();
    for &method in &spec.methods {
        for &rtol in &spec.rtols {
            for events in [true, false] {
                let mut row = vec![
                    method.name().to_string(),
                    format!("{rtol:e}"),
                    events.to_string(),
                ];
                let opts = options(method, rtol, events);
                let measured = (|| -> Result<Vec<String>> {
                    let mut walls = Vec::new();
                    let mut plain = None;
                    for _ in 0..spec.repeats {
                        let r = run(&sys, &y0, &opts, joint, &[])?;
                        walls.push(r.stats.wall);
                        plain = Some(r);
                    }
                    let plain = plain.ok_or_else(|| Error::numerical("events_bench", "no run"))?;
                    walls.sort_by(f64::total_cmp);
                    let sens = run(&sys, &y0, &opts, joint, &params)?;
                    let errs = rel(&sens.dtheta, &reference.dtheta);
                    let s = &plain.stats;
                    let mut v = vec![
                        "ok".to_string(),
                        format!("{:.4}", walls[walls.len() / 2] * 1e3),
                        s.rhs_calls.to_string(),
                        s.jvp_calls.to_string(),
                        s.jacobians.to_string(),
                        s.steps.to_string(),
                        s.error_test_failures.to_string(),
                        s.events.to_string(),
                        s.restarts.to_string(),
                        format!("{:.12e}", plain.theta),
                        format!("{:.3e}", (plain.theta - reference.theta).abs()),
                        format!("{:.4}", sens.stats.wall * 1e3),
                        sens.stats.rhs_calls.to_string(),
                        sens.stats.error_test_failures.to_string(),
                        format!("{:.3e}", errs.iter().copied().fold(0.0, f64::max)),
                    ];
                    v.extend(errs.iter().map(|e| format!("{e:.3e}")));
                    Ok(v)
                })();
                match measured {
                    Ok(v) => row.extend(v),
                    Err(e @ Error::Numerical { .. }) => {
                        row.push(format!("failed: {e}"));
                        row.extend(std::iter::repeat_n(String::new(), 14 + names.len()));
                    }
                    Err(e) => return Err(e),
                }
                row.push(format!("{spread_theta:.3e}"));
                row.push(format!("{spread_sens:.3e}"));
                if !quiet {
                    println!("{}", row.join(" "));
                }
                rows.push(row);
            }
        }
    }
    let dir = study.output_dir(out)?;
    let path = dir.join("events.csv");
    let mut w = Table::new(&path);
    w.row(headers(&names))?;
    for r in &rows {
        w.row(r)?;
    }
    w.finish()?;
    if !quiet {
        println!("wrote {}", path.display());
    }
    Ok(path)
}

fn validate(study: &Study, spec: &EventsSpec) -> Result<()> {
    if !(spec.t_end > 0.0 && spec.t_end.is_finite()) {
        return Err(study.error("events_bench.t_end", spec.t_end, "an end time > 0 (s)"));
    }
    if spec.methods.is_empty() {
        return Err(study.error("events_bench.methods", "[]", "at least one method"));
    }
    if spec.rtols.is_empty() {
        return Err(study.error("events_bench.rtols", "[]", "at least one rtol"));
    }
    for (k, &r) in spec
        .rtols
        .iter()
        .chain(std::iter::once(&spec.reference_rtol))
        .enumerate()
    {
        if !(r > 1e-14 && r < 1.0) {
            let key = if k < spec.rtols.len() {
                format!("events_bench.rtols[{k}]")
            } else {
                "events_bench.reference_rtol".to_string()
            };
            return Err(study.error(key, r, "1e-14 < rtol < 1"));
        }
    }
    if spec.repeats == 0 {
        return Err(study.error("events_bench.repeats", 0, "repeats ≥ 1"));
    }
    Ok(())
}
