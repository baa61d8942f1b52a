//! Lowest vibration modes of a panel and their derivatives with respect to
//! the design variables (paper §2.1 Eqs. 5–6, §3.1 Eqs. 17–19).
//!
//! # What it solves
//! `K x = λ M x` with `K` the reduced (supports applied) sparse stiffness in
//! full symmetric storage (`n × n`, N/m, N·m/rad) and `M` the lumped diagonal
//! mass (length `n`, kg, kg·m²). The `k` lowest pairs are returned with
//! `λ = ω²` [rad²/s²] ascending and modes `X` (`n × k`) mass-normalised,
//! `XᵀMX = I`, `XᵀKX = Λ` (the Λ of Eq. 6).
//!
//! # Method and why
//! Block shift-invert Lanczos (module `lanczos`) on one sparse Cholesky
//! factorization of `K − σM` (faer, AMD ordering):
//! - shift-invert turns the lowest eigenvalues into the dominant ones, so a
//!   basis of about `2k` vectors converges them to 1e-10 in a handful of
//!   block steps, i.e. ~2k triangular solves on one factorization;
//! - full M-reorthogonalisation (a local then a full classical
//!   Gram–Schmidt pass) keeps the basis orthonormal to
//!   rounding, so there are no spurious copies and the Ritz vectors are
//!   M-orthonormal to machine precision; with `k ≲ 30` the `O(n m²)` cost of
//!   reorthogonalisation is below that of the solves;
//! - a block (default 3) finds repeated eigenvalues, which single-vector
//!   Lanczos cannot (symmetric panels have them);
//! - subspace iteration was rejected: it needs many more solves for the same
//!   accuracy (convergence rate λᵢ/λ_{q+1} per sweep).
//!
//! The shift σ (default 0) must lie below the lowest eigenvalue: the
//! Cholesky factorization then succeeds, and if it fails the error names σ
//! and the pivot. For free-free structures (rigid-body modes, λ = 0) give a
//! negative shift of the order of the first elastic eigenvalue.
//!
//! Determinism: no random numbers; a fixed start block, sequential kernels,
//! and a fixed sign convention (see [`sign_normalize`]): two runs give the same
//! bits.
//!
//! # Derivatives
//! [`ModalSolver::derivatives`]: `λ' = xᵀK'x` (M' = 0, the lumped mass does
//! not depend on ply angles, §3.2) for every mode, and in the updated-mode
//! approach (Eq. 18) also `X'`, by Nelson's method for distinct eigenvalues
//! and the adjacent-eigenvector method (Ojalvo 1987, Dailey 1989) for
//! repeated or nearly repeated ones; see [`derivatives`] for the formulas,
//! the cluster threshold and what the caller gets for a cluster. The
//! fixed-mode approach (Eq. 19) returns only `λ'`.
//!
//! # Cost (measured, `examples/modal_bench.rs`, `results/modal_bench/`)
//! One symbolic analysis (AMD + elimination tree) per stiffness pattern,
//! reused by every numeric factorization ([`ModalSolver::set_stiffness`]
//! keeps it across designs). Then
//! - modes: one numeric Cholesky + ~6 triangular solves per wanted mode
//!   (block Lanczos, 14 modes: 90 solves, one thick restart, on a clustered
//!   2-D Laplacian spectrum) + `O(n m²)` orthogonalisation, `m ≈ 3k`;
//! - `λ'`: `k` sparse products per variable (negligible);
//! - `X'`: one numeric `LDLᵀ` per distinct eigenvalue or cluster (shared by
//!   all variables) + `2r + r·n_vars` solves. These `k` factorizations
//!   dominate the updated-mode cost; the fixed-mode approach avoids them.
//!
//! On a shared 2-core x86_64 VM (one core; fastest wall time of 7 runs,
//! which agreed with the CPU time), 10,000-DOF 5-point Laplacian
//! (nnz(L) = 2.1e5): symbolic 4.7 ms, 14 modes 47 ms (numeric Cholesky
//! 6.4 ms, 90 solves at ≈ 0.3 ms per column, orthogonalisation and
//! Rayleigh–Ritz the rest), `λ'` for 2 variables < 4 ms, `λ'` + `X'` for 2
//! variables 113 ms (14 `LDLᵀ` at ≈ 7 ms). A 10,092-DOF 3-DOF/node 9-point
//! block grid (nnz(L) = 9.0e5, closer to a shell): symbolic 9.4 ms,
//! 14 modes 91 ms, `λ'` + `X'` 199 ms. The targets of issue 2 (20 ms and
//! 100 ms on the paper panel) are not reached on these matrices: the
//! Lanczos solves (≈ 6 per wanted mode at tol 1e-10 on a clustered
//! spectrum) and the `k` numeric `LDLᵀ` of the updated-mode derivatives
//! dominate. Cheaper options, not implemented: `tol = 1e-8` (78 instead of
//! 90 solves), block size 1 (58 solves, but multiple eigenvalues are then
//! found only through rounding), and Nelson solves by deflated
//! preconditioned CG on the shift-invert factor instead of `k`
//! factorizations.
//!
//! Issue 2 (SAR panel 3, 4152 DOFs at 32 divisions, nnz(L) = 2.8e5, same
//! VM, `studies/panel_convergence.toml`): K assembly + 14 modes ≈ 20 ms and
//! K, K', K'' + 14 modes + `λ'`, `X'` for 2 variables ≈ 96 ms (before the
//! pre-permuted factor, block gather products, block first GMRES step,
//! buffer reuse and later Rayleigh–Ritz checks: 24 and 118 ms). The 14
//! numeric `LDLᵀ` (≈ 3.7 ms each) remain ~55 % of the derivative cost.
//!
//! # Principal types
//! [`ModalSolver`] (pattern, symbolic factorization, reused across designs),
//! [`ModalOptions`], [`Modes`], [`DesignDerivative`], [`DerivativeOptions`],
//! [`VariableDerivatives`], [`ModeShapeRow`] / [`mode_shape_rows`].

