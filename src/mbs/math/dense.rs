//! Dense kernels of the solve: the explicit inverse of a flexible body's
//! symmetric positive definite mass matrix (`n = 6 + modes`), its
//! Cholesky factor and solve, symmetric products, the Gram blocks
//! `g_ij = b_i · w_j` of the constraint-space matrix, and quadratic forms.

use super::scalar::{cst, Scalar};

/// In-place explicit inverse of a dense symmetric positive definite
/// matrix (row-major `n × n`, lower triangle read, both triangles
/// written): the Cholesky factor `A = L Lᵀ` ([`dense_cholesky`]), then
/// `X = L⁻¹` and `A⁻¹ = Xᵀ X`, about `n³/2` multiply–adds, each loop an
/// independent vector update. `false` at a non-positive pivot (the
/// contents are then unspecified).
pub fn spd_inverse(a: &mut [f64], n: usize) -> bool {
    if !dense_cholesky(a, n) {
        return false;
    }
    thread_local! {
        static X: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
    }
    X.with_borrow_mut(|x| {
        x.clear();
        x.resize(n * n, 0.0);
        // X = L⁻¹ row by row (row k = (e_k − Σ_{j<k} L_kj X_j) / L_kk,
        // lower triangular), each row update a vector operation.
        for k in 0..n {
            let (done, rest) = x.split_at_mut(k * n);
            let row = &mut rest[..n];
            row[k] = 1.0;
            for j in 0..k {
                let c = a[k * n + j];
                if c != 0.0 {
                    for (r, v) in row[..=j].iter_mut().zip(&done[j * n..j * n + j + 1]) {
                        *r -= c * v;
                    }
                }
            }
            let inv = 1.0 / a[k * n + k];
            for r in row[..=k].iter_mut() {
                *r *= inv;
            }
        }
        // A⁻¹ = Xᵀ X: (A⁻¹)_ij = Σ_{k ≥ max(i, j)} X_ki X_kj.
        a.fill(0.0);
        for k in 0..n {
            let xk = &x[k * n..k * n + k + 1];
            for (i, xi) in xk.iter().enumerate() {
                let out = &mut a[i * n..i * n + k + 1];
                for (o, xj) in out.iter_mut().zip(xk) {
                    *o += xi * xj;
                }
            }
        }
    });
    true
}

/// `out = S x` for a symmetric row-major `n × n` matrix `S`, as a sum of
/// its rows scaled by the entries of `x` (row `j` = column `j`): vector
/// updates, and nothing done for the zero entries of `x` (the rigid
/// part of a constraint row on a flexible body has zero modal entries).
/// Each entry is `0 + x_j S_jc + …` over `j` in increasing order; the
/// sums run 8, then 4, 2 and 1 entries at a time in registers, not
/// through `out` in memory after every row.
#[inline]
pub fn sym_times(s: &[f64], n: usize, x: &[f64], out: &mut [f64]) {
    let mut c0 = 0;
    while c0 + 8 <= n {
        sym_block::<8>(s, n, x, c0, out);
        c0 += 8;
    }
    for w in [4, 2, 1] {
        if c0 + w <= n {
            match w {
                4 => sym_block::<4>(s, n, x, c0, out),
                2 => sym_block::<2>(s, n, x, c0, out),
                _ => sym_block::<1>(s, n, x, c0, out),
            }
            c0 += w;
        }
    }
}

/// Entries `c0..c0 + W` of [`sym_times`], summed in a register block.
#[inline(always)]
fn sym_block<const W: usize>(s: &[f64], n: usize, x: &[f64], c0: usize, out: &mut [f64]) {
    let mut acc = [0.0f64; W];
    for (j, &xj) in x.iter().enumerate() {
        if xj != 0.0 {
            let row = &s[j * n + c0..j * n + c0 + W];
            for (a, v) in acc.iter_mut().zip(row) {
                *a += xj * v;
            }
        }
    }
    out[c0..c0 + W].copy_from_slice(&acc);
}

/// In-place dense Cholesky `A = L Lᵀ` of a symmetric positive definite
/// row-major `n × n` matrix (lower triangle read and overwritten).
/// Returns `false` at a non-positive pivot. For the small mass matrices
/// of flexible bodies (`6 + modes`).
pub fn dense_cholesky<T: Scalar>(a: &mut [T], n: usize) -> bool {
    for k in 0..n {
        let mut d = a[k * n + k];
        for j in 0..k {
            d -= a[k * n + j] * a[k * n + j];
        }
        if d.partial_cmp(&T::zero()) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let l = d.sqrt();
        a[k * n + k] = l;
        for r in k + 1..n {
            let mut v = a[r * n + k];
            for j in 0..k {
                v -= a[r * n + j] * a[k * n + j];
            }
            a[r * n + k] = v / l;
        }
    }
    true
}

/// Solve `L Lᵀ x = b` in place with the factor of [`dense_cholesky`].
pub fn dense_cholesky_solve<T: Scalar>(l: &[T], n: usize, b: &mut [T]) {
    for k in 0..n {
        let mut s = b[k];
        for j in 0..k {
            s -= l[k * n + j] * b[j];
        }
        b[k] = s / l[k * n + k];
    }
    for k in (0..n).rev() {
        let mut s = b[k];
        for r in k + 1..n {
            s -= l[r * n + k] * b[r];
        }
        b[k] = s / l[k * n + k];
    }
}

