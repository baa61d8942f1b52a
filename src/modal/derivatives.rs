//! Eigenvalue and eigenvector derivatives (paper §3.1, Eqs. 17–19).
//!
//! For a design variable `θ` with `K' = ∂K/∂θ`, `K'' = ∂²K/∂θ²` and `M' = 0`
//! (lumped mass independent of ply angles):
//!
//! - **Eigenvalues**: `λᵢ' = xᵢᵀ K' xᵢ` (mass-normalised `xᵢ`).
//! - **Clusters.** Consecutive eigenvalues with relative gap
//!   `(λᵢ₊₁ − λᵢ)/max(|λᵢ|, |λᵢ₊₁|, |σ|) < cluster_tol` form a cluster `C`
//!   of size `r`. A singleton is a distinct eigenvalue.
//! - **Distinct (Nelson 1976).** `xᵢ' = vᵢ + cᵢxᵢ` with
//!   `(K − λᵢM) vᵢ = −(K' − λᵢ'M) xᵢ`, made nonsingular by replacing the row
//!   and column of the largest |xᵢ| entry by the identity, and
//!   `cᵢ = −xᵢᵀMvᵢ` (normalisation `xᵀMx = 1`).
//! - **Repeated / nearly repeated (adjacent eigenvectors, Ojalvo 1987,
//!   Dailey 1989).** In a cluster the eigenvectors are not unique; the
//!   differentiable ("adjacent") ones are `Ψ = X_C Γ`, where `Γ` (`r × r`,
//!   orthogonal) diagonalises `D = X_CᵀK'X_C = Γ diag(λ') Γᵀ`; the
//!   eigenvalue derivatives are the eigenvalues of `D` (ascending). Then
//!   `ψⱼ' = vⱼ + Σ_l cⱼₗ ψₗ` where `vⱼ` solves the bordered system
//!   `(K − λ̄M) vⱼ + M X_C μ = −(K' − λⱼ'M) ψⱼ`, `X_CᵀM vⱼ = 0`
//!   (λ̄ the cluster mean), `cⱼⱼ = 0` and, from the second derivative of the
//!   eigenproblem premultiplied by `ψₗᵀ`,
//!   `cⱼₗ = (2ψₗᵀK'vⱼ + ψₗᵀK''ψⱼ) / (2(λⱼ' − λₗ'))` for `l ≠ j`.
//!   When `λⱼ' = λₗ'` too, the adjacent vectors are not determined by first
//!   derivatives; then `cⱼₗ = 0` (documented limitation).
//!
//! The bordered system is solved with one `LDLᵀ` of `K − λ̄M` whose `r`
//! rows/columns at well-conditioned DOFs of `X_C` (complete pivoting) are
//! replaced by the identity (same pattern: the symbolic factorization of
//! the eigen-solver is reused), plus a `2r × 2r` Schur complement for the
//! removed rows and the border (`2r` extra solves per cluster). For a
//! singleton the border is not needed — Nelson's reduced system is
//! consistent — and `x' = z − x(xᵀMz)`. Every solve is checked and, where
//! needed, refined by right-preconditioned GMRES on the exact matrix to a
//! relative residual of 1e-11 (`SOLVE_TOL`; the unpivoted `LDLᵀ` of an indefinite
//! matrix may meet a tiny pivot, e.g. a Sturm-sequence zero of a chain; such
//! pivots are regularised and the refinement removes the rank-one error).
//! One factorization per cluster serves every design variable.
//!
//! # Mass derivative (ply thickness)
//! When the lumped mass depends on the variable (`M' ≠ 0`, a ply
//! thickness; [`MassDerivative`]) the same steps hold with `K'` replaced
//! by `K' − λ̄M'` where it multiplies eigenvectors (Haftka & Gürdal,
//! *Elements of Structural Optimization*, §7.3; Nelson 1976):
//! `λᵢ' = xᵢᵀ(K' − λᵢM')xᵢ`, `D = X_Cᵀ(K' − λ̄M')X_C`, right-hand sides
//! `−(K' − λⱼ'M − λ̄M')ψⱼ`, and the normalisation `ψⱼᵀMψⱼ = 1` gives
//! `cⱼⱼ = −½ψⱼᵀM'ψⱼ` (Nelson's `c = −½xᵀM'x − xᵀMv`, with `xᵀMv = 0`).
//! The second derivative of the eigenproblem gives, for `l ≠ j` in a
//! cluster, `cⱼₗ = (2ψₗᵀ(K' − λ̄M')vⱼ + ψₗᵀ(K'' − 2λⱼ'M' − λ̄M'')ψⱼ) /
//! (2(λⱼ' − λₗ'))`, so repeated clusters need `M''` as well as `K''`.
//! With `M' = 0` every formula is the one above, computed by the same
//! operations (ply-angle results are unchanged to the bit).
//!
//! # What the caller gets
//! Per variable a [`VariableDerivatives`]: `dlambda[i]`; in the updated-mode
//! approach `dmodes` (`n × k`); and for each cluster of size ≥ 2 the
//! rotation `Γ`: for those columns, `dlambda` and `dmodes` refer to the
//! adjacent vectors `X_C Γ` (see [`VariableDerivatives::adjacent_modes`]),
//! not to the columns of `X`. For nearly repeated eigenvalues this treats
//! the cluster as degenerate: the result is the derivative of the smooth
//! branches with an error of the order of the relative gap (< `cluster_tol`),
//! instead of Nelson's exact but ill-conditioned derivative of the sorted
//! modes (which blows up as 1/gap when two modes cross).
//!
//! # Threshold
//! `cluster_tol` default 1e-6: above it Nelson is exact and its
//! conditioning (~1/gap) costs at most ~6 digits; below it the adjacent
//! method's O(gap) error is below 1e-6 relative.

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::sparse::SparseColMat;
use faer::{Mat, MatRef};
use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::blocks::Blocks;
use super::mass::subtract_mass_term;
pub use super::mass::MassDerivative;
use super::modes::{sign_normalize, Modes};
use super::sparse::{gmres_refine, spmv, sym_mul_block, Pencil, Refine};
use crate::error::{Error, Result};

