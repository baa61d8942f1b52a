//! The linear systems of the eigenvector derivatives: Nelson's reduced
//! system of a distinct eigenvalue and the bordered system of a cluster
//! (formulas in [`super`]'s module doc).
//!
//! `Â` is `K − λ̄M` (λ̄ the cluster's mean eigenvalue) with the rows and
//! columns of `r` well-conditioned DOFs of `X_C` (Gaussian elimination with
//! complete pivoting, [`pivot_rows`]) replaced by the identity. One `LDLᵀ`
//! of `Â` per cluster, reusing the symbolic factorization of the
//! eigen-solver, serves every design variable; a cluster of `r ≥ 2` adds the
//! `2r × 2r` Schur complement of the removed rows and the border
//! `X_CᵀM v = 0` (`2r` extra solves). Every solve is checked and, where
//! needed, refined by right-preconditioned GMRES on the exact matrix to the
//! relative residual [`SOLVE_TOL`].

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::Mat;
use nalgebra::{DMatrix, DVector};

use crate::error::{Error, Result};
use crate::modal::sparse::{gmres_refine, Factor, Pencil, Refine};

/// Rows of `x` (`n × r`) chosen by Gaussian elimination with complete
/// pivoting: the `r × r` submatrix on them is well conditioned.
fn pivot_rows(x: &Mat<f64>) -> Vec<usize> {
    let (n, r) = (x.nrows(), x.ncols());
    let mut a = x.clone();
    let mut rows = Vec::with_capacity(r);
    let mut cols_left: Vec<usize> = (0..r).collect();
    for _ in 0..r {
        let (mut bi, mut bc, mut bv) = (0, 0, -1.0);
        for (ci, &c) in cols_left.iter().enumerate() {
            for i in 0..n {
                if a[(i, c)].abs() > bv {
                    (bi, bc, bv) = (i, ci, a[(i, c)].abs());
                }
            }
        }
        let c = cols_left.remove(bc);
        rows.push(bi);
        let piv = a[(bi, c)];
        for &o in &cols_left {
            let f = a[(bi, o)] / piv;
            for i in 0..n {
                a[(i, o)] -= f * a[(i, c)];
            }
        }
    }
    rows
}

/// Relative residual `‖b − Âx‖/‖b‖` to which the derivative systems are
/// solved: a decade below the relative residual to which the eigenpairs
/// they are built from are converged (`ModalOptions::tol`, 1e-10), so the
/// solves add a tenth of the data's own error at most. On the SAR panels
/// (4152 DOFs, 14 modes) one solve with the factorization leaves 1e-13 to
/// 4e-11; refining every column to 1e-13, as this code did before, moved
/// the solutions by 1e-13 to 4e-12 relative and cost a third of the
/// derivative time (a second solve and product per cluster).
const SOLVE_TOL: f64 = 1e-11;

/// Solve `Â X = B` where `Â` is `K − λ̄M` with the rows and columns `rows`
/// (marked in `is_r`) replaced by the identity: one block solve with the
/// (possibly regularised) `LDLᵀ`, then Krylov refinement per column to
/// [`SOLVE_TOL`]. The residuals and the first GMRES step (one solve, one product)
/// are computed for all columns at once (block solve and one pass over `K`);
/// further GMRES steps, when needed, run per column.
fn refined_solve(
    pencil: &Pencil,
    factor: &mut Factor<'_>,
    lambda_bar: f64,
    (rows, is_r): (&[usize], &[bool]),
    b: &Mat<f64>,
) -> Result<Mat<f64>> {
    let (n, q) = (b.nrows(), b.ncols());
    let mass = pencil.mass();
    let mut x = b.clone();
    factor.solve_in_place(x.as_mut());
    // Residuals R = B − ÂX of all columns.
    let mut res = Mat::<f64>::zeros(n, q);
    pencil.shifted_mul_block(lambda_bar, rows, x.as_ref(), res.as_mut());
    let norm = |m: &Mat<f64>, j: usize| m.col(j).iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut todo = Vec::new();
    for j in 0..q {
        for i in 0..n {
            res[(i, j)] = b[(i, j)] - res[(i, j)];
        }
        let (beta, bn) = (norm(&res, j), norm(b, j).max(f64::MIN_POSITIVE));
        if beta > SOLVE_TOL * bn {
            todo.push((j, beta));
        }
    }
    if todo.is_empty() {
        return Ok(x);
    }
    // First GMRES step of every unconverged column: Z = F⁻¹ R/β, W = ÂZ.
    let mut z = Mat::<f64>::from_fn(n, todo.len(), |i, c| {
        let (j, beta) = todo[c];
        res[(i, j)] / beta
    });
    factor.solve_in_place(z.as_mut());
    let mut w = Mat::<f64>::zeros(n, todo.len());
    pencil.shifted_mul_block(lambda_bar, rows, z.as_ref(), w.as_mut());
    let apply = |v: &[f64], y: &mut [f64]| {
        let vn: Vec<f64> = (0..n).map(|i| if is_r[i] { 0.0 } else { v[i] }).collect();
        pencil.k_mul(&vn, y);
        for i in 0..n {
            y[i] = if is_r[i] {
                v[i]
            } else {
                y[i] - lambda_bar * mass[i] * vn[i]
            };
        }
    };
    for (c, &(j, _)) in todo.iter().enumerate() {
        let bj: Vec<f64> = b.col(j).iter().copied().collect();
        let mut xj: Vec<f64> = x.col(j).iter().copied().collect();
        let job = Refine {
            b: &bj,
            tol: SOLVE_TOL,
            max_iter: 40,
            residual: Some(res.col(j).iter().copied().collect()),
            first: Some((
                z.col(c).iter().copied().collect(),
                w.col(c).iter().copied().collect(),
            )),
        };
        let rj = gmres_refine(factor, &apply, &mut xj, job);
        if rj.is_nan() || rj > 1e-10 {
            return Err(Error::numerical(
                "modal::derivatives",
                format!(
                    "refined solve with K - lambda*M (lambda = {lambda_bar:e}) stalled at \
                     relative residual {rj:e}"
                ),
            ));
        }
        for i in 0..n {
            x[(i, j)] = xj[i];
        }
    }
    Ok(x)
}

