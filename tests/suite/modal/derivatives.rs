//! Eigenvalue and eigenvector derivatives: central finite differences and
//! modal expansion for distinct modes (Nelson), a constructed repeated
//! eigenvalue with known adjacent eigenvectors and derivatives, a
//! near-crossing, and the error paths.
#![allow(clippy::needless_range_loop)]

use crate::common::modal::*;
use faer::sparse::SparseColMat;
use faer::Mat;
use plyscape::modal::{
    DerivativeOptions, DesignDerivative, ModalOptions, ModalSolver, ModeUpdate, Modes,
};
use plyscape::Error;
use std::f64::consts::PI;

// Bounds of the checks below, about 3× the errors measured on the 2-core
// VM (2026-11-26), printed by each test.
/// Distinct modes, dλ against differences (relative): measured 1.7e-9.
const FD_L_BOUND: f64 = 5e-9;
/// Distinct modes, dX against differences (relative): measured 8.5e-11.
const FD_X_BOUND: f64 = 1e-9;
/// Repeated root, λ against the closed form: measured 6.7e-16.
const REP_LAM: f64 = 2e-15;
/// Repeated root, λ' against the closed form: measured 5.6e-17.
const REP_DLAM: f64 = 1e-15;
/// Repeated root, adjacent vectors: measured 7.8e-16.
const REP_VEC: f64 = 2e-15;
/// Repeated root, their derivatives (relative): measured 1.4e-15.
const REP_DVEC: f64 = 4e-15;
/// Generic repeated root, dλ against branch differences: measured 1.6e-12.
const GEN_L_BOUND: f64 = 5e-12;
/// Generic repeated root, dX against branch differences (relative):
/// measured 7.1e-10.
const GEN_X_BOUND: f64 = 2.1e-9;

/// Parameterised irregular grid: K(p) = Σ_e k_e (1 + α_e sin p₀ + β_e cos 2p₁) K_e
/// with varied α_e, β_e (so K' is not proportional to K) and varied masses.
struct Param {
    nx: usize,
    ny: usize,
    base: Vec<Spring>,
    alpha: Vec<f64>,
    beta: Vec<f64>,
    mass: Vec<f64>,
}

impl Param {
    fn new(nx: usize, ny: usize) -> Self {
        let mut base = grid_springs(nx, ny, 1.0);
        for (e, s) in base.iter_mut().enumerate() {
            s.k = 100.0 * (1.0 + 0.6 * ((e as f64) * 0.917).sin());
        }
        let m = base.len();
        let n = nx * ny;
        Param {
            nx,
            ny,
            alpha: (0..m).map(|e| 0.4 * ((e as f64) * 1.31).cos()).collect(),
            beta: (0..m)
                .map(|e| 0.3 * ((e as f64) * 0.53 + 0.2).sin())
                .collect(),
            mass: (0..n)
                .map(|i| 1.0 + 0.4 * ((i as f64) * 2.17).sin())
                .collect(),
            base,
        }
    }
    fn n(&self) -> usize {
        self.nx * self.ny
    }
    /// Matrix Σ_e k_e w_e(p) K_e for a spring-weight function w.
    fn build(&self, w: impl Fn(usize) -> f64) -> SparseColMat<usize, f64> {
        let s: Vec<Spring> = self
            .base
            .iter()
            .enumerate()
            .map(|(e, s)| Spring {
                k: s.k * w(e),
                ..*s
            })
            .collect();
        assemble(self.n(), &s)
    }
    fn k(&self, p: [f64; 2]) -> SparseColMat<usize, f64> {
        self.build(|e| 1.0 + self.alpha[e] * p[0].sin() + self.beta[e] * (2.0 * p[1]).cos())
    }
    /// ∂K/∂p_v and ∂²K/∂p_v² (closed form derivatives of the weights).
    fn dk(&self, p: [f64; 2], v: usize) -> (SparseColMat<usize, f64>, SparseColMat<usize, f64>) {
        if v == 0 {
            (
                self.build(|e| self.alpha[e] * p[0].cos()),
                self.build(|e| -self.alpha[e] * p[0].sin()),
            )
        } else {
            (
                self.build(|e| -2.0 * self.beta[e] * (2.0 * p[1]).sin()),
                self.build(|e| -4.0 * self.beta[e] * (2.0 * p[1]).cos()),
            )
        }
    }
}

