//! Ply thickness as a scene sensitivity parameter
//! (`<body>.design.thickness_<plies>`): a thickness moves the panel's
//! stiffness and its mass, so the modal basis's eigenvalues, mode shapes
//! and node masses all carry derivatives, and every inertia invariant
//! (mass, first and second moments included) is differentiated. The
//! gradients of a strain-energy integral, a peak deflection and a
//! frequency against central differences of whole simulations with the
//! basis rebuilt at t ± h.
use plyscape::scene::load_scene;
use plyscape::simulate::simulate;
use plyscape::study::Study;

/// A 1 m × 0.6 m four-ply panel (free–free, 4 modes, plies [0/45/−45/90]
/// with ply 1 of thickness `t1`, plies 2, 3 of `t23` and ply 4 of 1 mm) hinged to
/// ground along its edge x = −0.5, turned by a torsion spring toward
/// 1.5 rad against gravity; `sens` lists the sensitivity parameters.
fn panel(t1: f64, t23: f64, sens: &str) -> String {
    format!(
        r#"
[study]
name = "thick"

[[panels]]
name = "p"
length = 1.0
width = 0.6
divisions = 6
support = "free_free"
design = [[1], [2], [3], [4]]
material = {{ e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }}
plies = [{{ angle = 0.0, thickness = {t1:?} }}, {{ angle = 45.0, thickness = {t23:?} }}, {{ angle = -45.0, thickness = {t23:?} }}, {{ angle = 90.0, thickness = 1.0e-3 }}]

[scene]
effects = ["flexibility", "quadratic_velocity", "springs"]
sensitivities = [{sens}]

[[scene.bodies]]
name = "panel"
flexible = {{ kind = "panel", panel = "p", modes = 4, origin = [0.0, 0.0, 0.0], derivatives = "updated" }}

[[scene.joints]]
name = "hinge"
type = "revolute"
body_i = "ground"
body_j = "panel"
point = [-0.5, -0.3, 0.0]
axis = [0.0, 1.0, 0.0]

[[scene.joints]]
name = "pin"
type = "spherical"
body_i = "ground"
body_j = "panel"
point = [-0.5, 0.3, 0.0]

[[scene.markers]]
name = "tip"
body = "panel"
point = [0.5, 0.3, 0.0]

[[scene.forces]]
type = "spring"
name = "drive"
joint = "hinge"
stiffness = 20.0
angle = 1.5
damping = 0.02

[[scene.responses]]
name = "psi0"
kind = "integral"
of = ["panel.strain_energy"]
scale = 2.0

[[scene.responses]]
name = "tip_peak"
kind = "peak"
of = ["tip.deflection_z"]

[[scene.responses]]
name = "f1"
kind = "frequency"
of = ["panel"]
mode = 1

[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 0.3
dt_out = 0.01
"#
    )
}

/// Strain-energy integral, peak tip deflection and first frequency, with
/// their gradients along the thickness of ply 1 (B' ≠ 0: membrane and
/// bending couple) and the common thickness of plies 2 and 3, against
/// central differences with step 4e-8 m on 1 mm plies (truncation
/// ~(h/t)² ≈ 2e-9; integration noise ~rtol/(h/t) ≈ 3e-6 of the value).
#[test]
fn thickness_gradients_of_a_scene_match_central_differences() {
    let (t1, t23) = (1.0e-3, 1.0e-3);
    let sens = r#""panel.design.thickness_1", "panel.design.thickness_2_3""#;
    let run = |t1: f64, t23: f64, sens: &str| {
        let study = Study::parse("thick.toml", &panel(t1, t23, sens)).unwrap();
        simulate(&load_scene(&study).unwrap()).unwrap().1
    };
    let base = run(t1, t23, sens);
    let h = 4e-8;
    let mut worst = [0.0f64; 3];
    for v in 0..2 {
        let (p, m) = if v == 0 {
            (run(t1 + h, t23, ""), run(t1 - h, t23, ""))
        } else {
            (run(t1, t23 + h, ""), run(t1, t23 - h, ""))
        };
        for (k, r) in base.responses.iter().enumerate() {
            let fd = (p.responses[k].value - m.responses[k].value) / (2.0 * h);
            let an = r.gradient[v];
            let rel = (an - fd).abs() / fd.abs();
            println!(
                "{} along variable {v}: analytic {an:e}, FD {fd:e}, relative {rel:.1e}",
                r.name
            );
            worst[k] = worst[k].max(rel);
        }
    }
    // Bounds about 3× the errors measured on the 2-core VM (2026-11-27).
    assert!(worst[0] < 3e-5, "psi0: {:e}", worst[0]);
    assert!(worst[1] < 3e-5, "tip_peak: {:e}", worst[1]);
    assert!(worst[2] < 1e-6, "f1: {:e}", worst[2]);
}

#[test]
fn tmp_angle_check() {
    let run = |a: f64, sens: &str| {
        let t = panel(1e-3, 1e-3, sens).replace("angle = 0.0, thickness", &format!("angle = {a:?}, thickness"));
        let study = Study::parse("thick.toml", &t).unwrap();
        simulate(&load_scene(&study).unwrap()).unwrap().1
    };
    let base = run(0.0, r#""panel.design.theta_1""#);
    let h = 1e-3f64;
    let (p, m) = (run(h, ""), run(-h, ""));
    for (k, r) in base.responses.iter().enumerate() {
        let fd = (p.responses[k].value - m.responses[k].value) / (2.0 * h.to_radians());
        println!("ANGLE {}: analytic {:e}, FD {fd:e}", r.name, r.gradient[0]);
    }
}
