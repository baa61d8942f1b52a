//! [`Pencil`]: `K` and the lumped mass on one pattern, with its symbolic
//! factorization; construction, new designs' values and sub-blocks.

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::sparse::linalg::cholesky::SymbolicCholesky;
use faer::sparse::SparseColMat;

use super::pattern::{InputMap, Ordered, Pattern};
use crate::error::{Error, Result};

/// `K` (full symmetric CSC storage) on the pattern of `K` ∪ diagonal, with
/// the diagonal mass, and the symbolic Cholesky structure of that pattern.
pub(crate) struct Pencil {
    pub(super) n: usize,
    pub(super) col_ptr: Vec<usize>,
    pub(super) row_idx: Vec<usize>,
    /// Values of `K` on the pattern (zero where only the diagonal was added).
    pub(super) k_val: Vec<f64>,
    /// Values of `K` on the permuted lower pattern ([`Ordered`], entry `e`
    /// is `k_val[ordered.src[e]]`), gathered once per stiffness for the
    /// shifted factorizations (one per mode for the mode derivatives).
    pub(super) k_lower: Vec<f64>,
    /// Lumped mass, length `n`.
    pub(super) mass: Vec<f64>,
    /// The lower triangle of `P(K ∪ diag)Pᵀ` in the fill-reducing order.
    pub(super) ordered: Ordered,
    /// How the entries of the input matrix map onto the pattern.
    pub(super) input: InputMap,
    /// Symbolic Cholesky of the permuted pattern (identity ordering: the
    /// numeric factorizations then read `values` directly, without the
    /// per-factorization permutation of the input inside faer).
    pub(super) symbolic: SymbolicCholesky<usize>,
    /// Largest |K_ij|, used to scale pivot reports.
    pub(super) k_max: f64,
    /// For a block ([`Self::block`]): the full pencil's DOF of each of its
    /// DOFs, for messages (empty: the pencil's own numbering).
    pub(super) global: Vec<usize>,
}

impl Pencil {
    /// Build the pattern `K ∪ diag`, check sizes and values, and compute the
    /// AMD ordering and symbolic factorization once.
    pub(crate) fn new(k: &SparseColMat<usize, f64>, mass: &[f64]) -> Result<Self> {
        let n = k.nrows();
        if k.ncols() != n {
            return Err(Error::input(
                "stiffness",
                format!("{} x {} matrix", k.nrows(), k.ncols()),
                "a square matrix",
            ));
        }
        if n == 0 {
            return Err(Error::input(
                "stiffness",
                "0 x 0 matrix",
                "at least one DOF",
            ));
        }
        check_mass(mass, n)?;
        let pat = Pattern::build(k)?;
        let Pattern {
            col_ptr,
            row_idx,
            k_val,
            k_max,
            ..
        } = pat;
        let (ordered, symbolic) = Ordered::build(n, &col_ptr, &row_idx, false)?;
        let input = InputMap::build(k, &col_ptr, &row_idx).unwrap_or_else(InputMap::empty);
        let mut pencil = Pencil {
            n,
            col_ptr,
            row_idx,
            k_val,
            k_lower: Vec::new(),
            mass: mass.to_vec(),
            ordered,
            input,
            symbolic,
            k_max,
            global: Vec::new(),
        };
        pencil.gather_lower();
        Ok(pencil)
    }

    /// Replace `K` by a matrix of the same size; the symbolic structure is
    /// kept when the pattern is unchanged and rebuilt otherwise. Returns
    /// whether it was rebuilt (the positions of the stored entries moved).
    pub(crate) fn set_stiffness(&mut self, k: &SparseColMat<usize, f64>) -> Result<bool> {
        if k.nrows() != self.n || k.ncols() != self.n {
            return Err(Error::input(
                "stiffness",
                format!("{} x {} matrix", k.nrows(), k.ncols()),
                format!("a {0} x {0} matrix (same DOFs as before)", self.n),
            ));
        }
        if self.fast_values(k) {
            return Ok(false);
        }
        let pat = Pattern::build(k)?;
        if pat.col_ptr == self.col_ptr && pat.row_idx == self.row_idx {
            self.k_val = pat.k_val;
            self.k_max = pat.k_max;
            self.gather_lower();
            Ok(false)
        } else {
            let mass = std::mem::take(&mut self.mass);
            *self = Pencil::new(k, &mass)?;
            Ok(true)
        }
    }

