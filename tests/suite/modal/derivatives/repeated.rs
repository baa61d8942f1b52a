//! Repeated eigenvalues: a constructed double root with known adjacent
//! eigenvectors and derivatives, and a generic double root (K′, K″ ≠ 0)
//! against branch-wise central differences.
//!
//! Bounds: about 3× the errors measured on the 2-core VM (2026-11-26),
//! printed by each test.
#![allow(clippy::needless_range_loop)]

use crate::common::modal::*;
use plyscape::modal::{DerivativeOptions, DesignDerivative, ModalOptions, ModalSolver};
use plyscape::Error;
use std::f64::consts::PI;

/// Repeated root, λ against the closed form: measured 6.7e-16.
const REP_LAM: f64 = 2e-15;

/// Repeated root, λ' against the closed form: measured 5.6e-17.
const REP_DLAM: f64 = 1e-15;

/// Repeated root, adjacent vectors: measured 7.8e-16.
const REP_VEC: f64 = 2e-15;

/// Repeated root, their derivatives (relative): measured 1.4e-15.
const REP_DVEC: f64 = 4e-15;

/// Two identical fixed–fixed chains (nc unit masses, unit springs) joined at
/// their first masses by a spring p·s. At p = 0 every eigenvalue is double:
/// λ_l = 2(1 − cos(lπ/(nc+1))) (chain closed form, Strang 2007 §1.5), with
/// chain modes x_l,i = sqrt(2/(nc+1)) sin((i+1) lπ/(nc+1)).
///
/// Exact adjacent eigenvectors and derivatives (derived here): the coupling
/// S = s(e_A0 − e_B0)(e_A0 − e_B0)ᵀ annihilates the symmetric vectors
/// (y, y), so ψ_sym = (x_l, x_l)/√2 has λ' = 0 and ψ_sym' = 0; on the
/// antisymmetric vectors (y, −y) it acts as a grounded spring 2s at node 0 of
/// one chain, so ψ_anti = (x_l, −x_l)/√2, λ' = 2s x_l,0², and
/// ψ_anti' = (x', −x')/√2 with
/// x' = Σ_{q≠l} x_q · 2s x_q,0 x_l,0 / (λ_l − λ_q) (modal expansion in the
/// nc closed-form chain modes, exact).
#[test]
fn repeated_eigenvalue_adjacent_eigenvectors_exact() {
    let nc = 10;
    let s = 0.5;
    let n = 2 * nc;
    let mut springs = chain_springs(nc, 1.0, 0, true);
    springs.extend(chain_springs(nc, 1.0, nc, true));
    let kk = assemble(n, &springs);
    let dk = assemble(
        n,
        &[Spring {
            a: 0,
            b: Some(nc),
            k: s,
        }],
    );
    let d2k = assemble(n, &[]);
    let mass = vec![1.0; n];
    let mut solver = ModalSolver::new(&kk, &mass).unwrap();
    let modes = solver.solve(&ModalOptions::new(6)).unwrap();
    let var = [DesignDerivative {
        dk: &dk,
        d2k: Some(&d2k),
        mass: None,
    }];
    let der = solver
        .derivatives(&modes, &var, &DerivativeOptions::default())
        .unwrap();
    let d = &der[0];
    assert_eq!(d.clusters.len(), 3);
    let adj = d.adjacent_modes(&modes.modes);
    let dm = d.dmodes.as_ref().unwrap();
    let h = PI / (nc as f64 + 1.0);
    let lam = |l: usize| 2.0 * (1.0 - (l as f64 * h).cos());
    let xc = |l: usize, i: usize| {
        (2.0 / (nc as f64 + 1.0)).sqrt() * ((i + 1) as f64 * l as f64 * h).sin()
    };
    let r2 = 0.5f64.sqrt();
    // Largest errors against the closed forms: λ and λ' (absolute, all
    // O(0.1..1)), the adjacent vectors (max norm, unit-M-norm vectors),
    // the derivatives (relative to the largest entry of the exact one).
    let (mut e_lam, mut e_dlam, mut e_vec, mut e_dvec) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for l in 1..=3 {
        let (c0, c1) = (2 * (l - 1), 2 * (l - 1) + 1);
        assert_eq!(d.clusters[l - 1].first, c0);
        e_lam = e_lam
            .max((modes.lambda[c0] - lam(l)).abs())
            .max((modes.lambda[c1] - lam(l)).abs());
        // λ' ascending: symmetric (0) then antisymmetric (2s x_l,0²).
        let dl_anti = 2.0 * s * xc(l, 0).powi(2);
        e_dlam = e_dlam
            .max(d.dlambda[c0].abs())
            .max((d.dlambda[c1] - dl_anti).abs());
        // Adjacent vectors, reference signs set by the crate's convention.
        let mut sym: Vec<f64> = (0..n).map(|i| r2 * xc(l, i % nc)).collect();
        let mut anti: Vec<f64> = (0..n)
            .map(|i| {
                if i < nc {
                    r2 * xc(l, i)
                } else {
                    -r2 * xc(l, i - nc)
                }
            })
            .collect();
        plyscape::modal::sign_normalize(&mut sym);
        plyscape::modal::sign_normalize(&mut anti);
        e_vec = e_vec
            .max(maxdiff(&col(&adj, c0), &sym))
            .max(maxdiff(&col(&adj, c1), &anti));
        // Derivatives: ψ_sym' = 0 (measured against the scale of ψ_anti').
        let sgn = anti[0].signum() * xc(l, 0).signum();
        let mut xp = vec![0.0; nc];
        for q in 1..=nc {
            if q == l {
                continue;
            }
            let c = 2.0 * s * xc(q, 0) * xc(l, 0) / (lam(l) - lam(q));
            for i in 0..nc {
                xp[i] += c * xc(q, i);
            }
        }
        let exact: Vec<f64> = (0..n)
            .map(|i| {
                if i < nc {
                    sgn * r2 * xp[i]
                } else {
                    -sgn * r2 * xp[i - nc]
                }
            })
            .collect();
        e_dvec = e_dvec
            .max(maxabs(&col(dm, c0)) / maxabs(&exact))
            .max(maxdiff(&col(dm, c1), &exact) / maxabs(&exact));
    }
    println!(
        "repeated roots: λ {e_lam:.2e}, λ' {e_dlam:.2e}, adjacent vectors {e_vec:.2e}, \
         their derivatives {e_dvec:.2e} relative"
    );
    // Bounds: the module constants (REP_*), about 3× the measured errors.
    assert!(
        e_lam < REP_LAM && e_dlam < REP_DLAM,
        "λ {e_lam:e}, λ' {e_dlam:e}"
    );
    assert!(
        e_vec < REP_VEC && e_dvec < REP_DVEC,
        "X {e_vec:e}, X' {e_dvec:e}"
    );
    // Without K'' the repeated cluster cannot be differentiated.
    let no_d2 = [DesignDerivative {
        dk: &dk,
        d2k: None,
        mass: None,
    }];
    assert!(matches!(
        solver.derivatives(&modes, &no_d2, &DerivativeOptions::default()),
        Err(Error::Input { .. })
    ));
    // A mode count that splits a double eigenvalue is refused.
    let five = solver.solve(&ModalOptions::new(5)).unwrap();
    match solver.derivatives(&five, &var, &DerivativeOptions::default()) {
        Err(Error::Input { key, .. }) => assert_eq!(key, "n_modes"),
        other => panic!("expected input error, got {other:?}"),
    }
}

