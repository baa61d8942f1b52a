//! The shipped analytic studies run end to end through `plyscape run`.

use crate::common::explore::{column, table_without};
use crate::common::temp_dir;
use plyscape::cli::{run_study, RunConfig};
use plyscape::study::Study;

fn run(file: &str, out: &std::path::Path) -> Study {
    let study = Study::load(file).unwrap();
    let cfg = RunConfig {
        study: study.clone(),
        out: out.to_path_buf(),
        threads: 2,
        quiet: true,
        force: false,
        resume: false,
    };
    run_study(&cfg).unwrap_or_else(|e| panic!("{file}: {e}"));
    study
}

#[test]
fn analytic_studies_run_and_find_their_known_optima() {
    let tmp = temp_dir("studies");
    let dir = tmp.path().to_path_buf();
    // Known optima: Himmelblau f* = 0 (Himmelblau 1972); HS 22 f* = 1 at
    // (1, 1) (Hock & Schittkowski 1981); Periodic2 f* = -5 (closed form in
    // explore::problem::problems::Periodic2).
    for (file, f_star, tol) in [
        ("studies/himmelblau.toml", 0.0, 1e-6),
        ("studies/hs_constrained.toml", 1.0, 1e-6),
        ("studies/periodic2.toml", -5.0, 1e-6),
    ] {
        let s = run(file, &dir);
        let d = dir.join(s.name());
        for f in [
            "runs.csv",
            "optima.csv",
            "run_classes.csv",
            "evolution.csv",
            "comparison.csv",
            "map.csv",
            "map.svg",
            "convergence.svg",
            "manifest.json",
        ] {
            assert!(d.join(f).exists(), "{file}: {f}");
        }
        // The best certified optimum: f* to 1e-6 at max g <= 1e-6 (the
        // study's feasibility tolerance, the default).
        let o = table_without(&d.join("optima.csv"), &[]);
        let best: f64 = column(&o, "f")[0].parse().unwrap();
        assert!(
            best >= f_star - tol && best <= f_star + tol,
            "{file}: {best}"
        );
        if let Some(g) = column(&o, "max_g").first().filter(|g| !g.is_empty()) {
            assert!(g.parse::<f64>().unwrap() <= 1e-6, "{file}: {g}");
        }
        // comparison.csv: every method on both bases; every strictly
        // feasible row (max g <= 0) at f* (none below it: no method wins on
        // the tolerance), and CMA-ES has such a row.
        let t = table_without(&d.join("comparison.csv"), &[]);
        assert_eq!(
            column(&t, "basis"),
            ["tolerance", "strict", "tolerance", "strict"],
            "{file}"
        );
        let (methods, fs, gs) = (
            column(&t, "method"),
            column(&t, "best_f"),
            column(&t, "max_g"),
        );
        // A design within the tolerance may stand below f* by up to
        // (λ1 + λ2) · 1e-6 = 1.33e-6 on HS 22 (multipliers 2/3, 2/3 at (1, 1),
        // from ∇f + λ1 ∇g1 + λ2 ∇g2 = 0); a strictly feasible one may not.
        for k in 0..methods.len() {
            let f: f64 = fs[k].parse().unwrap();
            assert!(f >= f_star - 2e-6, "{file} {}: f = {f}", methods[k]);
            let strict = gs[k].is_empty() || gs[k].parse::<f64>().unwrap() <= 0.0;
            if strict {
                assert!((f - f_star).abs() <= tol, "{file} {}: f = {f}", methods[k]);
            }
        }
        let cmaes_strict = (0..methods.len()).any(|k| {
            methods[k].starts_with("cmaes")
                && !fs[k].is_empty()
                && (gs[k].is_empty() || gs[k].parse::<f64>().unwrap() <= 0.0)
        });
        assert!(cmaes_strict, "{file}: CMA-ES has a strictly feasible row");
        assert_eq!(column(&t, "feasible"), ["true"; 4], "{file}");
        // One feasibility tolerance for both methods, stated in the table.
        let tols = column(&t, "feasibility_tolerance");
        assert!(tols.iter().all(|t| t == "1e-6"), "{file}: {tols:?}");
        // The manifest keeps every step `plyscape run` did.
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("manifest.json")).unwrap())
                .unwrap();
        for c in ["multistart", "evolve", "map"] {
            assert!(m["commands"][c].is_object(), "{file}: {c}");
        }
    }
    // The timing studies are valid (they are run by hand: ~20 s each).
    for file in [
        "studies/multistart_cost.toml",
        "studies/multistart_sleep.toml",
    ] {
        let s = Study::load(file).unwrap();
        let p = plyscape::explore::problem(&s).unwrap();
        let plan = plyscape::explore::multistart_plan(&s, p.as_ref()).unwrap();
        assert_eq!(plan.starts.points.len(), 64);
    }
}

