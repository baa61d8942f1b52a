//! Design derivatives of the basis (eigenvalues, mode shapes, and the
//! invariants built on them) against central finite differences, for each
//! support, per ply and through the screening of the centre clamp.

use super::fixtures::{basis_at, column, max_abs, panel, rel};
use plyscape::fe::{Panel, Support};
use plyscape::laminate::DesignMap;
use plyscape::mbs::{Invariants, ModalBasis};
use plyscape::modal::ModeUpdate;
use plyscape::panels::basis::RIGID_CONTENT_LIMIT;
use plyscape::panels::panel_basis;

/// Updated-mode basis derivatives against central finite differences of
/// `panel_basis`, and the fixed-mode ones against them.
fn check_design_derivatives(support: Support) {
    let p = panel(1.0, 0.6, 8, &[30.0, -45.0, -45.0, 30.0], support);
    check_panel_derivatives(&p, 6);
}

/// [`check_design_derivatives`] for panel `p` and `n_asked` computed modes,
/// screened as a scene does (modes above the rigid-content limit dropped;
/// the kept modes' derivatives are checked, the same modes being dropped
/// at ±h). Returns the number dropped.
fn check_panel_derivatives(p: &Panel, n_asked: usize) -> usize {
    let support = p.support;
    // The scene's screening (ModalBasis::screened at the default limit).
    let screen = |b: ModalBasis| b.screened(RIGID_CONTENT_LIMIT).unwrap();
    let up = screen(panel_basis(p, n_asked, Some(ModeUpdate::Updated)).unwrap());
    let fixed = screen(panel_basis(p, n_asked, Some(ModeUpdate::Fixed)).unwrap());
    let n = up.n_modes;
    println!(
        "{support:?}: {n} of {n_asked} modes kept, dropped {:?}",
        up.rigid.dropped
    );
    up.validate("up").unwrap();
    // One derivative per design group, named by its plies (theta_1_4).
    let names: Vec<String> = p
        .design
        .groups()
        .iter()
        .map(|g| {
            let k: Vec<String> = g.iter().map(|k| (k + 1).to_string()).collect();
            format!("theta_{}", k.join("_"))
        })
        .collect();
    let got: Vec<&str> = up.derivatives.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(got, names);
    // Separated modes (the test's premise; 0.9 % is the closest pair of
    // the SAR panel's kept modes).
    for w in up.eigenvalues.windows(2) {
        assert!(w[1] > 1.005 * w[0], "{:?}", up.eigenvalues);
    }
    // Central finite differences, step 1e-4 rad: truncation O(h²) ~ 1e-8
    // relative, rounding ~ 1e-10 (Lanczos tolerance) / h ~ 1e-6.
    let h = 1e-4;
    for v in 0..p.design.len() {
        let (bp, bm) = (
            screen(basis_at(p, n_asked, v, h)),
            screen(basis_at(p, n_asked, v, -h)),
        );
        assert_eq!(
            (bp.rigid.dropped.len(), bm.rigid.dropped.len()),
            (n_asked - n, n_asked - n)
        );
        let d = &up.derivatives[v];
        let fd_l: Vec<f64> = bp
            .eigenvalues
            .iter()
            .zip(&bm.eigenvalues)
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect();
        let el = rel(&d.eigenvalues, &fd_l);
        println!("{support:?} variable {v}: dλ rel. error {el:.2e}");
        assert!(el < 1e-5, "dλ {:?} vs FD {fd_l:?}", d.eigenvalues);
        for j in 0..n {
            let fd: Vec<f64> = column(&bp.shapes, n, j)
                .iter()
                .zip(&column(&bm.shapes, n, j))
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            let e = rel(&column(&d.shapes, n, j), &fd);
            println!("{support:?} variable {v}, mode {j}: dX rel. error {e:.2e}");
            assert!(e < 1e-5, "variable {v}, mode {j}: dX rel. error {e:e}");
        }
        // Fixed-mode approach (Eq. 19): same dλ, dX = 0.
        let df = &fixed.derivatives[v];
        assert_eq!(df.name, d.name);
        for (a, b) in df.eigenvalues.iter().zip(&d.eigenvalues) {
            assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-300), "{a} vs {b}");
        }
        assert!(df.shapes.iter().all(|&x| x == 0.0));
    }
    // The modes themselves do not depend on the derivative request.
    assert_eq!(up.shapes, fixed.shapes);
    assert_eq!(up.eigenvalues, fixed.eigenvalues);
    n_asked - n
}