/// Derivatives of the stiffness (and, for a ply thickness, of the lumped
/// mass) with respect to one design variable θ_v.
/// Both matrices are `n × n` in full symmetric storage on the reduced DOFs.
/// First derivatives of modes need only the diagonal second derivative
/// `∂²K/∂θ_v²`; the mixed `∂²K/∂θ_v∂θ_w` are not used.
#[derive(Clone, Copy, Debug)]
pub struct DesignDerivative<'a> {
    /// `∂K/∂θ_v` [N/m per rad].
    pub dk: &'a SparseColMat<usize, f64>,
    /// `∂²K/∂θ_v²`; needed only for the eigenvector derivatives of repeated
    /// clusters (adjacent-eigenvector method).
    pub d2k: Option<&'a SparseColMat<usize, f64>>,
    /// `∂M/∂θ_v` (and `∂²M/∂θ_v²`) of the lumped mass; `None` when the
    /// mass does not depend on the variable (ply angles).
    pub mass: Option<MassDerivative<'a>>,
}

/// Which approach of §3.1 (Haftka and Gürdal) is used; written `fixed` or
/// `updated` in study files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModeUpdate {
    /// Fixed-mode approach (Eq. 19): eigenvectors kept, only `λ'`.
    Fixed,
    /// Updated-mode approach (Eq. 18): `λ'` and `X'`.
    Updated,
}

impl ModeUpdate {
    /// The name written in study files and reports.
    pub fn name(&self) -> &'static str {
        match self {
            ModeUpdate::Fixed => "fixed",
            ModeUpdate::Updated => "updated",
        }
    }
}

/// Options of [`super::ModalSolver::derivatives`].
#[derive(Clone, Debug)]
pub struct DerivativeOptions {
    /// Fixed or updated modes. Default [`ModeUpdate::Updated`].
    pub update: ModeUpdate,
    /// Relative eigenvalue gap below which modes form a cluster. Default
    /// 1e-6 (see the module doc).
    pub cluster_tol: f64,
}

impl Default for DerivativeOptions {
    fn default() -> Self {
        DerivativeOptions {
            update: ModeUpdate::Updated,
            cluster_tol: 1e-6,
        }
    }
}

/// A cluster of repeated or nearly repeated eigenvalues and the rotation to
/// its adjacent eigenvectors for one design variable.
#[derive(Clone, Debug)]
pub struct Cluster {
    /// Index of the first mode of the cluster.
    pub first: usize,
    /// Number of modes in the cluster (≥ 2).
    pub len: usize,
    /// `Γ` (`len × len`, orthogonal): adjacent vectors `Ψ = X[:, first..first+len] Γ`.
    pub rotation: Mat<f64>,
}

