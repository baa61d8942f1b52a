//! Shell triangle and assembly: patch tests, rigid-body modes, mass,
//! ply-angle derivatives against central finite differences, determinism.

use plyscape::fe::element::Mat18;
use plyscape::fe::{
    section_matrix, Derivatives, Mesh, MeshParams, PanelModel, PanelSystem, Support,
};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply};

fn laminate(angles_deg: &[f64], t: f64) -> Laminate {
    Laminate::new(
        angles_deg
            .iter()
            .map(|a| Ply {
                material: Orthotropic::im6_sc1081(),
                thickness: t,
                angle: a.to_radians(),
            })
            .collect(),
    )
    .unwrap()
}

/// A 1.0 × 0.8 m mesh with interior nodes moved off the grid (deterministic
/// offsets up to 0.2 of a cell), so the patch tests see distorted triangles.
fn distorted_mesh() -> Mesh {
    let mut mesh = Mesh::structured(&MeshParams {
        length: 1.0,
        width: 0.8,
        divisions: 5,
        points: vec![],
    })
    .unwrap();
    let h = 0.2;
    for (i, p) in mesh.nodes.iter_mut().enumerate() {
        let interior = p[0].abs() < 0.5 - 1e-9 && p[1].abs() < 0.4 - 1e-9;
        if interior {
            p[0] += 0.2 * h * (1.3 * i as f64).sin();
            p[1] += 0.2 * h * (2.1 * i as f64).cos();
        }
    }
    mesh
}

fn is_boundary(p: [f64; 2]) -> bool {
    (p[0].abs() - 0.5).abs() < 1e-9 || (p[1].abs() - 0.4).abs() < 1e-9
}

/// K·u (full symmetric storage).
fn k_times(sys: &PanelSystem, u: &[f64]) -> Vec<f64> {
    let k = sys.k.as_ref();
    let (cp, ri, val) = (k.col_ptr(), k.row_idx(), k.val());
    let mut out = vec![0.0; u.len()];
    for j in 0..u.len() {
        for p in cp[j]..cp[j + 1] {
            out[ri[p]] += val[p] * u[j];
        }
    }
    out
}

fn kmax(sys: &PanelSystem) -> f64 {
    sys.k.val().iter().fold(0.0, |m: f64, v| m.max(v.abs()))
}

fn field(sys: &PanelSystem, f: impl Fn([f64; 2], usize) -> f64) -> Vec<f64> {
    sys.dof_map
        .iter()
        .map(|&(n, c)| f(sys.nodes[n], c))
        .collect()
}

/// Unsymmetric lay-up: A, B, D all full (B ≠ 0 exercises the coupling).
fn coupled() -> Laminate {
    laminate(&[0.0, 45.0, -30.0], 0.5e-3)
}

fn free_system(lam: &Laminate) -> (PanelModel, PanelSystem) {
    let model = PanelModel::new(distorted_mesh(), Support::FreeFree).unwrap();
    let sys = model
        .assemble(
            lam,
            &DesignMap::per_ply(lam.plies().len()),
            Derivatives::None,
        )
        .unwrap();
    (model, sys)
}

/// Max interior residual of K u relative to max|K|·max|u|.
fn interior_residual(sys: &PanelSystem, u: &[f64]) -> f64 {
    let r = k_times(sys, u);
    let umax = u.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
    sys.dof_map
        .iter()
        .zip(&r)
        .filter(|((n, _), _)| !is_boundary(sys.nodes[*n]))
        .map(|(_, v)| v.abs())
        .fold(0.0, f64::max)
        / (kmax(sys) * umax)
}

