//! Numeric factorizations of the pencil on its shared symbolic structure:
//! `LLᵀ` of `K − σM` (shift-invert) and `LDLᵀ` of `K − λM` with fixed DOFs
//! (Nelson systems), and their block solves.

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{LdltRef, LltRef, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, MatMut, Par, Side};

use super::pencil::Pencil;
use crate::error::{Error, Result};

#[cfg(doc)]
use super::pattern::Ordered;

/// Which triangular factorization a [`Factor`] holds.
enum Kind {
    /// `LLᵀ` of a positive definite matrix (the shift-invert operator).
    Llt,
    /// `LDLᵀ` without pivoting of an indefinite matrix (Nelson systems).
    Ldlt,
}

/// Maximum number of right-hand sides solved at once (scratch size).
pub(crate) const MAX_RHS: usize = 64;

/// A numeric factorization on the shared symbolic structure.
pub(crate) struct Factor<'a> {
    symbolic: &'a SymbolicCholesky<usize>,
    /// Fill-reducing permutation, elimination step → original DOF.
    perm: &'a [usize],
    values: Vec<f64>,
    kind: Kind,
    buf: MemBuffer,
    /// Permuted right-hand sides, `n ×` (widest chunk solved so far).
    tmp: Mat<f64>,
}

impl Factor<'_> {
    /// Solve `A X = B` in place for the `n × r` block `rhs` (any `r`;
    /// solved in chunks of [`MAX_RHS`] columns).
    pub(crate) fn solve_in_place(&mut self, mut rhs: MatMut<'_, f64>) {
        let r = rhs.ncols();
        let mut c = 0;
        while c < r {
            let w = (r - c).min(MAX_RHS);
            self.solve_chunk(rhs.rb_mut().subcols_mut(c, w));
            c += w;
        }
    }

    fn solve_chunk(&mut self, mut rhs: MatMut<'_, f64>) {
        let (n, w) = (rhs.nrows(), rhs.ncols());
        if self.tmp.nrows() != n || self.tmp.ncols() < w {
            self.tmp = Mat::zeros(n, w);
        }
        for c in 0..w {
            let src = rhs.rb().col(c);
            let mut dst = self.tmp.col_mut(c);
            for (e, &o) in self.perm.iter().enumerate() {
                dst[e] = src[o];
            }
        }
        let mut pr = self.tmp.as_mut().subcols_mut(0, w);
        let stack = MemStack::new(&mut self.buf);
        match self.kind {
            Kind::Llt => LltRef::new(self.symbolic, &self.values).solve_in_place_with_conj(
                Conj::No,
                pr.rb_mut(),
                Par::Seq,
                stack,
            ),
            Kind::Ldlt => LdltRef::new(self.symbolic, &self.values).solve_in_place_with_conj(
                Conj::No,
                pr.rb_mut(),
                Par::Seq,
                stack,
            ),
        }
        for c in 0..w {
            let src = self.tmp.col(c);
            let mut dst = rhs.rb_mut().col_mut(c);
            for (e, &o) in self.perm.iter().enumerate() {
                dst[o] = src[e];
            }
        }
    }
}

impl Pencil {
    /// Values of `K − s·M` on the permuted lower pattern ([`Ordered`]),
    /// with the rows and columns listed in `fixed` (original DOFs) replaced
    /// by those of the identity.
    fn shifted_values(&self, s: f64, fixed: &[usize]) -> Vec<f64> {
        let o = &self.ordered;
        let mut val = self.k_lower.clone();
        for jn in 0..self.n {
            // Rows are sorted and ≥ the column: the diagonal comes first.
            val[o.col_ptr[jn]] -= s * self.mass[o.fwd[jn]];
        }
        if !fixed.is_empty() {
            let mut is_fixed = vec![false; self.n];
            for &f in fixed {
                is_fixed[o.inv[f]] = true;
            }
            for jn in 0..self.n {
                for e in o.col_ptr[jn]..o.col_ptr[jn + 1] {
                    let i_n = o.row_idx[e];
                    if is_fixed[i_n] || is_fixed[jn] {
                        val[e] = if i_n == jn { 1.0 } else { 0.0 };
                    }
                }
            }
        }
        val
    }

