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
    pub parts: Vec<Part>,
}

impl Blocks {
    /// The blocks of `pencil` with the design derivatives `dk` (module
    /// doc). `cache`: the blocks of the previous design, kept (values
    /// refreshed) when the partition is the same. `None` when the pencil
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modal::derivatives::{compute, DerivativeOptions, DesignDerivative};
    use crate::modal::{ModalOptions, ModalSolver};
    use faer::sparse::Triplet;
    use faer::Mat;

    /// Two fixed–free spring chains of `m` masses on interleaved DOFs
    /// (chain 0 on the even DOFs, chain 1 on the odd ones), spring `e` of
    /// chain `c` of stiffness `k_e (1 + α_e p)`; `weight(e, c)` gives the
    /// matrix's per-spring factor (`k_e(1 + α_e p)` for K, `k_e α_e` for
    /// K'). A spring of stiffness `couple` joins the two chains' first DOFs
    /// (kept in the pattern when zero, as the shell's zero B entries are).
    fn chains(
        m: usize,
        couple: f64,
        weight: impl Fn(usize, usize) -> f64,
    ) -> SparseColMat<usize, f64> {
        let n = 2 * m;
        let dof = |c: usize, i: usize| 2 * i + c;
        let mut t = vec![
            Triplet::new(0, 0, couple),
            Triplet::new(1, 1, couple),
            Triplet::new(0, 1, -couple),
            Triplet::new(1, 0, -couple),
        ];
        for c in 0..2 {
            for e in 0..m {
                let k = weight(e, c);
                let b = dof(c, e);
                t.push(Triplet::new(b, b, k));
                if e > 0 {
                    let a = dof(c, e - 1);
                    t.extend([
                        Triplet::new(a, a, k),
                        Triplet::new(a, b, -k),
                        Triplet::new(b, a, -k),
                    ]);
                }
            }
        }
        SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    fn stiffness(e: usize, c: usize) -> f64 {
        100.0 * (1.0 + 0.5 * ((e as f64) * 1.7 + c as f64).sin()) * (1.0 + 0.4 * c as f64)
    }

    fn alpha(e: usize, c: usize) -> f64 {
        0.6 * ((e as f64) * 0.83 + 2.0 * c as f64).cos()
    }

    /// The block path and the full path solve the same systems (each
    /// derivative is exact on its block: the pencil is block diagonal), so
    /// they agree to the solves' accuracy; modes of both chains occur.
    #[test]
    fn blocks_give_the_full_pencils_derivatives() {
        let (m, p) = (30, 0.3);
        let k = chains(m, 0.0, |e, c| stiffness(e, c) * (1.0 + alpha(e, c) * p));
        let dk = chains(m, 0.0, |e, c| stiffness(e, c) * alpha(e, c));
        let mass: Vec<f64> = (0..2 * m)
            .map(|i| 1.0 + 0.3 * ((i as f64) * 0.7).sin())
            .collect();
        let mut opts = ModalOptions::new(10);
        opts.tol = 1e-12;
        let modes = ModalSolver::new(&k, &mass).unwrap().solve(&opts).unwrap();
        let pencil = Pencil::new(&k, &mass).unwrap();
        let mut blocks = None;
        Blocks::refresh(&mut blocks, &pencil, &[&dk]).unwrap();
        let b = blocks.expect("two chains: two blocks");
        assert_eq!(b.parts.len(), 2);
        for (c, part) in b.parts.iter().enumerate() {
            assert!(part.dofs.iter().all(|d| d % 2 == c));
            assert_eq!(part.dofs.len(), m);
        }
        let held: Vec<usize> = (0..10)
            .map(|j| {
                b.holding(modes.modes.as_ref().subcols(j, 1), &mass)
                    .unwrap()
            })
            .collect();
        assert!(held.contains(&0) && held.contains(&1), "{held:?}");
        let var = [DesignDerivative { dk: &dk, d2k: None }];
        let o = DerivativeOptions::default();
        let full = compute(&pencil, None, &modes, &var, &o).unwrap();
        let split = compute(&pencil, Some(&b), &modes, &var, &o).unwrap();
        assert_eq!(full[0].dlambda, split[0].dlambda);
        let (xf, xs) = (
            full[0].dmodes.as_ref().unwrap(),
            split[0].dmodes.as_ref().unwrap(),
        );
        let scale = (0..10)
            .flat_map(|j| (0..2 * m).map(move |i| (i, j)))
            .fold(0.0f64, |a, (i, j)| a.max(xf[(i, j)].abs()));
        for j in 0..10 {
            for i in 0..2 * m {
                let d = (xf[(i, j)] - xs[(i, j)]).abs();
                assert!(d <= 1e-9 * scale, "mode {j} dof {i}: {d:e} of {scale:e}");
                if i % 2 != held[j] {
                    assert_eq!(xs[(i, j)], 0.0);
                }
            }
        }
    }

    /// A non-zero coupling in K or in a K' joins the blocks; a vector with
    /// weight in both blocks is held by neither.
    #[test]
    fn coupling_joins_blocks_and_mixed_vectors_have_no_block() {
        let m = 6;
        let mass = vec![1.0; 2 * m];
        let k0 = chains(m, 0.0, stiffness);
        let dk0 = chains(m, 0.0, alpha);
        let pencil = Pencil::new(&k0, &mass).unwrap();
        let mut blocks = None;
        Blocks::refresh(&mut blocks, &pencil, &[&dk0]).unwrap();
        let b = blocks.as_ref().expect("uncoupled chains split");
        let mut x = Mat::<f64>::zeros(2 * m, 1);
        x[(2, 0)] = 1.0;
        assert_eq!(b.holding(x.as_ref(), &mass), Some(0));
        x[(3, 0)] = 1e-6;
        assert_eq!(b.holding(x.as_ref(), &mass), None);
        let dk1 = chains(m, 1e-9, alpha);
        Blocks::refresh(&mut blocks, &pencil, &[&dk1]).unwrap();
        assert!(blocks.is_none(), "K' couples the chains");
        let k1 = chains(m, 1e-9, stiffness);
        let pencil = Pencil::new(&k1, &mass).unwrap();
        Blocks::refresh(&mut blocks, &pencil, &[&dk0]).unwrap();
        assert!(blocks.is_none(), "K couples the chains");
    }

    /// A stiffness with another stored pattern but the same partition (an
    /// explicit zero added inside a block) rebuilds the pencil, and the
    /// blocks with it: their maps point into the old pattern.
    #[test]
    fn a_new_pattern_rebuilds_the_blocks() {
        let m = 12;
        let mass: Vec<f64> = (0..2 * m).map(|i| 1.0 + 0.1 * i as f64).collect();
        let k_a = chains(m, 0.0, stiffness);
        let mut t: Vec<Triplet<usize, usize, f64>> = Vec::new();
        for j in 0..2 * m {
            let (rows, vals) = (
                k_a.as_ref().row_idx_of_col_raw(j),
                k_a.as_ref().val_of_col(j),
            );
            t.extend(rows.iter().zip(vals).map(|(&i, &v)| Triplet::new(i, j, v)));
        }
        t.extend([Triplet::new(0, 6, 0.0), Triplet::new(6, 0, 0.0)]);
        let k_b = SparseColMat::try_new_from_triplets(2 * m, 2 * m, &t).unwrap();
        let dk = chains(m, 0.0, alpha);
        let var = [DesignDerivative { dk: &dk, d2k: None }];
        let o = DerivativeOptions::default();
        let mut solver = ModalSolver::new(&k_a, &mass).unwrap();
        let modes = solver.solve(&ModalOptions::new(6)).unwrap();
        solver.derivatives(&modes, &var, &o).unwrap();
        solver.set_stiffness(&k_b).unwrap();
        let got = solver.derivatives(&modes, &var, &o).unwrap();
        let want = compute(&Pencil::new(&k_b, &mass).unwrap(), None, &modes, &var, &o).unwrap();
        let (xg, xw) = (
            got[0].dmodes.as_ref().unwrap(),
            want[0].dmodes.as_ref().unwrap(),
        );
        for j in 0..6 {
            for i in 0..2 * m {
                assert!((xg[(i, j)] - xw[(i, j)]).abs() <= 1e-9 * (1.0 + xw[(i, j)].abs()));
            }
        }
    }
}
