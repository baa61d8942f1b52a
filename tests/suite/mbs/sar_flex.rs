//! Flexible SAR antenna, phase 1 (studies/sar_phase1_flexible.toml: panels
//! 2 and 3 as floating-frame composite bodies; geometry reconstructed, see
//! docs/sar_reconstruction.md), on a coarse
//! version of the study made by text replacement (8 mesh divisions, 6
//! modes, 0–0.5 s, tight tolerances) so that each simulation takes well
//! under a second: it runs, the constraints hold, the work–energy balance
//! closes, θ(t) stays close to the rigid scene, and a ply-angle
//! sensitivity of panel 3's strain energy matches central differences.
//! The balance and the sensitivity are also checked on the study at full
//! size (2 × 14 modes on 32 divisions, 0–3 s; a few seconds each).

use crate::common::sar::{replace, vary_panel, CoarseSar};
use crate::common::tables::column_index;
use plyscape::mbs::{Force, PiecewiseLaw};
use plyscape::scene::load_scene;
use plyscape::simulate::{simulate, Simulation};
use plyscape::study::Study;

const STUDY: &str = include_str!("../../../studies/sar_phase1_flexible.toml");

/// The coarse scene: 8 divisions, 6 modes, 0–0.5 s at rtol 1e-10; panel
/// 3's outer plies (1 and 4) at `theta_deg`; `sens` = with the
/// sensitivity to B3.design.theta_1_4; `flexible` = false runs the
/// same scene rigid (no "flexibility" effect).
fn coarse(theta_deg: f64, sens: bool, flexible: bool) -> Simulation {
    let sar = CoarseSar {
        text: STUDY,
        file: "sar_phase1_flexible.toml",
        divisions: 8,
        modes: Some(6),
        panel: 3,
        theta_deg,
        sens,
        flexible,
    };
    simulate(&sar.scene()).unwrap().1
}

/// The index of history column `name` (by header prefix).
fn col(sim: &Simulation, name: &str) -> usize {
    column_index(&sim.headers, name)
}

/// ∫_{a}^{b} m(θ) dθ of the Eq. (32) law `m = value + slope·(anchor − θ)`
/// on each segment (lower, upper] (the outermost segments extend beyond
/// the table): exact, segment by segment (closed form derived here: the
/// antiderivative is value·θ + slope·(anchor·θ − θ²/2)).
fn law_integral(law: &PiecewiseLaw, a: f64, b: f64) -> f64 {
    let (lo, hi, sign) = if a <= b { (a, b, 1.0) } else { (b, a, -1.0) };
    let last = law.segments.len() - 1;
    let mut total = 0.0;
    for (k, s) in law.segments.iter().enumerate() {
        let lower = if k == 0 { f64::NEG_INFINITY } else { s.lower };
        let upper = if k == last { f64::INFINITY } else { s.upper };
        let (x0, x1) = (lo.max(lower), hi.min(upper));
        if x1 > x0 {
            let f = |x: f64| s.value * x + s.slope * (s.anchor * x - 0.5 * x * x);
            total += f(x1) - f(x0);
        }
    }
    sign * total
}

/// The R3 actuator of a SAR scene: its Eq. (32) law and damper c.
pub(super) fn actuator(scene: &plyscape::scene::Scene) -> (PiecewiseLaw, f64) {
    match scene.model.forces.first() {
        Some(Force::Rotational {
            law: Some(law),
            damping,
            ..
        }) => (law.clone(), *damping),
        other => panic!("expected the R3 actuator, got {other:?}"),
    }
}

