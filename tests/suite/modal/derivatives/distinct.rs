//! Well-separated modes of an irregular grid of springs with two design
//! variables: λ' and X' against central finite differences and the modal
//! expansion over the full spectrum.
//!
//! Bounds: about 3× the errors measured on the 2-core VM (2026-11-26),
//! printed by each test.
#![allow(clippy::needless_range_loop)]

use crate::common::modal::*;
use faer::sparse::SparseColMat;
use plyscape::modal::{
    DerivativeOptions, DesignDerivative, ModalOptions, ModalSolver, ModeUpdate, Modes,
};

/// Distinct modes, dλ against differences (relative): measured 1.7e-9.
const FD_L_BOUND: f64 = 5e-9;

/// Distinct modes, dX against differences (relative): measured 8.5e-11.
const FD_X_BOUND: f64 = 1e-9;

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
