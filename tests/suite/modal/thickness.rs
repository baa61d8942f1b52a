//! Eigenvalue and eigenvector derivatives with respect to a ply thickness
//! (mass and stiffness both move: `M' ≠ 0`) on small shell panels, against
//! central differences of the eigen-solutions: distinct modes (Nelson with
//! `c = −½xᵀM'x`) and an exactly repeated pair split by the thickness
//! (adjacent eigenvectors with the `M'`, `M''` terms).
#![allow(clippy::needless_range_loop)]

use crate::common::modal::*;
use faer::Mat;
use plyscape::fe::{Derivatives, Mesh, MeshParams, PanelModel, Support, ThicknessSystem};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply};
use plyscape::modal::{
    DerivativeOptions, DesignDerivative, MassDerivative, ModalOptions, ModalSolver, Modes,
    VariableDerivatives,
};

fn model(length: f64, width: f64, divisions: usize) -> PanelModel {
    let mesh = Mesh::structured(&MeshParams {
        length,
        width,
        divisions,
        points: vec![],
    })
    .unwrap();
    PanelModel::new(mesh, Support::CentreClamp).unwrap()
}

fn stack(material: Orthotropic, plies: &[(f64, f64)]) -> Laminate {
    Laminate::new(
        plies
            .iter()
            .map(|&(deg, t)| Ply {
                material,
                thickness: t,
                angle: deg.to_radians(),
            })
            .collect(),
    )
    .unwrap()
}

/// The stack with every ply of `group` at thickness `s`.
fn with_group(lam: &Laminate, group: &[usize], s: f64) -> Laminate {
    let t: Vec<f64> = lam
        .plies()
        .iter()
        .enumerate()
        .map(|(k, p)| if group.contains(&k) { s } else { p.thickness })
        .collect();
    lam.with_thicknesses(&t).unwrap()
}

/// Modes of `lam` (tol 1e-13).
fn modes_of(model: &PanelModel, lam: &Laminate, k: usize) -> Modes {
    let sys = model
        .assemble(
            lam,
            &DesignMap::per_ply(lam.plies().len()),
            Derivatives::None,
        )
        .unwrap();
    let mut o = ModalOptions::new(k);
    o.tol = 1e-13;
    ModalSolver::new(&sys.k, &sys.m_diag)
        .unwrap()
        .solve(&o)
        .unwrap()
}

/// Modes and their thickness derivatives for every group of `ts`.
fn derivatives(
    model: &PanelModel,
    lam: &Laminate,
    ts: &ThicknessSystem,
    k: usize,
) -> (Modes, Vec<VariableDerivatives>, Vec<f64>) {
    let sys = model
        .assemble(
            lam,
            &DesignMap::per_ply(lam.plies().len()),
            Derivatives::None,
        )
        .unwrap();
    let mut solver = ModalSolver::new(&sys.k, &sys.m_diag).unwrap();
    let mut o = ModalOptions::new(k);
    o.tol = 1e-13;
    let modes = solver.solve(&o).unwrap();
    let vars: Vec<DesignDerivative> = (0..ts.groups.len())
        .map(|v| DesignDerivative {
            dk: &ts.dk[v],
            d2k: Some(&ts.d2k[v]),
            mass: Some(MassDerivative {
                dm: &ts.dm[v],
                d2m: Some(&ts.d2m[v]),
            }),
        })
        .collect();
    let d = solver
        .derivatives(&modes, &vars, &DerivativeOptions::default())
        .unwrap();
    (modes, d, sys.m_diag)
}

/// Column `j` of `m` with the sign that makes its M-overlap with `x`
/// positive.
fn aligned(m: &Mat<f64>, j: usize, mass: &[f64], x: &[f64]) -> Vec<f64> {
    let c = col(m, j);
    let s = mdot(mass, &c, x).signum();
    c.iter().map(|v| s * v).collect()
}

// Bounds about 4× the errors measured on the 2-core VM (2026-11-27),
// printed by the tests.
/// Distinct modes, dλ (relative): measured 1.3e-8.
const DIST_L: f64 = 5e-8;
/// Distinct modes, dX (relative to max |dX|): measured 3.9e-8.
const DIST_X: f64 = 2e-7;
/// Repeated pair, dλ (relative): measured 2.5e-8.
const REP_L: f64 = 1e-7;
/// Repeated pair, dX (relative to max |dX|): measured 1.3e-7.
const REP_X: f64 = 5e-7;