fn solve(k: &SparseColMat<usize, f64>, mass: &[f64], n_modes: usize, tol: f64) -> Modes {
    let mut o = ModalOptions::new(n_modes);
    o.tol = tol;
    ModalSolver::new(k, mass).unwrap().solve(&o).unwrap()
}

/// Well-separated modes of an irregular grid, two design variables:
/// λ' and X' against fourth-order central finite differences (h = 1e-3,
/// eigen-solves at tol 1e-13: FD noise ~1e-10, truncation ~h⁴; bounds
/// FD_L_BOUND, FD_X_BOUND),
/// and X' against the modal expansion over the full dense spectrum
/// (Fox & Kapoor 1968: xᵢ' = Σ_{j≠i} xⱼ xⱼᵀK'xᵢ/(λᵢ − λⱼ) for M' = 0).
#[test]
fn distinct_modes_match_finite_differences_and_modal_expansion() {
    let pr = Param::new(12, 9);
    let n = pr.n();
    let k_modes = 10;
    let p = [0.3, 0.4];
    let kk = pr.k(p);
    let mut solver = ModalSolver::new(&kk, &pr.mass).unwrap();
    let mut o = ModalOptions::new(k_modes);
    o.tol = 1e-13;
    let modes = solver.solve(&o).unwrap();
    // Well separated: smallest relative gap.
    let gap = (1..=k_modes)
        .map(|i| {
            let next = if i < k_modes {
                modes.lambda[i]
            } else {
                modes.next_lambda.unwrap()
            };
            (next - modes.lambda[i - 1]) / next
        })
        .fold(f64::INFINITY, f64::min);
    assert!(gap > 1e-3, "test problem not well separated: {gap}");
    let d: Vec<_> = (0..2).map(|v| pr.dk(p, v)).collect();
    let vars: Vec<DesignDerivative> = d
        .iter()
        .map(|(a, b)| DesignDerivative {
            dk: a,
            d2k: Some(b),
            mass: None,
        })
        .collect();
    let der = solver
        .derivatives(&modes, &vars, &DerivativeOptions::default())
        .unwrap();
    let (lref, xref) = dense_eig(&kk, &pr.mass);
    // Fourth-order central differences (error O(h⁴)), h = 1e-3.
    let h = 1e-3;
    let (mut worst_l, mut worst_x) = (0.0f64, 0.0f64);
    for v in 0..2 {
        assert!(der[v].clusters.is_empty());
        let at = |t: f64| {
            let mut pp = p;
            pp[v] += t;
            solve(&pr.k(pp), &pr.mass, k_modes, 1e-13)
        };
        let (m2, m1, p1, p2) = (at(-2.0 * h), at(-h), at(h), at(2.0 * h));
        let fd =
            |f: &dyn Fn(&Modes) -> f64| (8.0 * (f(&p1) - f(&m1)) - (f(&p2) - f(&m2))) / (12.0 * h);
        let dm = der[v].dmodes.as_ref().unwrap();
        let kd = dense(&d[v].0);
        for i in 0..k_modes {
            let fd_l = fd(&|m: &Modes| m.lambda[i]);
            let dl = der[v].dlambda[i];
            let rel_l = (dl - fd_l).abs() / dl.abs().max(1e-3 * modes.lambda[i]);
            worst_l = worst_l.max(rel_l);
            assert!(rel_l < FD_L_BOUND, "var {v} mode {i}: dλ {dl} vs FD {fd_l}");
            // Sign convention is fixed, so FD of the returned modes is valid.
            let fd_x: Vec<f64> = (0..n).map(|r| fd(&|m: &Modes| m.modes[(r, i)])).collect();
            let dx = col(dm, i);
            let scale = maxabs(&fd_x).max(1e-3 * maxabs(&col(&modes.modes, i)));
            worst_x = worst_x.max(maxdiff(&dx, &fd_x) / scale);
            assert!(
                maxdiff(&dx, &fd_x) < FD_X_BOUND * scale,
                "var {v} mode {i}: |dX − FD| = {:e}, scale {scale:e}",
                maxdiff(&dx, &fd_x)
            );
            // Modal expansion (independent of the factorizations).
            let xi = col(&modes.modes, i);
            let s = mdot(
                &pr.mass,
                &xi,
                &(0..n).map(|r| xref[(r, i)]).collect::<Vec<_>>(),
            )
            .signum();
            let mut expn = vec![0.0; n];
            for j in 0..n {
                if j == i {
                    continue;
                }
                let xj = xref.column(j);
                let kxi = &kd * xref.column(i);
                let c = xj.dot(&kxi) / (lref[i] - lref[j]);
                for r in 0..n {
                    expn[r] += s * c * xj[r];
                }
            }
            assert!(
                maxdiff(&dx, &expn) < 1e-8 * maxabs(&expn),
                "expansion, mode {i}"
            );
        }
    }
    println!("dλ against FD: {worst_l:.2e} relative; dX: {worst_x:.2e} relative");
    // Fixed-mode approach: same λ', no X'.
    let fixed = DerivativeOptions {
        update: ModeUpdate::Fixed,
        ..Default::default()
    };
    let der_f = solver.derivatives(&modes, &vars, &fixed).unwrap();
    assert!(der_f[0].dmodes.is_none());
    assert_eq!(der_f[1].dlambda, der[1].dlambda);
}

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

