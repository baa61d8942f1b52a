//! The tangent of the constraint-space solve ([`super::solve`]) for the
//! lanes of a dual-number evaluation.
//!
//! The solve gives `v̇ = M⁻¹(Q + Gᵀλ)` with `(A + εD) λ = γ − G M⁻¹ Q`,
//! `A = G M⁻¹ Gᵀ`, `D = diag(A)` and `ε` = [`RANK_REG`] (the regularised
//! system that [`crate::mbs::math::ordered_cholesky`] factors). A dual
//! evaluation carries, per lane, the derivatives `G'`, `M'`, `Q'`, `γ'`
//! of the assembled quantities. Differentiating `M v̇ = Q + Gᵀλ` and the
//! equation for λ gives, with `r₁ = Q' − M' v̇ + G'ᵀλ` and
//! `r₂ = γ' − G' v̇`,
//!
//! ```text
//!   (A + εD) λ' = r₂ − G M⁻¹ r₁ − ε D' λ,     v̇' = M⁻¹ (r₁ + Gᵀ λ'),
//! ```
//!
//! `D'_ii = Σ_b (2 d'_i·w_i − w_iᵀ M'_b w_i)` (`w_i = M_b⁻¹ d_i`). Every
//! solve reuses the real factorizations (the constraint-space Cholesky and
//! each body's inverse mass), and no derivative of `A` is ever formed: a
//! lane costs one product with each `M'_b`, `M_b⁻¹` and the rows, and one
//! constraint-space solve.
//!
//! All lanes in one pass, lane-interleaved (`x[i · nl + l]`: the lanes of
//! an entry together): the rows' and forces' lanes as the solve gathers
//! them body by body ([`BodyBlock`]), `r₁`, the right-hand sides of λ',
//! `D'`, λ' and v̇' (the prestress force `B'λ` alone stays lane-major, as
//! the prestress code writes it). Every kernel runs over the lanes
//! innermost (vector instructions across lanes) and gives each lane the
//! operations, in the order, of the scalar kernels of the real solve
//! ([`fdot`], [`sym_times`]), so that a lane's numbers do not depend on
//! how many lanes ride together, nor on the layout. The one exception is
//! the quadratic forms of `D'` (`mass_lane_terms`), summed over the
//! lower triangle of `M'`; they enter only as `ε D'`.

use crate::mbs::math::{fdot, spd_solve_many, sym_times, Factored, Scalar, MAX_LANES};
use crate::mbs::model::Param;
use crate::mbs::system::{pval, BodyBlock, SolveScratch, System, Workspace, RANK_REG};

