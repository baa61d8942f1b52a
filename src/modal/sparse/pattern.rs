//! The stored patterns of the pencil: `K ∪ diag` with the values of `K`
//! ([`Pattern`]), its fill-reducing ordering and symbolic Cholesky structure
//! ([`Ordered`]), and the map from an input stiffness pattern onto it
//! ([`InputMap`]).

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, SymbolicSparseColMatRef};
use faer::Side;

use crate::error::{Error, Result};

#[cfg(doc)]
use super::Pencil;

/// The input stiffness pattern and where its entries go on the pattern of
/// `K ∪ diag`: lets [`Pencil::set_stiffness`] take a new design's values in
/// one pass (no sort, no binary search) when the input pattern is unchanged.
pub(super) struct InputMap {
    pub(super) col_ptr: Vec<usize>,
    pub(super) row_idx: Vec<usize>,
    /// Pattern position of each input entry (duplicates share one).
    pub(super) dest: Vec<usize>,
    /// For each pattern entry `(i, j)` with `i > j`: the position of
    /// `(j, i)`, or `usize::MAX` when absent.
    pub(super) transpose: Vec<usize>,
}

impl InputMap {
    /// No map: [`Pencil::set_stiffness`] takes the full path.
    pub(super) fn empty() -> Self {
        InputMap {
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            dest: Vec::new(),
            transpose: Vec::new(),
        }
    }

    pub(super) fn build(
        k: &SparseColMat<usize, f64>,
        col_ptr: &[usize],
        row_idx: &[usize],
    ) -> Option<Self> {
        let kr = k.as_ref();
        if kr.col_nnz().is_some() {
            return None;
        }
        let find = |j: usize, i: usize| {
            let r = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            r.binary_search(&i).ok().map(|q| col_ptr[j] + q)
        };
        let (in_ptr, in_idx) = (kr.col_ptr(), kr.row_idx());
        let mut dest = Vec::with_capacity(in_idx.len());
        for j in 0..kr.ncols() {
            for &i in &in_idx[in_ptr[j]..in_ptr[j + 1]] {
                dest.push(find(j, i)?);
            }
        }
        let mut transpose = vec![usize::MAX; row_idx.len()];
        for j in 0..kr.ncols() {
            for q in col_ptr[j]..col_ptr[j + 1] {
                if row_idx[q] > j {
                    transpose[q] = find(row_idx[q], j).unwrap_or(usize::MAX);
                }
            }
        }
        Some(InputMap {
            col_ptr: in_ptr.to_vec(),
            row_idx: in_idx.to_vec(),
            dest,
            transpose,
        })
    }
}

/// Lower triangle of the symmetrically permuted pattern, CSC, rows sorted,
/// with each entry's source position in the unpermuted values.
pub(super) struct Ordered {
    /// Elimination step → original DOF, and its inverse.
    pub(super) fwd: Vec<usize>,
    pub(super) inv: Vec<usize>,
    pub(super) col_ptr: Vec<usize>,
    pub(super) row_idx: Vec<usize>,
    /// Index into `Pencil::k_val` of each entry.
    pub(super) src: Vec<usize>,
}