#[test]
fn membrane_patch_test_constant_strain() {
    // Exact field u = a0 + a1 x + a2 y, v = b0 + b1 x + b2 y,
    // θz = ω = (b1 − a2)/2: every interior node must be in equilibrium and
    // every element must return the exact constant strains.
    let (a0, a1, a2, b0, b1, b2) = (1e-3, 2e-4, -3e-4, -2e-3, 5e-4, 1e-4);
    let (model, sys) = free_system(&coupled());
    let u = field(&sys, |[x, y], c| match c {
        0 => a0 + a1 * x + a2 * y,
        1 => b0 + b1 * x + b2 * y,
        5 => 0.5 * (b1 - a2),
        _ => 0.0,
    });
    let res = interior_residual(&sys, &u);
    assert!(res < 1e-12, "interior residual {res:e}");
    for e in 0..model.mesh().triangles.len() {
        let (_, g) = model.element(e);
        let t = model.mesh().triangles[e];
        let ue = nalgebra::SVector::<f64, 18>::from_fn(|a, _| {
            let [x, y] = model.mesh().nodes[t[a / 6]];
            match a % 6 {
                0 => a0 + a1 * x + a2 * y,
                1 => b0 + b1 * x + b2 * y,
                5 => 0.5 * (b1 - a2),
                _ => 0.0,
            }
        });
        let eps = g * ue;
        let want = [a1, b2, a2 + b1, 0.0, 0.0, 0.0, 0.0, 0.0];
        for (i, w) in want.iter().enumerate() {
            assert!((eps[i] - w).abs() < 1e-14, "element {e} strain {i}");
        }
    }
}

#[test]
fn bending_patch_test_constant_curvature() {
    // Exact Kirchhoff field w = (a x² + 2b xy + c y²)/2 + d x + e y,
    // θx = w,y, θy = −w,x (so γ = ∇w + β = 0): curvatures
    // κ = (−a, −c, −2b), transverse shear exactly zero in DSG3 (the
    // trapezoidal gap integral is exact for linear ∇w).
    let (a, b, c, d, e) = (2e-3, -1e-3, 3e-3, 1e-3, -2e-3);
    let (model, sys) = free_system(&coupled());
    let fld = |[x, y]: [f64; 2], comp: usize| match comp {
        2 => 0.5 * (a * x * x + 2.0 * b * x * y + c * y * y) + d * x + e * y,
        3 => b * x + c * y + e,
        4 => -(a * x + b * y + d),
        _ => 0.0,
    };
    let u = field(&sys, fld);
    let res = interior_residual(&sys, &u);
    assert!(res < 1e-12, "interior residual {res:e}");
    for el in 0..model.mesh().triangles.len() {
        let (_, g) = model.element(el);
        let t = model.mesh().triangles[el];
        let ue =
            nalgebra::SVector::<f64, 18>::from_fn(|i, _| fld(model.mesh().nodes[t[i / 6]], i % 6));
        let k = g * ue;
        let want = [0.0, 0.0, 0.0, -a, -c, -2.0 * b, 0.0, 0.0];
        for (i, w) in want.iter().enumerate() {
            assert!(
                (k[i] - w).abs() < 1e-14,
                "element {el} strain {i}: {}",
                k[i]
            );
        }
    }
}

#[test]
fn rigid_body_modes_have_zero_energy_and_mass_is_exact() {
    let lam = coupled();
    let (model, sys) = free_system(&lam);
    for (i, r) in model.rigid_fields().iter().enumerate() {
        let kr = k_times(&sys, r);
        let rmax = r.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
        let e = kr.iter().fold(0.0, |m: f64, v| m.max(v.abs())) / (kmax(&sys) * rmax);
        assert!(e < 1e-12, "rigid mode {i}: |K r| / |K||r| = {e:e}");
    }
    // The six returned modes are M-orthonormal: ΦᵀMΦ = I.
    assert_eq!(sys.rigid_modes.len(), 6);
    for (i, p) in sys.rigid_modes.iter().enumerate() {
        for (j, q) in sys.rigid_modes.iter().enumerate() {
            let mij: f64 = p
                .iter()
                .zip(q)
                .zip(&sys.m_diag)
                .map(|((a, b), m)| a * b * m)
                .sum();
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((mij - want).abs() < 1e-12, "({i},{j}): {mij}");
        }
    }
    // Total translational mass = ρ h L W (closed form), on each of u, v, w.
    let m_total = 1600.0 * 1.5e-3 * 1.0 * 0.8;
    for comp in 0..3 {
        let m: f64 = sys
            .dof_map
            .iter()
            .zip(&sys.m_diag)
            .filter(|((_, c), _)| *c == comp)
            .map(|(_, m)| m)
            .sum();
        assert!(
            (m - m_total).abs() < 1e-12 * m_total,
            "component {comp}: {m}"
        );
    }
    assert!(sys.m_diag.iter().all(|&m| m > 0.0));
}

