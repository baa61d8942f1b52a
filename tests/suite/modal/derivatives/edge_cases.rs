//! Eigen-derivatives at their edges: no blow-up across a near-crossing
//! (smooth-branch derivatives), the input error of a wrong derivative
//! size, and bitwise determinism.
#![allow(clippy::needless_range_loop)]

use crate::common::modal::*;
use faer::Mat;
use plyscape::modal::{DerivativeOptions, DesignDerivative, ModalOptions, ModalSolver};
use plyscape::Error;

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
