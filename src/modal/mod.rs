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
//! # Cost (measured, `benches/modal_bench.rs`, `results/modal_bench/`)
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
//! 14 modes 91 ms, `λ'` + `X'` 199 ms. The targets of 20 ms and
//! 100 ms on the paper panel are not reached on these matrices: the
//! Lanczos solves (≈ 6 per wanted mode at tol 1e-10 on a clustered
//! spectrum) and the `k` numeric `LDLᵀ` of the updated-mode derivatives
//! dominate. Cheaper options, not implemented: `tol = 1e-8` (78 instead of
//! 90 solves), block size 1 (58 solves, but multiple eigenvalues are then
//! found only through rounding), and Nelson solves by deflated
//! preconditioned CG on the shift-invert factor instead of `k`
//! factorizations.
//!
//! On SAR panel 3 (4152 DOFs at 32 divisions, nnz(L) = 2.8e5, same
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

mod blocks;
pub mod derivatives;
mod export;
mod lanczos;
mod mass;
mod modes;
mod solver;
mod sparse;
#[cfg(test)]
mod tests;

pub use derivatives::{
    has_repeated, keep_whole_clusters, Cluster, DerivativeOptions, DesignDerivative,
    MassDerivative, ModeUpdate, VariableDerivatives,
};
pub use export::{mode_shape_rows, DofLabel, ModeShapeRow};
pub use modes::{sign_normalize, ModalOptions, ModalStats, Modes};
pub use solver::ModalSolver;