impl System {
    /// The lanes of λ' and v̇' (module doc) into `sol.dlam` and
    /// `sol.dacc` (lane-interleaved), from the real solution in `sol` and
    /// the lanes of the rows, forces and masses in `ws`, with the real
    /// constraint-space factor `f`.
    pub(super) fn tangent<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        sol: &mut SolveScratch,
        f: Factored,
    ) {
        let (m, nv, nl) = (ws.rows.len(), self.nvel(), T::NL);
        sol.dacc.clear();
        sol.dacc.resize(nv * nl, 0.0);
        let take = std::mem::take::<Vec<f64>>;
        let (mut rhs, mut dd) = (take(&mut sol.lane_rhs), take(&mut sol.dd));
        let (mut dlam, mut mp) = (take(&mut sol.lane_lam), take(&mut sol.mp));
        let mut r1 = take(&mut sol.r1);
        rhs.clear();
        dd.clear();
        dd.resize(m * nl, 0.0);
        // r₂ = γ' − G'v̇ starts as γ'.
        for row in &ws.rows {
            rhs.extend((0..nl).map(|l| row.gamma.lane_part(l)));
        }
        // B'λ of the joint-load prestress, lane-major (`nl × nvel`).
        let prestress = !ws.pcols.is_empty();
        let mut bl = take(&mut sol.bz);
        bl.clear();
        if prestress {
            let mut one = Vec::new();
            for l in 0..nl {
                self.prestress_force(ws, &sol.lam, Some(l), &mut one);
                bl.extend_from_slice(&one);
            }
        }
        let (mut dm, mut t) = ([0.0; MAX_LANES], [0.0; MAX_LANES]);
        let (dm, t) = (&mut dm[..nl], &mut t[..nl]);
        for (s, bb) in ws.blocks.iter().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            let k = bb.rows.len();
            let a = &sol.acc[o..o + d];
            // r₁ starts as Q' − M'v̇ (a rigid body's M' is diag(m'I, 0)).
            r1.clear();
            r1.extend_from_slice(&bb.lanes[k * d * nl..(k + 1) * d * nl]);
            if d > 6 {
                mass_lane_terms(&ws.mfac[s], a, &bb.w[..k * d], d, (&mut mp, &mut sol.quad));
                for (x, p) in r1.iter_mut().zip(&mp) {
                    *x -= p;
                }
                if prestress {
                    for l in 0..nl {
                        let b = &bl[l * nv + o + 6..l * nv + o + d];
                        for (x, b) in r1[6 * nl..].chunks_exact_mut(nl).zip(b) {
                            x[l] -= b;
                        }
                    }
                }
            } else {
                let b = self.moving[s];
                let mass = pval(&ws.params, Param::Mass(b), self.model.bodies[b].mass);
                for (l, v) in dm.iter_mut().enumerate() {
                    *v = mass.lane_part(l);
                }
                for (x, v) in r1.chunks_exact_mut(nl).zip(&a[..3]) {
                    for (x, dm) in x.iter_mut().zip(dm.iter()) {
                        *x -= dm * v;
                    }
                }
            }
            for (i, &r) in bb.rows.iter().enumerate() {
                let wi = &bb.w[i * d..(i + 1) * d];
                let di = &bb.lanes[i * d * nl..(i + 1) * d * nl];
                let (rr, ddr) = (
                    &mut rhs[r * nl..(r + 1) * nl],
                    &mut dd[r * nl..(r + 1) * nl],
                );
                lane_dots(di, a, t);
                for (x, t) in rr.iter_mut().zip(t.iter()) {
                    *x -= t;
                }
                let lam = sol.lam[r];
                for (x, y) in r1.iter_mut().zip(di) {
                    *x += y * lam;
                }
                // D'_rr: 2 d'·w − wᵀM'w of this side.
                lane_dots(di, wi, t);
                let w2 = wi[0] * wi[0] + wi[1] * wi[1] + wi[2] * wi[2];
                for (l, (x, t)) in ddr.iter_mut().zip(t.iter()).enumerate() {
                    let quad = if d > 6 {
                        sol.quad[i * nl + l]
                    } else {
                        dm[l] * w2
                    };
                    *x += 2.0 * t - quad;
                }
            }
            // u = M⁻¹r₁ (straight into v̇'), and the right-hand side − G u.
            self.minv_lanes(bb, s, &r1, &mut sol.dacc[o * nl..(o + d) * nl]);
            for (i, &r) in bb.rows.iter().enumerate() {
                lane_dots(&r1, &bb.w[i * d..(i + 1) * d], t);
                for (x, t) in rhs[r * nl..(r + 1) * nl].iter_mut().zip(t.iter()) {
                    *x -= t;
                }
            }
        }
        for (r, (x, dd)) in rhs
            .chunks_exact_mut(nl)
            .zip(dd.chunks_exact(nl))
            .enumerate()
        {
            if sol.dropped[r] {
                x.fill(0.0);
            } else {
                for (x, dd) in x.iter_mut().zip(dd) {
                    *x -= RANK_REG * dd * sol.lam[r];
                }
            }
        }
        // λ' of every lane from one multi-column solve (the fill-reducing
        // permutation applied and undone, as in solve_factored).
        dlam.clear();
        dlam.resize(m * nl, 0.0);
        for (r, &p) in ws.inv_order.iter().enumerate() {
            dlam[p * nl..(p + 1) * nl].copy_from_slice(&rhs[r * nl..(r + 1) * nl]);
        }
        spd_solve_many(&ws.a, m, &ws.scale, f, nl, &mut dlam, &mut ws.spd);
        sol.dlam.clear();
        sol.dlam.resize(m * nl, 0.0);
        for (r, &p) in ws.inv_order.iter().enumerate() {
            sol.dlam[r * nl..(r + 1) * nl].copy_from_slice(&dlam[p * nl..(p + 1) * nl]);
        }
        if prestress {
            self.prestress_lanes(ws, sol, f, &rhs);
        }
        // v̇' = u + Σ_rows w λ'.
        for (s, bb) in ws.blocks.iter().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            let out = &mut sol.dacc[o * nl..(o + d) * nl];
            for (i, r) in bb.rows.iter().enumerate() {
                let lam = &sol.dlam[r * nl..(r + 1) * nl];
                let wi = &bb.w[i * d..(i + 1) * d];
                for (x, w) in out.chunks_exact_mut(nl).zip(wi) {
                    for (x, lr) in x.iter_mut().zip(lam) {
                        *x += w * lr;
                    }
                }
            }
        }
        (sol.lane_rhs, sol.dd, sol.lane_lam, sol.mp, sol.r1) = (rhs, dd, dlam, mp, r1);
        sol.bz = bl;
    }

    /// λ' of the joint-load prestress by the fixed-point iteration of the
    /// real solve, lane by lane, from the right-hand sides `rhs`
    /// (lane-interleaved) and the first λ' in `sol.dlam`; then
    /// `v̇' −= M⁻¹ B λ'`.
    fn prestress_lanes<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        sol: &mut SolveScratch,
        f: Factored,
        rhs: &[f64],
    ) {
        let (m, nl) = (ws.rows.len(), T::NL);
        let take = std::mem::take::<Vec<f64>>;
        let (mut z, mut r) = (take(&mut sol.prhs), take(&mut sol.plam));
        let mut next = take(&mut sol.tmp);
        let (mut lane_rhs, mut lane_lam) = (Vec::with_capacity(m), Vec::with_capacity(m));
        for l in 0..nl {
            lane_rhs.clear();
            lane_rhs.extend((0..m).map(|x| rhs[x * nl + l]));
            lane_lam.clear();
            lane_lam.extend((0..m).map(|x| sol.dlam[x * nl + l]));
            let ok = self.prestress_iterate(
                ws,
                f,
                (&lane_rhs, &sol.dropped),
                &mut lane_lam,
                (&mut z, &mut r, &mut next),
            );
            if !ok {
                lane_lam.fill(f64::NAN);
            }
            for (s, bb) in ws.blocks.iter().enumerate() {
                let (o, d) = (self.vel_local(s), self.dof(s));
                if d > 6 {
                    next.resize(d, 0.0);
                    self.minv_times(bb, s, &z[o..o + d], &mut next);
                    let out = &mut sol.dacc[o * nl..(o + d) * nl];
                    for (x, t) in out.chunks_exact_mut(nl).zip(&next) {
                        x[l] -= t;
                    }
                }
            }
            for (x, v) in lane_lam.iter().enumerate() {
                sol.dlam[x * nl + l] = *v;
            }
        }
        (sol.prhs, sol.plam, sol.tmp) = (z, r, next);
    }

    /// `M⁻¹ x` of slot `s` for every lane (`x`, `out` lane-interleaved,
    /// `dof × nl`): per lane the operations of [`System::minv_times`]
    /// ([`sym_times`] by the inverse mass of a flexible body; `diag(1/m,
    /// J'⁻¹)` of a rigid one).
    fn minv_lanes(&self, bb: &BodyBlock, s: usize, x: &[f64], out: &mut [f64]) {
        let nl = out.len() / self.dof(s);
        if self.modes[s] > 0 {
            sym_times_lanes(&bb.minv, self.dof(s), x, nl, out);
            return;
        }
        let ji = &self.model.bodies[self.moving[s]].inv_inertia;
        let lane = |c: usize| &x[c * nl..(c + 1) * nl];
        for c in 0..3 {
            for (o, x) in out[c * nl..(c + 1) * nl].iter_mut().zip(lane(c)) {
                *o = x * bb.inv_mass;
            }
            let (x3, x4, x5) = (lane(3), lane(4), lane(5));
            for (l, o) in out[(3 + c) * nl..(4 + c) * nl].iter_mut().enumerate() {
                *o = ji[(c, 0)] * x3[l] + ji[(c, 1)] * x4[l] + ji[(c, 2)] * x5[l];
            }
        }
    }
}