pub mod derivatives;
mod export;
mod lanczos;
mod sparse;

pub use derivatives::{
    Cluster, DerivativeOptions, DesignDerivative, ModeUpdate, VariableDerivatives,
};
pub use export::{mode_shape_rows, write_mode_shapes_csv, DofLabel, ModeShapeRow};

use faer::sparse::SparseColMat;
use faer::Mat;

use crate::error::{Error, Result};
use sparse::Pencil;

/// Options of the eigen-solver. Defaults are what the SAR panels need.
#[derive(Clone, Debug)]
pub struct ModalOptions {
    /// Number of lowest modes wanted, `1 ≤ k ≤ n`.
    pub n_modes: usize,
    /// Shift σ [rad²/s²], below the lowest eigenvalue. Default 0 (reduced,
    /// supported models are positive definite); negative for free-free.
    pub shift: f64,
    /// Lanczos block size. Default 3: the largest multiplicity expected in
    /// a symmetric panel model.
    pub block_size: usize,
    /// Convergence tolerance on the relative Ritz residual
    /// `‖Op x − θ x‖_M / θ` of the shift-inverted operator. Default 1e-10:
    /// eigenvectors then carry ~1e-10 relative error (well separated modes),
    /// far below what a finite-difference check of derivatives can see.
    pub tol: f64,
    /// Largest basis dimension before a thick restart. Default
    /// `3(k+1) + 4·block + 8` (the basis is `n × m` doubles; clustered
    /// spectra such as a square plate's need ~3k to avoid restarts).
    pub max_basis: Option<usize>,
    /// Restarts before giving up with a numerical error. Default 50.
    pub max_restarts: usize,
}

impl ModalOptions {
    /// Defaults for `n_modes` modes.
    pub fn new(n_modes: usize) -> Self {
        ModalOptions {
            n_modes,
            shift: 0.0,
            block_size: 3,
            tol: 1e-10,
            max_basis: None,
            max_restarts: 50,
        }
    }
}

/// Solver statistics, for reports and efficiency regressions.
#[derive(Clone, Debug, Default)]
pub struct ModalStats {
    /// Triangular solves (right-hand-side columns) with `K − σM`.
    pub solves: usize,
    /// Thick restarts of the Lanczos basis.
    pub restarts: usize,
    /// Largest Lanczos basis dimension.
    pub basis: usize,
    /// Stored entries of the Cholesky factor.
    pub factor_nnz: usize,
    /// Wall time of the numeric Cholesky factorization of `K − σM` \[s\].
    pub factor_seconds: f64,
    /// Wall time of the Lanczos iteration (solves, orthogonalisation,
    /// Rayleigh–Ritz) \[s\].
    pub lanczos_seconds: f64,
}

/// The lowest modes.
#[derive(Clone, Debug)]
pub struct Modes {
    /// Eigenvalues `λ = ω²` [rad²/s²], ascending, length `k`.
    pub lambda: Vec<f64>,
    /// Mode shapes, `n × k`, `XᵀMX = I`, sign convention of [`sign_normalize`].
    pub modes: Mat<f64>,
    /// Scaled residuals `‖Kx − λMx‖₂ / (max(|λ|, |σ|) ‖Mx‖₂)` per mode.
    pub residuals: Vec<f64>,
    /// The next eigenvalue `λ_{k+1}` (converged), when `k < n`; used to
    /// refuse a mode count that splits a repeated cluster.
    pub next_lambda: Option<f64>,
    /// The shift used.
    pub shift: f64,
    /// Solver statistics.
    pub stats: ModalStats,
}

impl Modes {
    /// Natural frequencies `ω/(2π)` \[Hz\] (negative λ from rounding → 0).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.lambda
            .iter()
            .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }
}

