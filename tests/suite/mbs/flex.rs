//! Floating-frame flexible bodies (paper Eqs. 5–6): conservation laws of a
//! free flexible body, exact Jacobian-vector products, the slow spin-up of
//! a cantilever against its quasi-static deflection, ply-angle
//! sensitivities through a panel's modal basis against central finite
//! differences, the effects switches, and input errors.

use crate::common::scenes::{shipped_study, shipped_text};
use num_dual::Dual64;
use plyscape::beams::{Beam, Plane};
use plyscape::mbs::{System, Workspace};
use plyscape::scene::load_scene;
use plyscape::simulate::simulate;
use plyscape::study::Study;

fn study(text: &str) -> Study {
    Study::parse("flex.toml", text).unwrap()
}

const FREE_BEAM: &str = r#"
[scene]
effects = ["flexibility", "quadratic_velocity"]
[[scene.bodies]]
name = "beam"
angular_velocity = [0.3, 0.2, 2.0]
velocity = [0.1, 0.0, 0.0]
flexible = { kind = "beam", modes = 4, origin = [0.0, 0.0, 0.0], length = 1.0, ei_y = 100.0, ei_z = 60.0, rho_a = 1.0, rho_ip = 0.01 }
[scene.integrator]
method = "bdf"
rtol = 1e-9
atol = 1e-11
t_end = 1.0
dt_out = 0.1
[scene.outputs]
quantities = ["beam.modal", "beam.strain_energy", "energy"]
"#;

#[test]
fn free_flexible_body_conserves_energy_and_momenta() {
    // A free beam tumbling about a skew axis: centrifugal and Coriolis
    // couplings excite the modes, while energy (kinetic + strain), linear
    // and angular momentum are invariants of the exact flow (no external
    // forces). Invariants derived from Newton's laws, exact.
    let scene = load_scene(&study(FREE_BEAM)).unwrap();
    let (sys, sim) = simulate(&scene).unwrap();
    let mut ws = Workspace::empty();
    let y0 = {
        let mut y = sys.initial_state();
        sys.project(0.0, &mut y).unwrap();
        y
    };
    let h0 = sys.angular_momentum(&y0, &mut ws);
    let h1 = sys.angular_momentum(&sim.y_end, &mut ws);
    let e = sim.energy_error.expect("conservative scene");
    println!(
        "energy error {e:e}, |ΔH|/|H| {:e}",
        (h1 - h0).norm() / h0.norm()
    );
    // Measured 1.6e-10 (energy) and 6.0e-11 (momentum); bounds 3×.
    assert!(e < 4.8e-10, "energy drift {e:e}");
    assert!((h1 - h0).norm() < 1.8e-10 * h0.norm());
    // The modes are really excited (the test cannot pass on a rigid body).
    let strain = sim.rows.iter().map(|r| r[5]).fold(0.0, f64::max);
    assert!(strain > 1e-7, "max strain energy {strain:e}");
    // Linear momentum: the frame origin (root) is not the centre of mass,
    // so check d/dt of the centre of mass through two positions: the
    // momentum m·v_c must be constant, i.e. the centre moves linearly.
    let c = |y: &[f64]| sys.centre_of_mass(y, 0);
    let drift = c(&sim.y_end) - c(&y0) - nalgebra::Vector3::new(0.1, 0.0, 0.0) * 1.0;
    // The initial velocity is that of the frame origin; the centre of mass
    // moves at v + ω × c0 (c0 = (0.5, 0, 0) for the undeformed beam).
    let w0 = nalgebra::Vector3::new(0.3, 0.2, 2.0);
    let vc = w0.cross(&nalgebra::Vector3::new(0.5, 0.0, 0.0));
    assert!(
        (drift - vc).norm() < 1e-7,
        "centre of mass drift {:?}",
        drift - vc
    );
}