/// Near-crossing: chain A (8 unit masses/springs, fixed–fixed, plus a
/// grounded spring p at node 2) and an uncoupled chain B = β·(chain) whose
/// first eigenvalue equals A's at p = 0.5 (β chosen so). The branches are
/// smooth in p and cross at 0.5; the sorted modes swap there. At
/// p = 0.5 + δ for δ from 1e-2 down to 0 the returned derivatives (of the
/// adjacent vectors when clustered) must stay bounded and equal the smooth
/// branch derivatives: B's are zero, A's come from the modal expansion
/// (Fox & Kapoor 1968) of the 8×8 subsystem, solved densely.
#[test]
fn near_crossing_stays_bounded_and_matches_smooth_branch() {
    let nc = 8;
    let n = 2 * nc;
    let node = 2;
    let mass = vec![1.0; n];
    let chain = assemble(nc, &chain_springs(nc, 1.0, 0, true));
    let sub = |p: f64| {
        let mut s = chain_springs(nc, 1.0, 0, true);
        s.push(Spring {
            a: node,
            b: None,
            k: p,
        });
        assemble(nc, &s)
    };
    let (la, _) = dense_eig(&sub(0.5), &vec![1.0; nc]);
    let (lc, _) = dense_eig(&chain, &vec![1.0; nc]);
    let beta = la[0] / lc[0];
    let full = |p: f64| {
        let mut s = chain_springs(nc, 1.0, 0, true);
        s.push(Spring {
            a: node,
            b: None,
            k: p,
        });
        s.extend(chain_springs(nc, beta, nc, true));
        assemble(n, &s)
    };
    let dk = assemble(
        n,
        &[Spring {
            a: node,
            b: None,
            k: 1.0,
        }],
    );
    let d2k = assemble(n, &[]);
    let var = [DesignDerivative {
        dk: &dk,
        d2k: Some(&d2k),
        mass: None,
    }];
    for delta in [1e-2, 1e-4, 1e-7, 1e-10, 0.0] {
        let p = 0.5 + delta;
        let kk = full(p);
        let mut solver = ModalSolver::new(&kk, &mass).unwrap();
        let mut o = ModalOptions::new(4);
        o.tol = 1e-13;
        let modes = solver.solve(&o).unwrap();
        let der = solver
            .derivatives(&modes, &var, &DerivativeOptions::default())
            .unwrap();
        let adj = der[0].adjacent_modes(&modes.modes);
        let dm = der[0].dmodes.as_ref().unwrap();
        // Branch A reference (embedded in DOFs 0..nc).
        let (l_a, x_a) = dense_eig(&sub(p), &vec![1.0; nc]);
        let xa: Vec<f64> = (0..n)
            .map(|i| if i < nc { x_a[(i, 0)] } else { 0.0 })
            .collect();
        let dl_a = x_a[(node, 0)].powi(2);
        let mut dxa = vec![0.0; n];
        for q in 1..nc {
            let c = x_a[(node, q)] * x_a[(node, 0)] / (l_a[0] - l_a[q]);
            for i in 0..nc {
                dxa[i] += c * x_a[(i, q)];
            }
        }
        let scale = maxabs(&dxa);
        for c in 0..2 {
            let x = col(&adj, c);
            let ov = mdot(&mass, &x, &xa);
            let dx = col(dm, c);
            assert!(
                maxabs(&dx) < 10.0 * scale,
                "δ = {delta:e}: blow-up {}",
                maxabs(&dx)
            );
            if ov.abs() > 0.5 {
                // Branch A.
                assert!((ov.abs() - 1.0).abs() < 1e-8, "δ = {delta:e}: overlap {ov}");
                let ref_dx: Vec<f64> = dxa.iter().map(|v| ov.signum() * v).collect();
                assert!(
                    (der[0].dlambda[c] - dl_a).abs() < 1e-8 * dl_a,
                    "δ = {delta:e}: dλ_A"
                );
                assert!(
                    maxdiff(&dx, &ref_dx) < 1e-6 * scale,
                    "δ = {delta:e}: dX_A error {:e}",
                    maxdiff(&dx, &ref_dx)
                );
            } else {
                // Branch B: independent of p.
                assert!(ov.abs() < 1e-8, "δ = {delta:e}: overlap {ov}");
                assert!(der[0].dlambda[c].abs() < 1e-8 * dl_a, "δ = {delta:e}: dλ_B");
                assert!(
                    maxabs(&dx) < 1e-6 * scale,
                    "δ = {delta:e}: dX_B {:e}",
                    maxabs(&dx)
                );
            }
        }
    }
}

