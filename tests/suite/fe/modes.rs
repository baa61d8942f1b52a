//! K and M together, solved by the crate's modal solver: natural
//! frequencies of simply supported plates against closed forms, the
//! free–free rigid-body count, and (ignored, run by hand) the mesh
//! convergence of the SAR panel's 14 lowest modes. Assembly and modal
//! timings are measured by `studies/panel_convergence.toml`, not here.

use plyscape::fe::{Derivatives, Mesh, MeshParams, PanelModel, PanelSystem, Support};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply};
use plyscape::modal::{ModalOptions, ModalSolver};

/// Lowest `nev` eigenvalues of K x = λ M x by the crate's shift-invert
/// Lanczos (`modal`), shift σ below the lowest eigenvalue.
fn lowest_eigenvalues(sys: &PanelSystem, sigma: f64, nev: usize) -> Vec<f64> {
    let mut opts = ModalOptions::new(nev);
    opts.shift = sigma;
    ModalSolver::new(&sys.k, &sys.m_diag)
        .unwrap()
        .solve(&opts)
        .unwrap()
        .lambda
}

#[test]
fn simply_supported_plate_frequencies_match_closed_form() {
    // Closed form (Kirchhoff plate, Leissa, Vibration of Plates, NASA SP-160,
    // Eq. 4.20): ω_mn = π² (m²/a² + n²/b²) √(D/(ρh)). Thin: a/h = 1000, so
    // shear and rotary inertia change ω by < 1e-5.
    let (a, h) = (1.0, 1e-3);
    let (e, nu, rho) = (70e9, 0.3, 2700.0);
    let g = e / (2.0 * (1.0 + nu));
    let m = Orthotropic {
        e1: e,
        e2: e,
        g12: g,
        g13: g,
        g23: g,
        nu12: nu,
        rho,
    };
    let lam = Laminate::new(vec![Ply {
        material: m,
        thickness: h,
        angle: 0.0,
    }])
    .unwrap();
    let d = e * h.powi(3) / (12.0 * (1.0 - nu * nu));
    let w = |mm: f64, nn: f64| {
        std::f64::consts::PI.powi(2) * (mm * mm + nn * nn) / (a * a) * (d / (rho * h)).sqrt()
    };
    let want = [w(1.0, 1.0), w(1.0, 2.0), w(2.0, 1.0), w(2.0, 2.0)];
    let mesh = Mesh::structured(&MeshParams {
        length: a,
        width: a,
        divisions: 24,
        points: vec![],
    })
    .unwrap();
    let sys = PanelModel::new(mesh, Support::SimplySupported)
        .unwrap()
        .assemble(&lam, &DesignMap::per_ply(1), Derivatives::None)
        .unwrap();
    let lam4 = lowest_eigenvalues(&sys, 0.0, 4);
    for (l, w) in lam4.iter().zip(want) {
        let err = (l.sqrt() - w).abs() / w;
        eprintln!(
            "ω = {:.5} rad/s, closed form {w:.5}, rel err {err:.2e}",
            l.sqrt()
        );
        // Measured at 24 divisions: 8.4e-4, 1.5e-3, 1.5e-3, 3.3e-3.
        assert!(err < 5e-3, "{err:e}");
    }
}

fn sar_laminate(angles_deg: [f64; 4]) -> Laminate {
    // IM6/SC1081, 4 plies of 0.5 mm (paper §6.2, docs/sar_reconstruction.md §6).
    let m = Orthotropic::im6_sc1081();
    Laminate::new(
        angles_deg
            .iter()
            .map(|a| Ply {
                material: m,
                thickness: 0.5e-3,
                angle: a.to_radians(),
            })
            .collect(),
    )
    .unwrap()
}

