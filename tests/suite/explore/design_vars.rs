//! Design variables of every kind in the scene problem
//! (`explore::problem::scene_problem`, `[[scene_problem.variables]]`): eight
//! independent ply angles (studies/sar_explore8.toml: every ply of panels
//! 2 and 3 free, unsymmetric stacks) and ply angles with scene parameters
//! (studies/sar_codesign.toml: the actuator's damping and one slope of its
//! law), each with exact gradients checked against central differences of
//! the problem's own `evaluate` on a coarse version of the study (8 mesh
//! divisions, 4 modes per panel, 0–0.5 s at rtol 1e-10: the shipped
//! studies use 32, 14, 0–3 s, rtol 1e-6); and the input errors of the
//! `sets` entries.

use crate::common::sar::{coarse_sar, replace};
use plyscape::explore;
use plyscape::optimize::Problem;
use plyscape::study::Study;

const EXPLORE8: &str = include_str!("../../../studies/sar_explore8.toml");
const CODESIGN: &str = include_str!("../../../studies/sar_codesign.toml");

fn build(text: &str) -> plyscape::Result<Box<dyn Problem>> {
    explore::problem(&Study::parse("design_vars.toml", text)?)
}

/// The gradients of f and g at `x` against central differences with steps
/// `h[i]`; errors relative to the largest component of each gradient
/// (the reference is the difference quotient, O(h²) plus the integrator's
/// rtol-1e-10 noise over h).
fn check_gradients(p: &dyn Problem, x: &[f64], h: &[f64], tol: f64) {
    let n = x.len();
    let e = p.evaluate(x, true).unwrap();
    let (gf, gg) = (e.grad_f.unwrap(), e.grad_g.unwrap());
    let mut fd = vec![vec![0.0; n]; 2];
    for i in 0..n {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[i] += h[i];
        xm[i] -= h[i];
        let (ep, em) = (
            p.evaluate(&xp, false).unwrap(),
            p.evaluate(&xm, false).unwrap(),
        );
        fd[0][i] = (ep.f - em.f) / (2.0 * h[i]);
        fd[1][i] = (ep.g[0] - em.g[0]) / (2.0 * h[i]);
    }
    for (k, (an, fd)) in [&gf, &gg[0]].into_iter().zip(&fd).enumerate() {
        let scale = fd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        for i in 0..n {
            let rel = (an[i] - fd[i]).abs() / scale;
            println!(
                "{} d/dx{i}: analytic {:e}, FD {:e}, error {rel:.1e} of the largest",
                ["f", "g"][k],
                an[i],
                fd[i]
            );
            assert!(rel < tol, "{} d/dx{i}: {rel:e}", ["f", "g"][k]);
        }
    }
}

#[test]
fn eight_ply_angles_have_exact_gradients() {
    // sar_explore8: plies 1-4 of panels 2 and 3 each a variable, at an
    // unsymmetric design (B ≠ 0 on both panels). Eight lanes, the per-ply
    // mode derivatives of both panels (updated-mode approach).
    let p = build(&coarse_sar(EXPLORE8, 8, 4)).unwrap();
    assert_eq!(p.variables().len(), 8);
    let x = [40.0, -25.0, -60.0, 70.0, 35.0, -20.0, -65.0, 50.0];
    check_gradients(p.as_ref(), &x, &[0.01; 8], 1e-5);
}

#[test]
fn ply_angles_with_scene_parameters_have_exact_gradients() {
    // sar_codesign: the two shared angles (deg), the actuator's damping
    // (N·m·s/rad) and the slope of its law on its first segment (N·m/rad).
    let p = build(&coarse_sar(CODESIGN, 8, 4)).unwrap();
    assert_eq!(p.variables().len(), 4);
    assert_eq!(p.variable_label(2), "damping [SI]");
    assert_eq!(p.variable_label(0), "θ1 [deg]");
    // At the start the normalized values are 1 and 0.
    let e0 = p.evaluate(&[55.0, -55.0, 0.5, 9.0], false).unwrap();
    assert!((e0.f - 1.0).abs() < 1e-12 && e0.g[0].abs() < 1e-12);
    let x = [40.0, -25.0, 0.8, 12.0];
    check_gradients(p.as_ref(), &x, &[0.01, 0.01, 1e-4, 1e-3], 1e-5);
    // The law's slope acts on the segment the actuator is on (3.08-3.12
    // rad over the run): its derivative is not zero.
    let e = p.evaluate(&x, true).unwrap();
    assert!(e.grad_f.unwrap()[3].abs() > 1e-6, "df/dslope");
    // Moving a scene variable changes the result (the value reaches the
    // model, not only its lane).
    let e1 = p.evaluate(&[40.0, -25.0, 1.6, 12.0], false).unwrap();
    let e2 = p.evaluate(&x, false).unwrap();
    assert!((e1.f - e2.f).abs() > 1e-6, "{} vs {}", e1.f, e2.f);
}