/// The Gram block `g_ij = b_i · w_j`, `j ≤ i` (row-major `k × k`, lower
/// triangle) of the `k` rows `b_i` of `rows` and `w_i` of `w` (both
/// row-major `k × n`): with `w_i = M⁻¹ b_i`, one body's block of the
/// constraint-space matrix (its constraint rows and applied force).
/// Four columns at a time ([`fdot4`]: the entries of `b_i` read once
/// for four dot products), each entry exactly [`fdot`]'s sum.
pub fn gram(rows: &[f64], w: &[f64], n: usize, g: &mut Vec<f64>) {
    let k = rows.len() / n;
    g.clear();
    g.resize(k * k, 0.0);
    for i in 0..k {
        let bi = &rows[i * n..(i + 1) * n];
        let mut j = 0;
        while j + 4 <= i + 1 {
            let wj = |q: usize| &w[(j + q) * n..(j + q + 1) * n];
            let d = fdot4(bi, [wj(0), wj(1), wj(2), wj(3)]);
            g[i * k + j..i * k + j + 4].copy_from_slice(&d);
            j += 4;
        }
        for j in j..=i {
            g[i * k + j] = fdot(bi, &w[j * n..(j + 1) * n]);
        }
    }
}

/// [`fdot`] of `a` with each of four vectors of its length, the
/// operations of each the same as [`fdot`]'s (the same bits), the four
/// sums side by side.
#[inline]
pub fn fdot4(a: &[f64], b: [&[f64]; 4]) -> [f64; 4] {
    let mut acc = [[0.0f64; 4]; 4];
    let m = a.len() / 4 * 4;
    for x in (0..m).step_by(4) {
        let ax = &a[x..x + 4];
        for (accv, bv) in acc.iter_mut().zip(&b) {
            let bx = &bv[x..x + 4];
            for q in 0..4 {
                accv[q] += ax[q] * bx[q];
            }
        }
    }
    std::array::from_fn(|v| {
        let tail: f64 = a[m..].iter().zip(&b[v][m..]).map(|(x, y)| x * y).sum();
        let c = &acc[v];
        (c[0] + c[1]) + (c[2] + c[3]) + tail
    })
}

/// `a · b` with four partial sums (independent additions the compiler
/// can keep in vector registers).
#[inline]
pub fn fdot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for q in 0..4 {
            acc[q] += x[q] * y[q];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// `½ vᵀ M v` of a dense row-major `d × d` matrix `m` (one sum per row,
/// then the rows in order).
pub fn quadratic_form<T: Scalar>(m: &[T], v: &[T], d: usize) -> T {
    let mut e = T::zero();
    for r in 0..d {
        let row = &m[r * d..(r + 1) * d];
        let mv = row
            .iter()
            .zip(v)
            .fold(T::zero(), |acc, (a, b)| acc + *a * *b);
        e += v[r] * mv;
    }
    e * cst::<T>(0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocked_products_equal_the_plain_sums_to_the_bit() {
        // sym_times (8-entry register blocks and a tail) against the sum
        // row by row through `out`, and gram (four dot products at once
        // and single ones) against fdot entry by entry, for sizes with
        // and without a tail; x has zero entries that are skipped.
        let v = |k: usize| ((k * 37 % 101) as f64 - 50.0) / 7.0 + 1e-3 * k as f64;
        for n in [5, 8, 13, 20, 23] {
            let s: Vec<f64> = (0..n * n).map(|k| v(k + n)).collect();
            let x: Vec<f64> = (0..n)
                .map(|j| if j % 3 == 1 { 0.0 } else { v(j) })
                .collect();
            let mut plain = vec![0.0; n];
            for (j, &xj) in x.iter().enumerate() {
                if xj != 0.0 {
                    for (o, sv) in plain.iter_mut().zip(&s[j * n..(j + 1) * n]) {
                        *o += xj * sv;
                    }
                }
            }
            let mut out = vec![f64::NAN; n];
            sym_times(&s, n, &x, &mut out);
            for c in 0..n {
                assert_eq!(out[c].to_bits(), plain[c].to_bits(), "n {n}, entry {c}");
            }
            let k = 9;
            let rows: Vec<f64> = (0..k * n).map(|q| v(3 * q + 1)).collect();
            let w: Vec<f64> = (0..k * n).map(|q| v(5 * q + 2)).collect();
            let mut g = Vec::new();
            gram(&rows, &w, n, &mut g);
            for i in 0..k {
                for j in 0..=i {
                    let f = fdot(&rows[i * n..(i + 1) * n], &w[j * n..(j + 1) * n]);
                    assert_eq!(g[i * k + j].to_bits(), f.to_bits(), "n {n}, g[{i}][{j}]");
                }
            }
        }
    }

    #[test]
    fn dense_cholesky_solves_spd_system() {
        // A = B Bᵀ + I (SPD by construction); residual check.
        let n = 5;
        let b: Vec<f64> = (0..n * n)
            .map(|k| ((k * 7 % 11) as f64 - 5.0) / 3.0)
            .collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum::<f64>()
                    + if i == j { 1.0 } else { 0.0 };
            }
        }
        let a0 = a.clone();
        let rhs: Vec<f64> = (0..n).map(|k| k as f64 - 1.5).collect();
        let mut x = rhs.clone();
        assert!(dense_cholesky(&mut a, n));
        dense_cholesky_solve(&a, n, &mut x);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| a0[i * n + j] * x[j]).sum::<f64>() - rhs[i];
            assert!(r.abs() < 1e-12);
        }
    }
}
