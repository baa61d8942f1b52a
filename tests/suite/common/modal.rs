//! Test problems for the modal tests: spring–mass chains and grids built
//! from springs, a dense reference eigen-solver (nalgebra) for small
//! problems, and the crate's solver at a given tolerance.
#![allow(dead_code)]

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use nalgebra::{DMatrix, SymmetricEigen};
use plyscape::modal::{ModalOptions, ModalSolver, Modes};

/// A spring between DOFs `a` and `b` (`b = None`: to ground) of stiffness `k`.
#[derive(Clone, Copy, Debug)]
pub struct Spring {
    pub a: usize,
    pub b: Option<usize>,
    pub k: f64,
}

/// Assemble `Σ k_e (e_a − e_b)(e_a − e_b)ᵀ` in full symmetric storage.
pub fn assemble(n: usize, springs: &[Spring]) -> SparseColMat<usize, f64> {
    let mut t = Vec::new();
    for s in springs {
        t.push(Triplet::new(s.a, s.a, s.k));
        if let Some(b) = s.b {
            t.push(Triplet::new(b, b, s.k));
            t.push(Triplet::new(s.a, b, -s.k));
            t.push(Triplet::new(b, s.a, -s.k));
        }
    }
    // Keep every diagonal in the pattern even when no spring touches it.
    for i in 0..n {
        t.push(Triplet::new(i, i, 0.0));
    }
    SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
}

/// Fixed–fixed chain of `n` masses and `n + 1` springs `k` (DOF offset `off`).
pub fn chain_springs(n: usize, k: f64, off: usize, fixed: bool) -> Vec<Spring> {
    let mut s = Vec::new();
    for i in 0..n.saturating_sub(1) {
        s.push(Spring {
            a: off + i,
            b: Some(off + i + 1),
            k,
        });
    }
    if fixed {
        s.push(Spring { a: off, b: None, k });
        s.push(Spring {
            a: off + n - 1,
            b: None,
            k,
        });
    }
    s
}

/// `nx × ny` grid of unit masses, springs `k` to the 4 neighbours and to
/// ground at the boundary (5-point Dirichlet Laplacian). DOF `i + nx·j`.
pub fn grid_springs(nx: usize, ny: usize, k: f64) -> Vec<Spring> {
    let id = |i: usize, j: usize| i + nx * j;
    let mut s = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if i + 1 < nx {
                s.push(Spring {
                    a: id(i, j),
                    b: Some(id(i + 1, j)),
                    k,
                });
            }
            if j + 1 < ny {
                s.push(Spring {
                    a: id(i, j),
                    b: Some(id(i, j + 1)),
                    k,
                });
            }
            let ground = [i == 0, i + 1 == nx, j == 0, j + 1 == ny];
            for g in ground {
                if g {
                    s.push(Spring {
                        a: id(i, j),
                        b: None,
                        k,
                    });
                }
            }
        }
    }
    s
}

/// Dense `K`.
pub fn dense(a: &SparseColMat<usize, f64>) -> DMatrix<f64> {
    let d = a.to_dense();
    DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| d[(i, j)])
}

/// Dense reference: all eigenpairs of `K x = λ M x` (ascending, `XᵀMX = I`)
/// via the symmetric matrix `M^{-1/2} K M^{-1/2}` (nalgebra).
pub fn dense_eig(k: &SparseColMat<usize, f64>, mass: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
    let n = mass.len();
    let kd = dense(k);
    let a = DMatrix::from_fn(n, n, |i, j| kd[(i, j)] / (mass[i] * mass[j]).sqrt());
    let e = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    let lam = order.iter().map(|&o| e.eigenvalues[o]).collect();
    let x = DMatrix::from_fn(n, n, |i, j| e.eigenvectors[(i, order[j])] / mass[i].sqrt());
    (lam, x)
}

/// Column `j` of a faer matrix.
pub fn col(m: &Mat<f64>, j: usize) -> Vec<f64> {
    (0..m.nrows()).map(|i| m[(i, j)]).collect()
}

/// M-inner product.
pub fn mdot(mass: &[f64], a: &[f64], b: &[f64]) -> f64 {
    mass.iter().zip(a).zip(b).map(|((m, x), y)| m * x * y).sum()
}

/// Max-norm of a vector.
pub fn maxabs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// Max-norm of a − b.
pub fn maxdiff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// The `n_modes` lowest modes of (K, M) by the crate's solver at
/// tolerance `tol`.
pub fn solve(k: &SparseColMat<usize, f64>, mass: &[f64], n_modes: usize, tol: f64) -> Modes {
    let mut o = ModalOptions::new(n_modes);
    o.tol = tol;
    ModalSolver::new(k, mass).unwrap().solve(&o).unwrap()
}
