//! Torsion springs on revolute joints (`type = "spring"`, `joint = <a
//! revolute joint>`) against closed forms: a disc on a tilted revolute
//! joint through its centre (J = 0.5 kg·m² about every axis) with a spring
//! k = 8 N·m/rad, so ω = √(k/J) = 4 rad/s, free and damped (ζ = c /
//! (2√(kJ))), with its exact stiffness and damping sensitivities.
//! `J θ̈ = −k(θ − θ0) − c θ̇ + τ0`, θ(0) = θ̇(0) = 0, is solved in each
//! test's comment.
use crate::common::scenes::{run, scene_spec};
use crate::common::tables::column;

/// The disc with a torsion spring of free angle 0.1 rad and `extra`
/// spring keys; `effects` beside `springs`.
fn disc(effects: &str, extra: &str) -> String {
    format!(
        r#"
[scene]
effects = ["springs"{effects}]
sensitivities = ["twist.stiffness", "twist.damping"]
[[scene.bodies]]
name = "disc"
mass = 2.0
com = [0.3, -0.2, 0.1]
inertia = [[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]]
[[scene.joints]]
name = "pin"
type = "revolute"
body_i = "ground"
body_j = "disc"
point = [0.3, -0.2, 0.1]
axis = [1.0, 2.0, 2.0]
[[scene.forces]]
type = "spring"
name = "twist"
joint = "pin"
stiffness = 8.0
angle = 0.1
{extra}
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 2.0
dt_out = 0.05
[scene.outputs]
quantities = ["pin.angle", "pin.rate", "energy"]
"#
    )
}

/// `θ(t)` of `J θ̈ + c θ̇ + k θ = k θe` from rest at 0 (underdamped):
/// `θe (1 − e^{−ζωt}(cos ωd t + ζ/√(1−ζ²) sin ωd t))`, ω = √(k/J),
/// ζ = c/(2√(kJ)), ωd = ω√(1−ζ²).
fn step_response(k: f64, c: f64, theta_e: f64, t: f64) -> f64 {
    let j = 0.5;
    let w = (k / j).sqrt();
    let z = c / (2.0 * (k * j).sqrt());
    let wd = w * (1.0 - z * z).sqrt();
    let s = z / (1.0 - z * z).sqrt();
    theta_e * (1.0 - (-z * w * t).exp() * ((wd * t).cos() + s * (wd * t).sin()))
}

#[test]
fn torsion_oscillator_turns_at_sqrt_k_over_j() {
    let sim = run(&disc("", ""));
    let (h, r) = (&sim.headers, &sim.rows);
    let (th, rate) = (column(h, r, "pin.angle"), column(h, r, "pin.rate"));
    // θ = θ0 (1 − cos ωt), ω = 4 rad/s.
    let (w, th0) = (4.0f64, 0.1);
    let mut err = 0.0f64;
    for (k, row) in r.iter().enumerate() {
        let t = row[0];
        err = err.max((th[k] - th0 * (1.0 - (w * t).cos())).abs());
        err = err.max((rate[k] - th0 * w * (w * t).sin()).abs() / w);
    }
    println!("error {err:e}, energy {:?}", sim.energy_error);
    // Measured: 8.1e-12 and an energy error of 1.6e-10.
    assert!(err < 1e-10, "angle error {err:e}");
    let de = sim
        .energy_error
        .expect("an undamped spring is conservative");
    assert!(de < 1e-9, "energy error {de:e}");
    // ∂θ/∂k = θ0 t sin(ωt) · dω/dk, dω/dk = 1/(2Jω); c = 0 here.
    let last = sim.sens_rows.last().unwrap();
    let t = last[0];
    let col = |name: &str| {
        let c = sim.sens_headers.iter().position(|x| x.starts_with(name));
        last[c.unwrap_or_else(|| panic!("{name} in {:?}", sim.sens_headers))]
    };
    let dk = th0 * t * (w * t).sin() / (2.0 * 0.5 * w);
    let gk = col("d(pin.angle)/d(twist.stiffness)");
    assert!((gk - dk).abs() < 1e-7 * dk.abs(), "dθ/dk {gk:e} vs {dk:e}");
}

#[test]
fn damped_torsion_oscillator_decays_with_zeta_and_settles_at_the_preload() {
    // c = 0.4 N·m·s/rad: ζ = 0.4/(2·√(8·0.5)) = 0.1; preload τ0 = 0.2 N·m
    // moves the equilibrium to θe = θ0 + τ0/k = 0.125 rad.
    let (k, c) = (8.0, 0.4);
    let sim = run(&disc(", \"damping\"", "damping = 0.4\ntorque = 0.2"));
    assert!(sim.energy_error.is_none(), "damped: not conservative");
    let (h, r) = (&sim.headers, &sim.rows);
    let th = column(h, r, "pin.angle");
    let mut err = 0.0f64;
    for (i, row) in r.iter().enumerate() {
        err = err.max((th[i] - step_response(k, c, 0.125, row[0])).abs());
    }
    assert!(err < 1e-9, "angle error {err:e}");
    // Exact sensitivities against central differences of the closed form.
    let last = sim.sens_rows.last().unwrap();
    let t = last[0];
    let col = |name: &str| {
        let i = sim.sens_headers.iter().position(|x| x.starts_with(name));
        last[i.unwrap_or_else(|| panic!("{name} in {:?}", sim.sens_headers))]
    };
    let hk = 1e-5;
    // θe = θ0 + τ0/k depends on k too.
    let fk = |k: f64| step_response(k, c, 0.1 + 0.2 / k, t);
    let dk = (fk(k + hk) - fk(k - hk)) / (2.0 * hk);
    let dc = (step_response(k, c + hk, 0.125, t) - step_response(k, c - hk, 0.125, t)) / (2.0 * hk);
    let (gk, gc) = (
        col("d(pin.angle)/d(twist.stiffness)"),
        col("d(pin.angle)/d(twist.damping)"),
    );
    println!("dθ/dk {gk:e} ({dk:e}), dθ/dc {gc:e} ({dc:e})");
    assert!(
        (gk - dk).abs() < 1e-6 * dk.abs().max(1e-3),
        "dθ/dk {gk:e} vs {dk:e}"
    );
    assert!(
        (gc - dc).abs() < 1e-6 * dc.abs().max(1e-3),
        "dθ/dc {gc:e} vs {dc:e}"
    );
}

#[test]
fn torsion_spring_keys_are_checked() {
    // A translational key on a torsion spring, and a torsion key on a
    // sliding joint, are refused by name.
    let e = scene_spec(&disc("", "length = 0.2"))
        .build()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("forces[0].length") && e.contains("torsion spring"),
        "{e}"
    );
    let slide = disc("", "").replace("type = \"revolute\"", "type = \"prismatic\"");
    let e = scene_spec(&slide).build().unwrap_err().to_string();
    assert!(
        e.contains("forces[0].angle") && e.contains("revolute"),
        "{e}"
    );
    let locked = disc("", "").replace("type = \"revolute\"", "type = \"locked\"");
    let e = scene_spec(&locked).build().unwrap_err().to_string();
    assert!(
        e.contains("forces[0].joint") && e.contains("a revolute joint"),
        "{e}"
    );
}
