//! What the eigen-solver is asked and what it returns: [`ModalOptions`],
//! [`Modes`] (eigenvalues, mass-normalised eigenvectors, statistics) and
//! the sign convention of the eigenvectors.

use faer::Mat;

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