/// Every study in `studies/` passes the whole-study check `plyscape run`
/// does before any work (so the check refuses only what is wrong).
#[test]
fn every_shipped_study_passes_the_upfront_check() {
    let mut n = 0;
    for e in std::fs::read_dir("studies").unwrap() {
        let path = e.unwrap().path();
        if path.extension().and_then(|x| x.to_str()) != Some("toml") {
            continue;
        }
        let s = Study::load(&path).unwrap();
        plyscape::cli::check_sections(&s).unwrap();
        plyscape::cli::check_study(&s).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        n += 1;
    }
    assert!(n >= 20, "{n} studies");
}

/// Table `key` of `s`, with the scene problem's constraints'
/// `critical_points` left out (sar_explore bounds two critical points of
/// peak U3: the same feasible set as the peak alone) and its `rtol` (the
/// evaluations' accuracy: sar_optimize chooses it from the measured noise,
/// `rtol = "auto"`; sar_explore keeps the scene's rtol 1e-6 of its
/// committed sweep).
fn section_without_critical_points(s: &Study, key: &str) -> toml::Value {
    let mut t = s.table[key].clone();
    if let Some(table) = t.as_table_mut() {
        table.remove("rtol");
    }
    if let Some(cs) = t.get_mut("constraints").and_then(|c| c.as_array_mut()) {
        for c in cs.iter_mut().filter_map(|c| c.as_table_mut()) {
            c.remove("critical_points");
        }
    }
    t
}

/// `studies/sar_explore.toml` is the sar_optimize problem on the same
/// scene, explored with the paper's start plus 63 Latin-hypercube starts,
/// both CMA-ES schedules and a 19 x 19 map on two threads. (The study
/// itself takes minutes of both cores and is run by hand.)
#[test]
fn sar_explore_is_sar_optimize_with_64_starts_and_both_schedules() {
    use plyscape::optimize::cmaes::Restarts;
    let s = Study::load("studies/sar_explore.toml").unwrap();
    let o = Study::load("studies/sar_optimize.toml").unwrap();
    for key in ["problem", "scene_problem", "scene", "panels"] {
        assert_eq!(
            section_without_critical_points(&s, key),
            section_without_critical_points(&o, key),
            "{key}"
        );
    }
    assert_eq!((s.meta.seed, s.meta.threads), (o.meta.seed, Some(2)));
    let ms = plyscape::explore::multistart_section(&s).unwrap();
    assert_eq!(
        (ms.method, ms.sampler),
        (
            plyscape::explore::local::solvers::LocalMethod::Mmfd,
            plyscape::explore::multistart::sampling::Sampler::Lhs
        )
    );
    assert_eq!(ms.points, [[55.0, -55.0]]);
    assert_eq!(ms.points.len() + ms.starts, 64);
    let ev = plyscape::explore::evolve_plan(&s).unwrap();
    assert_eq!(ev.schedules, [Restarts::Ipop, Restarts::Bipop]);
    // No budget of its own: under [compare] the multistart's calls.
    assert_eq!(ev.section.max_evaluations, None);
    assert!(s.has("compare"));
    assert_eq!(plyscape::explore::map_section(&s).unwrap().resolution, 19);
}

/// `studies/sar_discrete.toml` is sar_explore's problem and scene on the
/// 15° set from −75° to 90° (12 values per angle), with a ±2° robustness
/// check. (The study takes minutes and is run by hand; results in
/// results/sar_discrete/.)
#[test]
fn sar_discrete_is_sar_explore_on_15_degree_steps() {
    let s = Study::load("studies/sar_discrete.toml").unwrap();
    let e = Study::load("studies/sar_explore.toml").unwrap();
    for key in ["problem", "scene_problem", "scene", "panels"] {
        assert_eq!(
            s.table[key],
            section_without_critical_points(&e, key),
            "{key}"
        );
    }
    let d = plyscape::explore::discrete::lattice::section(&s)
        .unwrap()
        .unwrap();
    let set: Vec<f64> = (0..12).map(|k| -75.0 + 15.0 * k as f64).collect();
    assert_eq!(d.variables.len(), 2);
    for v in &d.variables {
        assert_eq!(v.values.as_deref(), Some(&set[..]), "{}", v.name);
    }
    let r = plyscape::explore::multistart::robustness::section(&s)
        .unwrap()
        .unwrap();
    assert_eq!(r.tolerance, [2.0, 2.0]);
}
