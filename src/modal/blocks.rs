//! Independent blocks of the pencil, for the eigen-solver's shift-invert
//! solves and the eigenvector derivatives.
//!
//! When `K` has no non-zero entry between two sets of DOFs (the lumped `M`
//! is diagonal), the pencil is block diagonal: every eigenvector of a
//! distinct eigenvalue lives in one block `B`, and every system
//! `(K − sM) v = f` splits into one system per block.
//!
//! The case in point is a flat shell of a symmetric laminate, whose
//! membrane (u, v, θz) and bending (w, θx, θy) DOFs are uncoupled exactly
//! (`laminate`, "Symmetric stacks"). Every low mode of the SAR panels is
//! flexural. Because no fill crosses between blocks, the blocks' factors
//! together are much smaller than the whole pencil's (SAR panel, 4416
//! DOFs: 2 × 66 894 stored entries of `L` against 323 475), so:
//! - the eigen-solver applies `(K − σM)⁻¹` block by block
//!   ([`ShiftInvert`]: the same operator, a cheaper solve);
//! - a mode's derivative system `(K − λM) v = −(K'ᵥ − λ'M) x` is solved
//!   with Nelson's method on the block `B` that holds `x`
//!   (`(K_BB − λ M_BB) v_B = −(K'ᵥ − λ'M)_B x_B`), and on each other block
//!   `Q` that a design derivative couples to `B` (`K'ᵥ` non-zero between
//!   them: a ply angle that breaks the symmetry of the stack, e.g. one ply
//!   of four) by a plain solve `(K_QQ − λ M_QQ) v_Q = −(K'ᵥ)_QB x_B`, `λ`
//!   not being an eigenvalue of `Q`. Blocks no `K'ᵥ` couples to `B` get
//!   `v_Q = 0`.
//!
//! The blocks are the connected components of the graph of non-zero
//! entries of `K`, found anew for every design (so the result for a design
//! never depends on the designs analysed before it), and which blocks the
//! `K'ᵥ` couple, found anew for every set of derivatives; each block's
//! pattern, ordering and symbolic factorization are built once and kept
//! while the partition stays the same.
//!
//! A cluster of modes is solved on a block when the part of its
//! eigenvectors outside the block is below [`OFF_BLOCK_TOL`] in M-norm
//! (the computed eigenvectors of the SAR panels carry about 1e-13 there,
//! the eigen-solver's rounding); otherwise, e.g. a cluster whose repeated
//! eigenvalue belongs to two blocks, on the full pencil. That part is an
//! error of the eigen-solver (the exact eigenvector has none): the full
//! pencil would carry it into the derivative amplified by the distance to
//! the other block's eigenvalues, the block solve leaves it out.

use faer::reborrow::ReborrowMut;
use faer::sparse::SparseColMat;
use faer::{Mat, MatMut, MatRef};

use super::sparse::{Factor, Pencil};
use crate::error::Result;

/// Largest relative M-norm `‖x_off‖_M / ‖x‖_M` of the part of a cluster's
/// eigenvectors outside a block for the cluster to be solved on the block.
pub(crate) const OFF_BLOCK_TOL: f64 = 1e-10;

/// One block: its DOFs and its restriction of the pencil.
pub(crate) struct Part {
    /// The block's DOFs, ascending (block index → DOF).
    pub dofs: Vec<usize>,
    /// `K_BB`, `M_B` with their own ordering and symbolic factorization.
    pub pencil: Pencil,
    /// Position in the full pencil of each stored entry of the block's.
    map: Vec<usize>,
}

/// The partition of the DOFs into independent blocks (two or more).
pub(crate) struct Blocks {
    /// Block of each DOF.
    of_dof: Vec<usize>,
    /// The blocks (two or more), each with its restricted pencil.
    pub parts: Vec<Part>,
    /// `coupled[p * parts + q]`: some design derivative of the last
    /// [`Blocks::couple`] has a non-zero entry between blocks `p` and `q`.
    coupled: Vec<bool>,
}

impl Blocks {
    /// The blocks of `pencil`'s `K` (module doc), none coupled. `cache`:
    /// the blocks of the previous design, kept (values of `K` and `M`
    /// refreshed) when the partition is the same. `None` when the pencil
    /// does not split.
    pub(crate) fn refresh(cache: &mut Option<Blocks>, pencil: &Pencil) -> Result<()> {
        let of_dof = components(pencil);
        let count = of_dof.iter().max().map_or(0, |&b| b + 1);
        if count < 2 {
            *cache = None;
            return Ok(());
        }
        if let Some(b) = cache.as_mut().filter(|b| b.of_dof == of_dof) {
            for part in &mut b.parts {
                part.pencil.gather_values(pencil, &part.map);
            }
            b.coupled.iter_mut().for_each(|c| *c = false);
            return Ok(());
        }
        let mut dofs = vec![Vec::new(); count];
        for (d, &b) in of_dof.iter().enumerate() {
            dofs[b].push(d);
        }
        let parts = dofs
            .into_iter()
            .map(|dofs| {
                let (pencil, map) = pencil.block(&dofs)?;
                Ok(Part { dofs, pencil, map })
            })
            .collect::<Result<Vec<_>>>()?;
        *cache = Some(Blocks {
            of_dof,
            parts,
            coupled: vec![false; count * count],
        });
        Ok(())
    }

