//! Geometric stiffening by the joint loads (`plyscape::mbs::model::geometric`,
//! "Joint-load prestress"; the solve in `plyscape::mbs::constraints::prestress`):
//! a cantilever pulled (or pushed) at its tip through a spherical joint.

use crate::common::scenes::{column, run};

/// A cantilever (L = 1 m, EI = 1 N·m², ρA = 1 kg/m, both planes, `modes`
/// modes) clamped to ground at its root, its tip held by a spherical
/// joint to a small body of mass `m` that carries a constant axial force
/// `t_axial` (N, + pulls: tension) and a short transverse triangle pulse
/// (peak 0.02 N over 0.3 s); the tip deflection along y is written.
fn scene(t_axial: f64, m: f64, modes: usize, effect: bool) -> String {
    let effects = if effect {
        r#"["flexibility", "loads", "geometric_stiffening"]"#
    } else {
        r#"["flexibility", "loads"]"#
    };
    let row = |t: f64, fy: f64| format!("[{t}, {t_axial}, {fy}, 0.0, 0.0, 0.0, 0.0]");
    let table = [
        row(0.0, 0.0),
        row(0.15, 0.02),
        row(0.3, 0.0),
        row(100.0, 0.0),
    ]
    .join(", ");
    format!(
        r#"
[scene]
effects = {effects}
baumgarte = 10.0

[[scene.bodies]]
name = "beam"
flexible = {{ kind = "beam", modes = {modes}, origin = [0.0, 0.0, 0.0], length = 1.0, ei_y = 1.0, ei_z = 1.0, rho_a = 1.0, rho_ip = 0.001 }}

[[scene.bodies]]
name = "puller"
mass = {m}
com = [1.0, 0.0, 0.0]
inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]

[[scene.joints]]
name = "root"
type = "fixed"
body_i = "ground"
body_j = "beam"
point = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]

[[scene.joints]]
name = "tip"
type = "spherical"
body_i = "beam"
body_j = "puller"
point = [1.0, 0.0, 0.0]

[[scene.markers]]
name = "end"
body = "beam"
point = [1.0, 0.0, 0.0]

[[scene.forces]]
type = "load"
body = "puller"
table = [{table}]

[scene.integrator]
method = "bdf"
rtol = 1e-9
atol = 1e-11
t_end = 10.0
dt_out = 0.002

[scene.outputs]
quantities = ["end.deflection"]
"#
    )
}

/// The first bending frequency (rad/s) of the free vibration after the
/// pulse: twice the mean interval between the zero crossings of the tip
/// deflection after t = 0.5 s (linear interpolation between the output
/// times).
fn measured_frequency(text: &str) -> f64 {
    let sim = run(text);
    let t = column(&sim, "t");
    let y = column(&sim, "end.deflection_y");
    let zeros: Vec<f64> = (1..t.len())
        .filter(|&k| t[k - 1] > 0.5 && (y[k - 1] < 0.0) != (y[k] < 0.0))
        .map(|k| t[k - 1] + (t[k] - t[k - 1]) * (-y[k - 1]) / (y[k] - y[k - 1]))
        .collect();
    assert!(zeros.len() >= 4, "{} zero crossings", zeros.len());
    let period = 2.0 * (zeros[zeros.len() - 1] - zeros[0]) / (zeros.len() - 1) as f64;
    2.0 * std::f64::consts::PI / period
}

