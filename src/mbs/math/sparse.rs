//! The regularised, rank-counting sparse Cholesky factorization of the
//! constraint-space matrix: a minimum-degree ordering, the symbolic
//! factorization ([`CholPattern`]), the numeric factor on its entries
//! ([`ordered_cholesky`]) and the solves.

use super::scalar::{cst, Scalar};

/// Real scratch storage of [`spd_factor`] / [`spd_solve`],
/// with the symbolic factorization they follow ([`SpdScratch::set_pattern`];
/// a dense pattern when none of the matrix's size was set).
#[derive(Debug, Clone, Default)]
pub struct SpdScratch {
    pattern: CholPattern,
    tmp: Vec<f64>,
}

impl SpdScratch {
    /// Factor every later matrix with the nonzero structure `pattern`
    /// (computed once per system: the rows touching each body never
    /// change).
    pub fn set_pattern(&mut self, pattern: CholPattern) {
        self.pattern = pattern;
    }

    /// Make `a` the zero `m × m` matrix as far as [`spd_factor`] reads
    /// it: a matrix of another size is replaced by zeros; one of this
    /// size has only the entries of the pattern (the diagonal and the
    /// possible nonzeros of `L`) set to zero, `m + nnz(L)` stores instead
    /// of `m²` (the SAR constraint-space matrix: 660 of 4225). Sound
    /// while nothing writes `a` outside the pattern: the factorization
    /// does not, and the caller scatters only entries of the matrix's own
    /// pattern, which the symbolic factorization contains.
    pub fn zero_matrix(&mut self, a: &mut Vec<f64>, m: usize) {
        if a.len() != m * m {
            a.clear();
            a.resize(m * m, 0.0);
            return;
        }
        let pattern = self.pattern(m);
        for (i, cols) in pattern.row_cols.iter().enumerate() {
            for &j in cols {
                a[i * m + j] = 0.0;
            }
            a[i * m + i] = 0.0;
        }
    }

    /// Replace row and column `p` of the lower triangle of `a` by the
    /// unit row (a row left out of the solve: its multiplier is zero):
    /// the entries of the pattern in row `p` and column `p` are set to
    /// zero, the diagonal to one; the others are zero already
    /// ([`SpdScratch::zero_matrix`]).
    pub fn unit_row(&mut self, a: &mut [f64], m: usize, p: usize) {
        let pattern = self.pattern(m);
        for &c in &pattern.row_cols[p] {
            a[p * m + c] = 0.0;
        }
        for &q in &pattern.col_rows[p] {
            a[q * m + p] = 0.0;
        }
        a[p * m + p] = 1.0;
    }

    /// The pattern for an `m × m` matrix: the one set, or a dense one.
    fn pattern(&mut self, m: usize) -> &CholPattern {
        if self.pattern.n != m {
            self.pattern = CholPattern::dense(m);
        }
        &self.pattern
    }
}

/// The symbolic Cholesky factorization of a sparse symmetric matrix in
/// its stored order: which entries of `L` (fill included) can be nonzero.
/// Computed once per system; the numeric factorization and the solves
/// then touch only these entries (the SAR constraint-space factor: 595
/// of the 2145 lower-triangle entries).
#[derive(Debug, Clone, Default)]
pub struct CholPattern {
    n: usize,
    /// Per column `k`: the rows `r > k` of its possible nonzeros, sorted.
    col_rows: Vec<Vec<usize>>,
    /// Per row `i`: the columns `j < i` of its possible nonzeros, sorted.
    row_cols: Vec<Vec<usize>>,
}

impl CholPattern {
    /// From the off-diagonal nonzeros `(i, j)` of the matrix (either
    /// triangle) by symbolic elimination: eliminating column `k` joins
    /// every pair of rows below it that it touches (`O(n³)` bit
    /// operations, once, for a few hundred rows at most).
    pub fn new(n: usize, entries: &[(usize, usize)]) -> CholPattern {
        let mut nz = vec![vec![false; n]; n];
        for &(i, j) in entries {
            if i != j {
                nz[i.max(j)][i.min(j)] = true;
            }
        }
        let mut col_rows = Vec::with_capacity(n);
        for k in 0..n {
            let rows: Vec<usize> = (k + 1..n).filter(|&r| nz[r][k]).collect();
            for (x, &r) in rows.iter().enumerate() {
                for &c in &rows[..x] {
                    nz[r][c] = true;
                }
            }
            col_rows.push(rows);
        }
        let row_cols = (0..n)
            .map(|i| (0..i).filter(|&j| nz[i][j]).collect())
            .collect();
        CholPattern {
            n,
            col_rows,
            row_cols,
        }
    }

