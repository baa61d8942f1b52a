//! Thickness derivatives of the assembled panel system
//! (`plyscape::fe::thickness`): K', K'', M', M'' against central
//! differences of the assembly in the common thickness of a ply group.

use plyscape::fe::{Derivatives, Mesh, MeshParams, PanelModel, Support};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply};

/// An unsymmetric 4-ply IM6/SC1081 stack with unequal plies \[deg, m\].
fn stack() -> Laminate {
    let ply = |deg: f64, t: f64| Ply {
        material: Orthotropic::im6_sc1081(),
        thickness: t,
        angle: deg.to_radians(),
    };
    Laminate::new(vec![
        ply(30.0, 0.4e-3),
        ply(-45.0, 0.2e-3),
        ply(-45.0, 0.2e-3),
        ply(60.0, 0.3e-3),
    ])
    .unwrap()
}

/// The stack with every ply of `group` at thickness `s`.
pub(crate) fn with_group(lam: &Laminate, group: &[usize], s: f64) -> Laminate {
    let t: Vec<f64> = lam
        .plies()
        .iter()
        .enumerate()
        .map(|(k, p)| if group.contains(&k) { s } else { p.thickness })
        .collect();
    lam.with_thicknesses(&t).unwrap()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

/// K and M are rational in the group thickness `s` (the shear factor
/// h²/(h² + αℓ²)) and polynomial otherwise; central differences (steps
/// below) on 0.2–0.4 mm plies, errors relative to each matrix's largest
/// entry, bounds about 5–10× those measured (printed).
#[test]
fn thickness_derivatives_match_central_differences() {
    let lam = stack();
    let mesh = Mesh::structured(&MeshParams {
        length: 0.6,
        width: 0.4,
        divisions: 6,
        points: vec![],
    })
    .unwrap();
    let model = PanelModel::new(mesh, Support::CentreClamp).unwrap();
    let design = DesignMap::per_ply(4);
    let groups = vec![vec![0], vec![1, 2], vec![3]];
    let ts = model.assemble_thickness(&lam, &groups, true).unwrap();
    // First derivatives: step 1e-9 m (truncation ~(h/s)² ≈ 2e-11, rounding
    // ~1e-16/(h·|K'|/|K|) ≈ 2e-11); second: 1e-5 m (the second central
    // difference of the cubic D, B, I is exact; the shear factor's
    // truncation is ~(h/s)²/12 ≈ 2e-4 of its own share).
    let (h, h2) = (1e-9, 1e-5);
    for (v, g) in groups.iter().enumerate() {
        let s0 = lam.plies()[g[0]].thickness;
        let at = |s: f64| {
            model
                .assemble(&with_group(&lam, g, s), &design, Derivatives::None)
                .unwrap()
        };
        let (p, z, m) = (at(s0 + h), at(s0), at(s0 - h));
        let (p2, m2) = (at(s0 + h2), at(s0 - h2));
        let fd1 = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
        };
        let fd2 = |a: &[f64], b: &[f64], c: &[f64]| -> Vec<f64> {
            a.iter()
                .zip(b)
                .zip(c)
                .map(|((x, y), w)| (x - 2.0 * y + w) / (h2 * h2))
                .collect()
        };
        let err = |an: &[f64], fd: &[f64]| {
            an.iter()
                .zip(fd)
                .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()))
                / max_abs(fd).max(max_abs(an))
        };
        let dk = fd1(p.k.val(), m.k.val());
        let d2k = fd2(p2.k.val(), z.k.val(), m2.k.val());
        let dm = fd1(&p.m_diag, &m.m_diag);
        let d2m = fd2(&p2.m_diag, &z.m_diag, &m2.m_diag);
        let e = [
            err(ts.dk[v].val(), &dk),
            err(&ts.dm[v], &dm),
            err(ts.d2k[v].val(), &d2k),
            err(&ts.d2m[v], &d2m),
        ];
        println!(
            "group {g:?}: K' {:.1e}, M' {:.1e}, K'' {:.1e}, M'' {:.1e}",
            e[0], e[1], e[2], e[3]
        );
        // Measured (2-core VM, 2026-11-27): K' ≤ 2.1e-10, M' ≤ 6.2e-11,
        // K'' ≤ 3.3e-7, M'' ≤ 8.9e-6 (the translational entries, whose
        // exact M'' is 0, carry the rounding 2e-16·M/h² of the linear mass).
        assert!(e[0] < 2e-9 && e[1] < 1e-9, "group {g:?}: {e:?}");
        assert!(e[2] < 3e-6 && e[3] < 5e-5, "group {g:?}: {e:?}");
    }
}
