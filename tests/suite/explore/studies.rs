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
    // explore::problems::Periodic2).
    for (file, f_star, tol) in [
        ("studies/himmelblau.toml", 0.0, 1e-6),
        // MMFD may end with the active constraints violated by up to DOT's
        // CTMIN = 3e-3, which lowers f by up to (λ1 + λ2) CTMIN = 4e-3 to
        // first order (multipliers λ1 = λ2 = 2/3 at (1, 1), from
        // ∇f + λ1 ∇g1 + λ2 ∇g2 = 0, derived here); 5e-3 allows second order.
        ("studies/hs_constrained.toml", 1.0, 5e-3),
        ("studies/periodic2.toml", -5.0, 1e-6),
    ] {
        let s = run(file, &dir);
        let d = dir.join(s.name());
        for f in [
            "runs.csv",
            "optima.csv",
            "evolution.csv",
            "comparison.csv",
            "map.csv",
            "map.svg",
            "convergence.svg",
            "manifest.json",
        ] {
            assert!(d.join(f).exists(), "{file}: {f}");
        }
        let t = table_without(&d.join("comparison.csv"), &[]);
        for (m, f) in column(&t, "method").iter().zip(column(&t, "best_f")) {
            let f: f64 = f.parse().unwrap();
            assert!((f - f_star).abs() <= tol, "{file} {m}: f = {f}");
        }
        assert_eq!(column(&t, "feasible"), ["true", "true"], "{file}");
        // One feasibility tolerance for both methods, stated in the table,
        // and every best design within it.
        let tols = column(&t, "feasibility_tolerance");
        assert_eq!(tols[0], tols[1], "{file}");
        let tol_g: f64 = tols[0].parse().unwrap();
        for g in column(&t, "max_g").iter().filter(|g| !g.is_empty()) {
            assert!(g.parse::<f64>().unwrap() <= tol_g, "{file}: max_g = {g}");
        }
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
        assert_eq!(s.table[key], o.table[key], "{key}");
    }
    assert_eq!((s.meta.seed, s.meta.threads), (o.meta.seed, Some(2)));
    let ms = plyscape::explore::multistart_section(&s).unwrap();
    assert_eq!(
        (ms.method, ms.sampler),
        (
            plyscape::explore::solvers::LocalMethod::Mmfd,
            plyscape::explore::sampling::Sampler::Lhs
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