#[test]
fn centre_clamp_dropped_modes_keep_exact_derivatives() {
    // The SAR panel (1.994 m × 1.3 m, [55/-55/-55/55]) at 16 divisions:
    // among its 14 lowest centre-clamp modes are the two rocking modes
    // 1 and 3 (rigid content 0.995, 0.985) and the in-plane drilling mode
    // 11 (0.999996): all three are dropped, and the derivatives of the 11
    // kept modes match central differences of the screened basis.
    let p = panel(
        1.994,
        1.3,
        16,
        &[55.0, -55.0, -55.0, 55.0],
        Support::CentreClamp,
    );
    assert_eq!(check_panel_derivatives(&p, 14), 3);
}

#[test]
fn per_ply_unsymmetric_design_derivatives_match_finite_differences() {
    // Every ply its own variable (design = [[1], [2], [3], [4]]) on an
    // unsymmetric stack: B ≠ 0, so membrane and bending couple in K and
    // in each K'ₖ (no block split), and each ply's derivative moves B.
    // Updated-mode dλ and dX of all four variables against central
    // differences of the basis (as for the tied variables above).
    let mut p = panel(1.0, 0.6, 8, &[30.0, -45.0, 60.0, 10.0], Support::FreeFree);
    p.design = DesignMap::per_ply(4);
    assert!(!p.laminate.is_symmetric());
    assert!(p.laminate.stiffness().b.abs().max() > 1.0);
    check_panel_derivatives(&p, 6);
}

#[test]
fn design_derivatives_match_finite_differences() {
    check_design_derivatives(Support::CentreClamp);
}

#[test]
fn free_free_design_derivatives_match_finite_differences() {
    // Elastic modes only; the six rigid modes (a repeated λ = 0 cluster in
    // the solver) and their derivatives are removed.
    check_design_derivatives(Support::FreeFree);
}

#[test]
fn invariant_derivatives_match_finite_differences() {
    // An unsymmetric lay-up (B ≠ 0): in-plane and flexural motion couple,
    // so the in-plane components of Φ, and with them v = Σ m Φᵢ × Φⱼ, are
    // not zero (for B = 0 the flexural modes have Φ ∥ z and v ≡ 0).
    let p = panel(
        1.0,
        0.6,
        8,
        &[30.0, -45.0, 60.0, 10.0],
        Support::CentreClamp,
    );
    let n = 5;
    let b = panel_basis(&p, n, Some(ModeUpdate::Updated)).unwrap();
    let (_, d) = Invariants::with_derivatives(&b);
    let h = 1e-4;
    for (v, dv) in d.iter().enumerate() {
        let ip = Invariants::new(&basis_at(&p, n, v, h));
        let im = Invariants::new(&basis_at(&p, n, v, -h));
        let fd = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
        };
        // Central finite differences of Invariants::new over the design.
        for (name, an, num) in [
            ("i3", &dv.i3, fd(&ip.i3, &im.i3)),
            ("p", &dv.p, fd(&ip.p, &im.p)),
            ("q", &dv.q, fd(&ip.q, &im.q)),
            ("v", &dv.v, fd(&ip.v, &im.v)),
            ("ls", &dv.ls, fd(&ip.ls, &im.ls)),
            ("c_rot", &dv.c_rot, fd(&ip.c_rot, &im.c_rot)),
            ("lambda", &dv.lambda, fd(&ip.lambda, &im.lambda)),
        ] {
            let e = rel(an, &num);
            println!("variable {v}: d{name} rel. error {e:.2e}");
            assert!(e < 1e-5, "variable {v}: d{name} rel. error {e:e}");
        }
        // Orthonormality is kept along the design: d(mww) = 0.
        assert!(max_abs(&dv.mww) < 1e-8, "{:?}", dv.mww);
        assert_eq!(dv.mass, 0.0);
    }
}