/// The exact first frequency (rad/s) of the clamped–free Euler–Bernoulli
/// beam under the dead axial tip load `t` (tension > 0) with a tip mass
/// `m`: `EI v'''' − T v'' = ρA ω² v`, `v(0) = v'(0) = 0`, `v''(L) = 0`,
/// `EI v'''(L) − T v'(L) = −m ω² v(L)` (the natural boundary conditions
/// of `½∫EI v''² + ½∫T v'² − ½ω²(∫ρA v² + m v(L)²)`; Bokaian, "Natural
/// frequencies of beams under tensile axial loads", J. Sound Vib. 142(3),
/// 1990, gives the same equation without the tip mass). With
/// `α², −β² = (T ± √(T² + 4 EI ρA ω²)) / 2EI` the solution is
/// `C₁(cosh αx − cos βx) + C₂(sinh αx − (α/β) sin βx)`, and ω is the
/// lowest root of the 2 × 2 determinant of the tip conditions (scan and
/// bisection).
fn exact_frequency(t: f64, m: f64) -> f64 {
    let (ei, rho_a, l) = (1.0, 1.0, 1.0);
    let det = |w: f64| {
        let root = (t * t + 4.0 * ei * rho_a * w * w).sqrt();
        let a = ((t + root) / (2.0 * ei)).sqrt();
        let b = ((root - t) / (2.0 * ei)).sqrt();
        let (ch, sh) = ((a * l).cosh(), (a * l).sinh());
        let (c, s) = ((b * l).cos(), (b * l).sin());
        // Columns C₁, C₂: v, v', v'', v''' at L.
        let v = [ch - c, sh - a / b * s];
        let d1 = [a * sh + b * s, a * ch - a * c];
        let d2 = [a * a * ch + b * b * c, a * a * sh + a * b * s];
        let d3 = [
            a.powi(3) * sh - b.powi(3) * s,
            a.powi(3) * ch + a * b * b * c,
        ];
        let r2 = [
            ei * d3[0] - t * d1[0] + m * w * w * v[0],
            ei * d3[1] - t * d1[1] + m * w * w * v[1],
        ];
        d2[0] * r2[1] - d2[1] * r2[0]
    };
    let (mut lo, mut step) = (1e-3, 1e-3);
    while det(lo).signum() == det(lo + step).signum() {
        lo += step;
        step *= 1.001;
        assert!(lo < 1e3, "no root");
    }
    let mut hi = lo + step;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if det(mid).signum() == det(lo).signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn exact_reference_without_load_is_the_cantilever() {
    // T = 0, m = 0: (β₁L)² √(EI/ρAL⁴) = 1.875104² = 3.516015 rad/s
    // (Blevins, Table 8-1, clamped–free).
    let w = exact_frequency(0.0, 0.0);
    assert!((w - 3.516_015).abs() < 1e-5, "{w}");
}

#[test]
fn axial_joint_load_stiffens_and_softens_as_the_taut_beam() {
    let m = 0.05;
    for t in [4.0, -1.5] {
        let want = exact_frequency(t, m);
        let got = measured_frequency(&scene(t, m, 12, true));
        let plain = measured_frequency(&scene(t, m, 12, false));
        let free = exact_frequency(0.0, m);
        println!(
            "T = {t}: ω = {got:.5} rad/s with the effect, {plain:.5} without; exact {want:.5} \
             (unloaded {free:.5})"
        );
        // Measured: 1.0e-4 (T = 4) and 0.8e-4 (T = −1.5) relative.
        assert!((got / want - 1.0).abs() < 0.005, "T = {t}: {got} vs {want}");
        // Without the effect the load changes nothing.
        assert!(
            (plain / free - 1.0).abs() < 0.01,
            "T = {t}: {plain} vs {free}"
        );
        // Tension stiffens, compression softens.
        assert_eq!(got > plain, t > 0.0);
    }
}

/// The pulled cantilever of the prestress tangent tests (axial load 4 N,
/// puller 0.05 kg, 8 modes, geometric stiffening on): its model, system,
/// a deformed and moving consistent state and the puller's body index.
fn deformed_pulled_cantilever() -> (plyscape::mbs::Model, plyscape::mbs::System, Vec<f64>, usize) {
    use crate::common::scenes::scene as build;
    use plyscape::mbs::System;
    let model = build(&scene(4.0, 0.05, 8, true)).model;
    let puller = model
        .bodies
        .iter()
        .position(|b| b.name == "puller")
        .unwrap();
    let sys = System::new(model.clone());
    let mut y = sys.initial_state();
    let (p, o) = (sys.pos_off(0), sys.vel_off(0));
    for j in 0..sys.modes[0] {
        y[p + 7 + j] = 2e-2 / (1 + j) as f64 * if j % 3 == 0 { 1.0 } else { -0.6 };
        y[o + 6 + j] = 0.1 * ((j as f64) * 0.9).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    (model, sys, y, puller)
}

#[test]
fn prestress_tangent_matches_central_differences() {
    // The tangent of the prestress iteration (plyscape::mbs::constraints::
    // prestress: r₁ gains −B'λ, λ' by the same iteration) at a deformed,
    // moving state of the pulled cantilever, in a state direction together
    // with a parameter lane (the puller's mass, which changes λ and so
    // B λ): one Dual64 evaluation against central differences of plain
    // evaluations.
    use num_dual::Dual64;
    use plyscape::mbs::{Param, System, Workspace};
    let (model, sys, y, puller) = deformed_pulled_cantilever();
    let n = y.len();
    let dir: Vec<f64> = (0..n).map(|k| ((k as f64) * 1.3).cos()).collect();
    let (m, dm) = (0.05, 0.02);
    let mut wsd = Workspace::empty();
    wsd.params = vec![(Param::Mass(puller), Dual64::new(m, dm))];
    let yd: Vec<Dual64> = (0..n).map(|k| Dual64::new(y[k], dir[k])).collect();
    let mut fd = vec![Dual64::from(0.0); n];
    sys.rhs(0.0, &yd, &mut fd, &mut wsd);
    let at = |s: &System, sign: f64, h: f64| {
        let mut ws = Workspace::empty();
        ws.params = vec![(Param::Mass(puller), m + sign * h * dm)];
        let yy: Vec<f64> = (0..n).map(|k| y[k] + sign * h * dir[k]).collect();
        let mut f = vec![0.0; n];
        s.rhs(0.0, &yy, &mut f, &mut ws);
        f
    };
    let h = 1e-6;
    let (fp, fm) = (at(&sys, 1.0, h), at(&sys, -1.0, h));
    let scale = fd.iter().map(|v| v.eps.abs()).fold(0.0, f64::max);
    let err = (0..n)
        .map(|k| ((fp[k] - fm[k]) / (2.0 * h) - fd[k].eps).abs())
        .fold(0.0, f64::max);
    // The prestress is in play: the same state without the effect
    // accelerates differently.
    let mut plain = model;
    plain.geometric_stiffening = false;
    let f0 = at(&System::new(plain), 0.0, 0.0);
    let f1 = at(&sys, 0.0, 0.0);
    let effect = (0..n).map(|k| (f1[k] - f0[k]).abs()).fold(0.0, f64::max);
    println!("max |Jv| {scale:e}, max |Jv − FD| {err:e}, effect on f {effect:e}");
    assert!(effect > 1e-3 * f1.iter().fold(0.0f64, |a, v| a.max(v.abs())));
    assert!(
        err < 1e-6 * scale,
        "tangent error {err:e} (scale {scale:e})"
    );
    for k in 0..n {
        assert!((f1[k] - fd[k].re).abs() <= 1e-12 * (1.0 + f1[k].abs()));
    }
}

#[test]
fn prestress_tangent_lanes_ride_together_as_alone() {
    // The multi-lane tangent of the prestress iteration (lane-interleaved,
    // plyscape::mbs::constraints::tangent): one 4-lane evaluation of the
    // pulled cantilever at a deformed, moving state, four state directions
    // and the puller's mass in the first lane, against four one-lane
    // (Dual64) evaluations, one per direction: each lane equal to the
    // bit (every lane gets the operations of a one-lane evaluation, in
    // the same order; the lanes must not see each other).
    use num_dual::Dual64;
    use plyscape::mbs::math::DualN;
    use plyscape::mbs::{Param, Workspace};
    let (_, sys, y, puller) = deformed_pulled_cantilever();
    let n = y.len();
    let dir = |l: usize, k: usize| ((k as f64) * (1.3 + 0.7 * l as f64)).cos();
    let (m, dm) = (0.05, 0.02);
    let mut w4 = Workspace::empty();
    w4.params = vec![(Param::Mass(puller), DualN::new(m, [dm, 0.0, 0.0, 0.0]))];
    let y4: Vec<DualN<4>> = (0..n)
        .map(|k| DualN::new(y[k], std::array::from_fn(|l| dir(l, k))))
        .collect();
    let mut f4 = vec![DualN::<4>::cst(0.0); n];
    sys.rhs(0.0, &y4, &mut f4, &mut w4);
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for l in 0..4 {
        let mut w1 = Workspace::empty();
        let dml = if l == 0 { dm } else { 0.0 };
        w1.params = vec![(Param::Mass(puller), Dual64::new(m, dml))];
        let y1: Vec<Dual64> = (0..n).map(|k| Dual64::new(y[k], dir(l, k))).collect();
        let mut f1 = vec![Dual64::from(0.0); n];
        sys.rhs(0.0, &y1, &mut f1, &mut w1);
        for k in 0..n {
            scale = scale.max(f1[k].eps.abs());
            worst = worst.max((f4[k].eps[l] - f1[k].eps).abs());
            assert_eq!(f4[k].re.to_bits(), f1[k].re.to_bits(), "value {k}");
        }
    }
    println!("max |Jv| {scale:e}, worst lane difference {worst:e}");
    assert!(scale > 0.0 && worst == 0.0, "{worst:e} of {scale:e}");
}

/// A centre-clamped panel (1.0 m × 0.6 m, [θ/−45/−45/θ]) swung about x by
/// a driven hinge (θ = t²) as in `flex.rs`, with a 0.2 kg body on a
/// spherical joint at its corner (0.5, 0.3) that carries an in-plane load
/// of 40 N along x: the corner node's point-force cases give the joint
/// load's membrane prestress.
fn pulled_panel_scene(theta1: f64, effect: bool) -> String {
    let effects = if effect {
        r#"["flexibility", "quadratic_velocity", "loads", "geometric_stiffening"]"#
    } else {
        r#"["flexibility", "quadratic_velocity", "loads"]"#
    };
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
plies = [{{ angle = {theta1}, thickness = 0.5e-3 }}, {{ angle = -45.0, thickness = 0.5e-3 }}, {{ angle = -45.0, thickness = 0.5e-3 }}, {{ angle = {theta1}, thickness = 0.5e-3 }}]

[scene]
effects = {effects}
sensitivities = ["panel.design.theta_1_4"]
[[scene.bodies]]
name = "hub"
mass = 0.5
com = [0.0, 0.0, 0.0]
inertia = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]]
[[scene.bodies]]
name = "panel"
flexible = {{ kind = "panel", panel = "p", modes = 4, origin = [0.0, 0.5, 0.0], derivatives = "updated", rigid_limit = 1.0 }}
[[scene.bodies]]
name = "weight"
mass = 0.2
com = [0.5, 0.8, 0.0]
inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]
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
[[scene.joints]]
name = "corner"
type = "spherical"
body_i = "panel"
body_j = "weight"
point = [0.5, 0.8, 0.0]
[[scene.forces]]
type = "load"
body = "weight"
force = [40.0, 0.0, 0.0]
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