/// Generic repeated root, dλ against branch differences: measured 1.6e-12.
const GEN_L_BOUND: f64 = 5e-12;

/// Generic repeated root, dX against branch differences (relative):
/// measured 7.1e-10.
const GEN_X_BOUND: f64 = 2.1e-9;

/// Repeated eigenvalue under a generic (non-symmetric) perturbation with
/// K'' ≠ 0: K(p) = K₀ + p K₁ + p² K₂, K₀ = two identical uncoupled chains
/// (every eigenvalue double), K₁, K₂ generic coupling and grounded springs.
/// Rellich's theorem gives analytic eigen-branches through p = 0; the
/// adjacent vectors are their limits. Reference: fourth-order central
/// differences of the branches, each branch picked at p = ±h, ±2h by its
/// overlap with the adjacent vector. This exercises the in-cluster
/// coefficients c_jl = (2ψ_lᵀK'v_j + ψ_lᵀK''ψ_j)/(2(λ_j' − λ_l')).
#[test]
fn repeated_eigenvalue_generic_perturbation_matches_branch_fd() {
    let nc = 9;
    let n = 2 * nc;
    let mut base = chain_springs(nc, 1.0, 0, true);
    base.extend(chain_springs(nc, 1.0, nc, true));
    let k1: Vec<Spring> = vec![
        Spring {
            a: 1,
            b: Some(nc + 3),
            k: 0.7,
        },
        Spring {
            a: 4,
            b: Some(nc + 2),
            k: 0.4,
        },
        Spring {
            a: 2,
            b: None,
            k: 0.9,
        },
        Spring {
            a: nc + 6,
            b: None,
            k: 0.3,
        },
    ];
    let k2: Vec<Spring> = vec![
        Spring {
            a: 0,
            b: Some(nc + 7),
            k: 0.8,
        },
        Spring {
            a: 5,
            b: None,
            k: 0.6,
        },
    ];
    let scaled = |s: &[Spring], f: f64| -> Vec<Spring> {
        s.iter().map(|x| Spring { k: x.k * f, ..*x }).collect()
    };
    let k_at = |p: f64| {
        let mut s = base.clone();
        s.extend(scaled(&k1, p));
        s.extend(scaled(&k2, p * p));
        assemble(n, &s)
    };
    let mass = vec![1.0; n];
    let dk = assemble(n, &k1);
    let d2k = assemble(n, &scaled(&k2, 2.0));
    let var = [DesignDerivative {
        dk: &dk,
        d2k: Some(&d2k),
        mass: None,
    }];
    let kk = k_at(0.0);
    let mut solver = ModalSolver::new(&kk, &mass).unwrap();
    let mut o = ModalOptions::new(4);
    o.tol = 1e-14;
    let modes = solver.solve(&o).unwrap();
    let der = solver
        .derivatives(&modes, &var, &DerivativeOptions::default())
        .unwrap();
    let d = &der[0];
    assert_eq!(d.clusters.len(), 2);
    let adj = d.adjacent_modes(&modes.modes);
    let dm = d.dmodes.as_ref().unwrap();
    let h = 1e-3;
    let at = |t: f64| {
        let mut o = ModalOptions::new(4);
        o.tol = 1e-14;
        ModalSolver::new(&k_at(t), &mass)
            .unwrap()
            .solve(&o)
            .unwrap()
    };
    let pts = [at(-2.0 * h), at(-h), at(h), at(2.0 * h)];
    let mut in_cluster_coupling = 0.0f64;
    let (mut worst_l, mut worst_x) = (0.0f64, 0.0f64);
    for c in 0..4 {
        let psi = col(&adj, c);
        // Branch at each point: the mode of largest overlap, sign aligned.
        let branch: Vec<(f64, Vec<f64>)> = pts
            .iter()
            .map(|m| {
                let (j, ov) = (0..4)
                    .map(|j| (j, mdot(&mass, &col(&m.modes, j), &psi)))
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                    .unwrap();
                assert!(ov.abs() > 0.99, "mode {c}: overlap {ov}");
                let x: Vec<f64> = col(&m.modes, j).iter().map(|v| v * ov.signum()).collect();
                (m.lambda[j], x)
            })
            .collect();
        let fd = |f: &dyn Fn(usize) -> f64| (8.0 * (f(2) - f(1)) - (f(3) - f(0))) / (12.0 * h);
        let fd_l = fd(&|k| branch[k].0);
        worst_l = worst_l.max((d.dlambda[c] - fd_l).abs());
        assert!(
            (d.dlambda[c] - fd_l).abs() < GEN_L_BOUND,
            "mode {c}: dλ {} vs {fd_l}",
            d.dlambda[c]
        );
        let fd_x: Vec<f64> = (0..n).map(|i| fd(&|k| branch[k].1[i])).collect();
        let dx = col(dm, c);
        worst_x = worst_x.max(maxdiff(&dx, &fd_x) / maxabs(&fd_x));
        assert!(
            maxdiff(&dx, &fd_x) < GEN_X_BOUND * maxabs(&fd_x),
            "mode {c}: |dψ − FD| = {:e} (scale {:e})",
            maxdiff(&dx, &fd_x),
            maxabs(&fd_x)
        );
        let partner = if c % 2 == 0 { c + 1 } else { c - 1 };
        in_cluster_coupling =
            in_cluster_coupling.max(mdot(&mass, &fd_x, &col(&adj, partner)).abs());
    }
    println!("generic repeated root: dλ against FD {worst_l:.2e}, dX {worst_x:.2e} relative");
    // The test is only meaningful if the in-cluster part is non-zero.
    assert!(
        in_cluster_coupling > 1e-3,
        "in-cluster coupling {in_cluster_coupling}"
    );
}