/// Work–energy balance of a SAR run. No gravity and no modal damping
/// (ζ = 0), so the only non-conservative force is the R3 actuator, torque
/// τ = −M(θ, θ̇) = −m(θ) − c θ̇ (docs/sar_reconstruction.md §5), and
///   E(t) − E(0) = −∫_{θ0}^{θ(t)} m dθ − c ∫ θ̇² dt,
/// E = kinetic + strain energy (the `energy` output). The first term is
/// exact (`law_integral`); the second is composite Simpson on the output
/// grid, checked at every second output time (the damper's work is
/// 3.7e-7 J on the coarse scene, 1.3e-4 J at full size; Simpson's error
/// ~h⁴ stays far below both tests' bounds, the trapezoid rule would leave
/// ~1e-11 J on the coarse scene).
/// Returns (largest |ΔE − W|, largest |ΔE|, the damper's work) [J].
pub(super) fn balance(sim: &Simulation, law: &PiecewiseLaw, c: f64) -> (f64, f64, f64) {
    let (ca, cr, ce) = (
        col(sim, "R3.angle"),
        col(sim, "R3.rate"),
        col(sim, "energy"),
    );
    let r0 = &sim.rows[0];
    let mut damper = 0.0;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for k in (2..sim.rows.len()).step_by(2) {
        let (a, m, b) = (&sim.rows[k - 2], &sim.rows[k - 1], &sim.rows[k]);
        let dt = b[0] - a[0];
        assert!((m[0] - a[0] - 0.5 * dt).abs() < 1e-12, "uneven output grid");
        damper += c * dt / 6.0 * (a[cr].powi(2) + 4.0 * m[cr].powi(2) + b[cr].powi(2));
        let work = -law_integral(law, r0[ca], b[ca]) - damper;
        let de = b[ce] - r0[ce];
        worst = worst.max((de - work).abs());
        scale = scale.max(de.abs());
    }
    (worst, scale, damper)
}

/// Assert a balance of [`balance`], `(worst, scale, damper)`: the largest
/// |ΔE − W| within `bound` of the largest |ΔE| (printed with `what`).
pub(super) fn assert_balanced(what: &str, (worst, scale, damper): (f64, f64, f64), bound: f64) {
    println!(
        "{what}: worst |ΔE − W| {worst:e} J of {scale:e} J ({:.2e} relative), damper work \
         {damper:e} J",
        worst / scale
    );
    assert!(
        scale > 0.0 && worst < bound * scale,
        "{what}: balance error {worst:e} of {scale:e} J"
    );
}

