//! The basis's lumped inertia invariants against closed forms, on a
//! uniform and on a graded mesh.

use super::fixtures::{panel, test_panel, PLY_T};
use plyscape::fe::{Mesh, MeshParams, Support};
use plyscape::laminate::Orthotropic;
use plyscape::mbs::Invariants;
use plyscape::panels::panel_basis;

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
