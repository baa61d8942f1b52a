//! Sparse modal analysis: closed-form eigenvalues, residuals, orthogonality,
//! determinism, repeated eigenvalues, free-free structures, errors, export.

#![allow(clippy::needless_range_loop)]

use crate::common::modal::*;
use plyscape::modal::{mode_shape_rows, DofLabel, ModalOptions, ModalSolver};
use plyscape::Error;
use std::f64::consts::PI;

/// Fixed–fixed chain of n equal masses m and n+1 equal springs k:
/// K = k·tridiag(−1, 2, −1), M = m·I. Closed form (eigenvalues of the
/// tridiagonal Toeplitz matrix, e.g. G. Strang, Computational Science and
/// Engineering, 2007, §1.5): λ_j = (2k/m)(1 − cos(jπ/(n+1))), j = 1..n,
/// eigenvector entries x_i ∝ sin(i·jπ/(n+1)).
#[test]
fn fixed_chain_matches_closed_form() {
    let (n, k, m) = (200, 3.0e4, 0.7);
    let kk = assemble(n, &chain_springs(n, k, 0, true));
    let mass = vec![m; n];
    let mut solver = ModalSolver::new(&kk, &mass).unwrap();
    let modes = solver.solve(&ModalOptions::new(14)).unwrap();
    for (j, &lam) in modes.lambda.iter().enumerate() {
        let jj = (j + 1) as f64;
        let exact = 2.0 * k / m * (1.0 - (jj * PI / (n as f64 + 1.0)).cos());
        assert!(
            ((lam - exact) / exact).abs() < 1e-10,
            "mode {j}: {lam} vs {exact}"
        );
        // Shape: x_i = c·sin(i jπ/(n+1)) with c = ±sqrt(2/((n+1)m)) (M-normalised).
        let c = (2.0 / ((n as f64 + 1.0) * m)).sqrt();
        let x = col(&modes.modes, j);
        let exact_x: Vec<f64> = (0..n)
            .map(|i| c * ((i as f64 + 1.0) * jj * PI / (n as f64 + 1.0)).sin())
            .collect();
        let s = mdot(&mass, &x, &exact_x).signum();
        let ex: Vec<f64> = exact_x.iter().map(|v| s * v).collect();
        assert!(maxdiff(&x, &ex) < 1e-7 * maxabs(&ex), "mode {j} shape");
    }
}

/// Square nx×nx Dirichlet grid of unit masses and springs k: eigenvalues
/// (tensor product of the chain closed form above)
/// λ_ab = 2k[(1 − cos(aπ/(nx+1))) + (1 − cos(bπ/(nx+1)))], a, b = 1..nx.
/// λ_ab = λ_ba: every mode with a ≠ b is double — the solver must return
/// both copies.
#[test]
fn square_grid_repeated_eigenvalues_closed_form() {
    let (nx, k) = (30, 2.0);
    let n = nx * nx;
    let kk = assemble(n, &grid_springs(nx, nx, k));
    let mass = vec![1.0; n];
    let mut solver = ModalSolver::new(&kk, &mass).unwrap();
    let modes = solver.solve(&ModalOptions::new(12)).unwrap();
    let h = PI / (nx as f64 + 1.0);
    let mut exact = Vec::new();
    for a in 1..=nx {
        for b in 1..=nx {
            let (a, b) = (a as f64, b as f64);
            exact.push(2.0 * k * ((1.0 - (a * h).cos()) + (1.0 - (b * h).cos())));
        }
    }
    exact.sort_by(f64::total_cmp);
    for (j, &lam) in modes.lambda.iter().enumerate() {
        assert!(
            ((lam - exact[j]) / exact[j]).abs() < 1e-10,
            "mode {j}: {lam} vs {}",
            exact[j]
        );
    }
    // Modes 1 and 2 are the double pair (a, b) = (1, 2), (2, 1).
    assert!((exact[1] - exact[2]).abs() < 1e-12 * exact[1]);
    check_residual_and_orthogonality(&kk, &mass, &modes.modes, &modes.lambda);
}

