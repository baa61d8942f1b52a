//! Independent blocks of the pencil, for the eigenvector derivatives.
//!
//! When neither `K` nor any design derivative `K'ᵥ` has a non-zero entry
//! between two sets of DOFs (the lumped `M` is diagonal), the pencil is
//! block diagonal: every eigenvector of a distinct eigenvalue lives in one
//! block `B`, and so does its derivative, since Nelson's right-hand side
//! `−(K'ᵥ − λ'M) x` is then zero off `B`. The derivative system is
//! `(K_BB − λ M_BB) v_B = −(K'ᵥ − λ'M)_B x_B` on the block alone.
//!
//! The case in point is a flat shell of a symmetric laminate, whose
//! membrane (u, v, θz) and bending (w, θx, θy) DOFs are uncoupled exactly
//! (`laminate`, "Symmetric stacks"). Every low mode of the SAR panels is
//! flexural, so each derivative system has half the unknowns; on the SAR
//! panel (4152 DOFs) its factorization is about half the cost of the full
//! one.
//!
//! The blocks are the connected components of the graph of non-zero
//! entries of `K` and the `K'ᵥ`, found anew for every design (so the result
//! for a design never depends on the designs analysed before it); each
//! block's pattern, ordering and symbolic factorization are built once and
//! kept while the partition stays the same.
//!
//! A cluster of modes is solved on a block when the part of its
//! eigenvectors outside the block is below [`OFF_BLOCK_TOL`] in M-norm
//! (the computed eigenvectors of the SAR panels carry about 1e-13 there,
//! the eigen-solver's rounding); otherwise, e.g. a cluster whose repeated
//! eigenvalue belongs to two blocks, on the full pencil. That part is an
//! error of the eigen-solver (the exact eigenvector has none): the full
//! pencil would carry it into the derivative amplified by the distance to
//! the other block's eigenvalues, the block solve leaves it out.

use faer::sparse::SparseColMat;
use faer::MatRef;

use super::sparse::Pencil;
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
}

impl Blocks {
    /// The blocks of `pencil` with the design derivatives `dk` (module
    /// doc). `cache`: the blocks of the previous design, kept (values of
    /// `K` and `M` refreshed) when the partition is the same. `None` when the pencil
    /// does not split. Matrices of another size than the pencil are left to
    /// the caller's checks.
    pub(crate) fn refresh(
        cache: &mut Option<Blocks>,
        pencil: &Pencil,
        dk: &[&SparseColMat<usize, f64>],
    ) -> Result<()> {
        let of_dof = components(pencil, dk);
        let count = of_dof.iter().max().map_or(0, |&b| b + 1);
        if count < 2 {
            *cache = None;
            return Ok(());
        }
        if let Some(b) = cache.as_mut().filter(|b| b.of_dof == of_dof) {
            for part in &mut b.parts {
                part.pencil.gather_values(pencil, &part.map);
            }
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
        *cache = Some(Blocks { of_dof, parts });
        Ok(())
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

/// Connected components of the non-zero entries of `K` and of every
/// matrix of `dk` (of the pencil's size), numbered by their first DOF.
fn components(pencil: &Pencil, dk: &[&SparseColMat<usize, f64>]) -> Vec<usize> {
    let n = pencil.n();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut join = |i: usize, j: usize| {
        let (a, b) = (root(&mut parent, i), root(&mut parent, j));
        if a != b {
            parent[a.max(b)] = a.min(b);
        }
    };
    let dk: Vec<_> = dk
        .iter()
        .filter(|m| m.nrows() == n && m.ncols() == n)
        .map(|m| m.as_ref())
        .collect();
    for j in 0..n {
        let columns = std::iter::once(pencil.k_col(j)).chain(
            dk.iter()
                .map(|m| (m.row_idx_of_col_raw(j), m.val_of_col(j))),
        );
        for (rows, vals) in columns {
            for (&i, &v) in rows.iter().zip(vals) {
                if i != j && v != 0.0 {
                    join(i, j);
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