#[test]
fn drilling_penalty_energy_matches_closed_form() {
    // Closed form derived in this test from ½γ∫(θz − ω)² dA on one triangle:
    // (i) θz = 1 at node 0 only, u = v = 0: qᵀKq = γ ∫N₀² dA = γ A/6;
    // (ii) u = −c·y, v = c·x at the nodes (ω = c), θz = 0: qᵀKq = γ A c²;
    // (iii) the same with θz = c at every node: 0.
    let t = plyscape::fe::Triangle::new([[0.1, 0.0], [0.9, 0.2], [0.3, 0.7]]).unwrap();
    let gamma = 3.7e6;
    let k = t.drilling_stiffness(gamma);
    let mut q = nalgebra::SVector::<f64, 18>::zeros();
    q[5] = 1.0;
    let e = (q.transpose() * k * q)[0];
    assert!((e - gamma * t.area / 6.0).abs() < 1e-12 * gamma);
    let c = 0.013;
    let mut q = nalgebra::SVector::<f64, 18>::zeros();
    for i in 0..3 {
        q[6 * i] = -c * t.x[i][1];
        q[6 * i + 1] = c * t.x[i][0];
    }
    let e = (q.transpose() * k * q)[0];
    assert!((e - gamma * t.area * c * c).abs() < 1e-12 * gamma * c * c);
    for i in 0..3 {
        q[6 * i + 5] = c;
    }
    assert!((q.transpose() * k * q)[0].abs() < 1e-12 * gamma * c * c);
}

#[test]
fn element_derivatives_match_central_differences() {
    // Reference: central finite differences of the element stiffness in the
    // ply angles (step 1e-4 rad); second derivative: central differences of
    // the exact first derivative. Two cases: the paper's symmetric tying
    // [θ1/θ2/θ2/θ1], and an unsymmetric stack with one variable per ply
    // (so dB/dθ ≠ 0 is exercised).
    let model = PanelModel::new(distorted_mesh(), Support::FreeFree).unwrap();
    let cases = [
        (
            laminate(&[20.0, -50.0, -50.0, 20.0], 0.5e-3),
            DesignMap::symmetric(4),
        ),
        (
            laminate(&[10.0, 75.0, -40.0], 0.5e-3),
            DesignMap::per_ply(3),
        ),
    ];
    for (lam, map) in &cases {
        let x0: Vec<f64> = map.groups().iter().map(|g| lam.angles()[g[0]]).collect();
        for el in [0, 7, 33] {
            let (t, gd) = model.element(el);
            let g = model.element_ops(el);
            let h = lam.thickness();
            // The compact block product equals the dense GᵀCG (up to rounding).
            let c0 = section_matrix(&lam.stiffness());
            let dense = t.section_stiffness_dense(&gd, &c0, h);
            let fast = t.section_stiffness(g, &c0, h);
            assert!((dense - fast).amax() <= 1e-13 * dense.amax());
            let scale = model.element_stiffness(el, lam).amax();
            let d1 = |l: &Laminate, v: usize| -> Mat18 {
                t.section_stiffness(g, &section_matrix(&l.design_derivative(map, v)), h)
            };
            let step = 1e-4;
            for v in 0..map.len() {
                let mut xp = x0.clone();
                let mut xm = x0.clone();
                xp[v] += step;
                xm[v] -= step;
                let lp = lam.with_design(map, &xp).unwrap();
                let lm = lam.with_design(map, &xm).unwrap();
                let fd = (model.element_stiffness(el, &lp) - model.element_stiffness(el, &lm))
                    / (2.0 * step);
                let err = (d1(lam, v) - fd).amax() / scale;
                assert!(err < 1e-7, "element {el} dK/dθ{v}: {err:e}");
                for w in 0..map.len() {
                    let fd2 = (d1(&lp, w) - d1(&lm, w)) / (2.0 * step);
                    let an = t.section_stiffness(
                        g,
                        &section_matrix(&lam.design_second_derivative(map, w, v)),
                        h,
                    );
                    let err = (an - fd2).amax() / scale;
                    assert!(err < 1e-7, "element {el} d²K/dθ{w}dθ{v}: {err:e}");
                }
            }
        }
    }
}