/// Solve `(K − λ̄M) X = B` on a pencil of which `λ̄` is not an eigenvalue
/// (a block that does not hold the cluster, [`crate::modal::blocks`]):
/// one `LDLᵀ` (reusing the buffers of `spare`) and the refinement of
/// [`refined_solve`]. Returns the solution and the factorization, to be
/// handed on as the next spare.
pub(super) fn plain_solve<'p>(
    pencil: &'p Pencil,
    lambda_bar: f64,
    b: &Mat<f64>,
    spare: Option<Factor<'p>>,
) -> Result<(Mat<f64>, Factor<'p>)> {
    let mut factor = pencil.factor_ldlt(lambda_bar, &[], spare)?;
    let is_r = vec![false; pencil.n()];
    let x = refined_solve(pencil, &mut factor, lambda_bar, (&[], &is_r), b)?;
    Ok((x, factor))
}

/// Everything about one cluster that does not depend on the variable.
pub(super) struct ClusterSystem<'p> {
    pencil: &'p Pencil,
    first: usize,
    r: usize,
    /// λ̄, the mean eigenvalue of the cluster.
    pub(super) lambda_bar: f64,
    rows: Vec<usize>,
    /// `X_C` and `M X_C`, `n × r`.
    xc: Mat<f64>,
    mx: Mat<f64>,
    /// `A_NN⁻¹ (M X_C)_N` and `A_NN⁻¹ A_NR`, `n × r` each (zero on R).
    y1: Mat<f64>,
    y2: Mat<f64>,
    /// LU of the `2r × 2r` Schur complement.
    schur: nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    /// The `LDLᵀ` of `Â`; handed on to the next cluster on this pencil.
    pub(super) factor: Factor<'p>,
}

impl<'p> ClusterSystem<'p> {
    /// `lambda`: the cluster's eigenvalues (its first mode is `first`);
    /// `xc`: its eigenvectors on the pencil's DOFs (`n × r`); `spare`: the
    /// factorization of a previous cluster on this pencil, whose buffers are
    /// reused.
    pub(super) fn new(
        pencil: &'p Pencil,
        (first, lambda): (usize, &[f64]),
        xc: Mat<f64>,
        spare: Option<Factor<'p>>,
    ) -> Result<Self> {
        let (n, r) = (pencil.n(), lambda.len());
        let mass = pencil.mass();
        let lambda_bar = lambda.iter().sum::<f64>() / r as f64;
        let rows = pivot_rows(&xc);
        let mut is_r = vec![false; n];
        rows.iter().for_each(|&i| is_r[i] = true);
        let mut factor = pencil.factor_ldlt(lambda_bar, &rows, spare)?;
        let mx = Mat::<f64>::from_fn(n, r, |i, j| mass[i] * xc[(i, j)]);
        if r == 1 {
            // Nelson: the system is consistent, no border needed.
            return Ok(ClusterSystem {
                pencil,
                first,
                r,
                lambda_bar,
                rows,
                xc,
                mx,
                y1: Mat::<f64>::zeros(0, 0),
                y2: Mat::<f64>::zeros(0, 0),
                schur: DMatrix::<f64>::identity(1, 1).lu(),
                factor,
            });
        }
        let mut y = Mat::<f64>::zeros(n, 2 * r);
        for l in 0..r {
            for i in 0..n {
                if !is_r[i] {
                    y[(i, l)] = mx[(i, l)];
                }
            }
            let (ri, rv) = pencil.k_col(rows[l]);
            for (&i, &v) in ri.iter().zip(rv) {
                if !is_r[i] {
                    y[(i, r + l)] = v;
                }
            }
        }
        let y = refined_solve(pencil, &mut factor, lambda_bar, (&rows, &is_r), &y)?;
        let y1 = Mat::<f64>::from_fn(n, r, |i, j| if is_r[i] { 0.0 } else { y[(i, j)] });
        let y2 = Mat::<f64>::from_fn(n, r, |i, j| if is_r[i] { 0.0 } else { y[(i, r + j)] });
        let mut sys = ClusterSystem {
            pencil,
            first,
            r,
            lambda_bar,
            rows,
            xc,
            mx,
            y1,
            y2,
            schur: DMatrix::<f64>::identity(1, 1).lu(),
            factor,
        };
        let mut s = DMatrix::<f64>::zeros(2 * r, 2 * r);
        for l in 0..r {
            let a_y1 = sys.a_rn(&sys.y1, l);
            let a_y2 = sys.a_rn(&sys.y2, l);
            let mt_y1 = sys.mx_t(&sys.y1, l);
            let mt_y2 = sys.mx_t(&sys.y2, l);
            for a in 0..r {
                // Removed rows: [(MX)_R − A_RN Y1] μ + [A_RR − A_RN Y2] s.
                s[(a, l)] = sys.mx[(sys.rows[a], l)] - a_y1[a];
                s[(a, r + l)] = sys.a_rr(a, l) - a_y2[a];
                // Border: −[(MX)_Nᵀ Y1] μ + [(MX)_Rᵀ − (MX)_Nᵀ Y2] s = −(MX)_Nᵀ z0.
                s[(r + a, l)] = -mt_y1[a];
                s[(r + a, r + l)] = sys.mx[(sys.rows[l], a)] - mt_y2[a];
            }
        }
        sys.schur = s.lu();
        Ok(sys)
    }