    /// Mark the pairs of blocks between which a matrix of `dk` (design
    /// derivatives of `K`, of the pencil's size) has a non-zero entry.
    pub(crate) fn couple(&mut self, dk: &[&SparseColMat<usize, f64>]) {
        let (n, count) = (self.of_dof.len(), self.parts.len());
        self.coupled.iter_mut().for_each(|c| *c = false);
        for m in dk.iter().filter(|m| m.nrows() == n && m.ncols() == n) {
            let m = m.as_ref();
            for j in 0..n {
                let bj = self.of_dof[j];
                for (&i, &v) in m.row_idx_of_col_raw(j).iter().zip(m.val_of_col(j)) {
                    let bi = self.of_dof[i];
                    if bi != bj && v != 0.0 {
                        self.coupled[bi * count + bj] = true;
                        self.coupled[bj * count + bi] = true;
                    }
                }
            }
        }
    }

    /// Whether the last [`Blocks::couple`] found a design derivative
    /// coupling blocks `p` and `q`.
    pub(crate) fn coupled(&self, p: usize, q: usize) -> bool {
        self.coupled[p * self.parts.len() + q]
    }

    /// The block that holds the columns of `x` (`n × r`, a cluster's
    /// eigenvectors) up to [`OFF_BLOCK_TOL`], if one does.
    pub(crate) fn holding(&self, x: MatRef<'_, f64>, mass: &[f64]) -> Option<usize> {
        let mut share = vec![0.0; self.parts.len()];
        let mut best = None;
        for j in 0..x.ncols() {
            share.iter_mut().for_each(|s| *s = 0.0);
            for (i, &b) in self.of_dof.iter().enumerate() {
                share[b] += mass[i] * x[(i, j)] * x[(i, j)];
            }
            let total: f64 = share.iter().sum();
            let (b, &inside) = share.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
            let off = (total - inside).max(0.0);
            let held = off <= OFF_BLOCK_TOL * OFF_BLOCK_TOL * total;
            if !held || best.is_some_and(|c| c != b) {
                return None;
            }
            best = Some(b);
        }
        best
    }
}

/// Connected components of the non-zero entries of `K`, numbered by
/// their first DOF.
fn components(pencil: &Pencil) -> Vec<usize> {
    let n = pencil.n();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for j in 0..n {
        let (rows, vals) = pencil.k_col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            if i < j && v != 0.0 {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut label = vec![usize::MAX; n];
    let mut count = 0;
    (0..n)
        .map(|d| {
            let r = root(&mut parent, d);
            if label[r] == usize::MAX {
                label[r] = count;
                count += 1;
            }
            label[r]
        })
        .collect()
}

/// The shift-invert solve `(K − σM)⁻¹` of the eigen-solver: with one
/// factorization of the whole pencil, or, when `K` splits into
/// independent blocks (a symmetric laminate's flat shell: membrane and
/// bending), with one factorization per block. The operator is the same
/// (`K − σM` is block diagonal, `M` diagonal), so Lanczos takes the same
/// steps up to rounding; the blocks' factors are smaller because no fill
/// crosses between them: on the SAR panel (4416 DOFs) the whole factor
/// has 323 475 stored entries, the two blocks' 2 × 66 894.
pub(crate) enum ShiftInvert<'a> {
    /// One `LLᵀ` of the whole pencil.
    Whole(Factor<'a>),
    /// One `LLᵀ` per block, with each block's DOFs, and a gather buffer.
    Split(Vec<(&'a [usize], Factor<'a>)>, Mat<f64>),
}

impl<'a> ShiftInvert<'a> {
    /// `LLᵀ` of `K − σM` on `pencil`, block by block when `blocks` (from
    /// [`Blocks::refresh`]) is given. Errors as [`Pencil::factor_llt`] (a block names its DOF in
    /// the whole pencil).
    pub(crate) fn new(pencil: &'a Pencil, blocks: Option<&'a Blocks>, sigma: f64) -> Result<Self> {
        match blocks {
            None => Ok(ShiftInvert::Whole(pencil.factor_llt(sigma)?)),
            Some(b) => {
                let parts = b
                    .parts
                    .iter()
                    .map(|p| Ok((p.dofs.as_slice(), p.pencil.factor_llt(sigma)?)))
                    .collect::<Result<Vec<_>>>()?;
                Ok(ShiftInvert::Split(parts, Mat::zeros(0, 0)))
            }
        }
    }

    /// Solve `(K − σM) X = B` in place for the `n × r` block `rhs`.
    pub(crate) fn solve_in_place(&mut self, mut rhs: MatMut<'_, f64>) {
        match self {
            ShiftInvert::Whole(f) => f.solve_in_place(rhs),
            ShiftInvert::Split(parts, tmp) => {
                let r = rhs.ncols();
                for (dofs, f) in parts.iter_mut() {
                    if tmp.nrows() < dofs.len() || tmp.ncols() < r {
                        *tmp = Mat::zeros(dofs.len().max(tmp.nrows()), r.max(tmp.ncols()));
                    }
                    let mut t = tmp.as_mut().submatrix_mut(0, 0, dofs.len(), r);
                    for c in 0..r {
                        for (l, &d) in dofs.iter().enumerate() {
                            t[(l, c)] = rhs[(d, c)];
                        }
                    }
                    f.solve_in_place(t.rb_mut());
                    for c in 0..r {
                        for (l, &d) in dofs.iter().enumerate() {
                            rhs[(d, c)] = t[(l, c)];
                        }
                    }
                }
            }
        }
    }
}
