//! A panel basis differentiated with respect to a ply thickness
//! (`BasisBuilder::set_thickness`): eigenvalues, mode shapes, node masses
//! and the flexible body's inertia invariants against central differences
//! of bases rebuilt at t ± h; and one builder reused across thicknesses
//! (what the scene's builder pool does) against fresh builders.
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
        mesh: mesh_1m_by_0_6m(),
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

/// IM6/SC1081 [0/90/90/0] with ply thicknesses `t` \[m\].
fn cross_ply(t: [f64; 4]) -> Laminate {
    let plies = [0.0f64, 90.0, 90.0, 0.0].iter().zip(t).map(|(deg, t)| Ply {
        material: Orthotropic::im6_sc1081(),
        thickness: t,
        angle: deg.to_radians(),
    });
    Laminate::new(plies.collect()).unwrap()
}

/// A simply supported 1.0 m × 0.6 m panel of [`cross_ply`] (angles tied
/// symmetrically: membrane and bending DOFs stay uncoupled, so the
/// updated-mode derivatives run on the pencil's blocks), 6 divisions.
fn cross_ply_panel(t: [f64; 4]) -> Panel {
    Panel {
        name: "p".into(),
        laminate: cross_ply(t),
        design: DesignMap::symmetric(4),
        mesh: mesh_1m_by_0_6m(),
        support: Support::SimplySupported,
    }
}

/// The 1.0 m × 0.6 m structured mesh of 6 divisions both panels use.
fn mesh_1m_by_0_6m() -> Mesh {
    Mesh::structured(&MeshParams {
        length: 1.0,
        width: 0.6,
        divisions: 6,
        points: vec![],
    })
    .unwrap()
}

/// Largest |a − b| over the largest |b|.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |e, (x, y)| e.max((x - y).abs()))
        / scale
}

/// A builder made for 0.5 mm plies and reused at 0.75 mm plies (as the
/// scene's builder pool reuses it for every design of a thickness
/// variable) gives the basis of a builder made at 0.75 mm: eigenvalues
/// to 1e-10, shapes and the updated-mode derivatives (on the blocks of
/// the symmetric stack) to 1e-8. Checked against two references that do
/// not come from a builder: the modes are M-orthonormal with the
/// basis's own node masses (`mww = I` to 1e-10, i.e. the eigen-solver
/// used the lumped M of 0.75 mm plies), and every lowest frequency
/// scales with the thickness as a homogeneous thin plate's,
/// `ω ∝ h·√(E/ρ)/a²` (Kirchhoff: bending stiffness ∝ h³, mass ∝ h), so
/// `λ(1.5 h)/λ(h) = 1.5²` up to the transverse-shear and rotary-inertia
/// terms of the shell element (∝ (h/a)², measured below 1e-3); with the
/// mass of the builder's panel (0.5 mm) it would be `1.5³`.
#[test]
fn a_reused_builder_follows_the_design_thickness() {
    let (t0, t1) = (0.5e-3, 0.75e-3);
    let names = ["thickness_1_4".to_string()];
    let builder = |t: f64| {
        let mut b = BasisBuilder::new(&cross_ply_panel([t; 4]), Some(ModeUpdate::Updated)).unwrap();
        b.set_thickness(&names).unwrap();
        b
    };
    let n_modes = 4;
    let mut reused = builder(t0);
    let b0 = reused.basis(&cross_ply([t0; 4]), n_modes).unwrap();
    let b1 = reused.basis(&cross_ply([t1; 4]), n_modes).unwrap();
    let fresh = builder(t1).basis(&cross_ply([t1; 4]), n_modes).unwrap();
    let e_lambda = rel_diff(&b1.eigenvalues, &fresh.eigenvalues);
    let e_mass = rel_diff(&b1.node_mass, &fresh.node_mass);
    let e_shape = rel_diff(&b1.shapes, &fresh.shapes);
    let mut e_dlambda = 0.0f64;
    let mut e_dshape = 0.0f64;
    assert_eq!(b1.derivatives.len(), fresh.derivatives.len());
    for (d, f) in b1.derivatives.iter().zip(&fresh.derivatives) {
        assert_eq!(d.name, f.name);
        e_dlambda = e_dlambda.max(rel_diff(&d.eigenvalues, &f.eigenvalues));
        e_dshape = e_dshape.max(rel_diff(&d.shapes, &f.shapes));
    }
    let mww = &Invariants::new(&b1).mww;
    let e_orth = (0..n_modes)
        .flat_map(|i| (0..n_modes).map(move |j| (i, j)))
        .fold(0.0f64, |e, (i, j)| {
            e.max((mww[i * n_modes + j] - f64::from(u8::from(i == j))).abs())
        });
    let ratio: Vec<f64> = (b1.eigenvalues.iter().zip(&b0.eigenvalues))
        .map(|(l1, l0)| l1 / l0)
        .collect();
    let s2 = (t1 / t0).powi(2);
    let e_scale = ratio
        .iter()
        .fold(0.0f64, |e, r| e.max((r / s2 - 1.0).abs()));
    println!(
        "reused vs fresh: λ {e_lambda:.1e}, m {e_mass:.1e}, X {e_shape:.1e}, \
         dλ {e_dlambda:.1e}, dX {e_dshape:.1e}; |XᵀMX − I| {e_orth:.1e}; \
         λ(t1)/λ(t0) = {ratio:?} (s² = {s2}, off by {e_scale:.1e})"
    );
    assert!(e_lambda < 1e-10, "eigenvalues {e_lambda:e}");
    assert!(e_mass < 1e-14, "node masses {e_mass:e}");
    assert!(e_shape < 1e-8, "shapes {e_shape:e}");
    assert!(
        e_dlambda < 1e-8 && e_dshape < 1e-8,
        "derivatives {e_dlambda:e}, {e_dshape:e}"
    );
    assert!(e_orth < 1e-10, "mass normalisation {e_orth:e}");
    assert!(e_scale < 1e-3, "thickness scaling {ratio:?}");
}
