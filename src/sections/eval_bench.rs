//! `[eval_bench]`: what one design evaluation of a scene problem costs and
//! where its time goes.
//!
//! For every listed study with a scene problem (`[problem] name = "scene"`),
//! every integration method listed in `methods` (default: the problem's
//! own) and every design (default: the problem's start), the evaluation is run
//! without gradients (`f`) and with them (`f+g`, once per sensitivity
//! form listed in `forms`, e.g. `f+g fused`), `repeats` times each
//! after one untimed warm-up of each kind (which makes the pooled panel
//! analyses: pattern, symbolic factorization). The repeats run in rounds:
//! each round evaluates every kind once, one after the other, so that
//! the `f+g` of a round is timed beside its `f`, and `total_per_f` is the
//! median over the rounds of a kind's total over the `f` total of the
//! same round (1 for `f`): the f+g/f ratio with the machine's slow and
//! fast spells paired out, which the ratio of the two medians is not on a
//! machine whose speed drifts. Reported per case, medians
//! over the repeats, one thread: the panel bases computed (and how many
//! with mode derivatives), the bodies that got a copy of another body's
//! basis of the same content instead (`shared_bases`,
//! [`crate::panels::shared`]) and the time of both, the rest of the
//! scene build, the integration (states and, for `f+g`, the sensitivity
//! lanes), the output and response evaluation, the total (with the
//! smallest and largest total of the repeats: the spread a single timing
//! carries on that machine), the integrator's steps, right-hand-side
//! calls and Jacobian-vector products (for fused sensitivities:
//! multi-lane dual evaluations) and the integration time per
//! right-hand-side call. Wall times are what a user waits; `cpu [ms]`
//! is the evaluating thread's own CPU time (Linux; empty elsewhere), which
//! stays close to the wall time on an idle machine and keeps measuring
//! the work when other processes share the cores (`load_1min`, read at
//! the start of each case, says how busy the machine was). The problem's
//! set-up (plan, start design and normalization evaluations) is timed
//! once.
//!
//! With `rtols`, every case runs at each of those integration tolerances
//! (atol at the problem's ratio atol/rtol; the constraint bounds and the
//! objective's divisor stay the problem's, so it is one problem evaluated
//! more or less accurately). With `reference_rtol`, each design is also
//! evaluated with gradients by the problem's own method at that tolerance,
//! and every row says how far its evaluation is from it: `f_rel_error`
//! (`|f − f_ref| / |f_ref|`), `g_max_error` (the largest `|g_j − g_ref,j|`,
//! the constraints being normalized) and, for `f+g`, `gradient_rel_error`
//! (the largest error of a component of ∇f or of a ∇g_j relative to the
//! largest component of that reference gradient).
//!
//! Output: `eval_bench.csv` in the study's output folder (columns in
//! [`HEADERS`]).

