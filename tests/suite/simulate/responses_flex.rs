//! Natural frequencies as responses (`kind = "frequency"`): against the
//! closed-form cantilever frequency, and the first frequency of a
//! composite panel hinged about an edge and its ply-angle derivative
//! against central differences of the panel's modal analysis.
use plyscape::scene::load_scene;
use plyscape::study::Study;

/// A 1 m × 0.6 m four-ply panel (free–free, 4 modes, ply 1 at `ply1`
/// degrees), hinged to ground along its edge x = −0.5 (a revolute joint
/// about y at one corner, a spherical joint at the other) and turned from
/// flat by a torsion spring of stiffness `k` toward 1.5 rad, damped; no
/// gravity. `tip` is the far corner.
fn panel(k: f64, ply1: f64) -> String {
    format!(
        r#"
[study]
name = "deploy"

[[panels]]
name = "p"
length = 1.0
width = 0.6
divisions = 6
support = "free_free"
design = [[1], [2], [3], [4]]
material = {{ e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }}
plies = [{{ angle = {ply1:?}, thickness = 0.25e-3 }}, {{ angle = 45.0, thickness = 0.25e-3 }}, {{ angle = -45.0, thickness = 0.25e-3 }}, {{ angle = 90.0, thickness = 0.25e-3 }}]

[scene]
effects = ["flexibility", "quadratic_velocity", "springs"]
sensitivities = ["drive.stiffness", "panel.design.theta_1"]

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
stiffness = {k:?}
angle = 1.5
damping = 0.02

[[scene.responses]]
name = "tip_peak"
kind = "peak"
of = ["tip.deflection_z"]

[[scene.responses]]
name = "strain_at"
kind = "value_at"
of = ["panel.strain_energy"]
time = 0.3

[[scene.responses]]
name = "strain_min"
kind = "peak"
sense = "min"
of = ["panel.strain_energy"]

[[scene.responses]]
name = "deploy_time"
kind = "crossing"
of = ["hinge.angle"]
level = 1.0

[[scene.responses]]
name = "f1"
kind = "frequency"
of = ["panel"]
mode = 1

[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 0.6
dt_out = 0.01
"#
    )
}

#[test]
fn panel_frequency_gradient_matches_central_differences() {
    // f1 of the free–free panel and df1/dθ1 (eigenvalue derivative of the
    // modal analysis, per radian) against central differences of the
    // frequency with the basis rebuilt at θ1 ± 0.01°; no integration.
    let f1 = |ply1: f64| {
        let study = Study::parse("deploy.toml", &panel(4.0, ply1)).unwrap();
        let scene = load_scene(&study).unwrap();
        let f = plyscape::simulate::sampled::frequencies(&scene).unwrap();
        assert_eq!(f.len(), 1);
        f[0].clone()
    };
    let base = f1(0.0);
    let h = 0.01f64;
    let fd = (f1(h).value - f1(-h).value) / (2.0 * h.to_radians());
    let err = (base.gradient[1] - fd).abs() / fd.abs();
    println!(
        "f1 {} Hz, df1/dθ1 {:e} Hz/rad, central difference {fd:e}, error {err:.1e}",
        base.value, base.gradient[1]
    );
    assert_eq!(
        base.gradient[0], 0.0,
        "the spring does not move a frequency"
    );
    assert!(err < 1e-6, "{err:e}");
}

#[test]
fn frequency_of_a_cantilever_beam_is_the_closed_form() {
    // Euler–Bernoulli cantilever: ω_1 = (β₁L)² √(EI/(ρA L⁴)),
    // β₁L = 1.875104068711961 (root of cos x cosh x = −1; Blevins,
    // Formulas for Natural Frequency and Mode Shape, Table 8-1). EI = 100
    // N·m² about y and 150 about z, ρA = 1 kg/m, L = 1 m: the lowest mode
    // bends about the softer axis.
    let text = r#"
[scene]
effects = ["flexibility"]
[[scene.bodies]]
name = "beam"
mass = 1.0
com = [0.5, 0.0, 0.0]
inertia = [[0.001, 0.0, 0.0], [0.0, 0.08333333333333333, 0.0], [0.0, 0.0, 0.08333333333333333]]
flexible = { kind = "beam", modes = 4, origin = [0.0, 0.0, 0.0], length = 1.0, ei_y = 100.0, ei_z = 150.0, rho_a = 1.0, rho_ip = 0.001 }
[[scene.joints]]
name = "clamp"
type = "fixed"
body_i = "ground"
body_j = "beam"
point = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
[[scene.responses]]
name = "f1"
kind = "frequency"
of = ["beam"]
mode = 1
[[scene.responses]]
name = "f2"
kind = "frequency"
of = ["beam"]
mode = 2
[scene.integrator]
t_end = 0.01
dt_out = 0.01
"#;
    let scene = crate::common::scenes::scene(text);
    let f = plyscape::simulate::sampled::frequencies(&scene).unwrap();
    let b1 = 1.875104068711961f64;
    let hz = |ei: f64| b1 * b1 * ei.sqrt() / (2.0 * std::f64::consts::PI);
    println!(
        "f1 {} Hz ({}), f2 {} Hz ({})",
        f[0].value,
        hz(100.0),
        f[1].value,
        hz(150.0)
    );
    assert_eq!(f[0].unit, "Hz");
    assert!((f[0].value - hz(100.0)).abs() < 1e-9 * hz(100.0));
    assert!((f[1].value - hz(150.0)).abs() < 1e-9 * hz(150.0));
    // A mode beyond the basis is refused with the range.
    let bad = text.replace("mode = 2", "mode = 5");
    let table: toml::Table = toml::from_str(&bad).unwrap();
    let spec: plyscape::scene::SceneSpec = table["scene"].clone().try_into().unwrap();
    let e = spec.build().err().unwrap().to_string();
    assert!(
        e.contains("responses[1].mode") && e.contains("from 1 to 4"),
        "{e}"
    );
}