/// Derivatives with respect to one design variable.
#[derive(Clone, Debug)]
pub struct VariableDerivatives {
    /// `dλᵢ/dθ` [rad²/s² per rad], length `k`.
    pub dlambda: Vec<f64>,
    /// `dX/dθ`, `n × k`, updated-mode approach only.
    pub dmodes: Option<Mat<f64>>,
    /// Clusters of size ≥ 2 with their rotations (empty when all distinct).
    pub clusters: Vec<Cluster>,
}

impl VariableDerivatives {
    /// The modes these derivatives refer to: `X` with each cluster's
    /// columns replaced by its adjacent vectors `X_C Γ`.
    pub fn adjacent_modes(&self, modes: &Mat<f64>) -> Mat<f64> {
        let mut out = modes.clone();
        for c in &self.clusters {
            for j in 0..c.len {
                for i in 0..modes.nrows() {
                    let mut s = 0.0;
                    for l in 0..c.len {
                        s += modes[(i, c.first + l)] * c.rotation[(l, j)];
                    }
                    out[(i, c.first + j)] = s;
                }
            }
        }
        out
    }
}

/// Whether the modes hold a cluster of repeated or nearly repeated
/// eigenvalues (relative gap below `cluster_tol`, module doc): only then
/// do the updated-mode derivatives read the second derivatives `K''`
/// (and `M''`), so a caller may assemble them on demand.
pub fn has_repeated(modes: &Modes, cluster_tol: f64) -> bool {
    find_clusters(&modes.lambda, modes.shift, cluster_tol)
        .iter()
        .any(|&(_, r)| r > 1)
}

/// Group consecutive eigenvalues into clusters: `(first, len)`.
fn find_clusters(lambda: &[f64], shift: f64, tol: f64) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut first = 0;
    for i in 1..=lambda.len() {
        if i == lambda.len() || !close(lambda[i - 1], lambda[i], shift, tol) {
            out.push((first, i - first));
            first = i;
        }
    }
    out
}

fn close(a: f64, b: f64, shift: f64, tol: f64) -> bool {
    let scale = a.abs().max(b.abs()).max(shift.abs()).max(f64::MIN_POSITIVE);
    (b - a).abs() < tol * scale
}

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

fn check_matrix(key: String, a: &SparseColMat<usize, f64>, n: usize) -> Result<()> {
    if a.nrows() != n || a.ncols() != n {
        return Err(Error::input(
            key,
            format!("{} x {} matrix", a.nrows(), a.ncols()),
            format!("a {n} x {n} matrix on the reduced DOFs"),
        ));
    }
    Ok(())
}

/// Per-variable eigenvalue derivatives and cluster rotations.
struct VarSetup {
    /// `(K' − λ̄M')X`, `n × k` (λ̄ the mean eigenvalue of each column's
    /// cluster; `K'X` when `M' = 0`).
    kpx: Mat<f64>,
    /// Rotation per cluster (identity 1×1 for singletons).
    gamma: Vec<DMatrix<f64>>,
    dlambda: Vec<f64>,
}