/// `out[l] = fdot(a_l, b)` for every lane `l` of the lane-interleaved
/// `a` (`len(b) × nl`, `nl = out.len()`) and the real `b`: per lane the
/// operations of [`fdot`] (four partial sums over the blocks of four, the
/// remainder summed in order, then `(s₀ + s₁) + (s₂ + s₃) + tail`), with
/// the lanes innermost.
fn lane_dots(a: &[f64], b: &[f64], out: &mut [f64]) {
    // Fixed lane counts get loops the compiler unrolls across the lanes.
    match out.len() {
        1 => out[0] = fdot(a, b),
        2 => lane_dots_n::<2>(a, b, out),
        4 => lane_dots_n::<4>(a, b, out),
        8 => lane_dots_n::<8>(a, b, out),
        _ => lane_dots_n::<0>(a, b, out),
    }
}

/// [`lane_dots`] with `N` = `out.len()` known at compile time, or `N` = 0
/// for any number of lanes (up to [`MAX_LANES`]).
#[inline]
fn lane_dots_n<const N: usize>(a: &[f64], b: &[f64], out: &mut [f64]) {
    let nl = if N == 0 { out.len() } else { N };
    let full = b.len() / 4 * 4;
    let mut acc = [[0.0f64; MAX_LANES]; 4];
    for (ac, bc) in a[..full * nl].chunks_exact(4 * nl).zip(b.chunks_exact(4)) {
        for (q, acc) in acc.iter_mut().enumerate() {
            for (s, ax) in acc[..nl].iter_mut().zip(&ac[q * nl..(q + 1) * nl]) {
                *s += ax * bc[q];
            }
        }
    }
    for (l, o) in out.iter_mut().enumerate() {
        let tail: f64 = (full..b.len()).map(|x| a[x * nl + l] * b[x]).sum();
        *o = (acc[0][l] + acc[1][l]) + (acc[2][l] + acc[3][l]) + tail;
    }
}

