//! [`ModalSolver`]: one stiffness pattern, factorizations reused across
//! designs, the lowest modes by block shift-invert Lanczos
//! ([`super::lanczos`]) and their design derivatives
//! ([`super::derivatives`]).

use super::blocks::{Blocks, ShiftInvert};
use super::derivatives::{
    self, DerivativeOptions, DesignDerivative, ModeUpdate, VariableDerivatives,
};
use super::lanczos;
use super::modes::{sign_normalize, ModalOptions, ModalStats, Modes};
use super::sparse::Pencil;
use crate::error::{Error, Result};
use faer::sparse::SparseColMat;
use faer::Mat;

/// Sparse modal analysis of one stiffness pattern: holds `K` ∪ diagonal, the
/// mass, and the symbolic Cholesky structure (AMD ordering), computed once
/// and reused by every numeric factorization (shift-invert and Nelson).
/// A new design gives its `K` ([`ModalSolver::set_stiffness`]) and, when
/// its ply thicknesses moved the mass, its `M` ([`ModalSolver::set_mass`]).
pub struct ModalSolver {
    pencil: Pencil,
    /// The independent blocks of `K` ([`super::blocks`]): the
    /// eigen-solver's shift-invert solves ([`ShiftInvert`]) and the
    /// derivative systems go block by block.
    blocks: Option<Blocks>,
    /// `K` or `M` changed since the blocks were found.
    stale: bool,
}