/// The worst error of the ply-angle sensitivities of [`pulled_panel_scene`]
/// (strain energy and modal coordinates at 0.4 s, relative to the largest)
/// against central differences of whole simulations with the basis
/// rebuilt at θ ± h, and the final strain energy (J).
fn pulled_panel_sensitivity_error(effect: bool) -> (f64, f64) {
    use plyscape::scene::load_scene;
    use plyscape::simulate::simulate;
    use plyscape::study::Study;
    let sim = |text: &str| {
        let study = Study::parse("pulled.toml", text).unwrap();
        simulate(&load_scene(&study).unwrap()).unwrap().1
    };
    let base = sim(&pulled_panel_scene(30.0, effect));
    let h: f64 = 2e-4; // rad
    let at = |deg: f64| {
        let text = pulled_panel_scene(deg, effect);
        sim(&text.replace("sensitivities = [\"panel.design.theta_1_4\"]\n", ""))
    };
    let (plus, minus) = (at(30.0 + h.to_degrees()), at(30.0 - h.to_degrees()));
    let last = base.rows.len() - 1;
    let cols = base.headers.len() - 1;
    let scale = (0..cols)
        .map(|c| base.sens_rows[last][1 + c].abs())
        .fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for c in 0..cols {
        let fd = (plus.rows[last][1 + c] - minus.rows[last][1 + c]) / (2.0 * h);
        let an = base.sens_rows[last][1 + c];
        println!("{}: analytic {an:e}, FD {fd:e}", base.headers[1 + c]);
        worst = worst.max((fd - an).abs() / scale);
    }
    (worst, base.rows[last][1])
}

