//! The SAR scene read as a book fold (studies/sar_phase1_fold.toml: R3
//! turns panel 3 about a hinge line in the panels' plane; R1, R2 free and
//! panel 2 held to the satellite by the locks D and E; geometry
//! reconstructed, docs/sar_reconstruction.md §11), on a coarse version made
//! by text replacement (16 mesh divisions, 6 modes, 0–0.5 s, tight
//! tolerances) so that each simulation takes about a second: the rank and
//! mobility the study states (the kernel's redundant rows against the rank
//! of a finite-difference constraint Jacobian, rigid and flexible), the
//! constraint violation over the run, the work–energy balance, both panels
//! loaded, and the ply-angle gradients of Ψ₀ against central differences
//! of whole simulations.

use super::sar_flex::{actuator, assert_balanced, balance};
use super::sar_holddown::{fd_jacobian, rank, response, rows_named_and_held};
use crate::common::sar::CoarseSar;
use crate::common::tables::column_index;
use plyscape::scene::Scene;
use plyscape::simulate::{simulate, Simulation};

const STUDY: &str = include_str!("../../../studies/sar_phase1_fold.toml");

/// The coarse fold scene: 16 divisions, 6 modes, 0–0.5 s at rtol 1e-10;
/// the outer plies (1 and 4) of panel `panel` at `theta_deg`; `sens` =
/// with the one lane B<panel>.design.theta_1_4; `flexible` = false runs it
/// rigid.
fn coarse(panel: usize, theta_deg: f64, sens: bool, flexible: bool) -> Scene {
    CoarseSar {
        text: STUDY,
        file: "sar_phase1_fold.toml",
        divisions: 16,
        modes: Some(6),
        panel,
        theta_deg,
        sens,
        flexible,
    }
    .scene()
}

/// Rank of the constraint Jacobian (central differences of Φ) at the
/// projected initial state of `scene`, with the kernel's own counts.
fn ranks(scene: &Scene) -> (usize, usize, Simulation) {
    let (sys, sim) = simulate(scene).unwrap();
    let mut y0 = sys.initial_state();
    sys.project(0.0, &mut y0).unwrap();
    let g = fd_jacobian(&sys, &y0, 1e-6);
    (g.nrows(), rank(&g), sim)
}

#[test]
fn fold_scene_rank_mobility_violation_and_energy_balance() {
    // Rigid: 69 equations (3 revolutes × 5 + 18 spherical × 3), rank 59,
    // mobility 11 × 6 − 59 = 7 (θ_R3 and the spins of the six
    // spherical–spherical bars), as the study header states.
    let rigid_scene = coarse(3, 55.0, false, false);
    let (m, r, rigid) = ranks(&rigid_scene);
    let moving = rigid_scene.model.bodies.iter().filter(|b| !b.fixed).count();
    println!(
        "rigid: {m} equations, rank {r}, kernel redundant {}, {moving} moving bodies",
        rigid.redundant
    );
    assert_eq!((m, r), (69, 59));
    assert_eq!(rigid.redundant, m - r);
    assert_eq!(6 * moving - r, 7, "mobility");

    // Flexible: the kernel's redundant rows are those the Jacobian's rank
    // leaves over, and they name joints of the scene.
    let scene = coarse(3, 55.0, false, true);
    let (m, r, sim) = ranks(&scene);
    println!(
        "flexible: {m} equations, rank {r}, redundant {:?}; max violation {:e}",
        sim.redundant_rows, sim.max_violation
    );
    assert_eq!(m, 69);
    assert_eq!(sim.redundant, m - r);
    assert_eq!(sim.redundant, 6);
    rows_named_and_held(&scene, &sim);
    let cv = column_index(&sim.headers, "violation");
    let worst = sim.rows.iter().map(|row| row[cv]).fold(0.0, f64::max);
    assert!(worst < 1e-8, "violation column {worst:e}");

    // Both panels bend: panel 2 lies in the load path (the R3 reaction is
    // a moment about a line in its plane). Measured on this coarse scene
    // in 0–0.5 s: panel 2 carries 1.25 % of Ψ₀ (the in-plane hold-down
    // scene: 0.05 %, tests/suite/mbs/sar_holddown.rs); bound 0.5 %.
    let (psi0, _) = response(&sim, "psi0");
    let (psi2, _) = response(&sim, "psi0_panel2");
    let (psi3, _) = response(&sim, "psi0_panel3");
    println!(
        "psi0 {psi0:e} J*s = panel 2 {psi2:e} ({:.2} %) + panel 3 {psi3:e}",
        100.0 * psi2 / psi0
    );
    assert!(psi2 > 5e-3 * psi0 && psi3 > 5e-3 * psi0);
    assert!((psi2 + psi3 - psi0).abs() < 1e-8 * psi0);

    // Work–energy balance: the R3 actuator (Eq. 32, τ = −M(θ, θ̇)) is the
    // only non-conservative force; ideal joints and locks do no work.
    // Measured 2.0e-10 of the energy change at rtol 1e-10; bound 1e-8, as
    // for the in-plane scenes.
    let (law, c) = actuator(&scene);
    assert_balanced("coarse fold", balance(&sim, &law, c), 1e-8);
}

