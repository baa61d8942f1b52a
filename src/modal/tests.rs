//! Tests across the files of `modal`: the independent blocks of the pencil
//! (`blocks`) against the full pencil's eigenvector derivatives
//! (`derivatives`).

use faer::sparse::SparseColMat;

use super::blocks::Blocks;
use super::sparse::Pencil;
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
fn chains(m: usize, couple: f64, weight: impl Fn(usize, usize) -> f64) -> SparseColMat<usize, f64> {
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

/// Two interleaved chains (`K` uncoupled) with the design derivative `K'`
/// coupling their first DOFs by `couple`: the eigenvector derivatives of
/// the 10 lowest modes on the full pencil and block by block, with the
/// block holding each mode. Asserts that the blocks are the chains, that
/// modes of both occur, and that the two paths agree to the solves'
/// accuracy (1e-9 of the largest entry); returns the block path's
/// derivatives, the holding blocks and that largest entry.
fn block_and_full_derivatives(couple: f64) -> (Mat<f64>, Vec<usize>, f64) {
    let (m, p) = (30, 0.3);
    let k = chains(m, 0.0, |e, c| stiffness(e, c) * (1.0 + alpha(e, c) * p));
    let dk = chains(m, couple, |e, c| stiffness(e, c) * alpha(e, c));
    let mass: Vec<f64> = (0..2 * m)
        .map(|i| 1.0 + 0.3 * ((i as f64) * 0.7).sin())
        .collect();
    let mut opts = ModalOptions::new(10);
    opts.tol = 1e-12;
    let modes = ModalSolver::new(&k, &mass).unwrap().solve(&opts).unwrap();
    let pencil = Pencil::new(&k, &mass).unwrap();
    let mut blocks = None;
    Blocks::refresh(&mut blocks, &pencil).unwrap();
    let mut b = blocks.expect("two chains: two blocks");
    b.couple(&[&dk]);
    assert_eq!(b.coupled(0, 1), couple != 0.0);
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
    let var = [DesignDerivative {
        dk: &dk,
        d2k: None,
        mass: None,
    }];
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
        }
    }
    (xs.clone(), held, scale)
}

/// The block path and the full path solve the same systems (each
/// derivative is exact on its block: the pencil is block diagonal), so
/// they agree to the solves' accuracy, and each derivative is zero off
/// its mode's block.
#[test]
fn blocks_give_the_full_pencils_derivatives() {
    let (xs, held, _) = block_and_full_derivatives(0.0);
    for (j, &h) in held.iter().enumerate() {
        for i in (0..xs.nrows()).filter(|i| i % 2 != h) {
            assert_eq!(xs[(i, j)], 0.0);
        }
    }
}

/// A K' that couples the blocks of a block-diagonal K (one ply of a
/// symmetric stack: membrane–bending coupling in K' only): each mode's
/// derivative is solved by Nelson's method on its block and by a plain
/// solve on the other, and agrees with the full pencil's, including the
/// part on the other block, which is not zero.
#[test]
fn coupled_derivatives_on_blocks_match_the_full_pencil() {
    let (xs, held, scale) = block_and_full_derivatives(40.0);
    let mut off_block = 0.0f64;
    for (j, &h) in held.iter().enumerate() {
        for i in (0..xs.nrows()).filter(|i| i % 2 != h) {
            off_block = off_block.max(xs[(i, j)].abs());
        }
    }
    assert!(off_block > 1e-3 * scale, "{off_block:e} of {scale:e}");
}

/// A non-zero coupling in K joins the blocks, one in a K' couples them;
/// a vector with weight in both blocks is held by neither.
#[test]
fn coupling_joins_blocks_and_mixed_vectors_have_no_block() {
    let m = 6;
    let mass = vec![1.0; 2 * m];
    let k0 = chains(m, 0.0, stiffness);
    let dk0 = chains(m, 0.0, alpha);
    let pencil = Pencil::new(&k0, &mass).unwrap();
    let mut blocks = None;
    Blocks::refresh(&mut blocks, &pencil).unwrap();
    let b = blocks.as_mut().expect("uncoupled chains split");
    b.couple(&[&dk0]);
    assert!(!b.coupled(0, 1));
    let mut x = Mat::<f64>::zeros(2 * m, 1);
    x[(2, 0)] = 1.0;
    assert_eq!(b.holding(x.as_ref(), &mass), Some(0));
    x[(3, 0)] = 1e-6;
    assert_eq!(b.holding(x.as_ref(), &mass), None);
    let dk1 = chains(m, 1e-9, alpha);
    b.couple(&[&dk0, &dk1]);
    assert!(b.coupled(0, 1) && b.coupled(1, 0), "K' couples the chains");
    assert!(!b.coupled(0, 0));
    let k1 = chains(m, 1e-9, stiffness);
    let pencil = Pencil::new(&k1, &mass).unwrap();
    Blocks::refresh(&mut blocks, &pencil).unwrap();
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
    let var = [DesignDerivative {
        dk: &dk,
        d2k: None,
        mass: None,
    }];
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

/// A new lumped mass on a reused solver ([`ModalSolver::set_mass`], a
/// design whose ply thicknesses moved M) reaches the modes and, through
/// the kept blocks, the updated-mode derivatives: the same bits as a
/// solver made with that mass. A bad mass is refused and leaves the
/// solver as it was.
#[test]
fn a_new_mass_reaches_the_modes_and_the_blocks() {
    let m = 20;
    let k = chains(m, 0.0, stiffness);
    let dk = chains(m, 0.0, alpha);
    let mass = |scale: f64| -> Vec<f64> {
        (0..2 * m)
            .map(|i| scale * (1.0 + 0.3 * ((i as f64) * 0.7).sin()))
            .collect()
    };
    let (m0, m1) = (mass(1.0), mass(1.7));
    let dm = mass(0.4);
    let var = [DesignDerivative {
        dk: &dk,
        d2k: None,
        mass: Some(crate::modal::MassDerivative { dm: &dm, d2m: None }),
    }];
    let o = DerivativeOptions::default();
    let opts = ModalOptions::new(6);
    let mut reused = ModalSolver::new(&k, &m0).unwrap();
    let modes0 = reused.solve(&opts).unwrap();
    // Two uncoupled chains: the derivatives make (and keep) two blocks.
    reused.derivatives(&modes0, &var, &o).unwrap();
    reused.set_mass(&m1).unwrap();
    let got = reused.solve(&opts).unwrap();
    let got_d = reused.derivatives(&got, &var, &o).unwrap();
    let mut fresh = ModalSolver::new(&k, &m1).unwrap();
    let want = fresh.solve(&opts).unwrap();
    let want_d = fresh.derivatives(&want, &var, &o).unwrap();
    assert_eq!(got.lambda, want.lambda);
    assert_eq!(got.modes, want.modes);
    assert_eq!(got_d[0].dlambda, want_d[0].dlambda);
    assert_eq!(got_d[0].dmodes, want_d[0].dmodes);
    // λ of M1 = 1.7 M0: λ0 / 1.7, to the solver's tolerance.
    for (l1, l0) in got.lambda.iter().zip(&modes0.lambda) {
        assert!((l1 * 1.7 / l0 - 1.0).abs() < 1e-9, "{l1} vs {l0}");
    }
    let mut bad = m1.clone();
    bad[3] = 0.0;
    assert!(reused
        .set_mass(&bad)
        .unwrap_err()
        .to_string()
        .contains("mass[3]"));
    assert!(reused.set_mass(&m1[1..]).is_err());
    assert_eq!(reused.solve(&opts).unwrap().lambda, want.lambda);
}
