//! Products with the pencil's matrices: `K x`, `K X`, `(K − s·M) X` with
//! fixed DOFs, and the general symmetric gather kernels.

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::reborrow::ReborrowMut;
use faer::sparse::SparseColMat;
use faer::{MatMut, MatRef};

use super::pencil::Pencil;

impl Pencil {
    /// `y = K x`. Full symmetric storage: column `j` is also row `j`, so
    /// each `yⱼ` is a gather (dot product) over column `j`, which has no
    /// store dependencies and vectorises better than the CSC scatter.
    pub(crate) fn k_mul(&self, x: &[f64], y: &mut [f64]) {
        for j in 0..self.n {
            let r = self.col_ptr[j]..self.col_ptr[j + 1];
            let mut s = 0.0;
            for (&i, &v) in self.row_idx[r.clone()].iter().zip(&self.k_val[r]) {
                s += v * x[i];
            }
            y[j] = s;
        }
    }

    /// `Y = K X` for a block of columns (`n × q`, column-major): the matrix
    /// is streamed once per group of up to 4 columns (gather form, as
    /// [`Self::k_mul`]; the same summation order per entry).
    pub(crate) fn k_mul_block(&self, x: MatRef<'_, f64>, y: MatMut<'_, f64>) {
        sym_mul_block(
            |j| {
                let r = self.col_ptr[j]..self.col_ptr[j + 1];
                (&self.row_idx[r.clone()], &self.k_val[r])
            },
            x,
            y,
        );
    }

    /// `Y = Â X` (`n × q`) with `Â = K − s·M` whose rows and columns listed
    /// in `fixed` are replaced by those of the identity (the matrix that
    /// [`Self::factor_ldlt`] factors).
    pub(crate) fn shifted_mul_block(
        &self,
        s: f64,
        fixed: &[usize],
        x: MatRef<'_, f64>,
        mut y: MatMut<'_, f64>,
    ) {
        self.k_mul_block(x, y.rb_mut());
        for c in 0..x.ncols() {
            for j in 0..self.n {
                y[(j, c)] -= s * self.mass[j] * x[(j, c)];
            }
            // Remove the couplings K[i, f] x[f] of the fixed DOFs, then put
            // the identity on their rows.
            for &f in fixed {
                let xf = x[(f, c)];
                let (ri, rv) = self.k_col(f);
                for (&i, &v) in ri.iter().zip(rv) {
                    y[(i, c)] -= v * xf;
                }
            }
            for &f in fixed {
                y[(f, c)] = x[(f, c)];
            }
        }
    }
}

/// Column `j` of a column-major matrix as a slice.
fn col_of(m: MatRef<'_, f64>, j: usize) -> &[f64] {
    m.col(j)
        .try_as_col_major()
        .expect("faer matrices are column-major")
        .as_slice()
}

/// `Y = A X` for a symmetric `A` in full storage given by its columns
/// (`col(j)` = rows and values of column `j`, which is also row `j`), `X`
/// `n × q`. Gather form, 4 columns of `X` per pass over `A`, row-interleaved
/// so that each stored entry reads one contiguous group of 4.
pub(crate) fn sym_mul_block<'m>(
    col: impl Fn(usize) -> (&'m [usize], &'m [f64]),
    x: MatRef<'_, f64>,
    mut y: MatMut<'_, f64>,
) {
    const W: usize = 4;
    let (n, q) = (x.nrows(), x.ncols());
    let mut xt = vec![0.0f64; n * W];
    let mut c0 = 0;
    while c0 < q {
        let w = (q - c0).min(W);
        for c in 0..W {
            if c < w {
                let xc = col_of(x, c0 + c);
                for i in 0..n {
                    xt[i * W + c] = xc[i];
                }
            } else {
                for i in 0..n {
                    xt[i * W + c] = 0.0;
                }
            }
        }
        for j in 0..n {
            let (rows, vals) = col(j);
            let mut acc = [0.0f64; W];
            for (&i, &v) in rows.iter().zip(vals) {
                let xr: &[f64; W] = xt[i * W..i * W + W].try_into().expect("W entries");
                for c in 0..W {
                    acc[c] += v * xr[c];
                }
            }
            for c in 0..w {
                y[(j, c0 + c)] = acc[c];
            }
        }
        c0 += w;
    }
}

/// `y = A x` for a sparse matrix in full symmetric storage.
pub(crate) fn spmv(a: &SparseColMat<usize, f64>, x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    let ar = a.as_ref();
    for (j, &xj) in x.iter().enumerate().take(a.ncols()) {
        for (&i, &v) in ar.row_idx_of_col_raw(j).iter().zip(ar.val_of_col(j)) {
            y[i] += v * xj;
        }
    }
}
