//! Sparse symmetric storage for the pencil `K − s·M` and its factorizations.
//!
//! Every matrix the modal code factors has the pattern of `K` plus the
//! diagonal (the lumped mass is diagonal): `K − σM` for shift-invert and
//! `K − λᵢM` (with some rows and columns replaced by the identity) for the
//! eigenvector derivatives. [`Pencil`] stores that one pattern, computes the
//! fill-reducing ordering and the symbolic Cholesky structure once (faer,
//! AMD ordering), and every numeric factorization reuses it.
//!
//! Performance choices (measured on the SAR panel, 4152 DOFs):
//! - the AMD permutation is applied once to the pattern ([`Ordered`]): the
//!   symbolic structure is computed on the permuted pattern with identity
//!   ordering, numeric values are written straight into the permuted lower
//!   triangle through a position map, and the solves permute the right-hand
//!   sides themselves, so faer does not re-permute `A` at every numeric
//!   factorization (15 per design with eigenvector derivatives);
//! - products with `K` are gathers over columns (symmetric full storage),
//!   4 right-hand sides per pass over `K` ([`sym_mul_block`]);
//! - a new design's stiffness on the same input pattern is taken through a
//!   precomputed map ([`InputMap`]) with the same checks, without re-sorting.

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

use crate::error::{Error, Result};

/// Which triangular factorization a [`Factor`] holds.
enum Kind {
    /// `LLᵀ` of a positive definite matrix (the shift-invert operator).
    Llt,
    /// `LDLᵀ` without pivoting of an indefinite matrix (Nelson systems).
    Ldlt,
}

/// Right-preconditioned GMRES on `A x = b` with the factorization `F ≈ A`
/// as preconditioner ("Krylov iterative refinement"). When `F = A` exactly
/// it stops after the residual check; each regularised pivot of `F` (a
/// rank-one difference) costs about one iteration. Modifies `x` (start:
/// `F⁻¹b`, end: the refined solution). Returns the relative residual.
pub(crate) fn gmres_refine(
    factor: &mut Factor<'_>,
    apply_a: &dyn Fn(&[f64], &mut [f64]),
    x: &mut [f64],
    job: Refine<'_>,
) -> f64 {
    let Refine {
        b,
        tol,
        max_iter,
        residual,
        mut first,
    } = job;
    let n = b.len();
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    let bn = norm(b).max(f64::MIN_POSITIVE);
    let r: Vec<f64> = residual.unwrap_or_else(|| {
        let mut ax = vec![0.0; n];
        apply_a(x, &mut ax);
        (0..n).map(|i| b[i] - ax[i]).collect()
    });
    let beta = norm(&r);
    if beta <= tol * bn {
        return beta / bn;
    }
    let mut basis: Vec<Vec<f64>> = vec![r.iter().map(|v| v / beta).collect()];
    let mut zs: Vec<Vec<f64>> = Vec::new();
    // Hessenberg columns after Givens rotations (upper triangular R).
    let mut rmat: Vec<Vec<f64>> = Vec::new();
    let mut cs: Vec<(f64, f64)> = Vec::new();
    let mut g = vec![beta];
    let mut res = beta;
    for j in 0..max_iter {
        let (z, mut w) = match first.take() {
            Some(zw) if j == 0 => zw,
            _ => {
                let mut z = Mat::<f64>::from_fn(n, 1, |i, _| basis[j][i]);
                factor.solve_in_place(z.as_mut());
                let z: Vec<f64> = (0..n).map(|i| z[(i, 0)]).collect();
                let mut w = vec![0.0; n];
                apply_a(&z, &mut w);
                (z, w)
            }
        };
        let mut h = vec![0.0; j + 2];
        for _ in 0..2 {
            for (i, v) in basis.iter().enumerate() {
                let c: f64 = v.iter().zip(&w).map(|(a, b)| a * b).sum();
                h[i] += c;
                w.iter_mut().zip(v).for_each(|(a, b)| *a -= c * b);
            }
        }
        h[j + 1] = norm(&w);
        for (i, &(c, s)) in cs.iter().enumerate() {
            let (a, b) = (h[i], h[i + 1]);
            h[i] = c * a + s * b;
            h[i + 1] = -s * a + c * b;
        }
        let d = (h[j] * h[j] + h[j + 1] * h[j + 1]).sqrt();
        let (c, s) = if d > 0.0 {
            (h[j] / d, h[j + 1] / d)
        } else {
            (1.0, 0.0)
        };
        h[j] = d;
        let gj = g[j];
        g[j] = c * gj;
        g.push(-s * gj);
        cs.push((c, s));
        res = g[j + 1].abs();
        let hn = h[j + 1];
        h.truncate(j + 1);
        rmat.push(h);
        zs.push(z);
        if res <= tol * bn || hn == 0.0 {
            break;
        }
        basis.push(w.iter().map(|v| v / hn).collect());
    }
    // Back substitution R y = g, x += Z y.
    let m = rmat.len();
    let mut y = vec![0.0; m];
    for i in (0..m).rev() {
        let mut t = g[i];
        for k in i + 1..m {
            t -= rmat[k][i] * y[k];
        }
        y[i] = t / rmat[i][i];
    }
    for (k, z) in zs.iter().enumerate() {
        x.iter_mut().zip(z).for_each(|(a, b)| *a += y[k] * b);
    }
    res / bn
}

