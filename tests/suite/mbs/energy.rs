//! Kinetic energy as an output and as responses (integral, peak, final)
//! against closed forms: a free tumbling body (T = ½ m|v|² + ½ ωᵀJω,
//! constant), a compound pendulum (T equals the drop of the gravity
//! potential), a free flexible beam (T = ½ m|v|² + ½ I_x ω_x² at the
//! start, T + U constant), with the sensitivities of the responses against
//! closed forms and central differences, and the exact state derivative
//! of a flexible body's kinetic energy; the energy error of runs that
//! start at E = 0.
use crate::common::scenes::{column, run, scene_spec};
use num_dual::Dual64;
use plyscape::mbs::responses::{ResponseKind, ResponseValue};
use plyscape::mbs::{Energy, Workspace};
use plyscape::simulate::{simulate, Simulation};

fn response<'a>(sim: &'a Simulation, name: &str) -> &'a ResponseValue {
    sim.responses.iter().find(|r| r.name == name).unwrap()
}

/// The three responses of `of` (integral, peak, final) as TOML.
fn responses(of: &str) -> String {
    ["integral", "peak", "final"]
        .iter()
        .map(|k| format!("[[scene.responses]]\nname = \"{k}\"\nkind = \"{k}\"\nof = [{of}]\n"))
        .collect()
}

/// A free 2 kg box with principal inertias (0.1, 0.2, 0.3) kg·m² spun
/// near its intermediate axis (it tumbles: ω' changes a lot) and
/// translating at v = (0.3, −0.4, 1.2) m/s; no forces.
fn tumbling_box() -> String {
    format!(
        r#"
[scene]
effects = ["quadratic_velocity"]
sensitivities = ["box.mass"]
[[scene.bodies]]
name = "box"
mass = 2.0
com = [0.0, 0.0, 0.0]
inertia = [[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]]
angular_velocity = [0.01, 5.0, 0.0]
velocity = [0.3, -0.4, 1.2]
{}
[scene.integrator]
method = "tsit45"
rtol = 1e-11
atol = 1e-13
t_end = 4.0
dt_out = 0.02
[scene.outputs]
quantities = ["kinetic_energy", "box.kinetic_energy"]
"#,
        responses("\"kinetic_energy\"")
    )
}

#[test]
fn kinetic_energy_of_a_tumbling_box_and_its_responses() {
    let sim = run(&tumbling_box());
    let (m, v2) = (2.0, 0.3f64 * 0.3 + 0.4 * 0.4 + 1.2 * 1.2);
    // T = ½ m|v|² + ½ Σ J_k ω_k², constant for a free body.
    let t0 = 0.5 * m * v2 + 0.5 * (0.1 * 0.01 * 0.01 + 0.2 * 25.0);
    let total = column(&sim, "kinetic_energy");
    let of_box = column(&sim, "box.kinetic_energy");
    let err = total
        .iter()
        .chain(&of_box)
        .fold(0.0f64, |e, t| e.max((t - t0).abs()));
    println!("T0 = {t0}, max |T − T0| {err:e}");
    // Measured 1.5e-11 J (T0 = 4.19 J); bound 1e-11 T0 = 4.2e-11 J.
    assert!(err < 1e-11 * t0, "{err:e}");
    // Integral T0·t_end, peak and final T0; d/dm: only ½|v|² (the free
    // flight does not depend on the mass).
    let t_end = 4.0;
    for (name, value, grad) in [
        ("integral", t0 * t_end, 0.5 * v2 * t_end),
        ("peak", t0, 0.5 * v2),
        ("final", t0, 0.5 * v2),
    ] {
        let r = response(&sim, name);
        println!("{name}: {} (d/dm {:?})", r.value, r.gradient);
        assert!((r.value - value).abs() < 1e-9 * value, "{name} {}", r.value);
        assert!(
            (r.gradient[0] - grad).abs() < 1e-9 * grad,
            "{name} {:?}",
            r.gradient
        );
    }
    assert_eq!(response(&sim, "final").kind, ResponseKind::Final);
    assert_eq!(response(&sim, "final").time, Some(t_end));
}