use super::stats::median;
use crate::error::Result;
use crate::explore::problem::scene_problem::{EvalProfile, SceneProblem};
use crate::integrate::{Method, SensitivityForm};
use crate::optimize::{Evaluation, Problem};
use crate::report::clock::{load_average, thread_cpu_seconds};
use crate::report::csv::Table;
use crate::study::Study;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The `[eval_bench]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvalBenchSpec {
    /// Study files with a scene problem (paths relative to this study).
    pub problems: Vec<PathBuf>,
    /// Designs to evaluate \[deg\], one value per problem variable;
    /// default: each problem's start.
    #[serde(default)]
    pub designs: Vec<Vec<f64>>,
    /// Timed repetitions of each case (≥ 1); medians are reported.
    pub repeats: usize,
    /// Forms of the sensitivities to time for `f+g` (default: the
    /// problem's own).
    #[serde(default)]
    pub forms: Vec<SensitivityForm>,
    /// Integration methods to run each problem with (default: the
    /// problem's own).
    #[serde(default)]
    pub methods: Vec<Method>,
    /// Relative integration tolerances to run each case at (default: the
    /// problem's own).
    #[serde(default)]
    pub rtols: Vec<f64>,
    /// The tolerance of the reference evaluations the errors are taken
    /// against (module doc; default: none, no error columns).
    pub reference_rtol: Option<f64>,
}

/// Column headers of `eval_bench.csv`.
pub const HEADERS: [&str; 28] = [
    "problem",
    "method",
    "rtol",
    "design [deg]",
    "mode",
    "setup [ms]",
    "lanes",
    "bases",
    "derivative_bases",
    "shared_bases",
    "bases [ms]",
    "build_other [ms]",
    "integrate [ms]",
    "outputs [ms]",
    "total [ms]",
    "total_min [ms]",
    "total_max [ms]",
    "total_per_f",
    "steps",
    "rhs_calls",
    "jvp_calls",
    "integrate_per_rhs [us]",
    "cpu [ms]",
    "load_1min",
    "repeats",
    "f_rel_error",
    "g_max_error",
    "gradient_rel_error",
];

/// One timed evaluation: its profile and the thread's CPU seconds (NaN
/// where the platform does not say).
struct Timed {
    profile: EvalProfile,
    cpu: f64,
}

/// The case a row belongs to: problem, method, rtol and design.
struct Case<'a> {
    problem: &'a str,
    method: &'a str,
    rtol: f64,
    x: &'a [f64],
}

/// The medians of one case.
fn row(
    case: &Case<'_>,
    (mode, load): (&str, Option<f64>),
    (setup, per_f): (f64, f64),
    timed: &[Timed],
    errors: [Option<f64>; 3],
) -> Vec<String> {
    let runs: Vec<&EvalProfile> = timed.iter().map(|t| &t.profile).collect();
    let med = |f: &dyn Fn(&EvalProfile) -> f64| median(runs.iter().map(|r| f(r)).collect());
    let ms = |f: &dyn Fn(&EvalProfile) -> f64| format!("{:.3}", 1e3 * med(f));
    let p = runs[0];
    let cpu = median(timed.iter().map(|t| t.cpu).collect());
    let design: Vec<String> = case.x.iter().map(|v| v.to_string()).collect();
    let per_rhs = med(&|r| r.integrate_seconds / r.rhs_calls.max(1) as f64);
    // The spread of the repeats' totals, beside their median: how far one
    // evaluation's wall time moved on this machine while the case ran.
    let (lo, hi) = runs.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
        (lo.min(r.total_seconds), hi.max(r.total_seconds))
    });
    let mut r = vec![
        case.problem.to_string(),
        case.method.to_string(),
        format!("{:e}", case.rtol),
        design.join(" "),
        mode.to_string(),
        format!("{:.1}", 1e3 * setup),
        p.lanes.to_string(),
        p.build.bases.to_string(),
        p.build.derivative_bases.to_string(),
        p.build.shared_bases.to_string(),
        ms(&|r| r.build.bases_seconds),
        ms(&|r| r.build.total_seconds - r.build.bases_seconds),
        ms(&|r| r.integrate_seconds),
        ms(&|r| r.outputs_seconds),
        ms(&|r| r.total_seconds),
        format!("{:.3}", 1e3 * lo),
        format!("{:.3}", 1e3 * hi),
        format!("{per_f:.3}"),
        p.steps.to_string(),
        p.rhs_calls.to_string(),
        p.jvp_calls.to_string(),
        format!("{:.2}", 1e6 * per_rhs),
        if cpu.is_finite() {
            format!("{:.3}", 1e3 * cpu)
        } else {
            String::new()
        },
        load.map_or(String::new(), |l| format!("{l:.2}")),
        runs.len().to_string(),
    ];
    r.extend(
        errors
            .iter()
            .map(|e| e.map_or(String::new(), |e| format!("{e:.2e}"))),
    );
    r
}

/// The errors of `e` against the reference `r` (module doc): f relative,
/// the largest absolute error of g, and (when both carry gradients) the
/// largest gradient error relative to each reference gradient's largest
/// component.
fn errors(e: &Evaluation, r: &Evaluation) -> [Option<f64>; 3] {
    let f = (e.f - r.f).abs() / r.f.abs().max(f64::MIN_POSITIVE);
    let g =
        e.g.iter()
            .zip(&r.g)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
    let rel = |a: &[f64], b: &[f64]| {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let d = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (u, v)| m.max((u - v).abs()));
        d / scale.max(f64::MIN_POSITIVE)
    };
    let grad = match (&e.grad_f, &r.grad_f, &e.grad_g, &r.grad_g) {
        (Some(ef), Some(rf), Some(eg), Some(rg)) => Some(
            eg.iter()
                .zip(rg)
                .map(|(a, b)| rel(a, b))
                .fold(rel(ef, rf), f64::max),
        ),
        _ => None,
    };
    [Some(f), Some(g), grad]
}

/// The modes of a design's evaluation: `f`, then `f+g` once per listed
/// sensitivity form (or with the problem's own).
type Mode = (String, bool, Option<SensitivityForm>);

fn modes(spec: &EvalBenchSpec) -> Vec<Mode> {
    let mut modes = vec![("f".to_string(), false, None)];
    if spec.forms.is_empty() {
        modes.push(("f+g".into(), true, None));
    }
    for form in &spec.forms {
        modes.push((format!("f+g {}", form.name()), true, Some(*form)));
    }
    modes
}

/// One design's warm-ups (whose evaluations are returned, one per mode)
/// and timed rounds (module doc).
fn time_design(
    problem: &mut SceneProblem,
    x: &[f64],
    modes: &[Mode],
    repeats: usize,
) -> Result<(Vec<Evaluation>, Vec<Vec<Timed>>)> {
    let set_form = |problem: &mut SceneProblem, form: &Option<SensitivityForm>| {
        if let Some(form) = form {
            problem.set_sensitivity_form(*form);
        }
    };
    let mut warm = Vec::new();
    for (_, gradients, form) in modes {
        set_form(problem, form);
        warm.push(problem.evaluate_profiled(x, *gradients)?.0);
    }
    let cpu = || thread_cpu_seconds().unwrap_or(f64::NAN);
    let mut timed: Vec<Vec<Timed>> = modes.iter().map(|_| Vec::new()).collect();
    for _ in 0..repeats {
        for ((_, gradients, form), runs) in modes.iter().zip(timed.iter_mut()) {
            set_form(problem, form);
            let c0 = cpu();
            let profile = problem.evaluate_profiled(x, *gradients)?.1;
            let cpu = cpu() - c0;
            runs.push(Timed { profile, cpu });
        }
    }
    Ok((warm, timed))
}

/// The reference evaluation (with gradients) of each design at `rtol` by
/// the problem's own method; the problem's tolerance is restored.
fn references(
    problem: &mut SceneProblem,
    designs: &[Vec<f64>],
    rtol: Option<f64>,
) -> Result<Vec<Option<Evaluation>>> {
    let Some(rtol) = rtol else {
        return Ok(vec![None; designs.len()]);
    };
    let own = problem.tolerances().0;
    problem.set_tolerance(rtol);
    let refs = designs
        .iter()
        .map(|x| problem.evaluate(x, true).map(Some))
        .collect();
    problem.set_tolerance(own);
    refs
}

/// Check the keys that take values (errors name the key).
fn check_spec(study: &Study, spec: &EvalBenchSpec) -> Result<()> {
    if spec.repeats == 0 {
        return Err(study.error("eval_bench.repeats", 0, "at least 1 repetition"));
    }
    if spec.problems.is_empty() {
        return Err(study.error("eval_bench.problems", "[]", "at least one study file"));
    }
    let tolerance = |v: f64| v > 0.0 && v <= 1e-2;
    for (k, &r) in spec.rtols.iter().enumerate() {
        if !tolerance(r) {
            return Err(study.error(
                format!("eval_bench.rtols[{k}]"),
                r,
                "a tolerance with 0 < rtol <= 1e-2",
            ));
        }
    }
    match spec.reference_rtol {
        Some(r) if !tolerance(r) => Err(study.error(
            "eval_bench.reference_rtol",
            r,
            "a tolerance with 0 < rtol <= 1e-2",
        )),
        _ => Ok(()),
    }
}

/// Run every case; `progress` gets each finished row.
pub fn run_eval_bench(
    study: &Study,
    spec: &EvalBenchSpec,
    mut progress: impl FnMut(&[String]),
) -> Result<Vec<Vec<String>>> {
    check_spec(study, spec)?;
    let base = study.path.parent().unwrap_or(Path::new("."));
    let mut rows = Vec::new();
    for (k, file) in spec.problems.iter().enumerate() {
        let at = format!("eval_bench.problems[{k}]");
        let inner = Study::load(base.join(file)).map_err(|e| e.in_file(&study.path, &at))?;
        let t = Instant::now();
        let mut problem = SceneProblem::from_study(&inner)?;
        let setup = t.elapsed().as_secs_f64();
        let designs = if spec.designs.is_empty() {
            vec![problem.start().to_vec()]
        } else {
            spec.designs.clone()
        };
        for (j, x) in designs.iter().enumerate() {
            if x.len() != problem.variables().len() {
                return Err(study.error(
                    format!("eval_bench.designs[{j}]"),
                    format!("{x:?}"),
                    format!("{} angles [deg]", problem.variables().len()),
                ));
            }
        }
        let refs = references(&mut problem, &designs, spec.reference_rtol)?;
        let methods: Vec<Option<Method>> = match spec.methods.as_slice() {
            [] => vec![None],
            m => m.iter().copied().map(Some).collect(),
        };
        let rtols: Vec<f64> = match spec.rtols.as_slice() {
            [] => vec![problem.tolerances().0],
            r => r.to_vec(),
        };
        let modes = modes(spec);
        for method in &methods {
            if let Some(m) = method {
                problem.set_method(*m);
            }
            let method_name = problem.method().name();
            for &rtol in &rtols {
                problem.set_tolerance(rtol);
                for (x, reference) in designs.iter().zip(&refs) {
                    let load = load_average();
                    let (warm, timed) = time_design(&mut problem, x, &modes, spec.repeats)?;
                    let name = inner.name();
                    let case = Case {
                        problem: &name,
                        method: method_name,
                        rtol,
                        x,
                    };
                    for (((mode, ..), runs), e) in modes.iter().zip(&timed).zip(&warm) {
                        let per_f = median(
                            runs.iter()
                                .zip(&timed[0])
                                .map(|(a, f)| a.profile.total_seconds / f.profile.total_seconds)
                                .collect(),
                        );
                        let err = reference.as_ref().map_or([None; 3], |r| errors(e, r));
                        let r = row(&case, (mode, load), (setup, per_f), runs, err);
                        progress(&r);
                        rows.push(r);
                    }
                }
            }
        }
    }
    Ok(rows)
}

/// Read `[eval_bench]` without running anything.
pub fn check(study: &Study) -> Result<EvalBenchSpec> {
    study.require_section("eval_bench", "the design-evaluation benchmark")
}

/// The `[eval_bench]` handler: run the section and write the CSV.
pub fn run_eval_bench_section(study: &Study, out: &Path, quiet: bool) -> Result<PathBuf> {
    let spec = check(study)?;
    let rows = run_eval_bench(study, &spec, |r| {
        if !quiet {
            println!("{}", r.join(", "));
        }
    })?;
    let path = study.output_dir(out)?.join("eval_bench.csv");
    let mut table = Table::new(&path);
    table.row(HEADERS)?;
    for r in &rows {
        table.row(r)?;
    }
    let path = table.finish()?;
    if !quiet {
        println!("wrote {}", path.display());
    }
    Ok(path)
}