/// Distinct modes of an unsymmetric-able angle-ply panel (1.0 m × 0.6 m,
/// 10 divisions, [30/−45/−45/30], IM6/SC1081): λ' and X' for the
/// thickness of ply 1 alone (B' ≠ 0, membrane and bending couple) and of
/// plies 2 and 3 together, against central differences (step 1e-8 m on
/// 0.5 mm plies: truncation ~(h/s)² ≈ 4e-10, eigen-solver noise ~1e-13/h·s
/// ≈ 5e-10 relative; Haftka & Gürdal §7.3 for the reference formulas).
#[test]
fn distinct_modes_match_central_differences() {
    let m = model(1.0, 0.6, 10);
    let t = 0.5e-3;
    let lam = stack(
        Orthotropic::im6_sc1081(),
        &[(30.0, t), (-45.0, t), (-45.0, t), (30.0, t)],
    );
    let groups = vec![vec![0], vec![1, 2]];
    let ts = m.assemble_thickness(&lam, &groups, true).unwrap();
    let k = 6;
    let (modes, der, _) = derivatives(&m, &lam, &ts, k);
    for d in &der {
        assert!(d.clusters.is_empty(), "test modes not distinct");
    }
    let h = 1e-8;
    for (v, g) in groups.iter().enumerate() {
        let mp = modes_of(&m, &with_group(&lam, g, t + h), k);
        let mm = modes_of(&m, &with_group(&lam, g, t - h), k);
        let mass = m
            .assemble(&lam, &DesignMap::per_ply(4), Derivatives::None)
            .unwrap()
            .m_diag;
        let dx = der[v].dmodes.as_ref().unwrap();
        let (mut el, mut ex) = (0.0f64, 0.0f64);
        for j in 0..k {
            let fd_l = (mp.lambda[j] - mm.lambda[j]) / (2.0 * h);
            el = el
                .max((der[v].dlambda[j] - fd_l).abs() / fd_l.abs().max(1e-3 * modes.lambda[j] / t));
            let x0 = col(&modes.modes, j);
            let (xp, xm) = (
                aligned(&mp.modes, j, &mass, &x0),
                aligned(&mm.modes, j, &mass, &x0),
            );
            let fd_x: Vec<f64> = xp
                .iter()
                .zip(&xm)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            ex = ex.max(maxdiff(&col(dx, j), &fd_x) / maxabs(&fd_x));
        }
        println!("group {g:?}: dλ {el:.1e}, dX {ex:.1e}");
        assert!(
            el < DIST_L && ex < DIST_X,
            "group {g:?}: dλ {el:e}, dX {ex:e}"
        );
    }
}

/// An exactly repeated pair: a square plate (1 m, union-jack mesh of 8
/// divisions, invariant under a 90° rotation) of a cross-ply
/// [0/90/90/0] whose outer plies are (2^{1/3} − 1) times the inner ones
/// (then D11 = D22) and a material with G13 = G23 (then S is isotropic):
/// the flexural problem is invariant under the rotation, so its E-type
/// modes come in repeated pairs. Thickening the 0° plies (group 1, 4;
/// mirror-closed, B' = 0) splits each pair; the adjacent vectors and their
/// derivatives are checked against central differences of the branches
/// (matched by M-overlap; the split branches are analytic in s, Rellich).
#[test]
fn repeated_pair_split_by_thickness_matches_branch_differences() {
    let m = model(1.0, 1.0, 8);
    let mut mat = Orthotropic::im6_sc1081();
    mat.g23 = mat.g13;
    let ti = 0.5e-3;
    let to = (2f64.cbrt() - 1.0) * ti;
    let lam = stack(mat, &[(0.0, to), (90.0, ti), (90.0, ti), (0.0, to)]);
    let groups = vec![vec![0, 3]];
    let ts = m.assemble_thickness(&lam, &groups, true).unwrap();
    // The largest mode count up to 8 that does not split a pair.
    let all = modes_of(&m, &lam, 12).lambda;
    let k = (2..=8)
        .rev()
        .find(|&k| all[k] - all[k - 1] > 1e-6 * all[k])
        .unwrap();
    let (modes, der, mass) = derivatives(&m, &lam, &ts, k);
    let d = &der[0];
    assert!(
        !d.clusters.is_empty(),
        "no repeated pair: {:?}",
        modes.lambda
    );
    let adj = d.adjacent_modes(&modes.modes);
    let dx = d.dmodes.as_ref().unwrap();
    // Fourth-order central differences of the branches, step 2e-6 m on a
    // 0.13 mm ply: the pair must be split far above the eigen-solver's
    // resolution (its vectors carry ~tol/gap), truncation ~(h/s)⁴ ≈ 6e-8.
    let h = 2e-6;
    let at: Vec<Modes> = [2.0, 1.0, -1.0, -2.0]
        .iter()
        .map(|f| modes_of(&m, &with_group(&lam, &groups[0], to + f * h), k))
        .collect();
    let w = [-1.0, 8.0, -8.0, 1.0];
    let (mut el, mut ex) = (0.0f64, 0.0f64);
    for c in &d.clusters {
        // The derivatives must split the pair (else the adjacent vectors
        // are not determined by first derivatives).
        let dl = &d.dlambda[c.first..c.first + c.len];
        assert!(
            (dl[1] - dl[0]).abs() > 1e-3 * dl[0].abs().max(dl[1].abs()),
            "{dl:?}"
        );
        for j in c.first..c.first + c.len {
            let psi = col(&adj, j);
            // At each step the branch with the largest overlap with ψⱼ.
            let pick = |md: &Modes| {
                (c.first..c.first + c.len)
                    .max_by(|&a, &b| {
                        mdot(&mass, &col(&md.modes, a), &psi)
                            .abs()
                            .total_cmp(&mdot(&mass, &col(&md.modes, b), &psi).abs())
                    })
                    .unwrap()
            };
            let js: Vec<usize> = at.iter().map(pick).collect();
            let fd_l: f64 = (0..4).map(|q| w[q] * at[q].lambda[js[q]]).sum::<f64>() / (12.0 * h);
            el = el.max((d.dlambda[j] - fd_l).abs() / fd_l.abs());
            let xs: Vec<Vec<f64>> = (0..4)
                .map(|q| aligned(&at[q].modes, js[q], &mass, &psi))
                .collect();
            let fd_x: Vec<f64> = (0..xs[0].len())
                .map(|i| (0..4).map(|q| w[q] * xs[q][i]).sum::<f64>() / (12.0 * h))
                .collect();
            ex = ex.max(maxdiff(&col(dx, j), &fd_x) / maxabs(&fd_x));
        }
    }
    println!(
        "repeated: clusters {:?}, dλ {el:.1e}, dX {ex:.1e}",
        d.clusters
            .iter()
            .map(|c| (c.first, c.len))
            .collect::<Vec<_>>()
    );
    assert!(el < REP_L && ex < REP_X, "dλ {el:e}, dX {ex:e}");
}
