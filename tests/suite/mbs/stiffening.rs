//! Geometric stiffening (`plyscape::mbs::model::geometric`): the Kane
//! spin-up studies against the independent Hencky bar-chain reference,
//! and the effect switched off leaves the modal terms untouched.

use crate::common::scenes::run;
use crate::common::scenes::{column, shipped_text, study_path};

/// `(t, tip_y)` of the committed reference: the Richardson extrapolation
/// (20 and 40 links) of the geometrically exact Hencky bar chain written
/// by `cargo bench --bench kane_reference` (benches/kane_reference.rs;
/// 10/20/40-link peaks at ωs = 4: −0.40663, −0.40173, −0.40051 m, so the
/// extrapolation's error is well below 0.1 %).
fn reference(ws: u32) -> Vec<(f64, f64)> {
    let path = study_path("../results/kane_spinup").join(format!("reference_ws{ws}.csv"));
    let text = std::fs::read_to_string(&path).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[4])
        })
        .collect()
}

fn peak(v: &[(f64, f64)]) -> (f64, f64) {
    v.iter()
        .copied()
        .fold((0.0, 0.0), |m, p| if p.1.abs() > m.1.abs() { p } else { m })
}

fn check(ws: u32) {
    let sim = run(&shipped_text(&format!("kane_spinup_ws{ws}.toml")));
    let t = column(&sim, "t");
    let y = column(&sim, "tip.deflection_y");
    let got: Vec<(f64, f64)> = t.into_iter().zip(y).collect();
    let want = reference(ws);
    let (pg, pw) = (peak(&got), peak(&want));
    let after = got
        .iter()
        .filter(|p| p.0 >= 15.0)
        .fold(0.0f64, |m, p| m.max(p.1.abs()));
    println!("ws = {ws}: peak {pg:?} vs reference {pw:?}, max |tip| after 15 s {after:e}");
    // Acceptance of issue 24: peak within 2 % of the reference, |tip| ≤
    // 0.01 m after the spin-up. Measured 0.06 % / 4.1e-3 m (ωs = 4) and
    // 0.22 % / 6.2e-3 m (ωs = 10). Kane, Ryan & Banerjee (1987) report a
    // peak of about −0.4 m at ωs = 4 (cited, not fitted).
    assert!((pg.1 / pw.1 - 1.0).abs() < 0.02, "peak {pg:?} vs {pw:?}");
    assert!(after <= 0.01, "tip after 15 s {after}");
}

#[test]
fn kane_spinup_ws4_matches_hencky_chain() {
    check(4);
}

#[test]
fn kane_spinup_ws10_matches_hencky_chain() {
    check(10);
}

#[test]
fn without_the_effect_the_linear_model_overshoots() {
    // The same scene without "geometric_stiffening", stopped at 8 s: the
    // linear floating-frame model's tip runs past the reference peak by
    // about 30 % (issue 24: −0.524 m at 7 s), so the effect is what the
    // check above measures.
    let text = shipped_text("kane_spinup_ws4.toml")
        .replace(", \"geometric_stiffening\"]", "]")
        .replace("t_end = 25.0", "t_end = 8.0");
    let sim = run(&text);
    let t = column(&sim, "t");
    let y = column(&sim, "tip.deflection_y");
    let (_, p) = peak(&t.into_iter().zip(y).collect::<Vec<_>>());
    assert!(p < -0.5, "linear model peak {p}");
}