/// Column `j` of a column-major matrix as a slice.
fn col_of(m: MatRef<'_, f64>, j: usize) -> &[f64] {
    m.col(j)
        .try_as_col_major()
        .expect("faer matrices are column-major")
        .as_slice()
}

/// One GMRES refinement job of [`gmres_refine`].
pub(crate) struct Refine<'a> {
    /// Right-hand side `b`.
    pub b: &'a [f64],
    /// Relative residual to reach.
    pub tol: f64,
    /// Largest number of iterations.
    pub max_iter: usize,
    /// `b − A x` when already known (else computed).
    pub residual: Option<Vec<f64>>,
    /// The first iteration's `z = F⁻¹ r/‖r‖` and `A z` when already known
    /// (computed for several columns at once by the caller).
    pub first: Option<(Vec<f64>, Vec<f64>)>,
}

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

/// `K` (full symmetric CSC storage) on the pattern of `K` ∪ diagonal, with
/// the diagonal mass, and the symbolic Cholesky structure of that pattern.
pub(crate) struct Pencil {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Values of `K` on the pattern (zero where only the diagonal was added).
    k_val: Vec<f64>,
    /// Lumped mass, length `n`.
    mass: Vec<f64>,
    /// The lower triangle of `P(K ∪ diag)Pᵀ` in the fill-reducing order.
    ordered: Ordered,
    /// How the entries of the input matrix map onto the pattern.
    input: InputMap,
    /// Symbolic Cholesky of the permuted pattern (identity ordering: the
    /// numeric factorizations then read `values` directly, without the
    /// per-factorization permutation of the input inside faer).
    symbolic: SymbolicCholesky<usize>,
    /// Largest |K_ij|, used to scale pivot reports.
    k_max: f64,
    /// For a block ([`Self::block`]): the full pencil's DOF of each of its
    /// DOFs, for messages (empty: the pencil's own numbering).
    global: Vec<usize>,
}

/// The input stiffness pattern and where its entries go on the pattern of
/// `K ∪ diag`: lets [`Pencil::set_stiffness`] take a new design's values in
/// one pass (no sort, no binary search) when the input pattern is unchanged.
struct InputMap {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Pattern position of each input entry (duplicates share one).
    dest: Vec<usize>,
    /// For each pattern entry `(i, j)` with `i > j`: the position of
    /// `(j, i)`, or `usize::MAX` when absent.
    transpose: Vec<usize>,
}

impl InputMap {
    /// No map: [`Pencil::set_stiffness`] takes the full path.
    fn empty() -> Self {
        InputMap {
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            dest: Vec::new(),
            transpose: Vec::new(),
        }
    }

    fn build(k: &SparseColMat<usize, f64>, col_ptr: &[usize], row_idx: &[usize]) -> Option<Self> {
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
struct Ordered {
    /// Elimination step → original DOF, and its inverse.
    fwd: Vec<usize>,
    inv: Vec<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Index into `Pencil::k_val` of each entry.
    src: Vec<usize>,
}

impl Ordered {
    /// AMD ordering of the pattern, the permuted lower pattern and the
    /// symbolic factorization of the permuted pattern.
    fn build(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
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
            CholeskySymbolicParams::default(),
        )
        .map_err(err)?;
        Ok((o, symbolic))
    }
}

/// CSC pattern of `K` ∪ diagonal with the values of `K`.
struct Pattern {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    k_val: Vec<f64>,
    k_max: f64,
}

impl Pattern {
    fn build(k: &SparseColMat<usize, f64>) -> Result<Self> {
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

/// Maximum number of right-hand sides solved at once (scratch size).
pub(crate) const MAX_RHS: usize = 64;

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
        let pat = Pattern::build(k)?;
        let Pattern {
            col_ptr,
            row_idx,
            k_val,
            k_max,
            ..
        } = pat;
        let (ordered, symbolic) = Ordered::build(n, &col_ptr, &row_idx)?;
        let input = InputMap::build(k, &col_ptr, &row_idx).unwrap_or_else(InputMap::empty);
        Ok(Pencil {
            n,
            col_ptr,
            row_idx,
            k_val,
            mass: mass.to_vec(),
            ordered,
            input,
            symbolic,
            k_max,
            global: Vec::new(),
        })
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
        true
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
        let (ordered, symbolic) = Ordered::build(nb, &col_ptr, &row_idx)?;
        let mut block = Pencil {
            n: nb,
            col_ptr,
            row_idx,
            k_val: Vec::new(),
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
    /// [`Self::block`]): the block of a new design's stiffness.
    pub(crate) fn gather_values(&mut self, full: &Pencil, map: &[usize]) {
        self.k_val.clear();
        self.k_val.extend(map.iter().map(|&p| full.k_val[p]));
        self.k_max = self.k_val.iter().fold(0.0f64, |a, v| a.max(v.abs()));
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

    /// Values of `K − s·M` on the permuted lower pattern ([`Ordered`]),
    /// with the rows and columns listed in `fixed` (original DOFs) replaced
    /// by those of the identity.
    fn shifted_values(&self, s: f64, fixed: &[usize]) -> Vec<f64> {
        let o = &self.ordered;
        let mut val: Vec<f64> = o.src.iter().map(|&p| self.k_val[p]).collect();
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

    /// Original DOF of elimination step `index` (AMD permutation; for a
    /// block, the full pencil's DOF).
    fn original_dof(&self, index: usize) -> usize {
        let d = self.ordered.fwd.get(index).copied().unwrap_or(index);
        self.global.get(d).copied().unwrap_or(d)
    }
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
