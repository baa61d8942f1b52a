//! The panel's modal basis for a floating-frame flexible body
//! (`plyscape::panels::basis`): lumped inertia against closed forms,
//! M-orthonormality, agreement with the modal solver, the clamp, design
//! derivatives and the invariants' derivatives against central finite
//! differences, the free–free frame, and input errors.

use plyscape::error::Error;
use plyscape::fe::{assemble, Derivatives, Mesh, MeshParams, Panel, Support};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply};
use plyscape::mbs::{Invariants, ModalBasis};
use plyscape::modal::{ModalOptions, ModalSolver, ModeUpdate};
use plyscape::panels::basis::RIGID_CONTENT_LIMIT;
use plyscape::panels::{basis_for_study, panel_basis};
use plyscape::study::Study;

/// Ply thickness of the test laminates \[m\].
const PLY_T: f64 = 0.5e-3;

/// IM6/SC1081 plies of `PLY_T` at the given angles \[deg\].
pub(super) fn laminate(angles_deg: &[f64]) -> Laminate {
    Laminate::new(
        angles_deg
            .iter()
            .map(|a| Ply {
                material: Orthotropic::im6_sc1081(),
                thickness: PLY_T,
                angle: a.to_radians(),
            })
            .collect(),
    )
    .unwrap()
}

/// A `length × width` panel, 4 plies tied [θ1/θ2/θ2/θ1], no extra mesh
/// points (uniform cells when `width` is a multiple of 2·length/divisions).
fn panel(length: f64, width: f64, divisions: usize, angles: &[f64], support: Support) -> Panel {
    Panel {
        name: "p".into(),
        laminate: laminate(angles),
        design: DesignMap::symmetric(4),
        mesh: Mesh::structured(&MeshParams {
            length,
            width,
            divisions,
            points: support.forced_points(),
        })
        .unwrap(),
        support,
    }
}

