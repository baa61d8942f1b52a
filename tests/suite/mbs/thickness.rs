//! Ply thickness as a scene sensitivity parameter
//! (`<body>.design.thickness_<plies>`): the swung centre-clamped panel of
//! `mbs/flex/sensitivities.rs`, its strain energy and modal coordinates at 0.4 s
//! differentiated along the thickness of ply 1 (stiffness and mass both
//! move), against central differences of whole simulations with the
//! basis rebuilt at t ± h.
use plyscape::scene::load_scene;
use plyscape::simulate::simulate;
use plyscape::study::Study;

fn scene(t1: f64, sens: &str) -> String {
    format!(
        r#"
[[panels]]
name = "p"
length = 1.0
width = 0.6
divisions = 6
support = "centre_clamp"
design = [[1, 4], [2, 3]]
material = {{ e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }}
plies = [{{ angle = 30.0, thickness = {t1:?} }}, {{ angle = -45.0, thickness = 0.5e-3 }}, {{ angle = -45.0, thickness = 0.5e-3 }}, {{ angle = 30.0, thickness = 0.5e-3 }}]

[scene]
effects = ["flexibility", "quadratic_velocity"]
sensitivities = [{sens}]
[[scene.bodies]]
name = "hub"
mass = 0.5
com = [0.0, 0.0, 0.0]
inertia = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]]
[[scene.bodies]]
name = "panel"
flexible = {{ kind = "panel", panel = "p", modes = 4, origin = [0.0, 0.5, 0.0], derivatives = "updated", rigid_limit = 1.0 }}
[[scene.joints]]
name = "hinge"
type = "driven"
body_i = "ground"
body_j = "hub"
point = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
drive = [0.0, 0.0, 1.0]
[[scene.joints]]
name = "mount"
type = "fixed"
body_i = "hub"
body_j = "panel"
point = [0.0, 0.5, 0.0]
axis = [0.0, 0.0, 1.0]
[scene.integrator]
method = "bdf"
rtol = 1e-10
atol = 1e-13
t_end = 0.4
dt_out = 0.1
[scene.outputs]
quantities = ["panel.strain_energy", "panel.modal"]
"#
    )
}

/// Step 2e-8 m on a 0.5 mm ply (truncation ~(h/t)² ≈ 2e-9); measured
/// 8.0e-9 of the largest sensitivity (2-core VM, 2026-11-27), bound 4×.
#[test]
fn thickness_sensitivities_of_the_swung_panel_match_central_differences() {
    let t = 0.5e-3;
    let run = |t1: f64, sens: &str| {
        let study = Study::parse("thick.toml", &scene(t1, sens)).unwrap();
        simulate(&load_scene(&study).unwrap()).unwrap().1
    };
    let base = run(t, r#""panel.design.thickness_1""#);
    let h = 2e-8;
    let (p, m) = (run(t + h, ""), run(t - h, ""));
    let last = base.rows.len() - 1;
    let cols = base.headers.len() - 1;
    let scale = (0..cols)
        .map(|c| base.sens_rows[last][1 + c].abs())
        .fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for c in 0..cols {
        let fd = (p.rows[last][1 + c] - m.rows[last][1 + c]) / (2.0 * h);
        let an = base.sens_rows[last][1 + c];
        println!("{}: analytic {an:e}, FD {fd:e}", base.headers[1 + c]);
        worst = worst.max((fd - an).abs() / scale);
    }
    println!("worst relative error {worst:e}");
    assert!(worst < 3.2e-8, "sensitivity error {worst:e}");
}