    /// Every entry possibly nonzero.
    pub fn dense(n: usize) -> CholPattern {
        CholPattern {
            n,
            col_rows: (0..n).map(|k| (k + 1..n).collect()).collect(),
            row_cols: (0..n).map(|i| (0..i).collect()).collect(),
        }
    }

    /// Possible nonzeros of `L` below the diagonal.
    pub fn nnz(&self) -> usize {
        self.col_rows.iter().map(Vec::len).sum()
    }
}

/// Factor the constraint-space matrix `a` (lower triangle, row-major
/// `m × m`) in place by [`ordered_cholesky`] on the pattern of `sc`.
pub fn spd_factor(
    a: &mut [f64],
    m: usize,
    scale: &mut Vec<f64>,
    tols: (f64, f64),
    sc: &mut SpdScratch,
) -> Factored {
    ordered_cholesky(a, m, scale, tols, sc.pattern(m))
}

/// Solve with the factor of [`spd_factor`] (`b` overwritten).
pub fn spd_solve(
    a: &[f64],
    m: usize,
    scale: &[f64],
    f: Factored,
    b: &mut [f64],
    sc: &mut SpdScratch,
) {
    sc.pattern(m);
    cholesky_solve(a, (scale, &sc.pattern), f.accepted, b, &mut sc.tmp);
}

/// [`spd_solve`] for `nc` right-hand sides at once, stored interleaved
/// (`b[i * nc + c]`: entry `i` of column `c`). Each column gets exactly
/// the operations, in the order, of [`spd_solve`] (the same results to
/// the bit); the factor and its pattern are read once for all columns.
pub fn spd_solve_many(
    a: &[f64],
    m: usize,
    scale: &[f64],
    f: Factored,
    nc: usize,
    b: &mut [f64],
    sc: &mut SpdScratch,
) {
    sc.pattern(m);
    let (pattern, tmp) = (&sc.pattern, &mut sc.tmp);
    let acc = f.accepted;
    tmp.clear();
    tmp.extend((0..acc * nc).map(|x| b[x] * scale[x / nc]));
    // Fixed column counts get loops the compiler unrolls across the
    // columns; the operations are the same.
    let l = (a, m, pattern, acc);
    match nc {
        2 => substitute::<2>(l, nc, tmp),
        4 => substitute::<4>(l, nc, tmp),
        8 => substitute::<8>(l, nc, tmp),
        _ => substitute::<0>(l, nc, tmp),
    }
    b.fill(0.0);
    for (x, t) in tmp.iter().enumerate() {
        b[x] = t * scale[x / nc];
    }
}

/// The forward and backward substitutions of [`spd_solve_many`] on the
/// `nc` interleaved columns of `tmp`; `N` = `nc` when it is not 0 (a
/// column count known at compile time), 0 for any `nc`.
fn substitute<const N: usize>(
    (a, m, pattern, acc): (&[f64], usize, &CholPattern, usize),
    nc: usize,
    tmp: &mut [f64],
) {
    let nc = if N == 0 { nc } else { N };
    for k in 0..acc {
        let (done, rest) = tmp.split_at_mut(k * nc);
        let s = &mut rest[..nc];
        for &j in &pattern.row_cols[k] {
            let l = a[k * m + j];
            for (x, t) in s.iter_mut().zip(&done[j * nc..(j + 1) * nc]) {
                *x -= l * t;
            }
        }
        let d = a[k * m + k];
        s.iter_mut().for_each(|x| *x /= d);
    }
    for k in (0..acc).rev() {
        let (head, later) = tmp.split_at_mut((k + 1) * nc);
        let s = &mut head[k * nc..];
        for &r in pattern.col_rows[k].iter().take_while(|&&r| r < acc) {
            let l = a[r * m + k];
            let off = (r - k - 1) * nc;
            for (x, t) in s.iter_mut().zip(&later[off..off + nc]) {
                *x -= l * t;
            }
        }
        let d = a[k * m + k];
        s.iter_mut().for_each(|x| *x /= d);
    }
}

