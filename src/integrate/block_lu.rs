//! The Newton matrix of the fused form with an implicit method: `B` equal
//! diagonal blocks, one LU.
//!
//! In the fused form the state is `z = [y; s_1; ..; s_np]` and
//! `ż = [f; J s_1 + ∂f/∂p_1; ..]`. Its exact Jacobian is block lower
//! triangular, with `J` in every diagonal block and the second-order terms
//! `∂(J s_i)/∂y` below. The implicit methods are given the block-diagonal
//! part `Ĵ = diag(J, .., J)` instead (the "simultaneous corrector" of
//! Maly & Petzold 1996, as in CVODES): their Newton matrix `I − cĴ` is then
//! `B = 1 + np` copies of the states' own `I − cJ`, which this solver
//! factors once (`n × n`, the same full-pivoting LU as diffsol's dense
//! solver) and applies to each block of a right-hand side; no second
//! derivatives are formed. The omitted terms are `O(c)` and act through
//! the state's increment, so the lanes contract with the states; but the
//! lanes are not in the Newton convergence test (their tolerance is
//! infinite, to keep them out of the error test), so what is left of
//! their Newton error is not checked: on the flexible SAR at rtol 1e-6
//! the fused BDF gradient differs from the staggered one by 9e-5 relative,
//! both within 3e-4 of a tight reference (the fused one the closer).
//!
//! diffsol creates its linear solver by `Default`, so the block count comes
//! from [`with_blocks`], which sets it for the solvers created in its scope
//! on this thread.

use diffsol::{FaerMat, FaerVec, LaError, MatrixCommon, Vector};
use diffsol_la::{LinearOp, LinearSolver};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::full_pivoting::{factor, solve};
use faer::perm::Perm;
use faer::reborrow::Reborrow;
use faer::{Conj, Mat, Par};
use std::cell::Cell;

/// faer's full-pivoting LU solve (plain or transposed).
type SolveFn = fn(
    faer::MatRef<'_, f64>,
    faer::MatRef<'_, f64>,
    faer::perm::PermRef<'_, usize>,
    faer::perm::PermRef<'_, usize>,
    Conj,
    faer::MatMut<'_, f64>,
    Par,
    &mut MemStack,
);

thread_local! {
    /// Block count of the [`BlockLu`] solvers created now on this thread.
    static BLOCKS: Cell<usize> = const { Cell::new(1) };
}

/// Run `f` with every [`BlockLu`] it creates splitting its matrix into
/// `blocks` equal diagonal blocks.
pub(super) fn with_blocks<R>(blocks: usize, f: impl FnOnce() -> R) -> R {
    /// Restores the previous count when the scope ends, also by unwinding.
    struct Restore(usize);
    impl Drop for Restore {
        fn drop(&mut self) {
            BLOCKS.with(|b| b.set(self.0));
        }
    }
    let _restore = Restore(BLOCKS.with(|b| b.replace(blocks.max(1))));
    f()
}

/// LU of the first diagonal block of a matrix made of `blocks` equal
/// diagonal blocks (module doc).
pub(super) struct BlockLu {
    blocks: usize,
    matrix: Option<FaerMat<f64>>,
    lu: Option<(Mat<f64>, Perm<usize>, Perm<usize>)>,
}

impl Default for BlockLu {
    fn default() -> Self {
        BlockLu {
            blocks: BLOCKS.with(|b| b.get()),
            matrix: None,
            lu: None,
        }
    }
}

impl BlockLu {
    /// The size of each of `blocks` equal blocks of `len` rows.
    fn block_size(blocks: usize, len: usize) -> Result<usize, LaError> {
        if !len.is_multiple_of(blocks) {
            return Err(LaError::Other(format!(
                "fused Newton matrix: {len} rows do not split into {blocks} equal blocks"
            )));
        }
        Ok(len / blocks)
    }

    fn apply(&self, x: &mut FaerVec<f64>, transpose: bool) -> Result<(), LaError> {
        let n = Self::block_size(self.blocks, x.len())?;
        let (lu, row, col) = self
            .lu
            .as_ref()
            .ok_or_else(|| LaError::Other("fused Newton matrix: LU not set".into()))?;
        // The blocks side by side: one solve with `blocks` right-hand sides.
        let data = x.inner_mut().col_as_slice_mut(0);
        let rhs = faer::MatMut::from_column_major_slice_mut(data, n, self.blocks);
        let k = self.blocks;
        let (scratch, solve_fn): (_, SolveFn) = if transpose {
            (
                solve::solve_transpose_in_place_scratch::<usize, f64>(n, k, Par::Seq),
                solve::solve_transpose_in_place_with_conj::<usize, f64>,
            )
        } else {
            (
                solve::solve_in_place_scratch::<usize, f64>(n, k, Par::Seq),
                solve::solve_in_place_with_conj::<usize, f64>,
            )
        };
        let mut buf = MemBuffer::new(scratch);
        solve_fn(
            lu.rb(),
            lu.rb(),
            row.rb(),
            col.rb(),
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut buf),
        );
        Ok(())
    }
}

impl LinearSolver<FaerMat<f64>> for BlockLu {
    fn set_sparsity<
        C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerMat<f64>, C = diffsol::FaerContext>,
    >(
        &mut self,
        op: &C,
    ) {
        self.matrix = Some(<FaerMat<f64> as diffsol::Matrix>::new_from_sparsity(
            op.nrows(),
            op.ncols(),
            op.sparsity(),
            *op.context(),
        ));
        self.lu = None;
    }

    fn set_linearisation<
        C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerMat<f64>, C = diffsol::FaerContext>,
    >(
        &mut self,
        op: &C,
    ) {
        self.lu = None;
        let Some(matrix) = self.matrix.as_mut() else {
            return; // the solves report the missing LU
        };
        op.matrix_inplace(matrix);
        let Ok(n) = Self::block_size(self.blocks, matrix.nrows()) else {
            return; // the solves report the block mismatch
        };
        let mut lu = matrix.inner().subrows(0, n).subcols(0, n).to_owned();
        let (mut rf, mut rb, mut cf, mut cb) = (vec![0; n], vec![0; n], vec![0; n], vec![0; n]);
        factor::lu_in_place(
            lu.as_mut(),
            &mut rf,
            &mut rb,
            &mut cf,
            &mut cb,
            Par::Seq,
            MemStack::new(&mut MemBuffer::new(
                factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            )),
            Default::default(),
        );
        self.lu = Some((
            lu,
            Perm::new_checked(rf.into_boxed_slice(), rb.into_boxed_slice(), n),
            Perm::new_checked(cf.into_boxed_slice(), cb.into_boxed_slice(), n),
        ));
    }

    fn solve_in_place(&self, x: &mut FaerVec<f64>) -> Result<(), LaError> {
        self.apply(x, false)
    }

    fn solve_transpose_in_place(&self, x: &mut FaerVec<f64>) -> Result<(), LaError> {
        self.apply(x, true)
    }
}
