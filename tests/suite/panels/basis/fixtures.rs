//! The panels the basis tests share: IM6/SC1081 laminates, panels on a
//! structured mesh, and measures of a basis (orthonormality, columns).

use plyscape::fe::{Mesh, MeshParams, Panel, Support};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply};
use plyscape::mbs::{Invariants, ModalBasis};
use plyscape::panels::panel_basis;

/// Ply thickness of the test laminates \[m\].
pub(super) const PLY_T: f64 = 0.5e-3;

/// IM6/SC1081 plies of `PLY_T` at the given angles \[deg\].
pub(in crate::panels) fn laminate(angles_deg: &[f64]) -> Laminate {
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
pub(super) fn panel(
    length: f64,
    width: f64,
    divisions: usize,
    angles: &[f64],
    support: Support,
) -> Panel {
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
pub(super) fn test_panel(support: Support) -> Panel {
    panel(1.0, 0.6, 10, &[30.0, -45.0, -45.0, 30.0], support)
}

pub(super) fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

/// `Σ_k m_k Φ_kᵢ·Φ_kⱼ + Ψ_kᵢᵀ J_k Ψ_kⱼ − δᵢⱼ`, largest entry.
pub(super) fn orthonormality_error(b: &ModalBasis) -> f64 {
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

/// Relative difference ‖a − b‖ / ‖b‖.
pub(super) fn rel(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let n: f64 = b.iter().map(|y| y * y).sum();
    (d / n).sqrt()
}

/// The basis with every ply of design variable `v`'s group turned by `dv`
/// rad (dK/dθ_v sums the group's ply derivatives: a common rotation).
pub(super) fn basis_at(p: &Panel, n: usize, v: usize, dv: f64) -> ModalBasis {
    let mut angles = p.laminate.angles();
    for &k in &p.design.groups()[v] {
        angles[k] += dv;
    }
    let mut q = p.clone();
    q.laminate = p.laminate.with_angles(&angles).unwrap();
    panel_basis(&q, n, None).unwrap()
}

/// Column j of the shapes (all nodes, 6 components).
pub(super) fn column(s: &[f64], n: usize, j: usize) -> Vec<f64> {
    s.chunks(n).map(|r| r[j]).collect()
}