impl ModalSolver {
    /// `k`: reduced stiffness, `n × n`, full symmetric storage; `mass`:
    /// lumped diagonal mass, length `n`, every entry finite and > 0.
    pub fn new(k: &SparseColMat<usize, f64>, mass: &[f64]) -> Result<Self> {
        Ok(ModalSolver {
            pencil: Pencil::new(k, mass)?,
            blocks: None,
            stale: true,
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
        if self.pencil.set_stiffness(k)? {
            // The blocks map entries of the old pattern.
            self.blocks = None;
        }
        self.stale = true;
        Ok(())
    }

    /// Replace the lumped mass (length `n`, every entry finite and > 0):
    /// a new design whose ply thicknesses moved it. `M` is diagonal, so
    /// the pattern and the symbolic factorization are kept; the blocks
    /// take it at their next refresh. Errors: as [`ModalSolver::new`]'s
    /// `mass`; on error the solver is unchanged.
    pub fn set_mass(&mut self, mass: &[f64]) -> Result<()> {
        self.pencil.set_mass(mass)?;
        self.stale = true;
        Ok(())
    }

    /// The blocks of the current `K` and `M`, found again only after a
    /// change.
    fn fresh_blocks(&mut self) -> Result<()> {
        if self.stale {
            Blocks::refresh(&mut self.blocks, &self.pencil)?;
            self.stale = false;
        }
        Ok(())
    }

    /// The lumped mass the modes are computed with (length `n`).
    pub fn mass(&self) -> &[f64] {
        self.pencil.mass()
    }

    /// The `opts.n_modes` lowest modes. Errors: `n_modes` = 0 or > n →
    /// [`Error::Input`]; `K − σM` not positive definite, or no convergence →
    /// [`Error::Numerical`].
    pub fn solve(&mut self, opts: &ModalOptions) -> Result<Modes> {
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
        self.fresh_blocks()?;
        let mut factor = ShiftInvert::new(&self.pencil, self.blocks.as_ref(), opts.shift)?;
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
                factor_nnz: self.blocks.as_ref().map_or(self.pencil.factor_nnz(), |b| {
                    b.parts.iter().map(|p| p.pencil.factor_nnz()).sum()
                }),
                factor_seconds,
                lanczos_seconds,
            },
        })
    }

    /// Static solve `K U = B` in place for the `n × r` block `rhs` with the
    /// current stiffness (loads in, displacements out).
    ///
    /// `rigid` empty: `K` must be positive definite (a supported
    /// structure); one `LLᵀ` of `K`. Otherwise `rigid` holds the
    /// M-orthonormal rigid-body modes `R` of a free structure and the
    /// solve is by *inertia relief*: the loads are first made
    /// self-equilibrated, `B ← (I − M R Rᵀ) B` (the rigid-body
    /// acceleration they would cause is taken off), and `U` is the
    /// solution M-orthogonal to `R`, found by the fixed point
    /// `(K − σM) U_{m+1} = B + σ M U_m` (σ = `shift` < 0, `K − σM`
    /// positive definite), each iterate projected by `I − R RᵀM`. On the
    /// elastic modes the error contracts by `|σ|/(λ_j − σ)` per step.
    /// Returns the number of iterations (1 for a supported structure).
    /// Errors: a failed factorization or no convergence in 200 steps →
    /// [`Error::Numerical`].
    pub fn solve_static(
        &self,
        mut rhs: faer::MatMut<'_, f64>,
        rigid: &[Vec<f64>],
        shift: f64,
    ) -> Result<usize> {
        let (n, r) = (rhs.nrows(), rhs.ncols());
        if rigid.is_empty() {
            self.pencil.factor_llt(0.0)?.solve_in_place(rhs);
            return Ok(1);
        }
        let mass = self.pencil.mass();
        // x ← x − R (Rᵀ M x) (displacements) or b ← b − M R (Rᵀ b) (loads).
        let project = |m: &mut faer::MatMut<'_, f64>, loads: bool| {
            for c in 0..m.ncols() {
                for q in rigid {
                    let a: f64 = if loads {
                        (0..n).map(|i| q[i] * m[(i, c)]).sum()
                    } else {
                        (0..n).map(|i| q[i] * mass[i] * m[(i, c)]).sum()
                    };
                    for i in 0..n {
                        m[(i, c)] -= a * if loads { mass[i] * q[i] } else { q[i] };
                    }
                }
            }
        };
        project(&mut rhs, true);
        let b = rhs.to_owned();
        let mut factor = self.pencil.factor_llt(shift)?;
        let mut u = Mat::<f64>::zeros(n, r);
        let mut last = f64::INFINITY;
        for it in 1..=200 {
            let mut next =
                Mat::<f64>::from_fn(n, r, |i, c| b[(i, c)] + shift * mass[i] * u[(i, c)]);
            factor.solve_in_place(next.as_mut());
            project(&mut next.as_mut(), false);
            let (mut change, mut size) = (0.0f64, 0.0f64);
            for c in 0..r {
                for i in 0..n {
                    change = change.max((next[(i, c)] - u[(i, c)]).abs());
                    size = size.max(next[(i, c)].abs());
                }
            }
            u = next;
            if !(change.is_finite() && size.is_finite()) {
                break;
            }
            // Converged, or stalled at the rounding floor of the solves.
            if change <= 1e-13 * size || size == 0.0 || (change >= last && change <= 1e-10 * size) {
                rhs.copy_from(&u);
                return Ok(it);
            }
            last = change;
        }
        Err(Error::numerical(
            "modal::solve_static",
            format!(
                "inertia-relief iteration with shift {shift:e} did not converge in 200 steps \
                 (a free structure with a rigid motion not among the {} given, or an \
                 eigenvalue near the shift)",
                rigid.len()
            ),
        ))
    }

    /// Eigenvalue (and, in the updated-mode approach, eigenvector)
    /// derivatives of `modes` for each design variable; see [`derivatives`].
    /// Where `K` splits into independent blocks (e.g. the membrane and
    /// bending DOFs of a symmetric laminate's flat shell), each mode's
    /// systems are solved on its block and on the blocks the `K'ᵥ` couple
    /// to it.
    pub fn derivatives(
        &mut self,
        modes: &Modes,
        vars: &[DesignDerivative<'_>],
        opts: &DerivativeOptions,
    ) -> Result<Vec<VariableDerivatives>> {
        let blocks = if opts.update == ModeUpdate::Updated {
            self.fresh_blocks()?;
            let dk: Vec<_> = vars.iter().map(|d| d.dk).collect();
            if let Some(b) = self.blocks.as_mut() {
                b.couple(&dk);
            }
            self.blocks.as_ref()
        } else {
            None
        };
        derivatives::compute(&self.pencil, blocks, modes, vars, opts)
    }
}