/// Mismatched derivative matrix size → input error naming the variable.
#[test]
fn wrong_derivative_size_is_input_error() {
    let n = 6;
    let kk = assemble(n, &chain_springs(n, 1.0, 0, true));
    let mut solver = ModalSolver::new(&kk, &vec![1.0; n]).unwrap();
    let modes = solver.solve(&ModalOptions::new(2)).unwrap();
    let bad = assemble(5, &chain_springs(5, 1.0, 0, true));
    let var = [DesignDerivative {
        dk: &bad,
        d2k: None,
        mass: None,
    }];
    match solver.derivatives(&modes, &var, &DerivativeOptions::default()) {
        Err(Error::Input { key, .. }) => assert_eq!(key, "dk[0]"),
        other => panic!("expected input error, got {other:?}"),
    }
    let _ = Mat::<f64>::zeros(1, 1);
}

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

/// Derivatives are bitwise reproducible (two solver instances, a repeated
/// cluster and distinct modes, so both Nelson and adjacent paths run).
#[test]
fn derivatives_bitwise_deterministic() {
    let nc = 7;
    let n = 2 * nc;
    let mut s = chain_springs(nc, 1.0, 0, true);
    s.extend(chain_springs(nc, 1.0, nc, true));
    let kk = assemble(n, &s);
    let dk = assemble(
        n,
        &[
            Spring {
                a: 1,
                b: Some(nc + 4),
                k: 0.6,
            },
            Spring {
                a: 3,
                b: None,
                k: 0.2,
            },
        ],
    );
    let d2k = assemble(
        n,
        &[Spring {
            a: 2,
            b: None,
            k: 0.5,
        }],
    );
    let var = [DesignDerivative {
        dk: &dk,
        d2k: Some(&d2k),
        mass: None,
    }];
    let mass = vec![1.0; n];
    let run = || {
        let mut solver = ModalSolver::new(&kk, &mass).unwrap();
        let modes = solver.solve(&ModalOptions::new(4)).unwrap();
        solver
            .derivatives(&modes, &var, &DerivativeOptions::default())
            .unwrap()
    };
    let (a, b) = (run(), run());
    assert_eq!(a[0].clusters.len(), 2);
    let (da, db) = (a[0].dmodes.as_ref().unwrap(), b[0].dmodes.as_ref().unwrap());
    for j in 0..4 {
        assert_eq!(a[0].dlambda[j].to_bits(), b[0].dlambda[j].to_bits());
        for i in 0..n {
            assert_eq!(da[(i, j)].to_bits(), db[(i, j)].to_bits());
        }
    }
}
