//! The spin-up of a flexible cantilever (studies/beam_spinup.toml): the
//! tip follows the quasi-static deflection, and the effects list switches
//! the flexible, quadratic-velocity and modal-damping terms.

use super::scenes::{spinup, study};
use crate::common::scenes::shipped_text;
use plyscape::beams::{Beam, Plane};
use plyscape::scene::load_scene;
use plyscape::simulate::simulate;

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