fn setup_variable(
    modes: &Mat<f64>,
    (lambda, d): (&[f64], &DesignDerivative<'_>),
    clusters: &[(usize, usize)],
) -> VarSetup {
    let (n, k) = (modes.nrows(), modes.ncols());
    let mut kpx = Mat::<f64>::zeros(n, k);
    let dkr = d.dk.as_ref();
    sym_mul_block(
        |j| (dkr.row_idx_of_col_raw(j), dkr.val_of_col(j)),
        modes.as_ref(),
        kpx.as_mut(),
    );
    if let Some(m) = &d.mass {
        subtract_mass_term(&mut kpx, modes, (lambda, m.dm), clusters);
    }
    let mut dlambda = vec![0.0; k];
    let mut gamma = Vec::with_capacity(clusters.len());
    for &(first, r) in clusters {
        let d = DMatrix::<f64>::from_fn(r, r, |a, b| {
            let mut s = 0.0;
            for i in 0..n {
                s += modes[(i, first + a)] * kpx[(i, first + b)];
            }
            s
        });
        if r == 1 {
            dlambda[first] = d[(0, 0)];
            gamma.push(DMatrix::identity(1, 1));
            continue;
        }
        let d = (&d + d.transpose()) * 0.5;
        let eig = SymmetricEigen::new(d);
        let mut order: Vec<usize> = (0..r).collect();
        order.sort_by(|&a, &b| {
            eig.eigenvalues[a]
                .total_cmp(&eig.eigenvalues[b])
                .then(a.cmp(&b))
        });
        let mut g = DMatrix::<f64>::from_fn(r, r, |a, b| eig.eigenvectors[(a, order[b])]);
        for (j, &o) in order.iter().enumerate() {
            dlambda[first + j] = eig.eigenvalues[o];
            // Sign convention on the adjacent vector ψⱼ = X_C γⱼ.
            let mut psi: Vec<f64> = (0..n)
                .map(|i| (0..r).map(|l| modes[(i, first + l)] * g[(l, j)]).sum())
                .collect();
            let before = psi.iter().position(|v| *v != 0.0).map(|p| psi[p]);
            sign_normalize(&mut psi);
            let after = psi.iter().position(|v| *v != 0.0).map(|p| psi[p]);
            if before.zip(after).is_some_and(|(b, a)| b != a) {
                for l in 0..r {
                    g[(l, j)] = -g[(l, j)];
                }
            }
        }
        gamma.push(g);
    }
    VarSetup {
        kpx,
        gamma,
        dlambda,
    }
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
    factor: &mut super::sparse::Factor<'_>,
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

/// Everything about one cluster that does not depend on the variable.
struct ClusterSystem<'p> {
    pencil: &'p Pencil,
    first: usize,
    r: usize,
    lambda_bar: f64,
    rows: Vec<usize>,
    /// `X_C` and `M X_C`, `n × r`.
    xc: Mat<f64>,
    mx: Mat<f64>,
    /// `A_NN⁻¹ (M X_C)_N` and `A_NN⁻¹ A_NR`, `n × r` each (zero on R).
    y1: Mat<f64>,
    y2: Mat<f64>,
    /// LU of the `2r × 2r` Schur complement.
    schur: nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    factor: super::sparse::Factor<'p>,
}

impl<'p> ClusterSystem<'p> {
    /// `lambda`: the cluster's eigenvalues (its first mode is `first`);
    /// `xc`: its eigenvectors on the pencil's DOFs (`n × r`); `spare`: the
    /// factorization of a previous cluster on this pencil, whose buffers are
    /// reused.
    fn new(
        pencil: &'p Pencil,
        (first, lambda): (usize, &[f64]),
        xc: Mat<f64>,
        spare: Option<super::sparse::Factor<'p>>,
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
    fn solve(&mut self, f: &Mat<f64>) -> Result<Mat<f64>> {
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

/// The pencil a cluster's derivative systems are solved on: the full one,
/// or the block of [`Blocks`] that holds the cluster's eigenvectors.
struct Restriction<'a> {
    pencil: &'a Pencil,
    /// The block's DOFs (`None`: all).
    dofs: Option<&'a [usize]>,
}

impl Restriction<'_> {
    /// Rows of `m` (`n × q`) on this pencil's DOFs.
    fn gather(&self, m: MatRef<'_, f64>, cols: std::ops::Range<usize>) -> Mat<f64> {
        match self.dofs {
            None => m.subcols(cols.start, cols.len()).to_owned(),
            Some(d) => Mat::from_fn(d.len(), cols.len(), |i, j| m[(d[i], cols.start + j)]),
        }
    }

    /// `v` (on this pencil's DOFs) on all `n` DOFs, zero off the block.
    fn scatter(&self, v: Mat<f64>, n: usize) -> Mat<f64> {
        match self.dofs {
            None => v,
            Some(d) => {
                let mut out = Mat::<f64>::zeros(n, v.ncols());
                for j in 0..v.ncols() {
                    for (i, &di) in d.iter().enumerate() {
                        out[(di, j)] = v[(i, j)];
                    }
                }
                out
            }
        }
    }
}

/// See the module doc; `blocks`: the independent blocks of the pencil for
/// this design, if it splits ([`super::blocks`]).
pub(crate) fn compute(
    pencil: &Pencil,
    blocks: Option<&Blocks>,
    modes: &Modes,
    vars: &[DesignDerivative<'_>],
    opts: &DerivativeOptions,
) -> Result<Vec<VariableDerivatives>> {
    let n = pencil.n();
    let k = modes.lambda.len();
    if modes.modes.nrows() != n || modes.modes.ncols() != k {
        return Err(Error::input(
            "modes",
            format!(
                "{} x {} mode matrix",
                modes.modes.nrows(),
                modes.modes.ncols()
            ),
            format!("{n} x {k} (modes of this solver)"),
        ));
    }
    crate::error::require_positive("cluster_tol", opts.cluster_tol)?;
    for (v, d) in vars.iter().enumerate() {
        check_matrix(format!("dk[{v}]"), d.dk, n)?;
        if let Some(d2) = d.d2k {
            check_matrix(format!("d2k[{v}]"), d2, n)?;
        }
        if let Some(m) = &d.mass {
            for (key, len) in [("dm", Some(m.dm.len())), ("d2m", m.d2m.map(<[f64]>::len))] {
                if let Some(len) = len.filter(|&l| l != n) {
                    return Err(Error::input(
                        format!("{key}[{v}]"),
                        format!("length {len}"),
                        format!("a diagonal of length {n} (the reduced DOFs)"),
                    ));
                }
            }
        }
    }
    let clusters = find_clusters(&modes.lambda, modes.shift, opts.cluster_tol);
    if let (Some(next), Some(&last)) = (modes.next_lambda, modes.lambda.last()) {
        if close(last, next, modes.shift, opts.cluster_tol) {
            return Err(Error::input(
                "n_modes",
                k,
                format!(
                    "a mode count that does not split a repeated eigenvalue: lambda[{}] = {last:e} \
                     and lambda[{k}] = {next:e} are closer than cluster_tol = {:e}",
                    k - 1,
                    opts.cluster_tol
                ),
            ));
        }
    }
    let setups: Vec<VarSetup> = vars
        .iter()
        .map(|d| setup_variable(&modes.modes, (&modes.lambda, d), &clusters))
        .collect();
    let mut out: Vec<VariableDerivatives> = setups
        .iter()
        .map(|s| VariableDerivatives {
            dlambda: s.dlambda.clone(),
            dmodes: None,
            clusters: clusters
                .iter()
                .zip(&s.gamma)
                .filter(|((_, r), _)| *r > 1)
                .map(|(&(first, len), g)| Cluster {
                    first,
                    len,
                    rotation: Mat::<f64>::from_fn(len, len, |i, j| g[(i, j)]),
                })
                .collect(),
        })
        .collect();
    if opts.update == ModeUpdate::Fixed || vars.is_empty() {
        return Ok(out);
    }
    for o in out.iter_mut() {
        o.dmodes = Some(Mat::<f64>::zeros(n, k));
    }
    let mass = pencil.mass();
    // Spare factorizations per pencil: the full one, then each block's.
    let n_parts = blocks.map_or(0, |b| b.parts.len());
    let mut spares: Vec<Option<super::sparse::Factor<'_>>> = (0..=n_parts).map(|_| None).collect();
    for (ci, &(first, r)) in clusters.iter().enumerate() {
        if r > 1 {
            if let Some(v) = vars
                .iter()
                .position(|d| d.mass.is_some_and(|m| m.d2m.is_none()))
            {
                return Err(Error::input(
                    format!("d2m[{v}]"),
                    "none",
                    format!(
                        "the second mass derivative: modes {first}..{} form a repeated \
                         cluster, whose eigenvector derivatives need M''",
                        first + r
                    ),
                ));
            }
            if let Some(v) = vars.iter().position(|d| d.d2k.is_none()) {
                return Err(Error::input(
                    format!("d2k[{v}]"),
                    "none",
                    format!(
                        "the second stiffness derivative: modes {first}..{} form a repeated \
                         cluster, whose eigenvector derivatives need K''",
                        first + r
                    ),
                ));
            }
        }
        let cluster_modes = modes.modes.as_ref().subcols(first, r);
        let (slot, on) = match blocks.and_then(|b| Some((b, b.holding(cluster_modes, mass)?))) {
            Some((b, p)) => (
                p + 1,
                Restriction {
                    pencil: &b.parts[p].pencil,
                    dofs: Some(&b.parts[p].dofs),
                },
            ),
            None => (0, Restriction { pencil, dofs: None }),
        };
        let mut sys = ClusterSystem::new(
            on.pencil,
            (first, &modes.lambda[first..first + r]),
            on.gather(modes.modes.as_ref(), first..first + r),
            spares[slot].take(),
        )?;
        // Right-hand sides −(K' − λⱼ'M) ψⱼ for every variable and cluster member.
        let nv = vars.len();
        let mut f = Mat::<f64>::zeros(n, nv * r);
        let mut psi_all: Vec<Mat<f64>> = Vec::with_capacity(nv);
        let mut kpsi_all: Vec<Mat<f64>> = Vec::with_capacity(nv);
        for (v, s) in setups.iter().enumerate() {
            let g = &s.gamma[ci];
            // Ψ = X_C Γ and K'Ψ; a distinct eigenvalue's Γ is the 1 × 1
            // identity, so its columns are copied (the same numbers).
            let (psi, kpsi) = if r == 1 {
                (
                    modes.modes.as_ref().subcols(first, 1).to_owned(),
                    s.kpx.as_ref().subcols(first, 1).to_owned(),
                )
            } else {
                (
                    Mat::<f64>::from_fn(n, r, |i, j| {
                        (0..r)
                            .map(|l| modes.modes[(i, first + l)] * g[(l, j)])
                            .sum()
                    }),
                    Mat::<f64>::from_fn(n, r, |i, j| {
                        (0..r).map(|l| s.kpx[(i, first + l)] * g[(l, j)]).sum()
                    }),
                )
            };
            for j in 0..r {
                let dl = s.dlambda[first + j];
                for i in 0..n {
                    f[(i, v * r + j)] = -(kpsi[(i, j)] - dl * mass[i] * psi[(i, j)]);
                }
            }
            psi_all.push(psi);
            kpsi_all.push(kpsi);
        }
        let vsol = on.scatter(sys.solve(&on.gather(f.as_ref(), 0..f.ncols()))?, n);
        for (v, d) in vars.iter().enumerate() {
            let psi = &psi_all[v];
            let kpsi = &kpsi_all[v];
            let dl = &setups[v].dlambda[first..first + r];
            // In-cluster coefficients (adjacent-eigenvector method).
            let mut c = DMatrix::<f64>::zeros(r, r);
            if r > 1 {
                let d2k = d.d2k.expect("checked above");
                let dscale = dl.iter().fold(0.0f64, |a, &x| a.max(x.abs()));
                let mut x = vec![0.0; n];
                let mut y = vec![0.0; n];
                for j in 0..r {
                    for (i, xi) in x.iter_mut().enumerate() {
                        *xi = psi[(i, j)];
                    }
                    spmv(d2k, &x, &mut y);
                    if let Some(m) = &d.mass {
                        // ψₗᵀ(K'' − 2λⱼ'M' − λ̄M'')ψⱼ (module doc).
                        let d2m = m.d2m.expect("checked above");
                        for i in 0..n {
                            y[i] -= (2.0 * dl[j] * m.dm[i] + sys.lambda_bar * d2m[i]) * x[i];
                        }
                    }
                    for l in 0..r {
                        if l == j {
                            continue;
                        }
                        let gap = dl[j] - dl[l];
                        if gap.abs() <= 1e-10 * dscale.max(f64::MIN_POSITIVE) {
                            continue;
                        }
                        let mut t1 = 0.0;
                        let mut t2 = 0.0;
                        for i in 0..n {
                            t1 += kpsi[(i, l)] * vsol[(i, v * r + j)];
                            t2 += psi[(i, l)] * y[i];
                        }
                        c[(j, l)] = (2.0 * t1 + t2) / (2.0 * gap);
                    }
                }
            }
            if let Some(m) = &d.mass {
                // Normalisation ψⱼᵀMψⱼ = 1: cⱼⱼ = −½ψⱼᵀM'ψⱼ (vⱼ is M-orthogonal
                // to the cluster).
                for j in 0..r {
                    c[(j, j)] = -0.5 * (0..n).map(|i| m.dm[i] * psi[(i, j)].powi(2)).sum::<f64>();
                }
            }
            let dm = out[v].dmodes.as_mut().expect("allocated above");
            for j in 0..r {
                for i in 0..n {
                    let mut s = vsol[(i, v * r + j)];
                    for l in 0..r {
                        s += c[(j, l)] * psi[(i, l)];
                    }
                    if !s.is_finite() {
                        return Err(Error::numerical(
                            "modal::derivatives",
                            format!(
                                "non-finite eigenvector derivative, mode {}, DOF {i}",
                                first + j
                            ),
                        ));
                    }
                    dm[(i, first + j)] = s;
                }
            }
        }
        spares[slot] = Some(sys.factor);
    }
    Ok(out)
}