/// Fixed sign convention: the first entry (lowest DOF index) whose magnitude
/// is at least half the largest magnitude is made positive. Using "first
/// entry above half the maximum" rather than "the maximum entry" keeps the
/// sign stable under small perturbations when two entries of equal size and
/// opposite sign compete (antisymmetric modes of symmetric structures).
pub fn sign_normalize(x: &mut [f64]) {
    let amax = x.iter().fold(0.0f64, |a, &v| a.max(v.abs()));
    if let Some(&v) = x.iter().find(|v| v.abs() >= 0.5 * amax) {
        if v < 0.0 {
            x.iter_mut().for_each(|e| *e = -*e);
        }
    }
}

/// Sparse modal analysis of one stiffness pattern: holds `K` ∪ diagonal, the
/// mass, and the symbolic Cholesky structure (AMD ordering), computed once
/// and reused by every numeric factorization (shift-invert and Nelson).
pub struct ModalSolver {
    pencil: Pencil,
}

impl ModalSolver {
    /// `k`: reduced stiffness, `n × n`, full symmetric storage; `mass`:
    /// lumped diagonal mass, length `n`, every entry finite and > 0.
    pub fn new(k: &SparseColMat<usize, f64>, mass: &[f64]) -> Result<Self> {
        Ok(ModalSolver {
            pencil: Pencil::new(k, mass)?,
        })
    }

    /// Number of free DOFs `n`.
    pub fn n_dofs(&self) -> usize {
        self.pencil.n()
    }

    /// Replace the stiffness by one with the same sparsity pattern (a new
    /// design); the symbolic factorization is kept. A different pattern
    /// rebuilds it.
    pub fn set_stiffness(&mut self, k: &SparseColMat<usize, f64>) -> Result<()> {
        self.pencil.set_stiffness(k)
    }

    /// The `opts.n_modes` lowest modes. Errors: `n_modes` = 0 or > n →
    /// [`Error::Input`]; `K − σM` not positive definite, or no convergence →
    /// [`Error::Numerical`].
    pub fn solve(&self, opts: &ModalOptions) -> Result<Modes> {
        let n = self.pencil.n();
        let k = opts.n_modes;
        if k == 0 || k > n {
            return Err(Error::input(
                "n_modes",
                k,
                format!("between 1 and the number of free DOFs ({n})"),
            ));
        }
        crate::error::require_finite("shift", opts.shift)?;
        crate::error::require_positive("tol", opts.tol)?;
        if opts.block_size == 0 {
            return Err(Error::input("block_size", 0, "at least 1"));
        }
        let t0 = std::time::Instant::now();
        let mut factor = self.pencil.factor_llt(opts.shift)?;
        let t1 = std::time::Instant::now();
        let want = (k + 1).min(n);
        let out = lanczos::block_lanczos(&self.pencil, &mut factor, opts, want)?;
        let (factor_seconds, lanczos_seconds) =
            ((t1 - t0).as_secs_f64(), t1.elapsed().as_secs_f64());
        let next_lambda = if want > k { Some(out.lambda[k]) } else { None };
        let mut modes = Mat::<f64>::zeros(n, k);
        let mut x = vec![0.0; n];
        for j in 0..k {
            for (i, xi) in x.iter_mut().enumerate() {
                *xi = out.vectors[(i, j)];
            }
            sign_normalize(&mut x);
            for (i, &xi) in x.iter().enumerate() {
                modes[(i, j)] = xi;
            }
        }
        // Residuals of all modes with one pass over K per 4 columns.
        let mut kx = Mat::<f64>::zeros(n, k);
        self.pencil.k_mul_block(modes.as_ref(), kx.as_mut());
        let mut lambda = Vec::with_capacity(k);
        let mut residuals = Vec::with_capacity(k);
        let mass = self.pencil.mass();
        for j in 0..k {
            let lam = out.lambda[j];
            let (mut r2, mut m2) = (0.0, 0.0);
            for i in 0..n {
                let mx = mass[i] * modes[(i, j)];
                r2 += (kx[(i, j)] - lam * mx).powi(2);
                m2 += mx * mx;
            }
            let scale = lam.abs().max(opts.shift.abs()).max(f64::MIN_POSITIVE);
            let res = r2.sqrt() / (scale * m2.sqrt());
            if !res.is_finite() || !lam.is_finite() {
                return Err(Error::numerical(
                    "modal::solve",
                    format!("mode {j}: lambda = {lam:e}, residual = {res:e}"),
                ));
            }
            lambda.push(lam);
            residuals.push(res);
        }
        Ok(Modes {
            lambda,
            modes,
            residuals,
            next_lambda,
            shift: opts.shift,
            stats: ModalStats {
                solves: out.solves,
                restarts: out.restarts,
                basis: out.basis,
                factor_nnz: self.pencil.factor_nnz(),
                factor_seconds,
                lanczos_seconds,
            },
        })
    }

    /// Eigenvalue (and, in the updated-mode approach, eigenvector)
    /// derivatives of `modes` for each design variable; see [`derivatives`].
    pub fn derivatives(
        &self,
        modes: &Modes,
        vars: &[DesignDerivative<'_>],
        opts: &DerivativeOptions,
    ) -> Result<Vec<VariableDerivatives>> {
        derivatives::compute(&self.pencil, modes, vars, opts)
    }
}