#[test]
fn simply_supported_cross_ply_panel_frequencies_match_closed_form() {
    // Specially orthotropic plate ([0/90/90/0]: D16 = D26 = 0, B = 0),
    // simply supported, closed form (Reddy, Mechanics of Laminated Composite
    // Plates and Shells, 2nd ed., Eq. 5.3.6 without rotary inertia):
    // ρh ω² = π⁴ [D11 (m/a)⁴ + 2(D12 + 2D66)(m/a)²(n/b)² + D22 (n/b)⁴].
    // SAR panel size and material; a/h ≈ 1000, so shear and rotary inertia
    // are negligible.
    let (a, b) = (1.994, 1.3);
    let lam = sar_laminate([0.0, 90.0, 90.0, 0.0]);
    let d = lam.stiffness().d;
    assert!(d[(0, 2)].abs() < 1e-12 * d[(0, 0)] && d[(1, 2)].abs() < 1e-12 * d[(0, 0)]);
    let rho_h = lam.mass_per_area();
    let pi4 = std::f64::consts::PI.powi(4);
    let mut want: Vec<f64> = Vec::new();
    for m in 1..6 {
        for n in 1..6 {
            let (p, q) = (m as f64 / a, n as f64 / b);
            let k = d[(0, 0)] * p.powi(4)
                + 2.0 * (d[(0, 1)] + 2.0 * d[(2, 2)]) * p * p * q * q
                + d[(1, 1)] * q.powi(4);
            want.push((pi4 * k / rho_h).sqrt());
        }
    }
    want.sort_by(f64::total_cmp);
    let mesh = Mesh::structured(&MeshParams {
        length: a,
        width: b,
        divisions: 40,
        points: vec![],
    })
    .unwrap();
    let sys = PanelModel::new(mesh, Support::SimplySupported)
        .unwrap()
        .assemble(&lam, &DesignMap::symmetric(4), Derivatives::None)
        .unwrap();
    let got = lowest_eigenvalues(&sys, 0.0, 5);
    for (l, w) in got.iter().zip(&want) {
        let err = (l.sqrt() - w).abs() / w;
        eprintln!(
            "ω = {:.5} rad/s, closed form {w:.5}, rel err {err:.2e}",
            l.sqrt()
        );
        // Measured max error (5th mode, (m, n) = (3, 1)): 1.28e-2 at 32
        // divisions, 3.1e-3 at 64 (second order); 40 divisions here.
        assert!(err < 1e-2, "{err:e}");
    }
}

#[test]
fn free_free_panel_has_exactly_six_zero_energy_modes() {
    // Identity: an unsupported body has exactly 6 rigid-body modes; a 7th
    // near-zero eigenvalue would be a spurious (hourglass or drilling) mode.
    // Shift σ = −1 makes K − σM definite.
    let lam = sar_laminate([30.0, -60.0, -60.0, 30.0]);
    let model = sar_panel3(12, Support::FreeFree);
    let sys = model
        .assemble(&lam, &DesignMap::symmetric(4), Derivatives::None)
        .unwrap();
    let l = lowest_eigenvalues(&sys, -1.0, 8);
    eprintln!("free-free eigenvalues [rad²/s²]: {l:?}");
    for (i, li) in l[..6].iter().enumerate() {
        assert!(
            li.abs() < 1e-6 * l[6],
            "mode {i}: {li:e} vs λ7 = {:e}",
            l[6]
        );
    }
    // First elastic mode: a few rad/s (the panel is soft), clearly non-zero.
    assert!(l[6].sqrt() > 1.0, "{}", l[6]);
    assert_eq!(sys.rigid_modes.len(), 6);
}

fn sar_panel3(divisions: usize, support: Support) -> PanelModel {
    let mut points = vec![
        [0.797, 0.45],
        [-0.797, 0.45],
        [0.797, -0.45],
        [-0.797, -0.45],
    ];
    points.extend(support.forced_points());
    let mesh = Mesh::structured(&MeshParams {
        length: 1.994,
        width: 1.3,
        divisions,
        points,
    })
    .unwrap();
    PanelModel::new(mesh, support).unwrap()
}

/// Measurement, not a check: run with
/// `cargo test --release --test fe_modes -- --ignored --nocapture`.
#[test]
#[ignore]
fn sar_panel_mode_convergence() {
    let lam = sar_laminate([0.0, 90.0, 90.0, 0.0]);
    let map = DesignMap::symmetric(4);
    for support in [
        Support::CentreClamp,
        Support::CentralPatch {
            length: 0.1,
            width: 0.1,
        },
    ] {
        let mut rows = Vec::new();
        for div in [20, 40, 64, 80, 160] {
            let model = sar_panel3(div, support);
            let sys = model.assemble(&lam, &map, Derivatives::None).unwrap();
            let f: Vec<f64> = lowest_eigenvalues(&sys, -1.0, 14)
                .iter()
                .map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
                .collect();
            eprintln!(
                "{support:?} div {div}: {} DOF, f [Hz] = {f:.5?}",
                sys.n_dof()
            );
            rows.push(f);
        }
        let fine = rows.last().unwrap().clone();
        for (r, div) in rows.iter().zip([20, 40, 64, 80]) {
            let e: Vec<String> = r
                .iter()
                .zip(&fine)
                .map(|(a, b)| format!("{:.1e}", (a - b) / b))
                .collect();
            eprintln!(
                "{support:?} div {div} rel. diff to div 160: {}",
                e.join(" ")
            );
        }
    }
}
