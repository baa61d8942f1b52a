//! Critical time points of a peak constraint
//! (`[[scene_problem.constraints]] critical_points`, explore::problem::scene_bounds,
//! mbs::responses::critical_points) on a coarse SAR scene (8 mesh
//! divisions, 4 modes per panel, 0–3 s at rtol 1e-10; the shipped
//! studies use 32, 14, rtol 1e-6): the peak-U3 bound with three
//! critical points gives three constraints, the first the peak's own (the
//! same number as without the key), the others the next local maxima of
//! U3 in time, each with its exact gradient against central differences
//! of the problem's own `evaluate`.

use crate::common::sar::{coarse_sar, replace};
use plyscape::explore::problem::scene_problem::SceneProblem;
use plyscape::optimize::Problem;
use plyscape::study::Study;

const EXPLORE: &str = include_str!("../../../studies/sar_explore.toml");

fn build(text: &str) -> plyscape::Result<SceneProblem> {
    SceneProblem::from_study(&Study::parse("critical_points.toml", text)?)
}

/// sar_explore, coarse, with `extra` in place of its constraint's
/// `critical_points = 2`.
fn study(extra: &str) -> String {
    // The whole 3 s run: over the first 0.5 s U3 only rises.
    let text = replace(&coarse_sar(EXPLORE, 8, 4), "t_end = 0.5", "t_end = 3.0", 1);
    replace(&text, "critical_points = 2\n", extra, 1)
}

#[test]
fn every_critical_point_is_a_constraint_with_its_exact_gradient() {
    let one = build(&study("")).unwrap();
    let three = build(&study("critical_points = 3\n")).unwrap();
    assert_eq!(one.n_constraints(), 1);
    assert_eq!(three.n_constraints(), 3);
    let labels = three.constraint_responses();
    println!("{labels:?}");
    assert_eq!(labels[1], "u3_peak (critical point 2)");
    let x = [40.0, -25.0];
    let e1 = one.evaluate(&x, true).unwrap();
    let e3 = three.evaluate(&x, true).unwrap();
    println!("g one point {:?}, three points {:?}", e1.g, e3.g);
    // The first is the peak's constraint, unchanged; the others are lower
    // local maxima of U3 in time (distinct: this run has three).
    assert_eq!(e3.g[0], e1.g[0]);
    assert_eq!(e3.grad_g.as_ref().unwrap()[0], e1.grad_g.unwrap()[0]);
    assert!(e3.g[0] > e3.g[1] && e3.g[1] > e3.g[2], "{:?}", e3.g);
    // Each against central differences (0.01°; the reference is the
    // difference quotient, O(h²) plus the rtol-1e-10 noise over h, and
    // the O(Δt³) location of each critical time point, which moves
    // smoothly with the design between samples).
    let gg = e3.grad_g.unwrap();
    let h = 0.01;
    for i in 0..2 {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[i] += h;
        xm[i] -= h;
        let (ep, em) = (
            three.evaluate(&xp, false).unwrap(),
            three.evaluate(&xm, false).unwrap(),
        );
        for (k, row) in gg.iter().enumerate() {
            let fd = (ep.g[k] - em.g[k]) / (2.0 * h);
            let scale = row.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let rel = (row[i] - fd).abs() / scale;
            println!(
                "g{k} d/dx{i}: analytic {:e}, FD {fd:e}, error {rel:.1e} of the largest",
                row[i]
            );
            assert!(rel < 1e-5, "g{k} d/dx{i}: {rel:e}");
        }
    }
}

#[test]
fn critical_points_need_a_peak_and_its_side() {
    for (extra, detail) in [
        ("critical_points = 0\n", "a count from 1 to 16"),
        ("critical_points = 17\n", "a count from 1 to 16"),
    ] {
        let e = build(&study(extra)).err().expect(extra).to_string();
        println!("{e}");
        assert!(
            e.contains("`scene_problem.constraints[0].critical_points`") && e.contains(detail),
            "{e}"
        );
    }
    // On an integral (not a peak).
    let text = replace(
        &study("critical_points = 2\n"),
        "response = \"u3_peak\"",
        "response = \"psi0\"",
        1,
    );
    let e = build(&text).err().expect("integral").to_string();
    assert!(e.contains("a `peak` response"), "{e}");
}