/// A 1.5 kg rod pendulum on a hinge about y at the origin (centre of mass
/// ℓ = 0.4 m from it, J_c = 0.03 kg·m²), released horizontally.
fn pendulum(mass: f64) -> String {
    format!(
        r#"
[scene]
effects = ["gravity", "quadratic_velocity"]
sensitivities = ["rod.mass"]
[[scene.bodies]]
name = "rod"
mass = {mass}
com = [0.4, 0.0, 0.0]
inertia = [[1e-3, 0.0, 0.0], [0.0, 0.03, 0.0], [0.0, 0.0, 0.03]]
[[scene.joints]]
name = "hinge"
type = "revolute"
body_i = "ground"
body_j = "rod"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
{}
[scene.integrator]
method = "tsit45"
rtol = 1e-11
atol = 1e-13
t_end = 1.5
dt_out = 0.01
[scene.outputs]
quantities = ["rod.kinetic_energy", "rod.position"]
"#,
        responses("\"rod.kinetic_energy\"")
    )
}

#[test]
fn pendulum_kinetic_energy_is_the_potential_drop_and_responses_match_differences() {
    let sim = run(&pendulum(1.5));
    let t = column(&sim, "rod.kinetic_energy");
    let z = column(&sim, "rod.position_z");
    // Energy conservation: T = m g (z0 − z), z0 = 0.
    let err = t
        .iter()
        .zip(&z)
        .fold(0.0f64, |e, (t, z)| e.max((t + 1.5 * 9.81 * z).abs()));
    let tmax = t.iter().fold(0.0f64, |a, b| a.max(*b));
    println!("max |T − m g Δz| {err:e}, max T {tmax}");
    // Measured 1.2e-10 J (max T 5.9 J); bound 5e-11 max T = 2.9e-10 J.
    assert!(tmax > 1.0 && err < 5e-11 * tmax, "{err:e}");
    // At the bottom T = m g ℓ, so the peak is m g ℓ with d/dm = g ℓ (its
    // time moves with m; the envelope theorem keeps the gradient exact);
    // located from samples 0.01 s apart (error O(Δt³), module doc of
    // mbs::responses).
    let peak = response(&sim, "peak");
    let (mgl, gl) = (1.5 * 9.81 * 0.4, 9.81 * 0.4);
    println!(
        "peak {} (m g ℓ = {mgl}), d/dm {:?} (g ℓ = {gl})",
        peak.value, peak.gradient
    );
    assert!((peak.value / mgl - 1.0).abs() < 1e-4);
    assert!((peak.gradient[0] / gl - 1.0).abs() < 1e-4);
    // The mass moves the motion (J_c/m changes) and T explicitly: the
    // exact gradients against central differences of whole runs.
    let h = 1e-5;
    let (plus, minus) = (run(&pendulum(1.5 + h)), run(&pendulum(1.5 - h)));
    for name in ["integral", "peak", "final"] {
        let g = response(&sim, name).gradient[0];
        let fd = (response(&plus, name).value - response(&minus, name).value) / (2.0 * h);
        println!("{name}: d/dm {g:.10e}, central difference {fd:.10e}");
        assert!(
            // Measured 2.2e-10, 1.3e-10, 3.2e-9 relative; bound 1e-8.
            (g - fd).abs() < 1e-8 * fd.abs().max(1e-3),
            "{name}: {g:e} vs {fd:e}"
        );
    }
}

#[test]
fn energy_error_of_runs_from_rest_at_the_datum_is_small() {
    // Free fall from rest at z = 0 and the pendulum released level with
    // its hinge both start with E0 = 0 and keep E ≈ 0: measured against
    // max |E| alone the error read 1.00; against the kinetic energy they
    // gain (m g h) it is the integrator's relative energy drift.
    let fall = r#"
[scene]
effects = ["gravity"]
[[scene.bodies]]
name = "ball"
mass = 2.0
com = [0.0, 0.0, 0.0]
inertia = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]]
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 1.0
dt_out = 0.1
[scene.outputs]
quantities = ["energy", "kinetic_energy"]
"#;
    let sim = run(fall);
    let t = column(&sim, "kinetic_energy");
    // T(1 s) = ½ m (g t)² = 96.2 J.
    assert!((t[t.len() - 1] - 0.5 * 2.0 * 9.81f64.powi(2)).abs() < 1e-8);
    let fall_error = sim.energy_error.expect("conservative");
    let swing_error = run(&pendulum(1.5)).energy_error.expect("conservative");
    println!("energy error: free fall {fall_error:e}, pendulum {swing_error:e}");
    // Measured 3.0e-15 and 2.0e-11; bound 1e-9.
    assert!(fall_error < 1e-9, "free fall {fall_error:e}");
    assert!(swing_error < 1e-9, "pendulum {swing_error:e}");
}