#[test]
fn assembled_derivatives_match_central_differences_and_are_deterministic() {
    // Reference: central finite differences of the assembled reduced K
    // (same sparsity pattern, values compared entry by entry).
    let mesh = Mesh::structured(&MeshParams {
        length: 1.994,
        width: 1.3,
        divisions: 8,
        points: vec![
            [0.797, 0.45],
            [-0.797, 0.45],
            [0.797, -0.45],
            [-0.797, -0.45],
        ],
    })
    .unwrap();
    let model = PanelModel::new(mesh, Support::CentreClamp).unwrap();
    let map = DesignMap::symmetric(4);
    let x0 = [0.3, -0.9];
    let lam = laminate(&[0.0; 4], 0.5e-3).with_design(&map, &x0).unwrap();
    let sys = model.assemble(&lam, &map, Derivatives::Second).unwrap();
    assert_eq!(sys.dk.len(), 2);
    assert_eq!(sys.d2k.len(), 2);
    assert!(sys.d2k_mixed(0, 1).is_none());
    let scale = kmax(&sys);
    let step = 1e-4;
    for v in 0..2 {
        let mut xp = x0;
        let mut xm = x0;
        xp[v] += step;
        xm[v] -= step;
        let sp = model
            .assemble(
                &lam.with_design(&map, &xp).unwrap(),
                &map,
                Derivatives::First,
            )
            .unwrap();
        let sm = model
            .assemble(
                &lam.with_design(&map, &xm).unwrap(),
                &map,
                Derivatives::First,
            )
            .unwrap();
        let max_err = |an: &[f64], p: &[f64], m: &[f64]| {
            an.iter()
                .zip(p.iter().zip(m))
                .map(|(a, (p, m))| (a - (p - m) / (2.0 * step)).abs())
                .fold(0.0, f64::max)
                / scale
        };
        let e1 = max_err(sys.dk[v].val(), sp.k.val(), sm.k.val());
        assert!(e1 < 1e-7, "dK/dθ{v}: {e1:e}");
        let e2 = max_err(sys.d2k[v].val(), sp.dk[v].val(), sm.dk[v].val());
        assert!(e2 < 1e-7, "d²K/dθ{v}²: {e2:e}");
        // mixed: d(dK/dθw)/dθv = 0
        let w = 1 - v;
        let e12 = sp.dk[w]
            .val()
            .iter()
            .zip(sm.dk[w].val())
            .map(|(p, m)| ((p - m) / (2.0 * step)).abs())
            .fold(0.0, f64::max)
            / scale;
        assert!(e12 < 1e-7, "mixed: {e12:e}");
    }
    // Deterministic to the bit, also when re-assembling into used buffers.
    let mut again = model.assemble(&lam, &map, Derivatives::Second).unwrap();
    let other = lam.with_design(&map, &[1.0, 2.0]).unwrap();
    model.assemble_into(&other, &map, &mut again).unwrap();
    model.assemble_into(&lam, &map, &mut again).unwrap();
    assert!(sys
        .k
        .val()
        .iter()
        .zip(again.k.val())
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert!(sys.d2k[1]
        .val()
        .iter()
        .zip(again.d2k[1].val())
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    // Symmetric storage: K(i,j) == K(j,i) exactly.
    let k = sys.k.as_ref();
    for j in 0..sys.n_dof() {
        for p in k.col_ptr()[j]..k.col_ptr()[j + 1] {
            let i = k.row_idx()[p];
            assert_eq!(k.get(j, i).copied(), Some(k.val()[p]));
        }
    }
}