/// ‖Kx − λMx‖ and ΦᵀMΦ − I with tolerances scaled by size (n·ε·‖K‖ style,
/// as in faer's `linalg/evd` tests).
fn check_residual_and_orthogonality(
    kk: &faer::sparse::SparseColMat<usize, f64>,
    mass: &[f64],
    x: &faer::Mat<f64>,
    lam: &[f64],
) {
    let n = mass.len();
    let kd = dense(kk);
    let knorm = kd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let eps = f64::EPSILON;
    for j in 0..x.ncols() {
        let xj = col(x, j);
        let xv = nalgebra::DVector::from_vec(xj.clone());
        let kx = &kd * &xv;
        let r: f64 = (0..n)
            .map(|i| (kx[i] - lam[j] * mass[i] * xj[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let mx: f64 = (0..n)
            .map(|i| (mass[i] * xj[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        // Lanczos tolerance 1e-10 on the shift-inverted residual; the
        // K-residual is bounded by tol·λ plus rounding n·ε·‖K‖.
        assert!(
            r / (lam[j] * mx) < 1e-8 + (n as f64) * eps * knorm / lam[j],
            "residual of mode {j}: {}",
            r / (lam[j] * mx)
        );
        for l in 0..x.ncols() {
            let g = mdot(mass, &xj, &col(x, l));
            let e = if j == l { 1.0 } else { 0.0 };
            assert!(
                (g - e).abs() < 10.0 * (n as f64).sqrt() * eps * 100.0,
                "XᵀMX[{j},{l}] = {g}"
            );
        }
    }
}

/// Non-uniform 2-D grid with varied masses: residuals, orthogonality and
/// agreement with the dense reference (nalgebra, all 600 eigenvalues).
#[test]
fn irregular_grid_residuals_and_dense_reference() {
    let (nx, ny) = (30, 20);
    let n = nx * ny;
    let mut springs = grid_springs(nx, ny, 1.0);
    for (e, s) in springs.iter_mut().enumerate() {
        s.k = 1.0e3 * (1.0 + 0.5 * ((e as f64) * 0.731).sin());
    }
    let kk = assemble(n, &springs);
    let mass: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.3 * ((i as f64) * 1.37).cos())
        .collect();
    let mut solver = ModalSolver::new(&kk, &mass).unwrap();
    let modes = solver.solve(&ModalOptions::new(14)).unwrap();
    let (lref, _) = dense_eig(&kk, &mass);
    for j in 0..14 {
        assert!(((modes.lambda[j] - lref[j]) / lref[j]).abs() < 1e-10);
        assert!(
            modes.residuals[j] < 1e-8,
            "reported residual {}",
            modes.residuals[j]
        );
    }
    check_residual_and_orthogonality(&kk, &mass, &modes.modes, &modes.lambda);
}

/// Two runs (and two solver instances) give identical bits.
#[test]
fn bitwise_deterministic() {
    let (nx, ny) = (25, 17);
    let n = nx * ny;
    let kk = assemble(n, &grid_springs(nx, ny, 5.0));
    let mass: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i % 7) as f64).collect();
    let a = ModalSolver::new(&kk, &mass)
        .unwrap()
        .solve(&ModalOptions::new(10))
        .unwrap();
    let b = ModalSolver::new(&kk, &mass)
        .unwrap()
        .solve(&ModalOptions::new(10))
        .unwrap();
    for j in 0..10 {
        assert_eq!(a.lambda[j].to_bits(), b.lambda[j].to_bits());
        for i in 0..n {
            assert_eq!(a.modes[(i, j)].to_bits(), b.modes[(i, j)].to_bits());
        }
    }
}

/// Free–free chain (no ground springs): K = k·(path-graph Laplacian).
/// Closed form (Neumann chain, e.g. Strang 2007 §1.5): λ_j = (2k/m)(1 −
/// cos(jπ/n)), j = 0..n−1, with the rigid-body mode λ_0 = 0. A negative
/// shift makes K − σM positive definite.
#[test]
fn free_free_chain_with_negative_shift() {
    let (n, k, m) = (60, 10.0, 2.0);
    let kk = assemble(n, &chain_springs(n, k, 0, false));
    let mass = vec![m; n];
    let mut solver = ModalSolver::new(&kk, &mass).unwrap();
    // σ = 0 fails: K is singular (rigid-body mode).
    let mut opts = ModalOptions::new(6);
    assert!(solver.solve(&opts).is_err());
    opts.shift = -0.1;
    let modes = solver.solve(&opts).unwrap();
    assert!(
        modes.lambda[0].abs() < 1e-10,
        "rigid mode {}",
        modes.lambda[0]
    );
    for j in 1..6 {
        let exact = 2.0 * k / m * (1.0 - (j as f64 * PI / n as f64).cos());
        assert!(((modes.lambda[j] - exact) / exact).abs() < 1e-10);
    }
    // Rigid mode: uniform translation, M-normalised: 1/sqrt(n m), positive.
    let x0 = col(&modes.modes, 0);
    let c = 1.0 / ((n as f64) * m).sqrt();
    assert!(x0.iter().all(|&v| (v - c).abs() < 1e-9));
}

/// A whole small problem (n = 5, all modes) exhausts the Krylov space.
#[test]
fn all_modes_of_a_tiny_problem() {
    let n = 5;
    let kk = assemble(n, &chain_springs(n, 1.0, 0, true));
    let mass = vec![1.0; n];
    let modes = ModalSolver::new(&kk, &mass)
        .unwrap()
        .solve(&ModalOptions::new(5))
        .unwrap();
    for j in 0..n {
        let exact = 2.0 * (1.0 - ((j + 1) as f64 * PI / 6.0).cos());
        assert!((modes.lambda[j] - exact).abs() < 1e-12, "{j}");
    }
}

#[test]
fn too_many_modes_is_input_error() {
    let n = 8;
    let kk = assemble(n, &chain_springs(n, 1.0, 0, true));
    let mut solver = ModalSolver::new(&kk, &vec![1.0; n]).unwrap();
    match solver.solve(&ModalOptions::new(9)) {
        Err(Error::Input { key, value, .. }) => {
            assert_eq!(key, "n_modes");
            assert_eq!(value, "9");
        }
        other => panic!("expected input error, got {other:?}"),
    }
    assert!(matches!(
        solver.solve(&ModalOptions::new(0)),
        Err(Error::Input { .. })
    ));
}

/// Lower-triangle-only storage (not full symmetric) is refused.
#[test]
fn unsymmetric_storage_is_input_error() {
    use faer::sparse::{SparseColMat, Triplet};
    let t = [
        Triplet::new(0usize, 0usize, 2.0),
        Triplet::new(1, 1, 2.0),
        Triplet::new(1, 0, -1.0),
    ];
    let k = SparseColMat::try_new_from_triplets(2, 2, &t).unwrap();
    match ModalSolver::new(&k, &[1.0, 1.0]) {
        Err(Error::Input { key, .. }) => assert_eq!(key, "stiffness[1, 0]"),
        other => panic!("expected input error, got {:?}", other.err()),
    }
}

#[test]
fn bad_mass_is_input_error() {
    let n = 4;
    let kk = assemble(n, &chain_springs(n, 1.0, 0, true));
    assert!(matches!(
        ModalSolver::new(&kk, &[1.0, 0.0, 1.0, 1.0]),
        Err(Error::Input { .. })
    ));
    assert!(matches!(
        ModalSolver::new(&kk, &[1.0; 3]),
        Err(Error::Input { .. })
    ));
}

/// A shift above the lowest eigenvalue makes K − σM indefinite: the
/// Cholesky factorization fails and the error names the shift and pivot.
#[test]
fn factorization_failure_is_numerical_error_with_shift_and_pivot() {
    let n = 50;
    let kk = assemble(n, &chain_springs(n, 1.0, 0, true));
    let mut solver = ModalSolver::new(&kk, &vec![1.0; n]).unwrap();
    let mut opts = ModalOptions::new(3);
    opts.shift = 0.5; // λ_1 = 2(1 − cos(π/51)) ≈ 3.8e-3 < 0.5
    match solver.solve(&opts) {
        Err(e @ Error::Numerical { .. }) => {
            let s = e.to_string();
            assert!(s.contains("sigma = 5e-1"), "{s}");
            assert!(s.contains("pivot"), "{s}");
            assert_eq!(e.exit_code(), 3);
        }
        other => panic!("expected numerical error, got {other:?}"),
    }
}

/// Export rows: one per mode and DOF, labels carried through.
#[test]
fn mode_shape_export_rows() {
    let n = 6;
    let kk = assemble(n, &chain_springs(n, 1.0, 0, true));
    let mass = vec![1.0; n];
    let modes = ModalSolver::new(&kk, &mass)
        .unwrap()
        .solve(&ModalOptions::new(2))
        .unwrap();
    let map: Vec<DofLabel> = (0..n)
        .map(|i| DofLabel {
            node: 10 + i / 3,
            component: i % 3,
        })
        .collect();
    let rows = mode_shape_rows(&modes, &map).unwrap();
    assert_eq!(rows.len(), 2 * n);
    assert_eq!(rows[n + 4].mode, 1);
    assert_eq!(rows[n + 4].node, 11);
    assert_eq!(rows[n + 4].component, 1);
    assert_eq!(rows[n + 4].value, modes.modes[(4, 1)]);
    assert!(matches!(
        mode_shape_rows(&modes, &map[..5]),
        Err(Error::Input { .. })
    ));
}

/// Same pattern, new values: the symbolic factorization is reused and the
/// result equals a fresh solver's.
#[test]
fn set_stiffness_reuses_pattern() {
    let n = 40;
    let mass = vec![1.0; n];
    let k1 = assemble(n, &chain_springs(n, 1.0, 0, true));
    let k2 = assemble(n, &chain_springs(n, 4.0, 0, true));
    let mut s = ModalSolver::new(&k1, &mass).unwrap();
    s.set_stiffness(&k2).unwrap();
    let a = s.solve(&ModalOptions::new(4)).unwrap();
    let b = ModalSolver::new(&k2, &mass)
        .unwrap()
        .solve(&ModalOptions::new(4))
        .unwrap();
    for j in 0..4 {
        assert_eq!(a.lambda[j].to_bits(), b.lambda[j].to_bits());
    }
}
