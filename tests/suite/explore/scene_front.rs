//! `[front]` on a scene (`[problem] name = "scene"`, explore::problem::scene_front)
//! and `[front] grid`: the objectives written in front.csv are the
//! responses of a direct simulation of each design, in their units; the
//! grid's hypervolume row against a closed form.

use crate::common::explore::{column, study, table_without};
use crate::common::sar::{coarse_sar, replace};
use crate::common::temp_dir;
use plyscape::cli::{run_study, RunConfig};
use plyscape::explore::problem::scene_problem::SceneProblem;
use plyscape::study::Study;

fn run(study: &Study, out: &std::path::Path) {
    let cfg = RunConfig {
        study: study.clone(),
        out: out.to_path_buf(),
        threads: 2,
        quiet: true,
        force: false,
        resume: false,
    };
    run_study(&cfg).unwrap_or_else(|e| panic!("{}: {e}", study.path.display()));
}

/// The SAR front on both panels flexible (the scene, variables and
/// normalisation of studies/sar_optimize.toml, its constraint and
/// drivers replaced by a small `[front]`: one subproblem, NSGA-II on 8
/// evaluations, a 3 × 3 grid), made coarse (4 mesh divisions, 2 modes per
/// panel, 0–0.5 s). studies/sar_front.toml itself has panel 2 rigid.
fn small_sar_front() -> String {
    let text = std::fs::read_to_string("studies/sar_optimize.toml").unwrap();
    let text = coarse_sar(&text, 4, 2);
    let text = replace(&text, "rtol = \"auto\"\n", "", 1);
    let (before, rest) = text.split_once("[[scene_problem.constraints]]\n").unwrap();
    let (_, after) = rest.split_once("\n[scene]\n").unwrap();
    let front = "[front]\nobjectives = [{ name = \"psi0\" }, { name = \"u3_peak\" }]\n\
                 subproblems = 1\npopulation = 4\nevaluations = 8\n\
                 reference_relative = [1.2, 1.2]\ngrid = 3\nfeasibility_tolerance = 1e-5\n";
    let text = format!("{before}{front}\n[scene]\n{after}");
    replace(
        &text,
        "name = \"sar_optimize\"",
        "name = \"small_front\"",
        1,
    )
}

#[test]
fn scene_front_values_are_the_responses_of_a_direct_simulation() {
    let tmp = temp_dir("scene-front");
    let s = study("small_front", &small_sar_front());
    run(&s, tmp.path());
    let dir = tmp.path().join("small_front");
    let front = table_without(&dir.join("front.csv"), &[]);
    assert_eq!(
        front[0],
        [
            "method",
            "x_theta1_deg",
            "x_theta2_deg",
            "psi0 [J*s]",
            "u3_peak [J]"
        ]
    );
    let summary = table_without(&dir.join("front_summary.csv"), &["wall_seconds"]);
    assert_eq!(
        column(&summary, "method"),
        ["mmfd-tchebycheff", "nsga2", "grid"]
    );
    assert_eq!(column(&summary, "function_calls")[2], "9");
    // Every method's designs, simulated again directly: the same responses
    // (written as f·|R(x_n)| from f = R/|R(x_n)|, so to a few ulps). A
    // design whose cached evaluation came from a simulation with gradients
    // carries that simulation's values, and a simulation with sensitivity
    // lanes is not bit-identical to one without (5.6e-12 relative apart
    // on this scene at rtol 1e-10).
    let problem = SceneProblem::from_study(&s).unwrap();
    let names = ["psi0".to_string(), "u3_peak".to_string()];
    let simulate = |x: &[f64], g: bool| problem.evaluate_with(x, g, &names).unwrap().1.values;
    let direct = |x: &[f64]| simulate(x, false);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs();
    let methods: Vec<&str> = front[1..].iter().map(|r| r[0].as_str()).collect();
    for m in ["mmfd-tchebycheff", "nsga2", "grid"] {
        assert!(methods.contains(&m), "{m} has no point: {methods:?}");
    }
    for row in &front[1..] {
        let v: Vec<f64> = row[1..].iter().map(|v| v.parse().unwrap()).collect();
        let same = |r: &[f64]| close(v[2], r[0]) && close(v[3], r[1]);
        let (r, rg) = (direct(&v[..2]), simulate(&v[..2], true));
        assert!(same(&r) || same(&rg), "{row:?} vs {r:?} or {rg:?}");
    }
    // The reference point: 1.2 × the start design's (55/−55) responses
    // (its cached evaluation may be the gradient side's, with gradients).
    let start = [55.0, -55.0];
    let (r, rg) = (direct(&start), simulate(&start, true));
    for (k, name) in names.iter().enumerate() {
        let col = column(&summary, &format!("reference_{name}"));
        let v: f64 = col[0].parse().unwrap();
        assert!(
            close(v, 1.2 * r[k]) || close(v, 1.2 * rg[k]),
            "{name}: {v} vs 1.2 × {} or 1.2 × {}",
            r[k],
            rg[k]
        );
    }
    // The grid: 3 values per periodic axis without the duplicate end.
    let grid = table_without(&dir.join("grid.csv"), &[]);
    assert_eq!(grid.len(), 10);
    assert_eq!(
        grid[0][..4],
        ["x_theta1_deg", "x_theta2_deg", "psi0 [J*s]", "u3_peak [J]"]
    );
    let t1: Vec<&str> = grid[1..].iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        t1,
        ["-90", "-90", "-90", "-30", "-30", "-30", "30", "30", "30"]
    );
    assert!(dir.join("front.svg").exists() && dir.join("front_design.svg").exists());
}