impl Ordered {
    /// AMD ordering of the pattern, the permuted lower pattern and the
    /// symbolic factorization of the permuted pattern.
    /// `supernodal`: always the supernodal factorization (a block of the
    /// pencil, [`crate::modal::blocks`]: measured faster there, for the
    /// Nelson `LDLᵀ`s above all); else faer's choice by flop count.
    pub(super) fn build(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        supernodal: bool,
    ) -> Result<(Self, SymbolicCholesky<usize>)> {
        let err = |e| Error::numerical("modal::Pencil", format!("symbolic factorization: {e:?}"));
        let sym = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let amd = factorize_symbolic_cholesky(
            sym,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(err)?;
        let (fwd, inv) = match amd.perm() {
            Some(p) => (p.arrays().0.to_vec(), p.arrays().1.to_vec()),
            None => ((0..n).collect(), (0..n).collect()),
        };
        // Full permuted pattern (the symbolic analysis reads the upper
        // triangle) and its lower triangle with source positions.
        let mut full: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut lower: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
        for j in 0..n {
            let jn = inv[j];
            for p in col_ptr[j]..col_ptr[j + 1] {
                let i_n = inv[row_idx[p]];
                full[jn].push(i_n);
                if i_n >= jn {
                    lower[jn].push((i_n, p));
                }
            }
        }
        let (mut f_ptr, mut f_idx) = (vec![0usize], Vec::with_capacity(row_idx.len()));
        for c in full.iter_mut() {
            c.sort_unstable();
            f_idx.extend_from_slice(c);
            f_ptr.push(f_idx.len());
        }
        let mut o = Ordered {
            fwd,
            inv,
            col_ptr: vec![0],
            row_idx: Vec::new(),
            src: Vec::new(),
        };
        for c in lower.iter_mut() {
            c.sort_unstable();
            for &(i, p) in c.iter() {
                o.row_idx.push(i);
                o.src.push(p);
            }
            o.col_ptr.push(o.row_idx.len());
        }
        let fsym = SymbolicSparseColMatRef::new_checked(n, n, &f_ptr, None, &f_idx);
        let symbolic = factorize_symbolic_cholesky(
            fsym,
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: if supernodal {
                    SupernodalThreshold::FORCE_SUPERNODAL
                } else {
                    SupernodalThreshold::AUTO
                },
                ..Default::default()
            },
        )
        .map_err(err)?;
        Ok((o, symbolic))
    }
}

/// CSC pattern of `K` ∪ diagonal with the values of `K`.
pub(super) struct Pattern {
    pub(super) col_ptr: Vec<usize>,
    pub(super) row_idx: Vec<usize>,
    pub(super) k_val: Vec<f64>,
    pub(super) k_max: f64,
}

impl Pattern {
    pub(super) fn build(k: &SparseColMat<usize, f64>) -> Result<Self> {
        let kr = k.as_ref();
        let n = k.nrows();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(kr.compute_nnz() + n);
        let mut k_val = Vec::with_capacity(kr.compute_nnz() + n);
        let mut k_max = 0.0f64;
        col_ptr.push(0);
        let mut col: Vec<(usize, f64)> = Vec::new();
        for j in 0..n {
            col.clear();
            let rows = kr.row_idx_of_col_raw(j);
            let vals = kr.val_of_col(j);
            let mut has_diag = false;
            for (&i, &v) in rows.iter().zip(vals) {
                if !v.is_finite() {
                    return Err(Error::input(
                        format!("stiffness[{i}, {j}]"),
                        v,
                        "a finite number",
                    ));
                }
                k_max = k_max.max(v.abs());
                has_diag |= i == j;
                col.push((i, v));
            }
            if !has_diag {
                col.push((j, 0.0));
            }
            col.sort_by_key(|&(i, _)| i);
            // Merge duplicates (summed, as in triplet assembly).
            let start = row_idx.len();
            for &(i, v) in &col {
                if row_idx.len() > start && *row_idx.last().unwrap() == i {
                    *k_val.last_mut().unwrap() += v;
                } else {
                    row_idx.push(i);
                    k_val.push(v);
                }
            }
            col_ptr.push(row_idx.len());
        }
        // Full symmetric storage is required (products use both triangles,
        // the factorization reads the lower one): K_ij = K_ji to 1e-10·max|K|.
        let tol = 1e-10 * k_max;
        for j in 0..n {
            for p in col_ptr[j]..col_ptr[j + 1] {
                let i = row_idx[p];
                if i <= j {
                    continue;
                }
                let rows = &row_idx[col_ptr[i]..col_ptr[i + 1]];
                let kji = rows
                    .binary_search(&j)
                    .map_or(0.0, |q| k_val[col_ptr[i] + q]);
                if (k_val[p] - kji).abs() > tol {
                    return Err(Error::input(
                        format!("stiffness[{i}, {j}]"),
                        k_val[p],
                        format!("a symmetric matrix in full storage (stiffness[{j}, {i}] = {kji})"),
                    ));
                }
            }
        }
        Ok(Pattern {
            col_ptr,
            row_idx,
            k_val,
            k_max,
        })
    }
}