/// The generic test panel: 1.0 m × 0.6 m, 10 divisions (uniform 0.1 m
/// cells), an angle-ply lay-up whose lowest modes are well separated.
fn test_panel(support: Support) -> Panel {
    panel(1.0, 0.6, 10, &[30.0, -45.0, -45.0, 30.0], support)
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

#[test]
fn lumped_inertia_matches_closed_forms() {
    // Uniform mesh: a = 1.0, b = 0.6, 10 divisions → square cells
    // hx = hy = 0.1 m (0.3 m half-width = 3 cells).
    let (a, b, hx, hy) = (1.0, 0.6, 0.1, 0.1);
    let p = test_panel(Support::CentreClamp);
    let basis = panel_basis(&p, 4, None).unwrap();
    basis.validate("basis").unwrap();
    let inv = Invariants::new(&basis);
    let rho = Orthotropic::im6_sc1081().rho;
    let h = 4.0 * PLY_T;
    // Mass: ρ·h·a·b (closed form).
    let m = rho * h * a * b;
    assert!((inv.mass - m).abs() < 1e-12 * m, "{} vs {m}", inv.mass);
    // Centre of mass at the centre: HRZ gives each vertex m_e/3, whose
    // moment Σ m_e·centroid_e is the exact first moment of the rectangle.
    assert!(inv.s0.norm() < 1e-14 * m * a, "s0 = {:?}", inv.s0);
    assert!(basis.centre_of_mass().norm() < 1e-14);
    // Second moment. Closed form derived here: for a triangle with vertex
    // x-coordinates x_v, the lumped value (A/3)Σx_v² exceeds the exact
    // ∫x² dA = (A/6)(Σx_v² + Σ_{v<w} x_v x_w) by (A/12)Σ_{v<w}(x_v−x_w)²;
    // every triangle of the structured mesh is half a cell with
    // Σ_{v<w}(x_v−x_w)² = 2hx², so e0_xx = m(a²/12 + hx²/6) exactly, i.e.
    // the lumping overestimates the continuum m·a²/12 by 2(hx/a)² (2 % here,
    // second order in the mesh size). Likewise the xy term is
    // (A/12)Σ(x_v−x_w)(y_v−y_w) = ±A·hx·hy/12 with the sign of the cell's
    // diagonal; the checkerboard of diagonals cancels it pairwise (even cell
    // counts), so e0_xy = 0. z = 0 for every node.
    let exx = m * (a * a / 12.0 + hx * hx / 6.0);
    let eyy = m * (b * b / 12.0 + hy * hy / 6.0);
    assert!((inv.e0[(0, 0)] - exx).abs() < 1e-12 * exx, "{}", inv.e0);
    assert!((inv.e0[(1, 1)] - eyy).abs() < 1e-12 * eyy, "{}", inv.e0);
    assert!(inv.e0[(0, 1)].abs() < 1e-14 * exx, "{}", inv.e0);
    assert!(inv.e0.row(2).norm() == 0.0 && inv.e0.column(2).norm() == 0.0);
    // Continuum comparison, for the record: within the 2(h/a)² above.
    assert!((inv.e0[(0, 0)] / (m * a * a / 12.0) - 1.0 - 2.0 * (hx / a).powi(2)).abs() < 1e-12);
    // Rotary inertia about x and y: Σ_e (ρh³/12)·A_e = ρh³/12·ab (single
    // material, closed form); about z, the element's drilling inertia
    // Σ_e ρh·A_e²/18 = ρh·ab·(hx·hy/2)/18 (every triangle has area hx·hy/2).
    let ir = rho * h.powi(3) / 12.0 * a * b;
    assert!((inv.j_rot[(0, 0)] - ir).abs() < 1e-12 * ir, "{}", inv.j_rot);
    assert!((inv.j_rot[(1, 1)] - ir).abs() < 1e-12 * ir, "{}", inv.j_rot);
    let jz = rho * h * a * b * (hx * hy / 2.0) / 18.0;
    assert!((inv.j_rot[(2, 2)] - jz).abs() < 1e-12 * jz, "{}", inv.j_rot);
}

#[test]
fn lumped_second_moment_on_a_graded_mesh() {
    // SAR panel 3's outline with its attachment points (non-uniform cells,
    // 12 divisions): the same per-triangle identity as above, summed over
    // the actual triangles — e0_xx = m a²/12 + Σ_e ρh A_e (Δx_e)²/6 with Δx_e
    // the triangle's x-extent (closed form derived in the previous test).
    let (a, b) = (1.994, 1.3);
    let mut p = panel(a, b, 12, &[0.0, 90.0, 90.0, 0.0], Support::CentreClamp);
    p.mesh = Mesh::structured(&MeshParams {
        length: a,
        width: b,
        divisions: 12,
        points: vec![
            [0.797, 0.45],
            [-0.797, 0.45],
            [0.797, -0.45],
            [-0.797, -0.45],
        ],
    })
    .unwrap();
    let basis = panel_basis(&p, 3, None).unwrap();
    let inv = Invariants::new(&basis);
    let mu = p.laminate.mass_per_area();
    let m = mu * a * b;
    let (mut ex, mut ey) = (m * a * a / 12.0, m * b * b / 12.0);
    for t in &p.mesh.triangles {
        let q = t.map(|i| p.mesh.nodes[i]);
        let area = 0.5
            * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]))
                .abs();
        let ext = |c: usize| {
            let v = [q[0][c], q[1][c], q[2][c]];
            v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
        };
        ex += mu * area * ext(0).powi(2) / 6.0;
        ey += mu * area * ext(1).powi(2) / 6.0;
    }
    assert!((inv.mass - m).abs() < 1e-12 * m);
    assert!(inv.s0.norm() < 1e-13 * m * a, "s0 = {:?}", inv.s0);
    assert!(
        (inv.e0[(0, 0)] - ex).abs() < 1e-12 * ex,
        "{} vs {ex}",
        inv.e0[(0, 0)]
    );
    assert!(
        (inv.e0[(1, 1)] - ey).abs() < 1e-12 * ey,
        "{} vs {ey}",
        inv.e0[(1, 1)]
    );
}

/// `Σ_k m_k Φ_kᵢ·Φ_kⱼ + Ψ_kᵢᵀ J_k Ψ_kⱼ − δᵢⱼ`, largest entry.
fn orthonormality_error(b: &ModalBasis) -> f64 {
    let inv = Invariants::new(b);
    let n = b.n_modes;
    let mut e: f64 = 0.0;
    for i in 0..n {
        for j in 0..n {
            let d = if i == j { 1.0 } else { 0.0 };
            e = e.max((inv.mww[i * n + j] - d).abs());
        }
    }
    e
}

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