/// The tumbling free beam (softer, 6 modes) with a rigid tip mass joined
/// to its tip node by `joint` (the TOML lines after `type`, naming the
/// joint `tip`).
fn tip_mass_scene(joint: &str) -> String {
    FREE_BEAM
        .replace("ei_y = 100.0, ei_z = 60.0", "ei_y = 20.0, ei_z = 12.0")
        .replace("modes = 4", "modes = 6")
        .replace(
            "[scene.integrator]",
            &format!(
                r#"[[scene.bodies]]
name = "tipmass"
mass = 0.5
com = [1.0, 0.0, 0.0]
inertia = [[0.01, 0.0, 0.0], [0.0, 0.02, 0.0], [0.0, 0.0, 0.03]]
angular_velocity = [0.3, 0.2, 2.0]
velocity = [0.1, 2.0, -0.2]
[[scene.joints]]
name = "tip"
body_i = "beam"
body_j = "tipmass"
point = [1.0, 0.0, 0.0]
{joint}
[scene.integrator]"#
            ),
        )
        .replace(
            r#"quantities = ["beam.modal", "beam.strain_energy", "energy"]"#,
            r#"quantities = ["beam.strain_energy", "energy", "tip.i.deflection"]"#,
        )
}

/// Simulate `text` and check that the tip mass stays attached (violation
/// below 1e-9: every Jacobian is the derivative of its constraint), that
/// the modes are excited, and that the free system conserves energy and
/// angular momentum (invariants, exact); returns the system.
fn assert_attached_and_conservative(text: &str) -> System {
    let scene = load_scene(&study(text)).unwrap();
    let (sys, sim) = simulate(&scene).unwrap();
    let e = sim.energy_error.expect("conservative");
    println!("violation {:e}, energy error {e:e}", sim.max_violation);
    // Measured violation 8.1e-12 (weld) and 1.7e-11 (spherical); bound 3×.
    assert!(
        sim.max_violation < 4.8e-11,
        "violation {:e}",
        sim.max_violation
    );
    assert!(e < 1e-8);
    let tip_y = sim
        .rows
        .iter()
        .map(|r| r[3].abs().max(r[4].abs()))
        .fold(0.0, f64::max);
    assert!(
        tip_y > 1e-5,
        "tip deflection {tip_y:e}: the modes must be excited"
    );
    let mut ws = Workspace::empty();
    let mut y0 = sys.initial_state();
    sys.project(0.0, &mut y0).unwrap();
    let (h0, h1) = (
        sys.angular_momentum(&y0, &mut ws),
        sys.angular_momentum(&sim.y_end, &mut ws),
    );
    assert!((h1 - h0).norm() < 1e-8 * h0.norm());
    sys
}

#[test]
fn rigid_tip_mass_welded_to_a_flexible_node_stays_exactly_attached() {
    // A tumbling free beam with a rigid tip mass welded (fixed joint) to
    // its tip node, where the modes translate AND rotate the marker frame:
    // with the exact node angular velocity ω + A T(Ψw) Ψẇ every Jacobian
    // is the derivative of its constraint, so the violation stays at the
    // integration-error level (it was 2e-8 with T = I, a first-order
    // model).
    let sys = assert_attached_and_conservative(&tip_mass_scene(
        "type = \"fixed\"\naxis = [1.0, 0.0, 0.0]",
    ));
    let mut flags = Vec::new();
    sys.node_rotations(&mut flags);
    assert!(flags.iter().all(|f| *f), "the weld reads both rotations");
}

#[test]
fn rigid_tip_mass_on_a_spherical_joint_at_a_flexible_node_stays_attached() {
    // The same tip mass on a spherical joint: only point rows read the tip
    // marker, so the kernel leaves the node's rotation out of its
    // kinematics (System::node_rotations). The point rows' modal Jacobian
    // entries must still be the derivatives of the constraint.
    let sys = assert_attached_and_conservative(&tip_mass_scene("type = \"spherical\""));
    let mut flags = Vec::new();
    sys.node_rotations(&mut flags);
    assert!(flags.iter().all(|f| !f), "no marker needs a node rotation");
}

