//! Ply-angle sensitivities of a swung composite panel through its modal
//! basis (outputs, strain-energy responses), with and without geometric
//! stiffening, against central differences of whole simulations.

use super::scenes::{panel_scene, stiffened_panel_scene, study};
use plyscape::scene::load_scene;
use plyscape::simulate::simulate;

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
