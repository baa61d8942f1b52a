//! Discrete designs (`[discrete]`): every method ends on the set, and the
//! exhaustive enumeration finds the known discrete optimum.

use crate::common::explore::{column, ctx, study, table_without};
use crate::common::temp_dir;
use plyscape::explore::discrete::command::run_discrete;
use plyscape::explore::{self, DriveFlags};

/// `h(d; ε) = −cos 2d − ε cos 4d` of the periodic2 problem
/// (`explore::problem::problems::Periodic2`, d in degrees here).
fn h(d: f64, eps: f64) -> f64 {
    let r = d.to_radians();
    -(2.0 * r).cos() - eps * (4.0 * r).cos()
}

/// periodic2 (f = h(θ₁ − 90°; 0.5) + 2 h(θ₂ + 30°; 0.75), continuous
/// minimum −5 at (±90, −30)) on θ₁ ∈ {−70, −20, 30, 80} and
/// θ₂ ∈ {−50, −5, 40, 85}. f is separable, so the discrete optimum takes
/// the best member of each set: θ₁ = 80 (d = −10°, the member nearest 90
/// on the circle), θ₂ = −50 (d = −20°); f = h(−10; 0.5) + 2 h(−20; 0.75)
/// = −3.1153 (closed form, evaluated below).
#[test]
fn exhaustive_rounding_and_cmaes_find_the_known_discrete_optimum() {
    let tmp = temp_dir("discrete-p2");
    let dir = tmp.path().to_path_buf();
    let text = "[study]\nname = \"d\"\nseed = 5\n[problem]\nname = \"periodic2\"\n\
                [multistart]\nstarts = 6\n\
                [discrete]\ncmaes_samples = 300\n\
                [[discrete.variables]]\nname = \"theta1_deg\"\nvalues = [-70.0, -20.0, 30.0, 80.0]\n\
                [[discrete.variables]]\nname = \"theta2_deg\"\nvalues = [85.0, -50.0, -5.0, 40.0]\n";
    let s = study("d", text);
    let c = ctx(&s, &dir, 2, DriveFlags::default());
    explore::run_multistart(&c).unwrap();
    let rows = run_discrete(&c).unwrap();
    let f_star = h(-10.0, 0.5) + 2.0 * h(-20.0, 0.75);
    assert!((f_star + 3.1153).abs() < 1e-4, "{f_star}");
    let set1 = [-70.0, -20.0, 30.0, 80.0];
    let set2 = [-50.0, -5.0, 40.0, 85.0];
    for r in &rows {
        assert!(
            set1.contains(&r.design.x[0]) && set2.contains(&r.design.x[1]),
            "{r:?} is off the set"
        );
    }
    let ex = rows.iter().find(|r| r.method == "exhaustive").unwrap();
    assert_eq!(ex.design.x, [80.0, -50.0]);
    assert!((ex.design.f - f_star).abs() < 1e-12, "{ex:?}");
    assert_eq!(ex.evaluations, 16);
    // The global continuous optimum (±90, −30) rounds to it directly; the
    // polish of every optimum ends where no neighbour improves, and
    // CMA-ES on the set finds it too.
    let best_polished = rows
        .iter()
        .filter(|r| r.method == "rounded_polished")
        .map(|r| r.design.f)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(best_polished, ex.design.f);
    let cma = rows.iter().find(|r| r.method == "cmaes_discrete").unwrap();
    assert_eq!(cma.design.x, [80.0, -50.0], "{cma:?}");
    assert!(
        cma.evaluations <= 16 && cma.samples > cma.evaluations,
        "{cma:?}"
    );
    // The tables: one row per method and optimum, 16 grid designs.
    let t = table_without(&dir.join("d/discrete.csv"), &[]);
    assert_eq!(t.len(), 1 + rows.len());
    assert_eq!(column(&t, "method")[0], "exhaustive");
    let g = table_without(&dir.join("d/discrete_grid.csv"), &[]);
    assert_eq!(g.len(), 17);
}