#[test]
fn flexible_sar_runs_balances_energy_and_stays_near_rigid() {
    let flex = coarse(55.0, false, true);
    let rigid = coarse(55.0, false, false);
    println!(
        "flexible: {} equations, {} redundant, max violation {:e}, {:?}",
        flex.equations, flex.redundant, flex.max_violation, flex.stats
    );
    // 26 equations as in the rigid scene (docs/sar_reconstruction.md §4:
    // 2 locks × 6 + R3 × 5 + 16 spherical × 3 = 65, less the two locks of
    // B4 and B12 to the fixed B1 and the 27 equations of panel 2 and its
    // struts, which stay at rest: all built fixed by scene::ground). The
    // six redundant equations of the folded rigid scene were all in panel
    // 2's group: none is left.
    assert_eq!(flex.equations, 26);
    assert_eq!((rigid.redundant, flex.redundant), (0, 0));
    assert!(
        flex.max_violation <= 1e-6,
        "violation {:e}",
        flex.max_violation
    );

    // Work–energy balance (`balance`), on the coarse scene's own law.
    let scene_text = replace(STUDY, "divisions = 32", "divisions = 8", 2);
    let scene = load_scene(&Study::parse("s.toml", &scene_text).unwrap()).unwrap();
    let (law, c) = actuator(&scene);
    let (ca, ce) = (col(&flex, "R3.angle"), col(&flex, "energy"));
    let (cs2, cs3) = (
        col(&flex, "B2.strain_energy"),
        col(&flex, "B3.strain_energy"),
    );
    let r0 = &flex.rows[0];
    let (worst, scale, damper) = balance(&flex, &law, c);
    let last = flex.rows.last().unwrap();
    println!(
        "ΔE {:e} J, damper work {damper:e} J, worst |ΔE − W| {worst:e} J; \
         strain energy B2 {:e} J, B3 {:e} J at t_end",
        last[ce] - r0[ce],
        last[cs2],
        last[cs3]
    );
    // The strain energy is a visible part of E (so the balance tests it).
    assert!(last[cs3] > 1e-3 * scale, "B3 strain energy {:e}", last[cs3]);
    // Measured 1.5e-9 relative at rtol 1e-10; bound 1e-8.
    assert!(
        worst < 1e-8 * scale,
        "balance error {worst:e} of {scale:e} J"
    );

    // θ(t) flexible vs rigid. The actuator winds up the elastic panel 3
    // (and the trusses run ahead of it): for a linear elastic link loaded
    // quasi-statically by the actuator torque m ≈ m(θ0) (Eq. 32, 0.1 N·m
    // at 3.12 rad) the extra rotation is δ = 2U/m, U the strain energy
    // (U = ½ m δ, closed form). The deployment itself is slow (travel
    // 5e-4 rad in 0.5 s, lowest panel mode ≈1 Hz), so θ_flex − θ_rigid
    // stays of the order of δ computed from the largest U3 of the run:
    // bounded by 2δ, and not negligible (> 0.1δ), i.e. flexibility shows.
    let travel = (rigid.rows[0][ca] - rigid.rows.last().unwrap()[ca]).abs();
    let dmax = flex
        .rows
        .iter()
        .zip(&rigid.rows)
        .map(|(f, r)| (f[ca] - r[ca]).abs())
        .fold(0.0, f64::max);
    let u_max = flex.rows.iter().map(|r| r[cs3]).fold(0.0, f64::max);
    let s0 = law.segment(r0[ca]);
    let m0 = s0.value + s0.slope * (s0.anchor - r0[ca]);
    let delta = 2.0 * u_max / m0;
    println!(
        "travel {travel:e} rad, max |θ_flex − θ_rigid| {dmax:e} rad, \
         wind-up 2U/m {delta:e} rad (U3 max {u_max:e} J, m {m0} N·m)"
    );
    assert!(travel > 1e-4, "travel {travel:e}");
    assert!(
        dmax < 2.0 * delta && dmax > 0.1 * delta,
        "θ differs by {dmax:e} rad, wind-up {delta:e} rad"
    );
}

#[test]
fn strain_energy_ply_angle_sensitivity_matches_central_differences() {
    // d U_3(t_end) / d θ_{1,4} of panel 3 (direct differentiation through
    // dΛ/dθ and dX/dθ, updated modes Eq. 18) against central finite
    // differences of whole simulations with panel 3 rebuilt at θ ± h.
    let base = coarse(55.0, true, true);
    let cs = col(&base, "B3.strain_energy");
    let last = base.rows.len() - 1;
    let sc = base
        .sens_headers
        .iter()
        .position(|h| h.starts_with("d(B3.strain_energy)/d(B3.design.theta_1_4)"))
        .expect("sensitivity column");
    let analytic = base.sens_rows[last][sc];
    let h: f64 = 2e-4; // rad
    let plus = coarse(55.0 + h.to_degrees(), false, true);
    let minus = coarse(55.0 - h.to_degrees(), false, true);
    let fd = (plus.rows[last][cs] - minus.rows[last][cs]) / (2.0 * h);
    let rel = (analytic - fd).abs() / fd.abs();
    println!(
        "U3(t_end) = {:e} J, dU3/dθ14: analytic {analytic:e}, central FD {fd:e}, rel {rel:e}",
        base.rows[last][cs]
    );
    assert!(base.rows[last][cs] > 0.0);
    assert!(rel < 1e-5, "relative error {rel:e}");
}

