//! Free rigid body spinning about its intermediate axis (Dzhanibekov
//! effect): energy and angular momentum are invariants of the exact flow
//! (Euler's equations), so their drift measures the integrator error.
use crate::common::scenes::{run as simulate_text, shipped_scene};
use plyscape::integrate::{integrate, Method, Options, SensitivityForm};
use plyscape::mbs::{System, Workspace};

/// The body of studies/dzhanibekov.toml: 1.5 kg, principal inertia
/// diag(1, 2, 3) kg m², spin 5 rad/s about the intermediate axis y with a
/// 0.01 rad/s perturbation about x, centre of mass drifting at
/// (0.1, 0, −0.2) m/s.
fn tumbling_body() -> System {
    let scene = shipped_scene("dzhanibekov.toml");
    System::new(scene.model)
}

fn run(method: Method, rtol: f64) -> (f64, f64, f64) {
    let sys = tumbling_body();
    let y0 = sys.initial_state();
    let mut ws = Workspace::empty();
    let e0 = sys.energy(&y0, &mut ws);
    let h0 = sys.angular_momentum(&y0, &mut ws);
    let (mut de, mut dh, mut min_wy) = (0.0f64, 0.0f64, f64::INFINITY);
    let opts = Options {
        method,
        rtol,
        atol: rtol * 1e-2,
        t0: 0.0,
        times: (1..=400).map(|k| k as f64 * 0.025).collect(),
        events: true,
        sensitivity: SensitivityForm::Staggered,
    };
    integrate(&sys, &y0, &opts, |_t, y| {
        let mut ws = Workspace::empty();
        de = de.max((sys.energy(y, &mut ws) - e0).abs() / e0);
        dh = dh.max((sys.angular_momentum(y, &mut ws) - h0).norm() / h0.norm());
        min_wy = min_wy.min(y[7 + 4]);
        Ok(())
    })
    .unwrap();
    (de, dh, min_wy)
}

#[test]
fn dzhanibekov_flips_and_conserves_invariants() {
    for method in [Method::Bdf, Method::Tsit45, Method::Esdirk34] {
        let (de, dh, min_wy) = run(method, 1e-8);
        // The intermediate-axis spin is unstable: ω_y changes sign (flip).
        assert!(min_wy < -4.0, "{method:?}: no flip, min ω_y = {min_wy}");
        // Invariants to the integrator tolerance (rtol 1e-8 over ~5 flips).
        // Measured at most 2.8e-7 (energy) and 6.9e-7 (momentum), both
        // ESDIRK 3(4); bounds about 3×.
        assert!(de < 9e-7, "{method:?}: energy drift {de:e}");
        assert!(dh < 2e-6, "{method:?}: momentum drift {dh:e}");
        println!("{method:?}: energy {de:.2e}, momentum {dh:.2e}");
    }
}

#[test]
fn constant_load_gives_uniform_acceleration() {
    // Constant force F at the centre and constant torque τ about a principal
    // axis of a body at rest: r(t) = r0 + F t²/(2m), ω(t) = τ t / I_zz
    // (closed form derived in this test; no gyroscopic term for ω ∥ e_z).
    let text = r#"
[scene]
effects = ["loads", "quadratic_velocity"]
[[scene.bodies]]
name = "box"
mass = 2.0
com = [0.0, 0.0, 0.0]
inertia = [[0.5, 0.0, 0.0], [0.0, 0.7, 0.0], [0.0, 0.0, 0.9]]
[[scene.forces]]
type = "load"
body = "box"
force = [1.0, -2.0, 4.0]
torque = [0.0, 0.0, 0.45]
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 2.0
dt_out = 0.5
[scene.outputs]
quantities = ["box.position"]
"#;
    let sim = simulate_text(text);
    for r in &sim.rows {
        let t = r[0];
        for (k, f) in [1.0, -2.0, 4.0].iter().enumerate() {
            let exact = f * t * t / (2.0 * 2.0);
            assert!(
                (r[1 + k] - exact).abs() < 1e-9,
                "t {t}: x{k} {} vs {exact}",
                r[1 + k]
            );
        }
    }
    let wz = sim.y_end[7 + 5];
    assert!((wz - 0.45 * 2.0 / 0.9).abs() < 1e-9, "ω_z {wz}");
}