/// [`sym_times`] for every lane: `out = S x` with `S` symmetric
/// row-major `n × n` and `x`, `out` lane-interleaved (`n × nl`). Per lane
/// the sums of [`sym_times`] in its order (its skipped zero entries of `x`
/// add `±0`, which leaves every finite sum as it was).
fn sym_times_lanes(s: &[f64], n: usize, x: &[f64], nl: usize, out: &mut [f64]) {
    if nl == 1 {
        sym_times(s, n, x, out);
        return;
    }
    out.fill(0.0);
    for (j, xj) in x.chunks_exact(nl).enumerate() {
        for (o, v) in out.chunks_exact_mut(nl).zip(&s[j * n..(j + 1) * n]) {
            for (o, xj) in o.iter_mut().zip(xj) {
                *o += xj * v;
            }
        }
    }
}

/// Every lane's `M'_l v` and `w_iᵀ M'_l w_i` from one pass over a
/// flexible body's dual mass matrix `s` (row-major `d × d`, symmetric;
/// the lanes of each entry are `M'`, [`Scalar::dense_factor`]) for the
/// `k` rows `w_i` of `w` (row-major `k × d`). Outputs lane-interleaved:
/// `mv[i * nl + l]`, `q[i * nl + l]`.
///
/// The operations per lane of `M'v` are those of [`sym_times`] (zero
/// entries of `v` skipped), so every lane's numbers are those of the
/// lane-by-lane product. The quadratic forms read the lower triangle of
/// `M'` only, half the products of a full `wᵀ(M'w)`; they enter the
/// tangent only through `ε D'` (module doc), so their rounding, which
/// differs from that of the full product in the last bits, is multiplied
/// by `ε` = 1e-12 there.
fn mass_lane_terms<T: Scalar>(
    s: &[T],
    v: &[f64],
    w: &[f64],
    d: usize,
    (mv, q): (&mut Vec<f64>, &mut Vec<f64>),
) {
    let nl = T::NL;
    let k = w.len() / d;
    mv.clear();
    mv.resize(d * nl, 0.0);
    for (j, &vj) in v.iter().enumerate() {
        if vj != 0.0 {
            for (i, e) in s[j * d..(j + 1) * d].iter().enumerate() {
                for (l, o) in mv[i * nl..(i + 1) * nl].iter_mut().enumerate() {
                    *o += vj * e.lane_part(l);
                }
            }
        }
    }
    q.clear();
    q.resize(k * nl, 0.0);
    // w_cᵀ M'_l w_c = Σ_x w_x (M'_xx w_x + 2 Σ_{j<x} M'_xj w_j): the lower
    // triangle only (M' is symmetric), every lane at once.
    let (mut acc, mut inner) = ([0.0; MAX_LANES], [0.0; MAX_LANES]);
    let (acc, inner) = (&mut acc[..nl], &mut inner[..nl]);
    for (wc, qc) in w.chunks_exact(d).zip(q.chunks_exact_mut(nl)) {
        acc.fill(0.0);
        for (x, &wx) in wc.iter().enumerate() {
            if wx == 0.0 {
                continue;
            }
            let row = &s[x * d..x * d + x + 1];
            inner.fill(0.0);
            for (e, &wj) in row[..x].iter().zip(&wc[..x]) {
                for (l, a) in inner.iter_mut().enumerate() {
                    *a = e.lane_part(l).mul_add(wj, *a);
                }
            }
            for (l, a) in acc.iter_mut().enumerate() {
                let diag = row[x].lane_part(l) * wx;
                *a = wx.mul_add(2.0 * inner[l] + diag, *a);
            }
        }
        qc.copy_from_slice(acc);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::math::DualN;

    #[test]
    fn all_lane_mass_terms_are_the_lane_by_lane_products() {
        // A symmetric dual matrix whose 8 lanes are 8 symmetric matrices
        // M'_l, a vector v with zero entries and k rows w_i (some entries
        // zero): the one-pass kernel must give, per lane, the numbers of
        // sym_times (M'_l v) to the bit, and the quadratic forms
        // w_iᵀ M'_l w_i = Σ_jk M'_jk w_ij w_ik of the definition to
        // rounding (1e-14 of Σ_jk |M'_jk w_ij w_ik|). Sizes of the SAR
        // panels (6 + 14) and others.
        let f = |k: usize| ((k as f64 * 0.618_033_988_7 + 0.1).fract() - 0.5) * 7.0;
        let mut bad = Vec::new();
        for (d, k) in [6, 8, 9, 12, 16, 20, 26, 34]
            .into_iter()
            .flat_map(|d| (1..=24).map(move |k| (d, k)))
        {
            let mut s = vec![DualN::<8>::cst(0.0); d * d];
            for i in 0..d {
                for j in 0..=i {
                    let lanes = std::array::from_fn(|l| f(1000 * (l + 1) + i * d + j));
                    let e = DualN::<8>::new(f(i * d + j), lanes);
                    s[i * d + j] = e;
                    s[j * d + i] = e;
                }
            }
            let v: Vec<f64> = (0..d)
                .map(|j| if j % 5 == 3 { 0.0 } else { f(50_000 + j) })
                .collect();
            let w: Vec<f64> = (0..k * d)
                .map(|x| if x % 11 == 4 { 0.0 } else { f(70_000 + x) })
                .collect();
            let (mut mv, mut q) = (Vec::new(), Vec::new());
            mass_lane_terms(&s, &v, &w, d, (&mut mv, &mut q));
            for l in 0..8 {
                let mp: Vec<f64> = s.iter().map(|e| e.eps[l]).collect();
                let mut want = vec![0.0; d];
                sym_times(&mp, d, &v, &mut want);
                let same_mv = (0..d).all(|i| mv[i * 8 + l].to_bits() == want[i].to_bits());
                let same_q = (0..k).all(|i| {
                    let wi = &w[i * d..(i + 1) * d];
                    let terms = (0..d * d).map(|x| mp[x] * wi[x / d] * wi[x % d]);
                    let (sum, size) = terms.fold((0.0, 0.0), |(s, a), t| (s + t, a + t.abs()));
                    (q[i * 8 + l] - sum).abs() <= 1e-14 * size
                });
                if !(same_mv && same_q) {
                    bad.push((d, k, l, same_mv, same_q));
                }
            }
        }
        assert!(
            bad.is_empty(),
            "(d, k, lane, M'v equal, quad within rounding): {bad:?}"
        );
    }

    #[test]
    fn lane_kernels_are_the_scalar_kernels_lane_by_lane_to_the_bit() {
        // lane_dots against fdot and sym_times_lanes against sym_times, for
        // 1, 2, 3, 4 and 8 interleaved lanes (3: the general path), lengths with every remainder
        // mod 4 (fdot's tail) and zero entries (which sym_times skips).
        let f = |k: usize| ((k as f64 * 0.618_033_988_7 + 0.1).fract() - 0.5) * 7.0;
        let mut bad = Vec::new();
        for nl in [1, 2, 3, 4, 8] {
            for d in [1, 3, 6, 7, 9, 20, 26] {
                let a: Vec<f64> = (0..d * nl)
                    .map(|x| if x % 7 == 2 { 0.0 } else { f(x) })
                    .collect();
                let b: Vec<f64> = (0..d).map(|x| f(1000 + x)).collect();
                let mut s = vec![0.0; d * d];
                for i in 0..d {
                    for j in 0..=i {
                        s[i * d + j] = f(5000 + i * d + j);
                        s[j * d + i] = s[i * d + j];
                    }
                }
                let mut dots = vec![0.0; nl];
                lane_dots(&a, &b, &mut dots);
                let mut y = vec![0.0; d * nl];
                sym_times_lanes(&s, d, &a, nl, &mut y);
                for l in 0..nl {
                    let al: Vec<f64> = (0..d).map(|x| a[x * nl + l]).collect();
                    let mut want = vec![0.0; d];
                    sym_times(&s, d, &al, &mut want);
                    let same_dot = dots[l].to_bits() == fdot(&al, &b).to_bits();
                    let same_sym = (0..d).all(|i| y[i * nl + l].to_bits() == want[i].to_bits());
                    if !(same_dot && same_sym) {
                        bad.push((nl, d, l, same_dot, same_sym));
                    }
                }
            }
        }
        assert!(
            bad.is_empty(),
            "(lanes, d, lane, dot equal, S x equal): {bad:?}"
        );
    }
}