fn spinup() -> Study {
    shipped_study("beam_spinup.toml")
}

#[test]
fn flexible_jacobian_vector_product_matches_central_differences() {
    // The spin-up scene (fixed joint on a flexible node, revolute, load) at
    // a state with deformation and velocities: J v from one Dual64
    // evaluation vs central finite differences.
    let sys = System::new(load_scene(&spinup()).unwrap().model);
    let mut y = sys.initial_state();
    let n = y.len();
    for (k, v) in y.iter_mut().enumerate() {
        *v += 1e-3 * ((k as f64) * 0.37).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    let dir: Vec<f64> = (0..n).map(|k| ((k as f64) * 1.3).cos()).collect();
    let yd: Vec<Dual64> = (0..n).map(|k| Dual64::new(y[k], dir[k])).collect();
    let mut fd = vec![Dual64::from(0.0); n];
    sys.rhs(0.5, &yd, &mut fd, &mut Workspace::empty());
    let h = 1e-6;
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut ws = Workspace::empty();
    let yp: Vec<f64> = (0..n).map(|k| y[k] + h * dir[k]).collect();
    let ym: Vec<f64> = (0..n).map(|k| y[k] - h * dir[k]).collect();
    sys.rhs(0.5, &yp, &mut fp, &mut ws);
    sys.rhs(0.5, &ym, &mut fm, &mut ws);
    let scale = fd.iter().map(|v| v.eps.abs()).fold(0.0, f64::max);
    let err = (0..n)
        .map(|k| ((fp[k] - fm[k]) / (2.0 * h) - fd[k].eps).abs())
        .fold(0.0, f64::max);
    println!("max |Jv| {scale:e}, max |Jv − FD| {err:e}");
    assert!(err < 1e-6 * scale, "JVP error {err:e} (scale {scale:e})");
}

#[test]
fn multi_lane_evaluations_equal_one_lane_at_a_time() {
    // The fused sensitivity right-hand side (`rhs_lanes`: one multi-lane
    // dual evaluation of width 1, 2, 4 or 8 for up to 8 lanes, chunks of
    // 8 beyond) against the plain right-hand side and one single-lane
    // `rhs_dir` per lane, for 1 to 9 lanes (parameters: the bodies'
    // masses, repeated when there are more lanes than bodies, each lane seeding
    // its own parameter and state direction).
    use plyscape::integrate::OdeModel;
    use plyscape::mbs::Param;
    let sys = System::new(load_scene(&spinup()).unwrap().model);
    let mut y = sys.initial_state();
    let n = y.len();
    for (k, v) in y.iter_mut().enumerate() {
        *v += 1e-3 * ((k as f64) * 0.37).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    let bodies: Vec<usize> = sys.moving.clone();
    let mut w = sys.work(n);
    for np in 1..=9 {
        let names: Vec<Param> = (0..np)
            .map(|i| Param::Mass(bodies[i % bodies.len()]))
            .collect();
        let p: Vec<f64> = names.iter().map(|q| sys.param_value(*q).unwrap()).collect();
        let lanes: Vec<f64> = (0..n * np).map(|k| ((k as f64) * 0.71).cos()).collect();
        let (mut dy, mut dl) = (vec![0.0; n], vec![0.0; n * np]);
        let duals = sys.rhs_lanes(&mut w, 0.5, &y, (&names, &p), &lanes, &mut dy, &mut dl);
        assert_eq!(duals, if np <= 4 { 1 } else { np.div_ceil(8) });
        let mut f = vec![0.0; n];
        OdeModel::rhs(&sys, &mut w, 0.5, &y, (&names, &p), &mut f);
        let scale = f.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        for k in 0..n {
            assert!(
                (dy[k] - f[k]).abs() <= 1e-12 * scale,
                "f[{k}] with {np} lanes"
            );
        }
        for i in 0..np {
            let mut e = vec![0.0; np];
            e[i] = 1.0;
            let mut one = vec![0.0; n];
            let s = &lanes[i * n..(i + 1) * n];
            sys.rhs_dir(&mut w, 0.5, &y, (&names, &p), (Some(s), Some(&e)), &mut one);
            let sc = one.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            for k in 0..n {
                let err = (dl[i * n + k] - one[k]).abs();
                assert!(err <= 1e-12 * sc, "lane {i} of {np}, row {k}: {err:e}");
            }
        }
    }
}

#[test]
fn design_seeds_with_the_same_variables_but_new_values_lift_the_basis_again() {
    // Regression: the lifted invariants and node shapes are cached while
    // a body's design seeds stay the same. num-dual's `==` compares real
    // parts only (zero for every seed), so two directions seeding the same
    // design variables with other values compared equal and the second
    // evaluation used the first one's lifted basis. Here one workspace
    // takes direction (0.3, 0.7) and then (0.5, -0.2) in the plies
    // (θ₁₄, θ₂₃): the second result must equal a fresh workspace's, and,
    // the product being linear in the direction, 0.5 e₁ − 0.2 e₂.
    use plyscape::integrate::OdeModel;
    let text = panel_scene(30.0).replace(
        "sensitivities = [\"panel.design.theta_1_4\"]",
        "sensitivities = [\"panel.design.theta_1_4\", \"panel.design.theta_2_3\"]",
    );
    let scene = load_scene(&study(&text)).unwrap();
    let names: Vec<_> = scene.params.iter().map(|(_, p)| *p).collect();
    assert_eq!(names.len(), 2);
    let sys = System::new(scene.model);
    let mut y = sys.initial_state();
    let n = y.len();
    for (k, v) in y.iter_mut().enumerate() {
        *v += 1e-3 * ((k as f64) * 0.37).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    let p: Vec<f64> = names.iter().map(|q| sys.param_value(*q).unwrap()).collect();
    let dir = |w: &mut _, vp: [f64; 2]| {
        let mut out = vec![0.0; n];
        sys.rhs_dir(w, 0.2, &y, (&names, &p), (None, Some(&vp)), &mut out);
        out
    };
    let mut reused = sys.work(n);
    let first = dir(&mut reused, [0.3, 0.7]);
    let second = dir(&mut reused, [0.5, -0.2]);
    let fresh = dir(&mut sys.work(n), [0.5, -0.2]);
    let e1 = dir(&mut sys.work(n), [1.0, 0.0]);
    let e2 = dir(&mut sys.work(n), [0.0, 1.0]);
    let scale = fresh.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0, "the design seeds move the right-hand side");
    let moved = first
        .iter()
        .zip(&fresh)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        moved > 1e-3 * scale,
        "the two directions give different products"
    );
    for k in 0..n {
        assert!(
            (second[k] - fresh[k]).abs() <= 1e-13 * scale,
            "row {k}: reused workspace {:e}, fresh {:e}",
            second[k],
            fresh[k]
        );
        let lin = 0.5 * e1[k] - 0.2 * e2[k];
        // Linear to the rounding of the regularised constraint-space
        // solve (measured 5e-12 of the largest entry).
        assert!(
            (fresh[k] - lin).abs() <= 1e-10 * scale,
            "row {k}: {:e} against 0.5 e1 - 0.2 e2 = {lin:e}",
            fresh[k]
        );
    }
}

#[test]
fn slow_spin_up_follows_the_quasi_static_deflection() {
    // studies/beam_spinup.toml: once the hub torque holds (t > 2 s) the
    // angular acceleration α is constant and the tip lags by the
    // quasi-static deflection of p(x) = −ρAαx: −11ρAαL⁵/(120EI)
    // (Euler–Bernoulli closed form, Roark Table 8.1; `Beam::
    // tip_deflection_linear_load`). α is read from the simulated hub rate.
    // The linear floating frame softens the beam by ≈ Ω²/ω₁² (6.5e-4 at
    // t = 4 s): the tolerance is 0.18 %.
    let scene = load_scene(&spinup()).unwrap();
    let (_, sim) = simulate(&scene).unwrap();
    let col = |name: &str| {
        sim.headers
            .iter()
            .position(|h| h.starts_with(name))
            .unwrap()
    };
    let (rate, tip) = (col("axle.rate"), col("tip.deflection_y"));
    let beam = Beam {
        length: 1.0,
        ei_y: 100.0,
        ei_z: 100.0,
        rho_a: 1.0,
    };
    let mut checked = 0;
    let mut worst = 0.0f64;
    for k in 1..sim.rows.len() - 1 {
        let t = sim.rows[k][0];
        if t < 2.5 {
            continue;
        }
        let (a, b) = (&sim.rows[k - 1], &sim.rows[k + 1]);
        let alpha = (b[rate] - a[rate]) / (b[0] - a[0]);
        let qs = beam.tip_deflection_linear_load(Plane::Y, -alpha * 1.0);
        let rel = sim.rows[k][tip] / qs - 1.0;
        worst = worst.max(rel.abs());
        assert!(
            rel.abs() < 1.8e-3,
            "t = {t}: tip {} vs quasi-static {qs} ({rel:e})",
            sim.rows[k][tip]
        );
        checked += 1;
    }
    println!(
        "tip against the quasi-static deflection: worst {worst:.2e} relative over {checked} times"
    );
    assert!(checked >= 25);
    // α = τ / (J_hub + ρAL³/3) = 0.4 / (1 + 1/3) (rigid-body closed form).
    let last = &sim.rows[sim.rows.len() - 2];
    let prev = &sim.rows[sim.rows.len() - 3];
    let alpha = (last[rate] - prev[rate]) / (last[0] - prev[0]);
    assert!((alpha - 0.3).abs() < 1e-3, "alpha {alpha}");
    assert!(sim.max_violation < 1e-8);
}

#[test]
fn effects_switch_flexibility_quadratic_terms_and_modal_damping() {
    // The same spin-up with effects removed: nothing of what is not listed
    // is built or evaluated (counters), and without `flexibility` the beam
    // is the rigid stand-in given by mass/com/inertia.
    let text = shipped_text("beam_spinup.toml").replace("t_end = 4.0", "t_end = 0.5");
    let run = |effects: &str| {
        let t = text.replace(
            r#"effects = ["flexibility", "quadratic_velocity", "loads", "damping"]"#,
            effects,
        );
        let (sys, sim) = simulate(&load_scene(&study(&t)).unwrap()).unwrap();
        (sys, sim)
    };
    let (full, _) = run(r#"effects = ["flexibility", "quadratic_velocity", "loads", "damping"]"#);
    assert!(full.counters.flexible.get() > 0);
    assert!(full.counters.quadratic.get() > 0);
    assert!(full.counters.modal_damping.get() > 0);
    let (rigid, sim) = run(r#"effects = ["quadratic_velocity", "loads"]"#);
    assert_eq!(rigid.counters.flexible.get(), 0);
    assert!(rigid.model.bodies.iter().all(|b| b.flex.is_none()));
    assert_eq!(rigid.nstates(), 26);
    assert!(sim.rows.iter().all(|r| r.iter().all(|v| v.is_finite())));
    let (no_quad, _) = run(r#"effects = ["flexibility", "loads", "damping"]"#);
    assert_eq!(no_quad.counters.quadratic.get(), 0);
    assert!(no_quad.counters.flexible.get() > 0);
    let (no_damp, _) = run(r#"effects = ["flexibility", "quadratic_velocity", "loads"]"#);
    assert_eq!(no_damp.counters.modal_damping.get(), 0);
}

/// A composite panel (1.0 m × 0.6 m, [30/−45/−45/30], centre clamp basis)
/// clamped at its centre to a hub swung about x by a prescribed angle
/// θ(t) = t² (like the SAR panel's deployment), with its first ply pair at
/// `theta1` degrees. The frame is held at the clamped node (the panel is
/// welded to the hub there), so the clamp's nearly rigid rocking modes are
/// real compliance and are kept (`rigid_limit = 1`).
fn panel_scene(theta1: f64) -> String {
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
effects = ["flexibility", "quadratic_velocity"]
sensitivities = ["panel.design.theta_1_4"]
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

#[test]
fn ply_angle_sensitivities_match_central_differences() {
    // d(strain energy)/dθ and dw/dθ of the swung panel: forward
    // sensitivities through dΛ/dθ and dX/dθ (updated modes, Eq. 18) in the
    // invariants, against central differences of whole simulations with
    // the modal basis rebuilt at θ ± h.
    let base = simulate(&load_scene(&study(&panel_scene(30.0))).unwrap())
        .unwrap()
        .1;
    let h: f64 = 2e-4; // rad
    let sim_at = |deg: f64| {
        let mut t = panel_scene(deg);
        t = t.replace("sensitivities = [\"panel.design.theta_1_4\"]\n", "");
        simulate(&load_scene(&study(&t)).unwrap()).unwrap().1
    };
    let plus = sim_at(30.0 + h.to_degrees());
    let minus = sim_at(30.0 - h.to_degrees());
    let last = base.rows.len() - 1;
    let cols = base.headers.len() - 1;
    let scale = (0..cols)
        .map(|c| base.sens_rows[last][1 + c].abs())
        .fold(0.0, f64::max);
    assert!(
        base.rows[last][1] > 1e-9,
        "strain energy {}",
        base.rows[last][1]
    );
    let mut worst = 0.0f64;
    for c in 0..cols {
        let fd = (plus.rows[last][1 + c] - minus.rows[last][1 + c]) / (2.0 * h);
        let an = base.sens_rows[last][1 + c];
        let rel = (fd - an).abs() / scale;
        println!("{}: analytic {an:e}, FD {fd:e}", base.headers[1 + c]);
        worst = worst.max(rel);
    }
    println!("worst relative error {worst:e}");
    // Measured 2.3e-6 (the strain energy's column); bound 3×.
    assert!(worst < 6.9e-6, "sensitivity error {worst:e}");
}

#[test]
fn strain_energy_responses_and_their_ply_angle_gradients() {
    // Ψ₀ = ∫ 2U dt (an integrated state) and max_t U (critical time point)
    // of the swung panel, 0–0.4 s. Values: Ψ₀ against Simpson's rule on
    // the strain energy sampled every 2.5 ms, the peak against the largest
    // sample (it can only be above it, by at most the sampling error).
    // Gradients against central differences of whole simulations with the
    // basis rebuilt at θ ± h.
    let with_responses = |deg: f64, sens: bool| {
        let mut t = panel_scene(deg)
            .replace("dt_out = 0.1", "dt_out = 0.0025")
            .replace(
                "[scene.outputs]",
                r#"[[scene.responses]]
name = "psi0"
kind = "integral"
of = ["panel.strain_energy"]
scale = 2.0
[[scene.responses]]
name = "umax"
kind = "peak"
of = ["panel.strain_energy"]
[scene.outputs]"#,
            );
        if !sens {
            t = t.replace("sensitivities = [\"panel.design.theta_1_4\"]\n", "");
        }
        simulate(&load_scene(&study(&t)).unwrap()).unwrap().1
    };
    let base = with_responses(30.0, true);
    let (psi, umax) = (&base.responses[0], &base.responses[1]);
    // Simpson on 160 intervals of the sampled U (column 1).
    let u: Vec<f64> = base.rows.iter().map(|r| r[1]).collect();
    let dt = 0.0025;
    let simpson: f64 = (0..u.len() - 1)
        .step_by(2)
        .map(|k| dt / 3.0 * (u[k] + 4.0 * u[k + 1] + u[k + 2]))
        .sum::<f64>()
        * 2.0;
    println!("psi0 {} vs Simpson {simpson}", psi.value);
    assert!((psi.value - simpson).abs() < 1e-6 * simpson);
    let sample_max = u.iter().cloned().fold(0.0, f64::max);
    println!(
        "umax {} at {:?} vs largest sample {sample_max}",
        umax.value, umax.time
    );
    assert!(umax.value >= sample_max && umax.value < sample_max * (1.0 + 1e-4));
    let h: f64 = 2e-4;
    let (p, m) = (
        with_responses(30.0 + h.to_degrees(), false),
        with_responses(30.0 - h.to_degrees(), false),
    );
    // Measured 2.4e-6 (Ψ₀) and 3.1e-8 (peak) relative; bounds 3×.
    for (k, bound) in [(0, 7.2e-6), (1, 9e-8)] {
        let fd = (p.responses[k].value - m.responses[k].value) / (2.0 * h);
        let an = base.responses[k].gradient[0];
        println!(
            "{}: analytic {an:e}, FD {fd:e}, relative {:.2e}",
            base.responses[k].name,
            (fd - an).abs() / an.abs()
        );
        assert!(
            (fd - an).abs() < bound * an.abs(),
            "{}: {an:e} vs {fd:e}",
            base.responses[k].name
        );
    }
}

#[test]
fn flexible_input_errors_name_the_key() {
    let cases = [
        (
            FREE_BEAM.replace("rho_ip = 0.01", "rho_ip = 0.0"),
            "bodies[0].flexible.rho_ip",
        ),
        (FREE_BEAM.replace("modes = 4", "modes = 0"), "bodies[0].flexible.modes"),
        (
            FREE_BEAM.replace("kind = \"beam\"", "kind = \"shell\""),
            "bodies[0].flexible.kind",
        ),
        (
            FREE_BEAM.replace("length = 1.0,", "length = -1.0,"),
            "bodies[0].flexible.length",
        ),
        (
            FREE_BEAM.replace(
                "[scene.integrator]",
                "[[scene.markers]]\nname = \"m\"\nbody = \"beam\"\npoint = [0.55, 0.0, 0.0]\n[scene.integrator]",
            ),
            "markers[0].point",
        ),
        (
            FREE_BEAM.replace("effects = [", "sensitivities = [\"beam.design.theta\"]\neffects = ["),
            "sensitivities[0]",
        ),
        (
            FREE_BEAM.replace("\"flexibility\", ", ""),
            "bodies[0].mass",
        ),
        (
            FREE_BEAM.replace(
                "[scene.integrator]",
                "[[scene.responses]]\nname = \"r\"\nkind = \"integral\"\nof = [\"beam.energy\"]\n[scene.integrator]",
            ),
            "responses[0].of[0]",
        ),
        (
            FREE_BEAM.replace(
                "[scene.integrator]",
                "[[scene.responses]]\nname = \"r\"\nkind = \"mean\"\nof = [\"beam.strain_energy\"]\n[scene.integrator]",
            ),
            "responses[0].kind",
        ),
    ];
    for (text, key) in cases {
        let err = load_scene(&study(&text)).unwrap_err().to_string();
        assert!(err.contains(key), "expected key {key} in: {err}");
        assert!(err.contains("flex.toml"), "file not named: {err}");
    }
}

#[test]
fn too_many_panel_modes_name_the_body_key_and_the_largest_allowed() {
    // The mode count is the body's key (not the panel's), with the value
    // as written and the largest count the mesh gives: 6 divisions of a
    // 1 × 0.6 plate clamped at the centre.
    let text = panel_scene(30.0).replace("modes = 4", "modes = 100000");
    let err = load_scene(&study(&text)).unwrap_err().to_string();
    println!("{err}");
    assert!(
        err.contains("`scene.bodies[1].flexible.modes` = 100000")
            && err.contains("expected between 1 and")
            && err.contains("free DOFs"),
        "{err}"
    );
}

/// A size that cannot fit is refused before anything is allocated, with
/// the key, the estimate and the machine's available memory (100 000 beam
/// modes per plane: about 24 TB by the measured scaling in
/// `study::memory`, more than any machine this runs on).
#[test]
fn a_size_that_cannot_fit_is_refused_with_the_estimate() {
    let s = study(&FREE_BEAM.replace("modes = 4,", "modes = 100000,"));
    let e = load_scene(&s).unwrap_err().to_string();
    assert!(
        e.contains("`scene.bodies[0].flexible.modes` = 100000")
            && e.contains("fits in memory")
            && e.contains("GiB available"),
        "{e}"
    );
}

/// [`panel_scene`] with `geometric_stiffening` in its effects.
fn stiffened_panel_scene(theta1: f64) -> String {
    panel_scene(theta1).replace(
        r#"effects = ["flexibility", "quadratic_velocity"]"#,
        r#"effects = ["flexibility", "quadratic_velocity", "geometric_stiffening"]"#,
    )
}

#[test]
fn geometric_stiffening_on_a_panel_body_is_accepted() {
    // Panels now carry the modal geometric stiffness of their membrane
    // prestress (plyscape::panels::geometric): the effect builds it (and
    // its ply-angle derivatives for the sensitivity parameter), and it
    // changes the run; without the effect no basis computes it.
    let scene = load_scene(&study(&stiffened_panel_scene(30.0))).unwrap();
    let flex = scene.model.bodies[1].flex.as_ref().unwrap();
    let g = flex.basis.geometric.as_ref().expect("geometric stiffness");
    assert_eq!(g.n, flex.basis.n_modes);
    assert_eq!(g.derivatives.len(), flex.basis.derivatives.len());
    assert!(!g.derivatives.is_empty());
    assert!(g.cases.iter().any(|v| v.abs() > 0.0));
    let plain = load_scene(&study(&panel_scene(30.0))).unwrap();
    let f0 = plain.model.bodies[1].flex.as_ref().unwrap();
    assert!(f0.basis.geometric.is_none());
    let u = |s: &plyscape::scene::Scene| {
        let h = simulate(s).unwrap().1;
        h.rows[h.rows.len() - 1][1]
    };
    let (with, without) = (u(&scene), u(&plain));
    println!("strain energy at 0.4 s: {with:e} J with, {without:e} J without");
    // The spin (θ = t², 0.8 rad/s at 0.4 s) is slow against the panel's
    // modes, so the effect is small but not nil.
    assert!(
        with != without && (with - without).abs() < 0.5 * without,
        "{with} vs {without}"
    );
}

#[test]
fn stiffened_panel_sensitivities_match_central_differences() {
    // The test above with geometric_stiffening on: the sensitivities
    // include dK_k/dθ of the prestress (plyscape::panels::geometric),
    // against central differences of whole simulations with the basis
    // (and its geometric stiffness) rebuilt at θ ± h.
    let base = simulate(&load_scene(&study(&stiffened_panel_scene(30.0))).unwrap())
        .unwrap()
        .1;
    let h: f64 = 2e-4; // rad
    let sim_at = |deg: f64| {
        let t = stiffened_panel_scene(deg)
            .replace("sensitivities = [\"panel.design.theta_1_4\"]\n", "");
        simulate(&load_scene(&study(&t)).unwrap()).unwrap().1
    };
    let plus = sim_at(30.0 + h.to_degrees());
    let minus = sim_at(30.0 - h.to_degrees());
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
    println!("worst relative error {worst:e}");
    // The same bound as without the effect (measured 2.3e-6 there).
    assert!(worst < 6.9e-6, "sensitivity error {worst:e}");
}