/// Outcome of [`ordered_cholesky`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Factored {
    /// Numerical rank: pivots whose Schur diagonal exceeds `tol`.
    pub rank: usize,
    /// Rows factored: all of them unless a pivot is not positive (possible
    /// only with `reg = 0` on a singular matrix, or non-finite input); the
    /// solve then uses the leading block.
    pub accepted: usize,
}

/// Greedy minimum-degree ordering of a symmetric sparsity pattern on `n`
/// nodes given by its off-diagonal `edges` (elimination-graph version:
/// eliminating a node joins its neighbours into a clique). Computed once
/// per system; `O(n³)` bit operations, trivial for ≤ a few hundred rows.
pub fn min_degree_order(n: usize, edges: &[(usize, usize)]) -> Vec<usize> {
    let mut adj = vec![vec![false; n]; n];
    for &(i, j) in edges {
        if i != j {
            adj[i][j] = true;
            adj[j][i] = true;
        }
    }
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for _ in 0..n {
        let degree = |v: usize, adj: &Vec<Vec<bool>>, done: &Vec<bool>| {
            (0..n).filter(|&u| !done[u] && adj[v][u]).count()
        };
        let v = (0..n)
            .filter(|&v| !done[v])
            .min_by_key(|&v| (degree(v, &adj, &done), v))
            .unwrap_or(0);
        let nb: Vec<usize> = (0..n).filter(|&u| !done[u] && adj[v][u]).collect();
        for &a in &nb {
            for &b in &nb {
                if a != b {
                    adj[a][b] = true;
                }
            }
        }
        done[v] = true;
        order.push(v);
    }
    order
}

/// Cholesky factorization of `Â + reg·I` (unit-diagonal scaling
/// `Â = S A S`, `S = diag(1/√a_kk)`) without pivoting, in the order the matrix is
/// stored (use [`min_degree_order`] to keep fill low), on the entries of
/// its symbolic factorization.
///
/// With `reg > 0` the matrix is positive definite, so no pivoting is
/// needed for stability. Each pivot is the squared distance of its row (in
/// the Gram sense) from the span of the rows before it, so the pivots not
/// exceeding `reg + tol` count the dependent rows (`n − rank`) in any
/// order. `scale` receives `S`. Only the entries of `pattern` (the
/// symbolic factorization, [`CholPattern`]) are read or written; every
/// other entry of the lower triangle must be zero.
pub fn ordered_cholesky<T: Scalar>(
    a: &mut [T],
    n: usize,
    scale: &mut Vec<T>,
    tols: (f64, f64),
    pattern: &CholPattern,
) -> Factored {
    let (tol, reg) = tols;
    let regt = cst::<T>(reg);
    let tolt = cst::<T>(tol);
    scale.clear();
    for k in 0..n {
        let d = a[k * n + k];
        scale.push(if d > T::zero() {
            T::one() / d.sqrt()
        } else {
            T::zero()
        });
    }
    for i in 0..n {
        let si = scale[i];
        for &j in &pattern.row_cols[i] {
            let v = &mut a[i * n + j];
            *v = *v * si * scale[j];
        }
        a[i * n + i] = a[i * n + i] * si * si + regt;
    }
    let mut rank = 0;
    let mut lk: Vec<T> = Vec::with_capacity(n);
    for k in 0..n {
        let d = a[k * n + k];
        if d.partial_cmp(&T::zero()) != Some(std::cmp::Ordering::Greater) {
            return Factored { rank, accepted: k };
        }
        if d - regt > tolt {
            rank += 1;
        }
        let lkk = d.sqrt();
        a[k * n + k] = lkk;
        let inv = T::one() / lkk;
        let rows = &pattern.col_rows[k];
        // Column k of L, also gathered into `lk` (contiguous) for the
        // update of the rows below it, which does not write column k.
        lk.clear();
        for &r in rows {
            let v = &mut a[r * n + k];
            *v *= inv;
            lk.push(*v);
        }
        for (ir, (&r, &lr)) in rows.iter().zip(&lk).enumerate() {
            if lr.is_exact_zero() {
                continue;
            }
            let row = &mut a[r * n..(r + 1) * n];
            for (&c, &lc) in rows[..=ir].iter().zip(&lk[..=ir]) {
                row[c] -= lr * lc;
            }
        }
    }
    Factored { rank, accepted: n }
}

