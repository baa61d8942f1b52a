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
use nalgebra::{DMatrix, SymmetricEigen};

use super::blocks::{Blocks, Part};
use super::mass::subtract_mass_term;
pub use super::mass::MassDerivative;
use super::modes::{sign_normalize, Modes};
use super::sparse::{spmv, sym_mul_block, Factor, Pencil};
use crate::error::{Error, Result};
use system::ClusterSystem;

mod system;

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

/// Keep clusters whole: when the first mode left out (`next_lambda`) and
/// the last one kept are one repeated eigenvalue (closer than
/// `cluster_tol`, as the derivatives group clusters), drop the kept
/// members of that cluster, so that the basis spans either the whole
/// eigenspace or none of it (a part of it would be an arbitrary choice of vectors within
/// it, and its derivatives do not exist). Returns the count before the
/// drop, or `None` when nothing was dropped: no split, or every mode kept
/// is in the split cluster (left to the mode-count check, which refuses
/// it).
pub fn keep_whole_clusters(modes: &mut Modes, cluster_tol: f64) -> Option<usize> {
    let k = modes.lambda.len();
    let next = modes.next_lambda?;
    let mut c = k;
    let mut above = next;
    while c > 0 && close(modes.lambda[c - 1], above, modes.shift, cluster_tol) {
        above = modes.lambda[c - 1];
        c -= 1;
    }
    if c == k || c == 0 {
        return None;
    }
    modes.next_lambda = Some(modes.lambda[c]);
    modes.lambda.truncate(c);
    modes.residuals.truncate(c);
    modes.modes = modes.modes.subcols(0, c).to_owned();
    Some(k)
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

impl VarSetup {
    /// The eigenvalue derivatives and the rotation of each cluster of
    /// size ≥ 2 (no mode derivatives yet).
    fn eigenvalues(&self, clusters: &[(usize, usize)]) -> VariableDerivatives {
        VariableDerivatives {
            dlambda: self.dlambda.clone(),
            dmodes: None,
            clusters: clusters
                .iter()
                .zip(&self.gamma)
                .filter(|((_, r), _)| *r > 1)
                .map(|(&(first, len), g)| Cluster {
                    first,
                    len,
                    rotation: Mat::<f64>::from_fn(len, len, |i, j| g[(i, j)]),
                })
                .collect(),
        }
    }
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

/// The pencil a cluster's derivative systems are solved on: the full one,
/// or the block of [`Blocks`] that holds the cluster's eigenvectors.
struct Restriction<'a> {
    pencil: &'a Pencil,
    /// The block's DOFs (`None`: all).
    dofs: Option<&'a [usize]>,
}

impl<'a> Restriction<'a> {
    /// The block of `blocks` that holds `cluster_modes`, else the full
    /// `pencil`; with the slot of its spare factorization (0: the full
    /// pencil, `p + 1`: block `p`).
    fn for_cluster(
        pencil: &'a Pencil,
        blocks: Option<&'a Blocks>,
        cluster_modes: MatRef<'_, f64>,
    ) -> (usize, Restriction<'a>) {
        let mass = pencil.mass();
        match blocks.and_then(|b| Some((b, b.holding(cluster_modes, mass)?))) {
            Some((b, p)) => (p + 1, Restriction::of_part(&b.parts[p])),
            None => (0, Restriction { pencil, dofs: None }),
        }
    }

    /// The restriction to one block of the pencil.
    fn of_part(part: &'a Part) -> Self {
        Restriction {
            pencil: &part.pencil,
            dofs: Some(&part.dofs),
        }
    }

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
            Some(_) => {
                let mut out = Mat::<f64>::zeros(n, v.ncols());
                self.scatter_into(&v, &mut out);
                out
            }
        }
    }

    /// Write `v` (on this pencil's DOFs) into the rows of `out` (all `n`
    /// DOFs) that this pencil covers.
    fn scatter_into(&self, v: &Mat<f64>, out: &mut Mat<f64>) {
        match self.dofs {
            None => out.copy_from(v),
            Some(d) => {
                for j in 0..v.ncols() {
                    for (i, &di) in d.iter().enumerate() {
                        out[(di, j)] = v[(i, j)];
                    }
                }
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
    check_inputs(n, modes, vars, opts)?;
    let clusters = find_clusters(&modes.lambda, modes.shift, opts.cluster_tol);
    check_mode_count(modes, opts.cluster_tol)?;
    let setups: Vec<VarSetup> = vars
        .iter()
        .map(|d| setup_variable(&modes.modes, (&modes.lambda, d), &clusters))
        .collect();
    let mut out: Vec<VariableDerivatives> =
        setups.iter().map(|s| s.eigenvalues(&clusters)).collect();
    if opts.update == ModeUpdate::Fixed || vars.is_empty() {
        return Ok(out);
    }
    for o in out.iter_mut() {
        o.dmodes = Some(Mat::<f64>::zeros(n, k));
    }
    // Spare factorizations per pencil: the full one, then each block's.
    let n_parts = blocks.map_or(0, |b| b.parts.len());
    let mut spares: Vec<Option<Factor<'_>>> = (0..=n_parts).map(|_| None).collect();
    for (ci, &(first, r)) in clusters.iter().enumerate() {
        if r > 1 {
            require_second_derivatives(vars, (first, r))?;
        }
        let cluster_modes = modes.modes.as_ref().subcols(first, r);
        let (slot, on) = Restriction::for_cluster(pencil, blocks, cluster_modes);
        let mut sys = ClusterSystem::new(
            on.pencil,
            (first, &modes.lambda[first..first + r]),
            on.gather(modes.modes.as_ref(), first..first + r),
            spares[slot].take(),
        )?;
        let adjacent: Vec<Adjacent> = setups
            .iter()
            .map(|s| Adjacent::new(&modes.modes, s, ci, (first, r)))
            .collect();
        let f = right_hand_sides(pencil.mass(), &setups, &adjacent, (first, r));
        let mut vsol = on.scatter(sys.solve(&on.gather(f.as_ref(), 0..f.ncols()))?, n);
        if let (Some(b), Some(p)) = (blocks, slot.checked_sub(1)) {
            // The blocks a K'ᵥ couples to the cluster's (module doc of
            // `blocks`): a plain solve, λ̄ being no eigenvalue there.
            let coupled = (b.parts.iter().enumerate()).filter(|&(q, _)| q != p && b.coupled(p, q));
            for (q, part) in coupled {
                let on_q = Restriction::of_part(part);
                let fq = on_q.gather(f.as_ref(), 0..f.ncols());
                let spare = spares[q + 1].take();
                let (vq, factor) = system::plain_solve(on_q.pencil, sys.lambda_bar, &fq, spare)?;
                on_q.scatter_into(&vq, &mut vsol);
                spares[q + 1] = Some(factor);
            }
        }
        for (v, d) in vars.iter().enumerate() {
            let adj = &adjacent[v];
            let sol = vsol.as_ref().subcols(v * r, r);
            let dl = &setups[v].dlambda[first..first + r];
            let c = coefficients(d, adj, sol, dl, sys.lambda_bar);
            let dm = out[v].dmodes.as_mut().expect("allocated above");
            write_mode_derivatives(dm, sol, &c, &adj.psi, first)?;
        }
        spares[slot] = Some(sys.factor);
    }
    Ok(out)
}

/// The shapes of the modes and of every variable's derivative matrices
/// against the pencil's `n` DOFs, and `cluster_tol > 0`.
fn check_inputs(
    n: usize,
    modes: &Modes,
    vars: &[DesignDerivative<'_>],
    opts: &DerivativeOptions,
) -> Result<()> {
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
    Ok(())
}

/// The mode count must not split a cluster: the first mode left out
/// (`next_lambda`) may not be close to the last one computed.
fn check_mode_count(modes: &Modes, cluster_tol: f64) -> Result<()> {
    let k = modes.lambda.len();
    if let (Some(next), Some(&last)) = (modes.next_lambda, modes.lambda.last()) {
        if close(last, next, modes.shift, cluster_tol) {
            return Err(Error::input(
                "n_modes",
                k,
                format!(
                    "a mode count that does not split a repeated eigenvalue: lambda[{}] = {last:e} \
                     and lambda[{k}] = {next:e} are closer than cluster_tol = {cluster_tol:e}",
                    k - 1,
                ),
            ));
        }
    }
    Ok(())
}

/// A repeated cluster (modes `first..first + r`) needs `K''` of every
/// variable and `M''` of every variable with a mass derivative.
fn require_second_derivatives(
    vars: &[DesignDerivative<'_>],
    (first, r): (usize, usize),
) -> Result<()> {
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
    Ok(())
}

/// One cluster's adjacent vectors for one variable.
struct Adjacent {
    /// `Ψ = X_C Γ`, `n × r`.
    psi: Mat<f64>,
    /// `(K' − λ̄M')Ψ`, `n × r`.
    kpsi: Mat<f64>,
}

impl Adjacent {
    /// The cluster `ci` (modes `first..first + r`) of `modes` rotated by
    /// the variable's `Γ`; a distinct eigenvalue's `Γ` is the 1 × 1
    /// identity, so its columns are copied (the same numbers).
    fn new(modes: &Mat<f64>, s: &VarSetup, ci: usize, (first, r): (usize, usize)) -> Adjacent {
        if r == 1 {
            return Adjacent {
                psi: modes.as_ref().subcols(first, 1).to_owned(),
                kpsi: s.kpx.as_ref().subcols(first, 1).to_owned(),
            };
        }
        let (n, g) = (modes.nrows(), &s.gamma[ci]);
        Adjacent {
            psi: Mat::<f64>::from_fn(n, r, |i, j| {
                (0..r).map(|l| modes[(i, first + l)] * g[(l, j)]).sum()
            }),
            kpsi: Mat::<f64>::from_fn(n, r, |i, j| {
                (0..r).map(|l| s.kpx[(i, first + l)] * g[(l, j)]).sum()
            }),
        }
    }
}

/// Right-hand sides `−(K' − λⱼ'M) ψⱼ` (with `K' − λ̄M'` for `K'`) of every
/// variable `v` and cluster member `j`, in column `v r + j` (`n × nv r`).
fn right_hand_sides(
    mass: &[f64],
    setups: &[VarSetup],
    adjacent: &[Adjacent],
    (first, r): (usize, usize),
) -> Mat<f64> {
    let n = mass.len();
    let mut f = Mat::<f64>::zeros(n, setups.len() * r);
    for (v, (s, a)) in setups.iter().zip(adjacent).enumerate() {
        for j in 0..r {
            let dl = s.dlambda[first + j];
            for i in 0..n {
                f[(i, v * r + j)] = -(a.kpsi[(i, j)] - dl * mass[i] * a.psi[(i, j)]);
            }
        }
    }
    f
}

/// The coefficients `cⱼₗ` (`r × r`) of `ψⱼ' = vⱼ + Σ_l cⱼₗ ψₗ` for one
/// variable (module doc): in a cluster the in-cluster ones of the
/// adjacent-eigenvector method (0 where `λⱼ' = λₗ'`), and with a mass
/// derivative the normalisation `cⱼⱼ`. `vsol`: the solutions `vⱼ`
/// (`n × r`); `dl`: the cluster's `λⱼ'`.
fn coefficients(
    d: &DesignDerivative<'_>,
    adj: &Adjacent,
    vsol: MatRef<'_, f64>,
    dl: &[f64],
    lambda_bar: f64,
) -> DMatrix<f64> {
    let (n, r) = (adj.psi.nrows(), adj.psi.ncols());
    let (psi, kpsi) = (&adj.psi, &adj.kpsi);
    let mut c = DMatrix::<f64>::zeros(r, r);
    if r > 1 {
        let d2k = d.d2k.expect("checked by require_second_derivatives");
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
                let d2m = m.d2m.expect("checked by require_second_derivatives");
                for i in 0..n {
                    y[i] -= (2.0 * dl[j] * m.dm[i] + lambda_bar * d2m[i]) * x[i];
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
                    t1 += kpsi[(i, l)] * vsol[(i, j)];
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
    c
}

/// `ψⱼ' = vⱼ + Σ_l cⱼₗ ψₗ` into the columns `first..first + r` of
/// `dmodes`; an error at a non-finite entry.
fn write_mode_derivatives(
    dmodes: &mut Mat<f64>,
    vsol: MatRef<'_, f64>,
    c: &DMatrix<f64>,
    psi: &Mat<f64>,
    first: usize,
) -> Result<()> {
    let (n, r) = (psi.nrows(), psi.ncols());
    for j in 0..r {
        for i in 0..n {
            let mut s = vsol[(i, j)];
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
            dmodes[(i, first + j)] = s;
        }
    }
    Ok(())
}
