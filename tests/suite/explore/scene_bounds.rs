//! Absolute constraint bounds of a scene problem
//! (`[[scene_problem.constraints]] upper`, `lower`, explore::problem::scene_bounds)
//! on a frequency-only problem (no integration): a free composite panel
//! whose outer ply angle is the variable. Maximizing the first frequency
//! (minimizing −f1) under `upper = U` ends on the bound, minimizing it
//! under `lower = L` too; bad bounds are refused with their key.

use crate::common::explore::{ctx, study};
use crate::common::temp_dir;
use plyscape::explore::{self, DriveFlags};

/// The study: the panel's plies [θ, 45, −45, 90], θ in [20, 75]°, the
/// objective `objective` (a response), and `constraint` (a TOML table
/// body for `[[scene_problem.constraints]]`).
fn text(objective: &str, constraint: &str) -> String {
    format!(
        r#"
[study]
name = "bounds"
seed = 3

[problem]
name = "scene"

[[panels]]
name = "p"
length = 1.0
width = 0.6
divisions = 4
support = "free_free"
design = [[1], [2], [3], [4]]
material = {{ e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }}
plies = [{{ angle = 0.0, thickness = 0.25e-3 }}, {{ angle = 45.0, thickness = 0.25e-3 }}, {{ angle = -45.0, thickness = 0.25e-3 }}, {{ angle = 90.0, thickness = 0.25e-3 }}]

[scene]
effects = ["flexibility"]
sensitivities = ["panel.design.theta_1"]

[[scene.bodies]]
name = "panel"
flexible = {{ kind = "panel", panel = "p", modes = 2, origin = [0.0, 0.0, 0.0], derivatives = "updated" }}

[[scene.responses]]
name = "f1"
kind = "frequency"
of = ["panel"]
mode = 1

[[scene.responses]]
name = "neg_f1"
kind = "frequency"
of = ["panel"]
mode = 1
scale = -1.0

[scene.integrator]
t_end = 0.01
dt_out = 0.01

[scene_problem]
start = [45.0]

[[scene_problem.variables]]
name = "theta1_deg"
bounds = [20.0, 75.0]
sets = ["p:theta_1"]

[scene_problem.objective]
response = "{objective}"

[[scene_problem.constraints]]
response = "f1"
{constraint}

[multistart]
method = "mmfd"
sampler = "lhs"
starts = 2
"#
    )
}

/// f1 over θ1 = 20, 25, .., 75° (no constraint needed: a lower bound far
/// below). f1 falls monotonically over this range (it has a local maximum
/// near 5° and a minimum near 80°, which the bounds leave out).
fn sweep() -> Vec<f64> {
    let s = study("bounds", &text("f1", "lower = 0.001"));
    let p = explore::problem(&s).unwrap();
    (0..=11)
        .map(|k| p.evaluate(&[20.0 + 5.0 * k as f64], false).unwrap().f)
        .collect()
}

#[test]
fn absolute_bounds_are_reached_by_the_optimum() {
    let f = sweep();
    let (lo, hi) = f
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    println!("f1 over θ1 = 20..75°: {f:?}");
    assert!(f.windows(2).all(|w| w[1] < w[0]), "{f:?}");
    assert!(hi > 1.02 * lo, "the ply angle must move f1: {f:?}");
    let mid = 0.5 * (lo + hi);
    // Maximize f1 (minimize −f1) under f1 ≤ mid, minimize f1 under
    // f1 ≥ mid: both optima lie on the bound.
    for (objective, constraint, sign) in [
        ("neg_f1", format!("upper = {mid:?}"), -1.0),
        ("f1", format!("lower = {mid:?}"), 1.0),
    ] {
        let tmp = temp_dir("scene-bounds");
        let s = study("bounds", &text(objective, &constraint));
        let r = explore::run_multistart(&ctx(&s, tmp.path(), 1, DriveFlags::default())).unwrap();
        for o in &r.optima {
            println!(
                "optimum {:?}: f {}, g {:?}, feasible {}",
                o.x, o.f, o.g, o.feasible
            );
        }
        let best = r
            .optima
            .iter()
            .filter(|o| o.feasible)
            .min_by(|a, b| a.f.total_cmp(&b.f))
            .expect("a feasible optimum");
        let f1 = sign * best.f;
        println!(
            "{objective} with {constraint}: θ1 = {:?}, f1 = {f1} Hz, g = {:?}",
            best.x, best.g
        );
        // On the bound to MMFD's feasibility tolerance (1e-5 of the
        // bound, the normalization) plus its convergence in f.
        assert!((f1 - mid).abs() < 1e-3 * mid, "{f1} vs bound {mid}");
        assert!(best.g[0].abs() < 1e-3, "{:?}", best.g);
    }
}

#[test]
fn bad_absolute_bounds_are_refused_with_their_key() {
    for (constraint, key, detail) in [
        (
            "upper = 0.0",
            "scene_problem.constraints[0].upper",
            "a `scale` beside it",
        ),
        (
            "upper = 1.0\nlower = 2.0",
            "scene_problem.constraints[0].lower",
            "at most the upper bound",
        ),
        (
            "lower = 1.0\nscale = -1.0",
            "scene_problem.constraints[0].scale",
            "a finite scale > 0",
        ),
        ("scale = 1.0", "scene_problem.constraints[0]", "a bound"),
        (
            "lower = 1.0\ncritical_points = 2",
            "scene_problem.constraints[0].critical_points",
            "a `peak` response",
        ),
        (
            "upper = 1.0\nupper_relative = 1.0",
            "scene_problem.constraints[0]",
            "exactly one",
        ),
    ] {
        let s = study("bounds", &text("f1", constraint));
        let e = explore::problem(&s).err().expect(key).to_string();
        println!("{e}");
        assert!(e.contains(&format!("`{key}`")) && e.contains(detail), "{e}");
    }
}
