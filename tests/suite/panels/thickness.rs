//! A panel basis differentiated with respect to a ply thickness
//! (`BasisBuilder::set_thickness`): eigenvalues, mode shapes, node masses
//! and the flexible body's inertia invariants against central differences
//! of bases rebuilt at t ± h.
use plyscape::fe::{Mesh, MeshParams, Panel, Support};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply};
use plyscape::mbs::{Invariants, ModalBasis};
use plyscape::modal::ModeUpdate;
use plyscape::panels::BasisBuilder;

fn panel(support: Support, t1: f64) -> Panel {
    let ply = |deg: f64, t: f64| Ply {
        material: Orthotropic::im6_sc1081(),
        thickness: t,
        angle: deg.to_radians(),
    };
    Panel {
        name: "p".into(),
        laminate: Laminate::new(vec![
            ply(0.0, t1),
            ply(45.0, 1e-3),
            ply(-45.0, 1e-3),
            ply(90.0, 1e-3),
        ])
        .unwrap(),
        design: DesignMap::per_ply(4),
        mesh: Mesh::structured(&MeshParams {
            length: 1.0,
            width: 0.6,
            divisions: 6,
            points: vec![],
        })
        .unwrap(),
        support,
    }
}

fn basis(support: Support, t1: f64, derivatives: bool) -> ModalBasis {
    let p = panel(support, t1);
    let mut b = BasisBuilder::new(&p, derivatives.then_some(ModeUpdate::Updated)).unwrap();
    b.set_thickness(&["thickness_1".to_string()]).unwrap();
    b.basis(&p.laminate, 4).unwrap()
}

fn flat(i: &Invariants) -> Vec<f64> {
    let mut v = vec![i.mass];
    v.extend(i.s0.iter());
    v.extend(i.e0.iter());
    for x in [&i.i3, &i.ls, &i.p, &i.q, &i.v, &i.c_rot, &i.mww, &i.lambda] {
        v.extend(x.iter());
    }
    v.extend(i.j_rot.iter());
    v
}

/// Central differences, step 4e-8 m on a 1 mm ply (truncation ~(h/t)²
/// ≈ 2e-9, eigen-solver noise ~1e-10/(h/t) ≈ 3e-6 at most), errors relative
/// to each quantity's largest entry; free–free and centre clamp.
#[test]
fn basis_and_invariant_thickness_derivatives_match_central_differences() {
    for support in [Support::FreeFree, Support::CentreClamp] {
        let t = 1e-3;
        let b = basis(support, t, true);
        let v = b.derivatives.len() - 1;
        let d = &b.derivatives[v];
        assert_eq!(d.name, "thickness_1");
        let h = 4e-8;
        let (p, m) = (basis(support, t + h, false), basis(support, t - h, false));
        let rel = |an: &[f64], fd: &[f64]| {
            let scale = fd.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            an.iter()
                .zip(fd)
                .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()))
                / scale
        };
        let fd = |a: &[f64], c: &[f64]| -> Vec<f64> {
            a.iter().zip(c).map(|(x, y)| (x - y) / (2.0 * h)).collect()
        };
        let e_l = rel(&d.eigenvalues, &fd(&p.eigenvalues, &m.eigenvalues));
        let e_x = rel(&d.shapes, &fd(&p.shapes, &m.shapes));
        let e_m = rel(&d.node_mass, &fd(&p.node_mass, &m.node_mass));
        let flat3 = |x: &[nalgebra::Vector3<f64>]| -> Vec<f64> {
            x.iter().flat_map(|v| v.iter().copied()).collect()
        };
        let e_j = rel(
            &flat3(&d.node_inertia),
            &fd(&flat3(&p.node_inertia), &flat3(&m.node_inertia)),
        );
        let (_, di) = Invariants::with_derivatives(&b);
        let e_i = rel(
            &flat(&di[v]),
            &fd(&flat(&Invariants::new(&p)), &flat(&Invariants::new(&m))),
        );
        println!("{support:?}: dλ {e_l:.1e}, dX {e_x:.1e}, dm {e_m:.1e}, dJ {e_j:.1e}, invariants {e_i:.1e}");
        assert!(e_l < 1e-6 && e_x < 1e-4 && e_m < 1e-8 && e_j < 1e-6 && e_i < 1e-5);
    }
}
