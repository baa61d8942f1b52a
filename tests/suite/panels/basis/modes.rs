//! The basis's modes: the modal solver's and M-orthonormal, zero at the
//! constrained components of each support, without rigid content free–free,
//! and the nearly rigid ones dropped by the screening.

use super::fixtures::{column, max_abs, orthonormality_error, test_panel, PLY_T};
use plyscape::fe::{assemble, Derivatives, Support};
use plyscape::laminate::Orthotropic;
use plyscape::mbs::Invariants;
use plyscape::modal::{ModalOptions, ModalSolver};
use plyscape::panels::basis::RIGID_CONTENT_LIMIT;
use plyscape::panels::panel_basis;

#[test]
fn modes_are_the_solvers_and_m_orthonormal() {
    let p = test_panel(Support::CentreClamp);
    let n = 8;
    let basis = panel_basis(&p, n, None).unwrap();
    basis.validate("basis").unwrap();
    assert_eq!(basis.n_modes, n);
    assert_eq!(basis.n_nodes(), p.mesh.nodes.len());
    let e = orthonormality_error(&basis);
    assert!(e < 1e-9, "mww − I = {e:e}");
    // The modal solver on the same assembled system (independent call).
    let sys = assemble(
        &p.mesh,
        &p.laminate,
        p.support,
        &p.design,
        Derivatives::None,
    )
    .unwrap();
    let modes = ModalSolver::new(&sys.k, &sys.m_diag)
        .unwrap()
        .solve(&ModalOptions::new(n))
        .unwrap();
    for j in 0..n {
        let (l, r) = (basis.eigenvalues[j], modes.lambda[j]);
        assert!((l - r).abs() <= 1e-12 * r, "mode {j}: {l} vs {r}");
        for (f, &(node, comp)) in sys.dof_map.iter().enumerate() {
            assert_eq!(basis.shape(node, comp, j), modes.modes[(f, j)]);
        }
    }
    // Centre clamp: all six components at the centre node are zero.
    let c = p.mesh.centre;
    assert_eq!(p.mesh.nodes[c], [0.0, 0.0]);
    for comp in 0..6 {
        for j in 0..n {
            assert_eq!(basis.shape(c, comp, j), 0.0);
        }
    }
    // The centre node still carries its lumped mass.
    assert!(basis.node_mass[c] > 0.0);
}

#[test]
fn other_supports_zero_their_constrained_components() {
    // Central patch 0.2 m × 0.2 m: every node in it is clamped. Simple
    // support (SS-1): w = 0 on all edges, v = θx = 0 on x = ±a/2,
    // u = θy = 0 on y = ±b/2 (fe::Support).
    for support in [
        Support::CentralPatch {
            length: 0.2,
            width: 0.2,
        },
        Support::SimplySupported,
    ] {
        let p = test_panel(support);
        let n = 5;
        let basis = panel_basis(&p, n, None).unwrap();
        basis.validate("basis").unwrap();
        assert!(orthonormality_error(&basis) < 1e-9, "{support:?}");
        let tol = 1e-9;
        let mut constrained = 0;
        for (k, q) in p.mesh.nodes.iter().enumerate() {
            let comps: Vec<usize> = match support {
                Support::CentralPatch { .. }
                    if q[0].abs() <= 0.1 + tol && q[1].abs() <= 0.1 + tol =>
                {
                    (0..6).collect()
                }
                Support::SimplySupported => {
                    let mut c = Vec::new();
                    if (q[0].abs() - 0.5).abs() <= tol {
                        c.extend([1, 2, 3]);
                    }
                    if (q[1].abs() - 0.3).abs() <= tol {
                        c.extend([0, 2, 4]);
                    }
                    c
                }
                _ => Vec::new(),
            };
            for c in comps {
                constrained += 1;
                for j in 0..n {
                    assert_eq!(basis.shape(k, c, j), 0.0, "{support:?} node {k} comp {c}");
                }
            }
        }
        assert!(constrained > 0);
        // The whole panel's mass is kept (closed form ρ·h·a·b).
        let m = Orthotropic::im6_sc1081().rho * 4.0 * PLY_T * 1.0 * 0.6;
        let total: f64 = basis.node_mass.iter().sum();
        assert!((total - m).abs() < 1e-12 * m);
    }
}