    /// `(A_RN z)_a` for column `col` of `z` (zero on R): row R_a of K.
    fn a_rn(&self, z: &Mat<f64>, col: usize) -> Vec<f64> {
        self.rows
            .iter()
            .map(|&ra| {
                let (ri, rv) = self.pencil.k_col(ra);
                ri.iter().zip(rv).map(|(&i, &v)| v * z[(i, col)]).sum()
            })
            .collect()
    }

    /// `((M X_C)ᵀ z)_a` for column `col` of `z`.
    fn mx_t(&self, z: &Mat<f64>, col: usize) -> Vec<f64> {
        (0..self.r)
            .map(|a| (0..z.nrows()).map(|i| self.mx[(i, a)] * z[(i, col)]).sum())
            .collect()
    }

    /// `A[R_a, R_l] = K[R_a, R_l] − λ̄ M δ_al`.
    fn a_rr(&self, a: usize, l: usize) -> f64 {
        let (ri, rv) = self.pencil.k_col(self.rows[l]);
        let kv = ri
            .iter()
            .position(|&i| i == self.rows[a])
            .map_or(0.0, |p| rv[p]);
        if a == l {
            kv - self.lambda_bar * self.pencil.mass()[self.rows[a]]
        } else {
            kv
        }
    }

    /// Solve the bordered system for the columns of `f` (`n × q`); returns
    /// `v` (`n × q`) with `X_CᵀM v = 0`.
    pub(super) fn solve(&mut self, f: &Mat<f64>) -> Result<Mat<f64>> {
        let (n, q, r) = (f.nrows(), f.ncols(), self.r);
        let mut is_r = vec![false; n];
        self.rows.iter().for_each(|&i| is_r[i] = true);
        let z = Mat::<f64>::from_fn(n, q, |i, j| if is_r[i] { 0.0 } else { f[(i, j)] });
        let mut z = refined_solve(
            self.pencil,
            &mut self.factor,
            self.lambda_bar,
            (&self.rows, &is_r),
            &z,
        )?;
        for j in 0..q {
            for i in 0..n {
                if is_r[i] {
                    z[(i, j)] = 0.0;
                }
            }
        }
        if r == 1 {
            // Nelson (distinct eigenvalue): v = z − x (xᵀM z), so xᵀM v = 0
            // (the normalisation coefficient c = −xᵀMz of Nelson 1976).
            for j in 0..q {
                let c: f64 = (0..n).map(|i| self.mx[(i, 0)] * z[(i, j)]).sum();
                for i in 0..n {
                    z[(i, j)] -= c * self.xc[(i, 0)];
                }
            }
            return Ok(z);
        }
        let mut v = z.clone();
        for j in 0..q {
            let a_z = self.a_rn(&z, j);
            let mt_z = self.mx_t(&z, j);
            let rhs = DVector::<f64>::from_fn(2 * r, |a, _| {
                if a < r {
                    f[(self.rows[a], j)] - a_z[a]
                } else {
                    -mt_z[a - r]
                }
            });
            let sol = self.schur.solve(&rhs).ok_or_else(|| {
                Error::numerical(
                    "modal::derivatives",
                    format!(
                        "singular bordered system for cluster of modes {}..{} at lambda = {:e}",
                        self.first,
                        self.first + r,
                        self.lambda_bar
                    ),
                )
            })?;
            for i in 0..n {
                let mut s = 0.0;
                for l in 0..r {
                    s += self.y1[(i, l)] * sol[l] + self.y2[(i, l)] * sol[r + l];
                }
                v[(i, j)] -= s;
            }
            for (l, &rl) in self.rows.iter().enumerate() {
                v[(rl, j)] = sol[r + l];
            }
        }
        Ok(v)
    }
}