/// A free flexible beam (L = 1 m, ρA = 1 kg/m, polar inertia 0.001 kg·m
/// per metre) translating at v = (0, 0.3, 0.4) m/s and spinning about its
/// own axis at ω_x = 10 rad/s, plus a small tumble that excites the modes.
fn free_beam(tumble: f64) -> String {
    format!(
        r#"
[scene]
effects = ["flexibility", "quadratic_velocity"]
[[scene.bodies]]
name = "beam"
angular_velocity = [10.0, {tumble}, {tumble}]
velocity = [0.0, 0.3, 0.4]
flexible = {{ kind = "beam", modes = 4, origin = [0.0, 0.0, 0.0], length = 1.0, ei_y = 100.0, ei_z = 60.0, rho_a = 1.0, rho_ip = 0.001 }}
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 1.0
dt_out = 0.05
[scene.outputs]
quantities = ["beam.kinetic_energy", "beam.strain_energy", "kinetic_energy"]
"#
    )
}

#[test]
fn kinetic_energy_of_a_free_flexible_beam() {
    // Undeformed, spinning about the axis through its centre of mass:
    // T = ½ m|v|² + ½ I_x ω_x², m = ρA L = 1 kg, I_x = 0.001 kg·m².
    let sim = run(&free_beam(0.0));
    let t0 = 0.5 * 0.25 + 0.5 * 0.001 * 100.0;
    let t = column(&sim, "beam.kinetic_energy");
    println!("T(0) = {} (closed form {t0})", t[0]);
    assert!((t[0] - t0).abs() < 1e-12, "{}", t[0]);
    // Tumbling: the modes take energy, T + U stays.
    let sim = run(&free_beam(1.5));
    let (t, u) = (
        column(&sim, "beam.kinetic_energy"),
        column(&sim, "beam.strain_energy"),
    );
    let e0 = t[0] + u[0];
    let drift = t
        .iter()
        .zip(&u)
        .fold(0.0f64, |d, (t, u)| d.max((t + u - e0).abs()));
    let umax = u.iter().fold(0.0f64, |a, b| a.max(*b));
    println!("T + U drift {drift:e}, max U {umax:e}");
    assert!(umax > 1e-8, "modes not excited: {umax:e}");
    // Measured 7.4e-14 J; bound 3e-13 J.
    assert!(drift < 3e-13, "{drift:e} (E0 {e0:e})");
}

#[test]
fn flexible_kinetic_energy_has_exact_state_derivatives() {
    // ∂T/∂y · v from one dual evaluation against central differences at a
    // deformed, tumbling state of the beam (T depends on the modal
    // coordinates through the mass matrix).
    let spec = scene_spec(&free_beam(1.5));
    let (sys, sim) = simulate(&spec.build().unwrap()).unwrap();
    let y = sim.y_end.clone();
    let v: Vec<f64> = (0..y.len())
        .map(|k| ((k * 7 + 3) % 11) as f64 / 11.0 - 0.4)
        .collect();
    let terms = [Energy::Kinetic(0)];
    let yd: Vec<Dual64> = y.iter().zip(&v).map(|(a, b)| Dual64::new(*a, *b)).collect();
    let exact = sys.energy_sum(&terms, &yd, &mut Workspace::empty()).eps;
    let h = 1e-6;
    let at = |s: f64| {
        let ys: Vec<f64> = y.iter().zip(&v).map(|(a, b)| a + s * b).collect();
        sys.energy_sum(&terms, &ys, &mut Workspace::empty())
    };
    let fd = (at(h) - at(-h)) / (2.0 * h);
    println!("dT·v {exact:.12e}, central difference {fd:.12e}");
    assert!(
        (exact - fd).abs() < 1e-8 * exact.abs().max(1.0),
        "{exact:e} vs {fd:e}"
    );
}