/// Solve `(Â + reg·I)(S⁻¹x) = S b` with the factor of [`ordered_cholesky`]
/// (`accepted` = [`Factored::accepted`], normally all rows): forward and
/// backward substitution with `L` over the entries of `pattern`, scaling
/// by `S` on both sides. `b` is overwritten by `x`; `tmp` is scratch.
pub fn cholesky_solve<T: Scalar>(
    l: &[T],
    (scale, pattern): (&[T], &CholPattern),
    accepted: usize,
    b: &mut [T],
    tmp: &mut Vec<T>,
) {
    let n = pattern.n;
    tmp.clear();
    tmp.extend((0..accepted).map(|k| b[k] * scale[k]));
    for k in 0..accepted {
        let mut s = tmp[k];
        for &j in &pattern.row_cols[k] {
            s -= l[k * n + j] * tmp[j];
        }
        tmp[k] = s / l[k * n + k];
    }
    for k in (0..accepted).rev() {
        let mut s = tmp[k];
        for &r in pattern.col_rows[k].iter().take_while(|&&r| r < accepted) {
            s -= l[r * n + k] * tmp[r];
        }
        tmp[k] = s / l[k * n + k];
    }
    for v in b.iter_mut() {
        *v = T::zero();
    }
    for k in 0..accepted {
        b[k] = tmp[k] * scale[k];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multi_column_solve_is_the_single_solve_to_the_bit() {
        // A sparse SPD matrix (a band plus a coupling row, rank-deficient
        // by one duplicated row so the regularised pivot is met too) on its
        // symbolic pattern: 2, 3 and 8 right-hand sides solved together
        // (the fixed-count and the general substitutions) equal, bit for
        // bit, single solves (spd_solve_many's contract).
        let n = 7;
        let g = |i: usize, k: usize| {
            let i = if i == 6 { 2 } else { i };
            (((i * 5 + k * 3) % 11) as f64 - 5.0) / 4.0 + if i == k { 2.0 } else { 0.0 }
        };
        let mut a = vec![0.0; n * n];
        let mut edges = Vec::new();
        for i in 0..n {
            for j in 0..=i {
                let coupled = i == j || i - j <= 2 || i == 6;
                if coupled {
                    a[i * n + j] = (0..n).map(|k| g(i, k) * g(j, k)).sum();
                    if i != j {
                        edges.push((i, j));
                    }
                }
            }
        }
        let mut sc = SpdScratch::default();
        sc.set_pattern(CholPattern::new(n, &edges));
        let mut scale = Vec::new();
        let f = spd_factor(&mut a, n, &mut scale, (1e-8, 1e-12), &mut sc);
        assert_eq!(f.rank, n - 1);
        for nc in [2, 3, 8] {
            let cols: Vec<Vec<f64>> = (0..nc)
                .map(|c| {
                    (0..n)
                        .map(|i| ((i * 7 + c * 13) % 9) as f64 - 4.3)
                        .collect()
                })
                .collect();
            let mut many: Vec<f64> = (0..n * nc).map(|x| cols[x % nc][x / nc]).collect();
            spd_solve_many(&a, n, &scale, f, nc, &mut many, &mut sc);
            for (c, col) in cols.iter().enumerate() {
                let mut one = col.clone();
                spd_solve(&a, n, &scale, f, &mut one, &mut sc);
                for i in 0..n {
                    assert_eq!(
                        many[i * nc + c].to_bits(),
                        one[i].to_bits(),
                        "{nc} columns: column {c}, row {i}"
                    );
                }
            }
        }
    }

    #[test]
    fn ordered_cholesky_counts_rank_and_solves_regularised_system() {
        // A = G Gᵀ with G 4×3 whose 4th row = row0 + row1 (rank 3):
        // identity construction, closed form derived in this test. The
        // right-hand side is in the range of A (consistent).
        let g = [
            [1.0, 2.0, 0.5],
            [0.0, 1.0, -1.0],
            [3.0, 0.0, 1.0],
            [1.0, 3.0, -0.5],
        ];
        let n = 4;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..3).map(|k| g[i][k] * g[j][k]).sum();
            }
        }
        let a0 = a.clone();
        let b0: Vec<f64> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| a0[i * n + j] * [0.3, -1.2, 0.7, 0.0][j])
                    .sum()
            })
            .collect();
        let mut b = b0.clone();
        let (mut scale, mut tmp) = (vec![], vec![]);
        let dense = CholPattern::dense(n);
        let f = ordered_cholesky(&mut a, n, &mut scale, (1e-8, 1e-12), &dense);
        assert_eq!((f.rank, f.accepted), (3, 4));
        cholesky_solve(&a, (&scale, &dense), n, &mut b, &mut tmp);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| a0[i * n + j] * b[j]).sum::<f64>() - b0[i];
            assert!(r.abs() < 1e-9, "row {i} residual {r}");
        }
        // The same matrix on its symbolic factorization (all entries
        // are coupled here: the pattern is dense) gives the same factor.
        let edges: Vec<(usize, usize)> = (0..n).flat_map(|i| (0..i).map(move |j| (i, j))).collect();
        let sym = CholPattern::new(n, &edges);
        assert_eq!(sym.nnz(), dense.nnz());
        // Minimum degree on a path 0-1-2-3 eliminates an end first.
        let order = min_degree_order(4, &[(0, 1), (1, 2), (2, 3)]);
        assert!(order[0] == 0 || order[0] == 3);
    }

    #[test]
    fn symbolic_pattern_has_the_fill_and_factors_like_the_dense_one() {
        // An arrow: row 0 coupled to every other row. Eliminated first it
        // fills the whole lower triangle (the classic worst order); last,
        // it fills nothing. Exact counts from the elimination graph.
        let n = 6;
        let arrow_first: Vec<(usize, usize)> = (1..n).map(|i| (i, 0)).collect();
        assert_eq!(CholPattern::new(n, &arrow_first).nnz(), n * (n - 1) / 2);
        let arrow_last: Vec<(usize, usize)> = (0..n - 1).map(|i| (n - 1, i)).collect();
        assert_eq!(CholPattern::new(n, &arrow_last).nnz(), n - 1);
        // A sparse SPD matrix (arrow last plus a band) factored and solved
        // on its pattern equals the dense-pattern factorization to the bit
        // (the skipped entries are exact zeros).
        let mut edges = arrow_last.clone();
        edges.extend((1..n - 1).map(|i| (i, i - 1)));
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            a[i * n + i] = 4.0 + i as f64;
        }
        for &(i, j) in &edges {
            a[i * n + j] = -0.5 - 0.1 * j as f64;
            a[j * n + i] = a[i * n + j];
        }
        let sparse = CholPattern::new(n, &edges);
        let dense = CholPattern::dense(n);
        let (mut a1, mut a2) = (a.clone(), a.clone());
        let (mut s1, mut s2, mut tmp) = (vec![], vec![], vec![]);
        let f1 = ordered_cholesky(&mut a1, n, &mut s1, (1e-8, 1e-12), &sparse);
        let f2 = ordered_cholesky(&mut a2, n, &mut s2, (1e-8, 1e-12), &dense);
        assert_eq!(f1, f2);
        for i in 0..n {
            for j in 0..=i {
                assert_eq!(a1[i * n + j], a2[i * n + j], "L[{i}][{j}]");
            }
        }
        let b: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let (mut x1, mut x2) = (b.clone(), b.clone());
        cholesky_solve(&a1, (&s1, &sparse), n, &mut x1, &mut tmp);
        cholesky_solve(&a2, (&s2, &dense), n, &mut x2, &mut tmp);
        assert_eq!(x1, x2);
        // And it solves the (regularised) system.
        for i in 0..n {
            let r: f64 = (0..n).map(|j| a[i * n + j] * x1[j]).sum::<f64>() - b[i];
            assert!(r.abs() < 1e-10, "row {i} residual {r}");
        }
    }
}