/// The shipped study at full size (2 × 14 modes on 32 divisions, 0–3 s,
/// tsit45 at rtol 1e-6, no sensitivities): the constraints hold and the
/// work–energy balance closes over the whole window.
#[test]
fn full_size_fold_scene_balances_energy() {
    let t0 = std::time::Instant::now();
    let text = crate::common::sar::replace(
        STUDY,
        "sensitivities = [\"B3.design.theta_1_4\", \"B3.design.theta_2_3\", \
         \"B2.design.theta_1_4\", \"B2.design.theta_2_3\"]",
        "",
        1,
    );
    let study = plyscape::study::Study::parse("sar_phase1_fold.toml", &text).unwrap();
    let scene = plyscape::scene::load_scene(&study).unwrap();
    let sim = simulate(&scene).unwrap().1;
    let (law, c) = actuator(&scene);
    println!(
        "full size: max violation {:e}; {:.2} s",
        sim.max_violation,
        t0.elapsed().as_secs_f64()
    );
    assert_eq!(sim.rows.len(), 301);
    // Measured 1.2e-7 of the energy change (298 steps, 0.3 s) and a
    // largest residual of 8.5e-10; bounds 3× and 1e-8.
    assert!(
        sim.max_violation < 1e-8,
        "violation {:e}",
        sim.max_violation
    );
    assert_balanced("full-size fold", balance(&sim, &law, c), 3.6e-7);
}

/// dΨ₀/dθ₁₄ of panel `panel` by direct differentiation (the panel's modes
/// updated, Eq. 18) against central differences of whole simulations with
/// its basis rebuilt at θ ± h. Returns the relative error.
fn psi0_gradient_error(panel: usize) -> f64 {
    let base = simulate(&coarse(panel, 55.0, true, true)).unwrap().1;
    let (psi0, grad) = response(&base, "psi0");
    let h: f64 = 2e-4; // rad
    let run = |deg: f64| {
        let sim = simulate(&coarse(panel, deg, false, true)).unwrap().1;
        response(&sim, "psi0").0
    };
    let fd = (run(55.0 + h.to_degrees()) - run(55.0 - h.to_degrees())) / (2.0 * h);
    let rel = (grad[0] - fd).abs() / fd.abs();
    println!(
        "panel {panel}: psi0 {psi0:e} J*s, dpsi0/dθ14 analytic {:e}, central FD {fd:e}, rel {rel:e}",
        grad[0]
    );
    assert!(fd.abs() > 1e-3 * psi0, "a gradient worth checking");
    rel
}

#[test]
fn fold_psi0_ply_angle_gradients_match_central_differences() {
    for panel in [2, 3] {
        let rel = psi0_gradient_error(panel);
        // Measured 2.5e-7 (panel 2) and 2.9e-7 (panel 3), the central
        // difference's truncation and the integrator's 1e-10; bound 1e-5.
        assert!(rel < 1e-5, "panel {panel}: relative error {rel:e}");
    }
}