    /// New values on an unchanged input pattern: scatter through
    /// [`InputMap`] (duplicates summed in input order, as
    /// [`Pattern::build`] does), then the finiteness and symmetry checks.
    /// Returns `false`, leaving `self` unchanged, when the pattern differs or
    /// a check fails (the caller's full path then reports the error).
    fn fast_values(&mut self, k: &SparseColMat<usize, f64>) -> bool {
        let kr = k.as_ref();
        let m = &self.input;
        if m.dest.is_empty()
            || kr.col_nnz().is_some()
            || kr.col_ptr() != m.col_ptr.as_slice()
            || kr.row_idx() != m.row_idx.as_slice()
        {
            return false;
        }
        let mut val = vec![0.0; self.row_idx.len()];
        let mut k_max = 0.0f64;
        for (&v, &d) in kr.val().iter().zip(&m.dest) {
            if !v.is_finite() {
                return false;
            }
            k_max = k_max.max(v.abs());
            val[d] += v;
        }
        let tol = 1e-10 * k_max;
        for j in 0..self.n {
            for q in self.col_ptr[j]..self.col_ptr[j + 1] {
                if self.row_idx[q] <= j {
                    continue;
                }
                let t = m.transpose[q];
                let kji = if t == usize::MAX { 0.0 } else { val[t] };
                if (val[q] - kji).abs() > tol {
                    return false;
                }
            }
        }
        self.k_val = val;
        self.k_max = k_max;
        self.gather_lower();
        true
    }

    /// Replace the lumped mass by `mass` (a new design whose ply
    /// thicknesses moved it: `M` is diagonal, so the pattern, ordering and
    /// symbolic factorization are unchanged; every later factorization of
    /// `K − σM` reads it). Errors: as [`Pencil::new`]'s `mass` (length `n`,
    /// every entry finite and > 0); on error the pencil is unchanged.
    pub(crate) fn set_mass(&mut self, mass: &[f64]) -> Result<()> {
        check_mass(mass, self.n)?;
        self.mass.copy_from_slice(mass);
        Ok(())
    }

    /// `k_lower` from `k_val` (after new values of `K`).
    fn gather_lower(&mut self) {
        let (src, val) = (&self.ordered.src, &self.k_val);
        self.k_lower.clear();
        self.k_lower.extend(src.iter().map(|&p| val[p]));
    }

    /// The pencil restricted to `dofs` (ascending): `K_BB` and `M_B` on the
    /// pattern's rows and columns `dofs`, with its own AMD ordering and
    /// symbolic factorization, and for each of its stored entries the
    /// position of the same entry in `self` (for [`Self::gather_values`]).
    pub(crate) fn block(&self, dofs: &[usize]) -> Result<(Pencil, Vec<usize>)> {
        let mut local = vec![usize::MAX; self.n];
        for (l, &d) in dofs.iter().enumerate() {
            local[d] = l;
        }
        let nb = dofs.len();
        let (mut col_ptr, mut row_idx, mut map) = (vec![0usize], Vec::new(), Vec::new());
        for &j in dofs {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let l = local[self.row_idx[p]];
                if l != usize::MAX {
                    row_idx.push(l);
                    map.push(p);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let (ordered, symbolic) = Ordered::build(nb, &col_ptr, &row_idx, true)?;
        let mut block = Pencil {
            n: nb,
            col_ptr,
            row_idx,
            k_val: Vec::new(),
            k_lower: Vec::new(),
            mass: dofs.iter().map(|&d| self.mass[d]).collect(),
            ordered,
            input: InputMap::empty(),
            symbolic,
            k_max: 0.0,
            global: dofs.to_vec(),
        };
        block.gather_values(self, &map);
        Ok((block, map))
    }

    /// Take the values of `K` from `full` through `map` (from
    /// [`Self::block`]) and the mass of the block's DOFs: the block of a
    /// new design's pencil (its mass moves with the ply thicknesses).
    pub(crate) fn gather_values(&mut self, full: &Pencil, map: &[usize]) {
        for (m, &d) in self.mass.iter_mut().zip(&self.global) {
            *m = full.mass[d];
        }
        self.k_val.clear();
        self.k_val.extend(map.iter().map(|&p| full.k_val[p]));
        self.k_max = self.k_val.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        self.gather_lower();
    }

    /// Column `j` of `K` (rows, values); by symmetry also row `j`.
    pub(crate) fn k_col(&self, j: usize) -> (&[usize], &[f64]) {
        let r = self.col_ptr[j]..self.col_ptr[j + 1];
        (&self.row_idx[r.clone()], &self.k_val[r])
    }

    /// Number of DOFs.
    pub(crate) fn n(&self) -> usize {
        self.n
    }

    /// The lumped mass (length `n`).
    pub(crate) fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// Number of stored nonzeros of `L` (for reports).
    pub(crate) fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Original DOF of elimination step `index` (AMD permutation; for a
    /// block, the full pencil's DOF).
    pub(super) fn original_dof(&self, index: usize) -> usize {
        let d = self.ordered.fwd.get(index).copied().unwrap_or(index);
        self.global.get(d).copied().unwrap_or(d)
    }
}

/// A lumped diagonal mass for `n` DOFs: `n` entries, each finite and > 0
/// (kg or kg·m²); else an input error on key `mass` or `mass[i]`.
fn check_mass(mass: &[f64], n: usize) -> Result<()> {
    if mass.len() != n {
        return Err(Error::input(
            "mass",
            format!("{} entries", mass.len()),
            format!("{n} entries (one per DOF of the stiffness matrix)"),
        ));
    }
    for (i, &m) in mass.iter().enumerate() {
        if !(m.is_finite() && m > 0.0) {
            return Err(Error::input(
                format!("mass[{i}]"),
                m,
                "a finite lumped mass > 0",
            ));
        }
    }
    Ok(())
}
