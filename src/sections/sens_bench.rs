//! `[sens_bench]`: what the forward sensitivities of a scene cost, side by
//! side in both forms, and what they give.
//!
//! For the study's own `[scene]` and each listed relative tolerance (the
//! absolute tolerance scaled with it, keeping the scene's ratio), the
//! scene is simulated without sensitivities (`plain`) and with all its
//! sensitivity parameters in each listed form (`fused`: the lanes ride in
//! the state, one dual evaluation per lane and stage or Newton iterate;
//! `staggered`: diffsol's sensitivity equations, two), `repeats` times
//! after one untimed warm-up. Reported per case, medians over the repeats
//! on one thread: the integrator's wall time
//! ([`crate::integrate::Stats::wall`]: stepping and sensitivities, output
//! evaluation excluded) and the whole simulation's (projection, outputs
//! and their sensitivities included), both also as ratios to the plain
//! run at the same tolerance; steps, right-hand-side calls and dual
//! evaluations; the 1-minute load average at the end of the case (Linux;
//! empty elsewhere); the scene's first response with its gradient.
//!
//! ```toml
//! [sens_bench]
//! repeats = 7                      # timed runs per case (medians)
//! rtols = [1e-6, 1e-8, 1e-10]      # default: the scene's rtol
//! forms = ["fused", "staggered"]   # default: both
//! ```
//!
//! Output: `sens_bench.csv` in the study's output folder (columns:
//! [`HEADERS`], then `d/d(<parameter>)` per sensitivity parameter).