#[test]
fn tabulated_load_is_integrated_piecewise_exactly() {
    // A time table F(t) = (0, 0, 0) at t = 0, (3, 0, 0) at t = 1, (3, 0, 0)
    // at t = 2, (0, 0, 0) at t = 3 (linear between rows, held outside) on a
    // 1.5 kg body at rest: x(t) is the double integral of F/m, piecewise
    // cubic/quadratic (closed form derived in this test).
    let text = r#"
[scene]
effects = ["loads"]
[[scene.bodies]]
name = "box"
mass = 1.5
com = [0.0, 0.0, 0.0]
inertia = [[0.5, 0.0, 0.0], [0.0, 0.7, 0.0], [0.0, 0.0, 0.9]]
[[scene.forces]]
type = "load"
body = "box"
table = [[0.0, 0, 0, 0, 0, 0, 0], [1.0, 3, 0, 0, 0, 0, 0], [2.0, 3, 0, 0, 0, 0, 0], [3.0, 0, 0, 0, 0, 0, 0]]
[scene.integrator]
method = "bdf"
rtol = 1e-10
atol = 1e-12
t_end = 4.0
dt_out = 0.25
[scene.outputs]
quantities = ["box.position"]
"#;
    let sim = simulate_text(text);
    // a(t) = F/m: 2t on [0,1], 2 on [1,2], 2(3 − t) on [2,3], 0 after.
    let exact = |t: f64| -> f64 {
        let (v1, x1) = (1.0, 1.0 / 3.0); // v = t², x = t³/3 on [0, 1]
        let (v2, x2) = (v1 + 2.0, x1 + v1 + 1.0); // v = 1 + 2(t−1), x = x1 + (t−1) + (t−1)²
        let v3 = v2 + 1.0; // ∫_2^3 2(3−t) dt = 1
        let x3 = x2 + v2 + 2.0 / 3.0; // ∫_2^3 [v2 + 2(τ) − τ²] dτ, τ = t−2: v2 + 1 − 1/3
        if t <= 1.0 {
            t.powi(3) / 3.0
        } else if t <= 2.0 {
            let s = t - 1.0;
            x1 + v1 * s + s * s
        } else if t <= 3.0 {
            let s = t - 2.0;
            x2 + v2 * s + s * s - s.powi(3) / 3.0
        } else {
            x3 + v3 * (t - 3.0)
        }
    };
    for r in &sim.rows {
        let e = exact(r[0]);
        assert!(
            (r[1] - e).abs() < 1e-7 * (1.0 + e.abs()),
            "t {}: {} vs {e}",
            r[0],
            r[1]
        );
    }
}

#[test]
fn revolute_angles_are_written_continuous() {
    // A free rotor on a frictionless hinge, no gravity, spinning at
    // ω = 10 rad/s about the hinge axis through its centre of mass: the
    // closed form is θ(t) = 10 t, which passes π at t = 0.314 s and turns
    // three times by t = 2 s. The relative angle is measured in (−π, π],
    // history.csv writes it continuous.
    let sim = simulate_text(
        r#"
[scene]
effects = []
[[scene.bodies]]
name = "rotor"
mass = 1.0
com = [0.0, 0.0, 0.0]
inertia = [[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]]
angular_velocity = [0.0, 0.0, 10.0]
[[scene.joints]]
name = "hinge"
type = "revolute"
body_i = "ground"
body_j = "rotor"
point = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 2.0
dt_out = 0.05
[scene.outputs]
quantities = ["hinge.angle"]
"#,
    );
    assert_eq!(sim.headers[1], "hinge.angle [rad]");
    let mut worst = 0.0f64;
    for row in &sim.rows {
        worst = worst.max((row[1] - 10.0 * row[0]).abs());
    }
    let last = sim.rows.last().unwrap();
    println!(
        "θ(2 s) = {} (closed form 20), worst error {worst:.1e}",
        last[1]
    );
    assert!(worst < 1e-6, "{worst}");
    assert!((last[1] - 20.0).abs() < 1e-6);
}