    /// The permuted lower pattern as a faer symbolic matrix.
    fn ordered_sym(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.ordered.col_ptr,
            None,
            &self.ordered.row_idx,
        )
    }

    fn scratch(&self, llt: bool) -> MemBuffer {
        let fac = if llt {
            self.symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
        } else {
            self.symbolic
                .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
        };
        let solve = self
            .symbolic
            .solve_in_place_scratch::<f64>(MAX_RHS, Par::Seq);
        MemBuffer::new(fac.or(solve))
    }

    /// Cholesky `LLᵀ` of `K − σM`. Fails with [`Error::Numerical`] naming
    /// the shift and the pivot (original DOF index) when the matrix is not
    /// positive definite, i.e. when σ is not below the lowest eigenvalue.
    pub(crate) fn factor_llt(&self, sigma: f64) -> Result<Factor<'_>> {
        let a = self.shifted_values(sigma, &[]);
        let mut buf = self.scratch(true);
        let mut values = vec![0.0; self.symbolic.len_val()];
        let sym = self.ordered_sym();
        let res = self.symbolic.factorize_numeric_llt(
            &mut values,
            SparseColMatRef::new(sym, &a),
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut buf),
            Default::default(),
        );
        match res {
            Ok(_) => Ok(Factor {
                symbolic: &self.symbolic,
                perm: &self.ordered.fwd,
                values,
                tmp: Mat::zeros(0, 0),
                kind: Kind::Llt,
                buf,
            }),
            Err(LltError::NonPositivePivot { index }) => {
                let dof = self.original_dof(index);
                Err(Error::numerical(
                    "modal::shift_invert",
                    format!(
                        "Cholesky factorization of K - sigma*M failed: non-positive pivot at \
                         elimination step {index} (DOF {dof}) with shift sigma = {sigma:e} \
                         (|K|max = {:e}); the shift must lie below the lowest eigenvalue \
                         (use a negative shift for free-free structures)",
                        self.k_max
                    ),
                ))
            }
        }
    }

    /// `LDLᵀ` (no pivoting) of `K − λM` with the rows and columns `fixed`
    /// replaced by the identity (Nelson's trick keeps the pattern, so the
    /// symbolic structure is reused). `spare`: a previous `LDLᵀ` of this
    /// pencil whose buffers (factor values, scratch, permuted right-hand
    /// sides) are reused, avoiding fresh allocations and page faults per
    /// factorization (faer overwrites the values).
    pub(crate) fn factor_ldlt<'s>(
        &'s self,
        lambda: f64,
        fixed: &[usize],
        spare: Option<Factor<'s>>,
    ) -> Result<Factor<'s>> {
        let a = self.shifted_values(lambda, fixed);
        let (mut values, mut buf, tmp) = match spare {
            Some(f) if matches!(f.kind, Kind::Ldlt) => (f.values, f.buf, f.tmp),
            _ => (
                vec![0.0; self.symbolic.len_val()],
                self.scratch(false),
                Mat::zeros(0, 0),
            ),
        };
        let sym = self.ordered_sym();
        // Pivots below 1e-10·max|Aᵢᵢ| (zero pivots of the unpivoted LDLᵀ of
        // an indefinite matrix, e.g. a Sturm-sequence zero) are replaced by
        // ±1e-2·max|Aᵢᵢ|: a rank-one change per pivot, which the Krylov
        // refinement of `solve_refined` removes in one iteration each.
        let dmax = (0..self.n)
            .map(|jn| a[self.ordered.col_ptr[jn]].abs())
            .fold(0.0f64, f64::max)
            .max(f64::MIN_POSITIVE);
        let reg = LdltRegularization {
            dynamic_regularization_signs: None,
            dynamic_regularization_delta: 1e-2 * dmax,
            dynamic_regularization_epsilon: 1e-10 * dmax,
        };
        let res = self.symbolic.factorize_numeric_ldlt(
            &mut values,
            SparseColMatRef::new(sym, &a),
            Side::Lower,
            reg,
            Par::Seq,
            MemStack::new(&mut buf),
            Default::default(),
        );
        match res {
            Ok(_) => Ok(Factor {
                symbolic: &self.symbolic,
                perm: &self.ordered.fwd,
                values,
                tmp,
                kind: Kind::Ldlt,
                buf,
            }),
            Err(LdltError::ZeroPivot { index }) => Err(Error::numerical(
                "modal::derivatives",
                format!(
                    "LDLT factorization of K - lambda*M (lambda = {lambda:e}, fixed DOFs \
                     {fixed:?}) hit a zero pivot at elimination step {index} (DOF {})",
                    self.original_dof(index)
                ),
            )),
        }
    }
}