use super::stats::median;
use crate::error::Result;
use crate::integrate::{SensitivityForm, Stats};
use crate::mbs::responses::ResponseValue;
use crate::report::csv::{num, Table};
use crate::scene::{load_scene, Scene};
use crate::simulate::simulate;
use crate::study::Study;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The `[sens_bench]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensBenchSpec {
    /// Timed repetitions of each case (≥ 1); medians are reported.
    pub repeats: usize,
    /// Relative tolerances (default: the scene's).
    #[serde(default)]
    pub rtols: Vec<f64>,
    /// Sensitivity forms (default: fused and staggered with tsit45,
    /// staggered with the implicit methods).
    #[serde(default)]
    pub forms: Vec<SensitivityForm>,
}

/// The fixed column headers of `sens_bench.csv`; one `d/d(<parameter>)`
/// column per sensitivity parameter follows.
pub const HEADERS: [&str; 16] = [
    "method",
    "rtol",
    "form",
    "lanes",
    "repeats",
    "integrate [ms]",
    "integrate_ratio",
    "simulate [ms]",
    "simulate_ratio",
    "steps",
    "rhs_calls",
    "jvp_calls",
    "load_1min",
    "response",
    "value",
    "time [s]",
];

/// The medians and counts of one case.
#[derive(Debug, Clone)]
pub struct Timed {
    /// `plain`, `fused` or `staggered`.
    pub form: String,
    /// Sensitivity lanes: the number of the scene's sensitivity parameters.
    pub lanes: usize,
    /// Median integrator wall time (s).
    pub integrate: f64,
    /// Median wall time of the whole simulation (s).
    pub simulate: f64,
    /// Counters of the last run (the same in every run).
    pub stats: Stats,
    /// The scene's first response, if any.
    pub response: Option<ResponseValue>,
}

/// Simulate `scene` once untimed and `repeats` times timed.
fn time_case(scene: &Scene, form: &str, repeats: usize) -> Result<Timed> {
    let (_, warm) = simulate(scene)?;
    let (mut integrate, mut whole) = (Vec::new(), Vec::new());
    let mut stats = warm.stats;
    for _ in 0..repeats {
        let t = Instant::now();
        let (_, sim) = simulate(scene)?;
        whole.push(t.elapsed().as_secs_f64());
        integrate.push(sim.stats.wall);
        stats = sim.stats;
    }
    Ok(Timed {
        form: form.to_string(),
        lanes: scene.params.len(),
        integrate: median(integrate),
        simulate: median(whole),
        stats,
        response: warm.responses.into_iter().next(),
    })
}

/// One CSV row of `case`, with ratios to `plain`.
fn record(scene: &Scene, case: &Timed, plain: &Timed, repeats: usize) -> Vec<String> {
    let ms = |s: f64| format!("{:.3}", 1e3 * s);
    let s = &case.stats;
    let mut row = vec![
        scene.options.method.name().to_string(),
        num(scene.options.rtol),
        case.form.clone(),
        case.lanes.to_string(),
        repeats.to_string(),
        ms(case.integrate),
        format!("{:.3}", case.integrate / plain.integrate),
        ms(case.simulate),
        format!("{:.3}", case.simulate / plain.simulate),
        s.steps.to_string(),
        s.rhs_calls.to_string(),
        s.jvp_calls.to_string(),
        crate::report::clock::load_average().map_or(String::new(), |l| format!("{l:.2}")),
    ];
    match &case.response {
        Some(r) => {
            row.extend([r.name.clone(), num(r.value)]);
            row.push(r.time.map_or(String::new(), num));
            let grad = r.gradient.iter().map(|g| num(*g));
            row.extend(
                grad.chain(std::iter::repeat(String::new()))
                    .take(scene.params.len()),
            );
        }
        None => row.extend(std::iter::repeat_n(String::new(), 3 + scene.params.len())),
    }
    row
}

/// Run every case; `progress` gets each finished row. Returns the header
/// and the rows.
pub fn run_sens_bench(
    study: &Study,
    spec: &SensBenchSpec,
    mut progress: impl FnMut(&[String]),
) -> Result<(Vec<String>, Vec<Vec<String>>)> {
    let mut scene = load_scene(study)?;
    let params = std::mem::take(&mut scene.params);
    validate(study, spec, params.is_empty())?;
    let rtols = match spec.rtols.as_slice() {
        [] => vec![scene.options.rtol],
        r => r.to_vec(),
    };
    let forms = match spec.forms.as_slice() {
        [] => vec![SensitivityForm::Fused, SensitivityForm::Staggered],
        f => f.to_vec(),
    };
    let mut header: Vec<String> = HEADERS.iter().map(|h| h.to_string()).collect();
    header.extend(params.iter().map(|(p, _)| format!("d/d({p})")));
    let ratio = scene.options.atol / scene.options.rtol;
    let mut rows = Vec::new();
    for rtol in rtols {
        scene.options.rtol = rtol;
        scene.options.atol = rtol * ratio;
        scene.params.clear();
        let plain = time_case(&scene, "plain", spec.repeats).map_err(study.locate("scene"))?;
        let mut cases = vec![plain.clone()];
        scene.params = params.clone();
        for form in &forms {
            scene.options.sensitivity = *form;
            cases
                .push(time_case(&scene, form.name(), spec.repeats).map_err(study.locate("scene"))?);
        }
        for case in &cases {
            let row = record(&scene, case, &plain, spec.repeats);
            progress(&row);
            rows.push(row);
        }
    }
    Ok((header, rows))
}

/// Repeats ≥ 1, tolerances in range, a scene with sensitivity parameters.
fn validate(study: &Study, spec: &SensBenchSpec, no_params: bool) -> Result<()> {
    if spec.repeats == 0 {
        return Err(study.error("sens_bench.repeats", 0, "at least 1 repetition"));
    }
    for (k, &r) in spec.rtols.iter().enumerate() {
        if !(r > 1e-14 && r < 1.0) {
            return Err(study.error(format!("sens_bench.rtols[{k}]"), r, "1e-14 < rtol < 1"));
        }
    }
    if no_params {
        return Err(study.error(
            "scene.sensitivities",
            "[]",
            "at least one sensitivity parameter (the [sens_bench] section times them)",
        ));
    }
    Ok(())
}

/// Read `[sens_bench]` without running anything (the scene-dependent
/// checks run with the section).
pub fn check(study: &Study) -> Result<SensBenchSpec> {
    study.require_section("sens_bench", "the sensitivity cost benchmark")
}

/// The `[sens_bench]` handler: run the section and write the CSV.
pub fn run_sens_bench_section(study: &Study, out: &Path, quiet: bool) -> Result<PathBuf> {
    let spec = check(study)?;
    let (header, rows) = run_sens_bench(study, &spec, |r| {
        if !quiet {
            println!("{}", r.join(", "));
        }
    })?;
    let path = study.output_dir(out)?.join("sens_bench.csv");
    let mut table = Table::new(&path);
    table.row(&header)?;
    for r in &rows {
        table.row(r)?;
    }
    let path = table.finish()?;
    if !quiet {
        println!("wrote {}", path.display());
    }
    Ok(path)
}