#[test]
fn ply_thickness_variables_have_exact_gradients() {
    // sar_codesign with the actuator's damping replaced by the common
    // thickness of the outer plies 1 and 4 of both panels, in mm (the
    // study's plies are 0.5 mm, so the start 0.5 is the study's design):
    // stiffness and mass both move, through the lanes
    // `<body>.design.thickness_1_4` (per metre) of both panel bodies.
    let text = replace(
        &coarse_sar(CODESIGN, 8, 4),
        "name = \"damping\"\nbounds = [0.1, 2.0]\nsets = [\"scene:forces[0].damping\"]",
        "name = \"t_1_4_mm\"\nbounds = [0.1, 2.0]\nsets = [\"panel2:thickness_1_4\", \"panel3:thickness_1_4\"]",
        1,
    );
    let text = replace(
        &text,
        "\"forces[0].damping\"",
        "\"B2.design.thickness_1_4\", \"B3.design.thickness_1_4\"",
        1,
    );
    let p = build(&text).unwrap();
    assert_eq!(p.variable_label(2), "t_1_4 [mm]");
    // At the start the lay-up is the study's: normalized values 1 and 0.
    let e0 = p.evaluate(&[55.0, -55.0, 0.5, 9.0], false).unwrap();
    assert!((e0.f - 1.0).abs() < 1e-12 && e0.g[0].abs() < 1e-12);
    let x = [40.0, -25.0, 0.6, 12.0];
    check_gradients(p.as_ref(), &x, &[0.01, 0.01, 1e-4, 1e-3], 1e-5);
    // Thicker outer plies change Ψ₀ (the variable reaches the laminate).
    let e = p.evaluate(&x, true).unwrap();
    assert!(e.grad_f.unwrap()[2].abs() > 1e-3, "df/dt");
    // Bounds outside [0.001, 25] mm are refused naming the unit: a
    // thickness in metres, and a bound of 1e6 mm (every evaluation would
    // fail in the modal analysis).
    for bounds in ["[0.0001, 0.002]", "[0.1, 1e6]"] {
        let bad = replace(
            &text,
            "bounds = [0.1, 2.0]",
            &format!("bounds = {bounds}"),
            1,
        );
        let e = match build(&bad) {
            Ok(_) => panic!("accepted {bounds}"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("scene_problem.variables[2].bounds") && e.contains("millimetres"),
            "{e}"
        );
    }
}

#[test]
fn bad_scene_entries_name_the_key() {
    let base = coarse_sar(CODESIGN, 8, 4);
    let err = |from: &str, to: &str| -> String {
        let text = replace(&base, from, to, 1);
        match build(&text) {
            Ok(_) => panic!("accepted {to}"),
            Err(e) => e.to_string(),
        }
    };
    // Kinds mixed in one variable.
    let e = err(
        r#"sets = ["scene:forces[0].damping"]"#,
        r#"sets = ["scene:forces[0].damping", "panel2:theta_1_4"]"#,
    );
    assert!(
        e.contains("scene_problem.variables[2].sets[1]") && e.contains("one kind"),
        "{e}"
    );
    // A scene parameter is not periodic.
    let e = err(
        "bounds = [0.1, 2.0]\n",
        "bounds = [0.1, 2.0]\nperiodic = true\n",
    );
    assert!(e.contains("scene_problem.variables[2].periodic"), "{e}");
    // Not in [scene] sensitivities.
    let e = err(
        r#"sets = ["scene:forces[0].damping"]"#,
        r#"sets = ["scene:forces[0].segments[1].slope"]"#,
    );
    assert!(
        e.contains("scene.sensitivities") && e.contains("forces[0].segments[1].slope"),
        "{e}"
    );
    // Listed in [scene] sensitivities but not a parameter of the scene:
    // found at the first evaluation (the start design).
    let text = replace(
        &base,
        r#""forces[0].damping", "forces"#,
        r#""forces[0].damping", "B99.mass", "forces"#,
        1,
    );
    let text = replace(
        &text,
        r#"sets = ["scene:forces[0].damping"]"#,
        r#"sets = ["scene:B99.mass"]"#,
        1,
    );
    let e = match build(&text) {
        Ok(_) => panic!("accepted B99.mass"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("B99.mass") && e.contains("has none"), "{e}");
    // A ply angle spelled as a scene parameter.
    let e = err(
        r#"sets = ["scene:forces[0].damping"]"#,
        r#"sets = ["scene:B2.design.theta_1_4"]"#,
    );
    assert!(e.contains("scene_problem.variables[2].sets[0]"), "{e}");
}