/// HS 22 (f = (x₁−2)² + (x₂−1)², x₁ + x₂ ≤ 2, x₁² ≤ x₂) on
/// x₁ ∈ {0, 0.4, 0.8, 1.2, 1.6, 2}, x₂ ∈ {0.5, 1.1, 1.7}: by hand, the
/// feasible designs nearest (2, 1) are (0.8, 1.1) with f = 1.45 and
/// (0.4, 1.1) with 2.57; (1.2, 1.1) violates x₁ + x₂ ≤ 2 and (0.8, 0.5)
/// x₁² ≤ x₂. Every method ends on the set, feasible, at (0.8, 1.1).
#[test]
fn constrained_discrete_designs_are_feasible_and_on_the_set() {
    let tmp = temp_dir("discrete-hs22");
    let dir = tmp.path().to_path_buf();
    let text = "[study]\nname = \"c\"\nseed = 3\n[problem]\nname = \"hs22\"\n\
                [multistart]\nsampler = \"sobol\"\nstarts = 4\nfeasible_only = true\n\
                points = [[0.0, 1.0]]\n\
                [discrete]\ncmaes_samples = 400\n\
                [[discrete.variables]]\nname = \"x1\"\nvalues = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0]\n\
                [[discrete.variables]]\nname = \"x2\"\nvalues = [0.5, 1.1, 1.7]\n";
    let s = study("c", text);
    let c = ctx(&s, &dir, 2, DriveFlags::default());
    explore::run_multistart(&c).unwrap();
    let rows = run_discrete(&c).unwrap();
    assert!(rows.len() >= 4, "{rows:?}");
    for r in rows.iter().filter(|r| r.method != "rounded") {
        assert_eq!(r.design.x, [0.8, 1.1], "{r:?}");
        assert!((r.design.f - 1.45).abs() < 1e-12, "{r:?}");
        assert!(r.design.max_g() <= 0.0, "{r:?}");
    }
    // Without [multistart] the gradient route has nothing to round.
    let bad = study(
        "c",
        &text.replace("[multistart]", "[evolve]").replace(
            "sampler = \"sobol\"\nstarts = 4\nfeasible_only = true\npoints = [[0.0, 1.0]]\n",
            "",
        ),
    );
    let e = run_discrete(&ctx(&bad, &dir, 2, DriveFlags::default()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("[multistart]"), "{e}");
}

/// Every `[discrete]` set and the `[robustness]` length are checked with
/// the study, before any section runs (before, only after the whole
/// multistart): a periodic step that does not divide the period, a step
/// giving 1.8e11 values, an unknown variable, a tolerance list of the
/// wrong length, and a CMA-ES budget below one generation.
#[test]
fn discrete_sets_and_robustness_are_checked_before_anything_runs() {
    let base = "[study]\nname = \"p2\"\n[problem]\nname = \"periodic2\"\n\
                [multistart]\nstarts = 4\n";
    let var = |name: &str, step: &str| {
        format!("[[discrete.variables]]\nname = \"{name}\"\nstep = {step}\n")
    };
    for (extra, key, detail) in [
        (
            var("theta1_deg", "7.0"),
            "discrete.variables[0].step",
            "divides the period",
        ),
        (
            var("theta1_deg", "1e-9"),
            "discrete.variables[0].step",
            "at most 100000 values",
        ),
        (
            var("z", "15.0"),
            "discrete.variables[0].name",
            "a variable of the problem",
        ),
        (
            "[robustness]\ntolerance = [1.0]\n".to_string(),
            "robustness.tolerance",
            "2 tolerances",
        ),
        // Fewer designs than one CMA-ES generation (6 for 2 variables):
        // named with the section's own key, not CMA-ES's budget.
        (
            format!(
                "[discrete]\ncmaes_samples = 1\n{}",
                var("theta1_deg", "15.0")
            ),
            "discrete.cmaes_samples",
            "6 designs for 2 variables",
        ),
    ] {
        let s = study("p2", &format!("{base}{extra}"));
        let e = match plyscape::sections::registry::check_study(&s) {
            Ok(()) => panic!("{extra}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(key) && e.contains(detail), "{extra}: {e}");
    }
    // 15° steps divide the 180° period: accepted.
    let s = study("p2", &format!("{base}{}", var("theta1_deg", "15.0")));
    plyscape::sections::registry::check_study(&s).unwrap();
}