/// Relative difference ‖a − b‖ / ‖b‖.
fn rel(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let n: f64 = b.iter().map(|y| y * y).sum();
    (d / n).sqrt()
}

/// The basis with every ply of design variable `v`'s group turned by `dv`
/// rad (dK/dθ_v sums the group's ply derivatives: a common rotation).
fn basis_at(p: &Panel, n: usize, v: usize, dv: f64) -> ModalBasis {
    let mut angles = p.laminate.angles();
    for &k in &p.design.groups()[v] {
        angles[k] += dv;
    }
    let mut q = p.clone();
    q.laminate = p.laminate.with_angles(&angles).unwrap();
    panel_basis(&q, n, None).unwrap()
}

/// Column j of the shapes (all nodes, 6 components).
fn column(s: &[f64], n: usize, j: usize) -> Vec<f64> {
    s.chunks(n).map(|r| r[j]).collect()
}

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

#[test]
fn bad_input_is_reported() {
    let text = r#"
[[panels]]
name = "panel3"
length = 1.0
width = 0.6
divisions = 8
material = { e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }
plies = [{ angle = 0.0, thickness = 0.5e-3 }, { angle = 90.0, thickness = 0.5e-3 }]
"#;
    let study = Study::parse("basis.toml", text).unwrap();
    // The named panel works.
    let b = basis_for_study(&study, "panel3", 3, None, None).unwrap();
    assert_eq!(b.n_modes, 3);
    // Unknown name: input error naming file, key and value.
    match basis_for_study(&study, "panel9", 3, None, None) {
        Err(Error::Input {
            file,
            key,
            value,
            expected,
        }) => {
            assert_eq!(file, "basis.toml");
            assert_eq!(key, "panels.name");
            assert_eq!(value, "\"panel9\"");
            assert!(expected.contains("\"panel3\""), "{expected}");
        }
        other => panic!("expected an input error, got {other:?}"),
    }
    // No modes.
    let e = basis_for_study(&study, "panel3", 0, None, None).unwrap_err();
    assert!(
        matches!(&e, Error::Input { key, .. } if key == "n_modes"),
        "{e:?}"
    );
    let p = test_panel(Support::CentreClamp);
    let e = panel_basis(&p, 0, Some(ModeUpdate::Fixed)).unwrap_err();
    assert!(
        matches!(&e, Error::Input { key, .. } if key == "n_modes"),
        "{e:?}"
    );
    // More modes than free DOFs.
    let tiny = panel(1.0, 0.6, 1, &[0.0, 90.0, 90.0, 0.0], Support::CentreClamp);
    let dofs = 6 * (tiny.mesh.nodes.len() - 1);
    let e = panel_basis(&tiny, dofs + 1, None).unwrap_err();
    assert!(
        matches!(&e, Error::Input { key, .. } if key == "n_modes"),
        "{e:?}"
    );
}

#[test]
fn repeated_modes_refuse_updated_derivatives() {
    // A square plate of an isotropic material (E1 = E2, G = E/2(1+ν)) on the
    // union-jack mesh, which is invariant under a 90° rotation: the two
    // rocking modes of the centre clamp form an exactly repeated pair.
    let e = 70e9;
    let nu = 0.3;
    let g = e / (2.0 * (1.0 + nu));
    let iso = Orthotropic {
        e1: e,
        e2: e,
        g12: g,
        g13: g,
        g23: g,
        nu12: nu,
        rho: 2700.0,
    };
    let mut p = panel(1.0, 1.0, 8, &[0.0, 0.0, 0.0, 0.0], Support::CentreClamp);
    p.laminate = Laminate::new(
        (0..4)
            .map(|_| Ply {
                material: iso,
                thickness: PLY_T,
                angle: 0.0,
            })
            .collect(),
    )
    .unwrap();
    let fixed = panel_basis(&p, 4, Some(ModeUpdate::Fixed)).unwrap();
    let l = &fixed.eigenvalues;
    assert!((l[1] - l[0]).abs() < 1e-8 * l[1], "{l:?}");
    match panel_basis(&p, 4, Some(ModeUpdate::Updated)) {
        Err(Error::Numerical { place, detail, .. }) => {
            assert!(place.contains("panels::basis"), "{place}");
            assert!(detail.contains("modes 0..=1"), "{detail}");
        }
        other => panic!("expected a numerical error, got {other:?}"),
    }
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
