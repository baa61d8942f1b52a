//! Geometric stiffening of panel bodies (`plyscape::panels::geometric`,
//! through [`panel_basis_geometric`]): the centrifugal stiffening of a
//! clamped strip against the beam closed form and Southwell's
//! coefficient, and the exact ply-angle derivatives against central
//! differences (supported and free–free panels).

use super::basis::laminate;
use nalgebra::Vector3;
use plyscape::beams::Beam;
use plyscape::fe::{Mesh, MeshParams, Panel, Support};
use plyscape::laminate::{DesignMap, Laminate};
use plyscape::mbs::model::geometric::CASES;
use plyscape::mbs::ModalBasis;
use plyscape::modal::ModeUpdate;
use plyscape::panels::panel_basis_geometric;

/// Unit load case ω_z² (module doc table of `mbs::model::geometric`).
const WZ2: usize = 2;

fn panel(length: f64, width: f64, divisions: usize, lam: Laminate, support: Support) -> Panel {
    Panel {
        name: "p".into(),
        laminate: lam,
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

#[test]
fn a_spinning_clamped_strip_stiffens_like_a_beam() {
    // A 2.0 m × 0.1 m strip clamped across its middle (central patch
    // 0.1 m × full width) is two cantilevers of L = 0.95 m whose roots sit
    // at r = 0.05 m from the spin axis z (the panel normal). Turning about
    // z at Ω, the centrifugal membrane tension raises the flexural
    // eigenvalue to ω² = ω0² + S Ω² to first order (Southwell), and with
    // mass-normalized modes S = K_wz2[j][j]. Its value for this hub is the
    // beam closed form (`Beam::geometric`, shifted to the hub radius);
    // for a root on the axis the beam gives Southwell's 1.193 (uniform
    // cantilever, first flapwise mode: Wright, Smith, Thresher & Wang,
    // J. Appl. Mech. 49 (1982) 197–202; Bramwell, Helicopter Dynamics,
    // 1976, §5). 0° plies: the strip's bending is the beam's.
    let (len, width, patch) = (2.0, 0.1, 0.1);
    let p = panel(
        len,
        width,
        40,
        laminate(&[0.0; 4]),
        Support::CentralPatch {
            length: patch,
            width,
        },
    );
    let b = panel_basis_geometric(&p, 2, None, Some(&[])).unwrap();
    b.validate("strip").unwrap();
    let g = b.geometric.as_ref().unwrap();
    // The two lowest modes: one flexural mode per half (equal frequencies).
    let rel = (b.eigenvalues[1] - b.eigenvalues[0]) / b.eigenvalues[0];
    assert!(rel.abs() < 1e-6, "{:?}", b.eigenvalues);
    let cantilever = 0.5 * (len - patch);
    let beam = Beam {
        length: cantilever,
        ei_y: 1.0,
        ei_z: 1.0,
        rho_a: 1.0,
    };
    let on_axis = beam.basis(1, Beam::segments_for(1)).unwrap();
    let s0 = on_axis.geometric.as_ref().unwrap().get(WZ2, 0, 0);
    assert!((s0 - 1.193).abs() < 1e-3, "Southwell coefficient {s0}");
    let hub = on_axis.shifted(&nalgebra::Vector3::new(-0.5 * patch, 0.0, 0.0));
    let s_beam = hub.geometric.as_ref().unwrap().get(WZ2, 0, 0);
    for j in 0..2 {
        let s = g.get(WZ2, j, j);
        println!("mode {j}: panel S = {s}, beam S = {s_beam} (on axis {s0})");
        assert!(
            (s - s_beam).abs() < 0.03 * s_beam,
            "mode {j}: panel S = {s}, beam S = {s_beam}"
        );
    }
    // Spinning about z loads nothing out of plane and nothing along the
    // strip's width: the cases ω_x², ω_y² (body force (0, y, z), (x, 0, z))
    // differ from ω_z² only by the part along y, small on a narrow strip.
    assert!(g.get(0, 0, 0).abs() < 0.05 * s_beam, "{}", g.get(0, 0, 0));
}

/// Basis with the geometric stiffness (point cases at the panel-frame
/// `points`) and updated-mode derivatives.
fn basis(p: &Panel, lam: &Laminate, n: usize, points: &[Vector3<f64>]) -> ModalBasis {
    let mut q = p.clone();
    q.laminate = lam.clone();
    panel_basis_geometric(&q, n, Some(ModeUpdate::Updated), Some(points)).unwrap()
}

fn check_derivatives(support: Support) {
    // Small panel, [θ1/θ2/θ2/θ1] with 2 design variables; every entry of
    // every case against central differences with step 1e-4 rad
    // (truncation ~1e-8 relative; measured agreement in the message).
    let lam = laminate(&[30.0, -45.0, -45.0, 30.0]);
    let design = DesignMap::symmetric(4);
    let p = panel(0.6, 0.4, 6, lam.clone(), support);
    let n = 3;
    // Two joint nodes (the last and an inner one): their point-force cases
    // (joint-load prestress) follow the inertial ones and are checked too,
    // against their own largest entry (1/s² per N, not per unit
    // coefficient).
    let at = |k: usize| Vector3::new(p.mesh.nodes[k][0], p.mesh.nodes[k][1], 0.0);
    let points = [at(p.mesh.nodes.len() - 1), at(p.mesh.nodes.len() / 3)];
    let b = basis(&p, &lam, n, &points);
    let g = b.geometric.as_ref().unwrap();
    assert_eq!(g.derivatives.len(), 2);
    assert_eq!(g.point_nodes.len(), 2);
    let split = CASES * n * n;
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let (scale, point_scale) = (largest(&g.cases[..split]), largest(&g.cases[split..]));
    assert!(scale > 0.0 && point_scale > 0.0);
    let h = 1e-4;
    let angles = |v: usize, d: f64| {
        let mut x: Vec<f64> = design
            .groups()
            .iter()
            .map(|grp| lam.angles()[grp[0]])
            .collect();
        x[v] += d;
        lam.with_design(&design, &x).unwrap()
    };
    for v in 0..2 {
        let gp = basis(&p, &angles(v, h), n, &points).geometric.unwrap();
        let gm = basis(&p, &angles(v, -h), n, &points).geometric.unwrap();
        let mut worst = 0.0f64;
        for e in 0..g.cases.len() {
            let fd = (gp.cases[e] - gm.cases[e]) / (2.0 * h);
            let s = if e < split { scale } else { point_scale };
            let err = (g.derivatives[v][e] - fd).abs() / s;
            worst = worst.max(err);
        }
        println!("{support:?} variable {v}: worst error {worst:e} of the largest entry");
        assert!(
            worst < 1e-6,
            "{support:?} variable {v}: error {worst:e} of the largest entry"
        );
    }
}

#[test]
fn geometric_stiffness_derivatives_match_central_differences_clamped() {
    check_derivatives(Support::CentreClamp);
}

#[test]
fn geometric_stiffness_derivatives_match_central_differences_free_free() {
    check_derivatives(Support::FreeFree);
}