#[test]
fn free_free_basis_has_no_rigid_content() {
    let p = test_panel(Support::FreeFree);
    let n = 6;
    let basis = panel_basis(&p, n, None).unwrap();
    basis.validate("basis").unwrap();
    assert_eq!(basis.n_modes, n);
    assert!(orthonormality_error(&basis) < 1e-9);
    // Elastic only: the lowest eigenvalue is far from the rigid λ = 0
    // (a 1 m angle-ply plate of 2 mm: first elastic ω of tens of rad/s).
    assert!(basis.eigenvalues[0] > 10.0, "{:?}", basis.eigenvalues);
    let inv = Invariants::new(&basis);
    // Identities of elastic modes M-orthogonal to the six rigid motions
    // about the centre (module doc of panels::basis): Σ m Φ = 0 and
    // Σ m s × Φ + Σ J Ψ = 0. Scale: by Cauchy–Schwarz |Σ m Φ| ≤ √m_total
    // for a mass-normalised mode; the solver's orthogonality to the rigid
    // modes is at rounding level (measured ~1e-14 relative).
    let scale = inv.mass.sqrt();
    assert!(max_abs(&inv.i3) < 1e-10 * scale, "i3 = {:?}", inv.i3);
    let sum: Vec<f64> = inv.ls.iter().zip(&inv.c_rot).map(|(l, c)| l + c).collect();
    assert!(max_abs(&sum) < 1e-10 * scale, "ls + c_rot = {sum:?}");
    // ls ≈ 0: ls = −c_rot, and by Cauchy–Schwarz |Σ_k J_k,c Ψ_k,c| ≤
    // √(Σ J_k,c)·√(Σ J_k,c Ψ_k,c²) ≤ √(j_rot,cc) (the rotary part of mww = 1),
    // so |ls_c| ≤ √(j_rot,cc), which is h/√(a² + b²) ≈ 2e-3 times the
    // translational scale √(Σ m s²) (bound derived in this test).
    let arm = (inv.e0[(0, 0)] + inv.e0[(1, 1)]).sqrt();
    for c in 0..3 {
        let bound = inv.j_rot[(c, c)].sqrt();
        for j in 0..n {
            assert!(
                inv.ls[c * n + j].abs() <= bound * (1.0 + 1e-9),
                "ls = {:?}",
                inv.ls
            );
        }
    }
    assert!(max_abs(&inv.ls) < 2e-3 * arm, "ls = {:?}", inv.ls);
    println!(
        "free-free: max i3 / √m = {:.1e}, max (ls + c_rot) / √m = {:.1e}, max ls / √(Σ m s²) = {:.1e}",
        max_abs(&inv.i3) / scale,
        max_abs(&sum) / scale,
        max_abs(&inv.ls) / arm
    );
}

#[test]
fn screening_drops_the_nearly_rigid_modes_only() {
    // A panel basis carries every computed mode with its rigid-body
    // content; screening at 0.9 drops the centre clamp's rocking modes
    // (content > 0.98) and keeps the others as they are.
    let p = test_panel(Support::CentreClamp);
    let n = 8;
    let b = panel_basis(&p, n, None).unwrap();
    assert_eq!((b.n_modes, b.rigid.content.len()), (n, n));
    assert!(b.rigid.dropped.is_empty());
    let s = b.screened(RIGID_CONTENT_LIMIT).unwrap();
    s.validate("screened").unwrap();
    assert!(!s.rigid.dropped.is_empty());
    assert_eq!(s.n_modes + s.rigid.dropped.len(), n);
    assert!(orthonormality_error(&s) < 1e-9);
    let mut k = 0;
    for j in 0..n {
        if let Some(d) = s.rigid.dropped.iter().find(|d| d.mode == j + 1) {
            assert!(d.content > 0.98 && d.content == b.rigid.content[j], "{d:?}");
            continue;
        }
        assert!(b.rigid.content[j] < 0.9);
        assert_eq!(s.eigenvalues[k], b.eigenvalues[j]);
        assert_eq!(column(&s.shapes, s.n_modes, k), column(&b.shapes, n, j));
        k += 1;
    }
    // Limit 1 keeps every mode.
    assert_eq!(b.screened(1.0).unwrap().n_modes, n);
}