/// The shipped study at full size (2 × 14 modes on 32 divisions, 0–3 s,
/// dt_out 0.01 s) with `rtol`, `atol` and `method`; `sens` keeps only the
/// sensitivity to B3.design.theta_1_4 (else none); panel 3's outer plies
/// at `theta_deg`.
fn full(theta_deg: f64, sens: bool, method: &str, rtol: &str, atol: &str) -> Simulation {
    let mut t = vary_panel(STUDY, 3, theta_deg, sens);
    t = replace(&t, "method = \"bdf\"", &format!("method = \"{method}\""), 1);
    t = replace(&t, "rtol = 1e-6", &format!("rtol = {rtol}"), 1);
    t = replace(&t, "atol = 1e-8", &format!("atol = {atol}"), 1);
    let study = Study::parse("sar_phase1_flexible.toml", &t).unwrap();
    simulate(&load_scene(&study).unwrap()).unwrap().1
}

/// The work–energy balance of the shipped flexible study at full size and
/// its own settings (BDF, rtol 1e-6, atol 1e-8): the balance closes to
/// the integration tolerance over the whole deployment window.
#[test]
fn full_size_flexible_sar_balances_energy() {
    let t0 = std::time::Instant::now();
    let sim = full(55.0, false, "bdf", "1e-6", "1e-8");
    let study = Study::parse("sar_phase1_flexible.toml", STUDY).unwrap();
    let (law, c) = actuator(&load_scene(&study).unwrap());
    let (worst, scale, damper) = balance(&sim, &law, c);
    let cs3 = col(&sim, "B3.strain_energy");
    let u3 = sim.rows.iter().map(|r| r[cs3]).fold(0.0, f64::max);
    println!(
        "full size: worst |ΔE − W| {worst:e} J of {scale:e} J ({:.2e} relative), \
         damper work {damper:e} J, peak U3 {u3:e} J, {:?}; {:.2} s",
        worst / scale,
        sim.stats,
        t0.elapsed().as_secs_f64()
    );
    assert_eq!(sim.rows.len(), 301);
    assert!(u3 > 1e-3 * scale, "peak U3 {u3:e}");
    // Measured 1.4e-7 of the energy change (862 steps, about 2 s); bound 3×.
    assert!(
        worst < 4.3e-7 * scale,
        "balance error {worst:e} of {scale:e} J"
    );
}

/// d U_3(3 s) / d θ_{1,4} of panel 3 at full size (2 × 14 modes on 32
/// divisions, 0–3 s) against central differences of whole simulations
/// with panel 3 rebuilt at θ ± h; tsit45 at rtol 1e-10 so that the
/// differences resolve the derivative (the shipped rtol 1e-6 would leave
/// ~1e-6/h of noise in them).
#[test]
fn full_size_strain_energy_ply_angle_sensitivity() {
    let t0 = std::time::Instant::now();
    let (rtol, atol) = ("1e-10", "1e-12");
    let base = full(55.0, true, "tsit45", rtol, atol);
    let cs = col(&base, "B3.strain_energy");
    let last = base.rows.len() - 1;
    let sc = base
        .sens_headers
        .iter()
        .position(|h| h.starts_with("d(B3.strain_energy)/d(B3.design.theta_1_4)"))
        .expect("sensitivity column");
    let analytic = base.sens_rows[last][sc];
    let h: f64 = 2e-4; // rad
    let plus = full(55.0 + h.to_degrees(), false, "tsit45", rtol, atol);
    let minus = full(55.0 - h.to_degrees(), false, "tsit45", rtol, atol);
    let fd = (plus.rows[last][cs] - minus.rows[last][cs]) / (2.0 * h);
    let rel = (analytic - fd).abs() / fd.abs();
    println!(
        "full size: U3(3 s) = {:e} J, dU3/dθ14: analytic {analytic:e}, central FD {fd:e}, \
         rel {rel:e}; {:.2} s",
        base.rows[last][cs],
        t0.elapsed().as_secs_f64()
    );
    // Measured 2.3e-6 (three runs, about 4 s); bound 3×.
    assert!(rel < 6.8e-6, "relative error {rel:e}");
}