#[test]
fn pulled_panel_ply_angle_sensitivities_match_central_differences() {
    // dK_{P,a}/dθ of the corner's point cases (plyscape::panels::geometric,
    // through the static solve's derivative) and B'λ in the tangent. The
    // scene's own sensitivities (integration error of the lanes, which the
    // integrator does not control) differ from the differences by 3.2e-5
    // without the effect; with it measured 2.3e-5. The tangent itself is
    // exact (prestress_tangent_matches_central_differences: 1.2e-10).
    use plyscape::scene::load_scene;
    use plyscape::study::Study;
    let text = pulled_panel_scene(30.0, true);
    let scene = load_scene(&Study::parse("pulled.toml", &text).unwrap()).unwrap();
    let flex = scene.model.bodies[1].flex.as_ref().unwrap();
    let g = flex.basis.geometric.as_ref().unwrap();
    assert_eq!(g.point_nodes.len(), 2, "mount and corner nodes");
    assert_eq!(g.derivatives.len(), flex.basis.derivatives.len());
    let (with, u) = pulled_panel_sensitivity_error(true);
    let (without, u0) = pulled_panel_sensitivity_error(false);
    println!("worst relative error {with:e} with the effect, {without:e} without; strain energy {u:e} J with, {u0:e} J without");
    // The joint load's prestress changes the run (measured +26 %).
    assert!((u / u0 - 1.0).abs() > 0.05, "{u} vs {u0}");
    assert!(
        with < 2.0 * without && with < 1e-4,
        "sensitivity error {with:e} ({without:e} without)"
    );
}