/// DTLZ2 (Deb et al. 2002) on the grid of 2 values per variable (12
/// variables, 4096 designs at 0 and 1): `g = Σ_{i≥3} (x_i − ½)² = 10/4`
/// for all, so every design lies on the sphere of radius 3.5, and the
/// non-dominated ones are the three corners (3.5, 0, 0), (0, 3.5, 0),
/// (0, 0, 3.5) (up to cos(π/2) ≈ 6e-17). Their hypervolume to (4, 4, 4)
/// by inclusion–exclusion: 3 boxes of 0.5·4·4 = 8, pairwise overlaps
/// 0.5·0.5·4 = 1, triple overlap 0.125: 24 − 3 + 0.125 = 21.125.
#[test]
fn grid_row_has_the_hypervolume_of_the_grid_front() {
    let tmp = temp_dir("grid-front");
    let text = "[problem]\nname = \"dtlz2\"\n[front]\n\
                objectives = [{ name = \"f1\" }, { name = \"f2\" }, { name = \"f3\" }]\n\
                subproblems = 3\npopulation = 8\nevaluations = 16\n\
                reference = [4.0, 4.0, 4.0]\ngrid = 2\n";
    let s = study("dgrid", text);
    run(&s, tmp.path());
    let summary = table_without(
        &tmp.path().join("dgrid/front_summary.csv"),
        &["wall_seconds"],
    );
    let grid = &summary[3];
    assert_eq!(grid[0], "grid");
    assert_eq!(column(&summary, "function_calls")[2], "4096");
    let hv: f64 = column(&summary, "hypervolume")[2].parse().unwrap();
    assert!((hv - 21.125).abs() < 1e-12, "{hv}");
    assert!(!tmp.path().join("dgrid/front_design.svg").exists());
}

#[test]
fn scene_front_input_errors_name_the_key() {
    let text = small_sar_front();
    let err = |t: &str| {
        plyscape::explore::front::command::check(&study("bad", t))
            .err()
            .unwrap()
            .to_string()
    };
    let e = err(&replace(
        &text,
        "{ name = \"u3_peak\" }",
        "{ name = \"u3\" }",
        1,
    ));
    assert!(
        e.contains("front.objectives[1].name") && e.contains("psi0, u3_peak"),
        "{e}"
    );
    let e = err(&replace(&text, "grid = 3", "grid = 1", 1));
    assert!(e.contains("front.grid"), "{e}");
    let e = err(&replace(
        &text,
        "reference_relative = [1.2, 1.2]",
        "reference_relative = [1.2, 1.2]\nreference = [1.0, 1.0]",
        1,
    ));
    assert!(e.contains("front.reference_relative"), "{e}");
    let e = err(&replace(
        &text,
        "reference_relative = [1.2, 1.2]",
        "reference_relative = [-1.0, 1.2]",
        1,
    ));
    assert!(
        e.contains("front.reference_relative") && e.contains("positive factors"),
        "{e}"
    );
    // critical_points: on a peak of sense max, minimized, 1 to 16.
    let pieces = |a: &str, b: &str| {
        let objectives = format!("[{{ name = \"psi0\"{a} }}, {{ name = \"u3_peak\"{b} }}]");
        err(&replace(
            &text,
            "[{ name = \"psi0\" }, { name = \"u3_peak\" }]",
            &objectives,
            1,
        ))
    };
    let e = pieces(", critical_points = 2", "");
    assert!(
        e.contains("front.objectives[0].critical_points") && e.contains("`peak` response"),
        "{e}"
    );
    let e = pieces("", ", critical_points = 0");
    assert!(
        e.contains("front.objectives[1].critical_points") && e.contains("1 to 16"),
        "{e}"
    );
    let e = pieces("", ", critical_points = 2, goal = \"maximize\"");
    assert!(
        e.contains("front.objectives[1].critical_points") && e.contains("minimized"),
        "{e}"
    );
    let ok = replace(
        &text,
        "{ name = \"u3_peak\" }",
        "{ name = \"u3_peak\", critical_points = 2 }",
        1,
    );
    plyscape::explore::front::command::check(&study("ok", &ok)).unwrap();
}
