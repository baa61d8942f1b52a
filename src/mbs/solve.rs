//! The per-evaluation linear algebra of [`System`]: `M⁻¹` per body and
//! the constraint-space solve for the multipliers and accelerations (see
//! the method in [`super::dynamics`]).

use super::dynamics::{pval, System, Workspace, RANK_REG, RANK_TOL, RIGID};
use super::linalg::{cst, min_degree_order, CholPattern, Scalar};
use super::model::Param;
use super::workspace::BodyBlock;
use nalgebra::Vector3;

impl System {
    /// `M⁻¹ x` for rigid slot `s` (in place): `diag(1/m, J'⁻¹)`.
    fn rigid_minv<T: Scalar>(&self, params: &[(Param, T)], s: usize, x: &mut [T]) {
        let b = self.moving[s];
        let body = &self.model.bodies[b];
        let im = T::one() / pval(params, Param::Mass(b), body.mass);
        let w = body.inv_inertia.map(cst::<T>) * Vector3::new(x[3], x[4], x[5]);
        for c in 0..3 {
            x[c] *= im;
            x[3 + c] = w[c];
        }
    }

    /// Gather every body's block: the rows touching it (`d`: the row's
    /// `[∂/∂ṙ, ∂/∂ω', ∂/∂ẇ]` entries of that body) and, last, its applied
    /// force `Q`; then `w = M⁻¹d`, `M⁻¹Q` and the Gram block `d_i·M⁻¹d_j`
    /// of each body ([`Scalar::gram_rows`] for flexible bodies).
    fn body_blocks<T: Scalar>(&self, ws: &mut Workspace<T>) {
        let nb = self.nb();
        let mut blocks = std::mem::take(&mut ws.blocks);
        blocks.resize_with(nb, BodyBlock::default);
        for bb in blocks.iter_mut() {
            bb.rows.clear();
            bb.b.clear();
        }
        for (r, row) in ws.rows.iter().enumerate() {
            for (side, (slot, blk)) in row.blocks.iter().enumerate() {
                let Some(s) = *slot else { continue };
                let d = self.dof(s);
                let bb = &mut blocks[s];
                bb.b.extend_from_slice(blk);
                if d > 6 {
                    let mo = row.modal[side];
                    if mo == RIGID {
                        bb.b.extend(std::iter::repeat_n(T::zero(), d - 6));
                    } else {
                        bb.b.extend_from_slice(&ws.mjac[mo..mo + d - 6]);
                    }
                }
                bb.rows.push(r);
            }
        }
        for (s, bb) in blocks.iter_mut().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            bb.b.extend_from_slice(&ws.q[o..o + d]);
            if self.modes[s] > 0 {
                T::gram_rows(&ws.mfac[s], d, &bb.b, &mut bb.w, &mut bb.g);
                continue;
            }
            bb.w.clone_from(&bb.b);
            for x in bb.w.chunks_exact_mut(d) {
                self.rigid_minv(&ws.params, s, x);
            }
            let k = bb.rows.len() + 1;
            bb.g.clear();
            bb.g.resize(k * k, T::zero());
            for i in 0..k {
                for j in 0..=i {
                    bb.g[i * k + j] = dot(&bb.b[i * d..(i + 1) * d], &bb.w[j * d..(j + 1) * d]);
                }
            }
        }
        ws.blocks = blocks;
    }

    /// Solve for the multipliers and accelerations with the rows, applied
    /// forces and mass factors in `ws`. Returns `v̇` (velocity layout);
    /// `ws.rhs` = λ.
    ///
    /// Structure: `G M⁻¹ Gᵀ = Σ_bodies G_b M_b⁻¹ G_bᵀ`, each body's term a
    /// Gram block of the few rows that touch it ([`System::body_blocks`]);
    /// the matrix is scattered into a fill-reducing order, whose symbolic
    /// factorization ([`CholPattern`]) is computed once per workspace (the
    /// rows touching each body never change), and factored on that
    /// pattern by the rank-counting Cholesky of [`super::linalg`].
    pub(crate) fn solve<T: Scalar>(&self, ws: &mut Workspace<T>) -> Vec<T> {
        let m = ws.rows.len();
        self.body_blocks(ws);
        // λ's right-hand side γ − G M⁻¹ Q: the force is each block's last
        // vector, so d_i·M⁻¹Q is the block's last Gram row.
        ws.rhs.clear();
        ws.rhs.extend(ws.rows.iter().map(|row| row.gamma));
        for bb in &ws.blocks {
            let k = bb.rows.len() + 1;
            for (i, &r) in bb.rows.iter().enumerate() {
                ws.rhs[r] -= bb.g[(k - 1) * k + i];
            }
        }
        // Fill-reducing order, computed once per workspace (the row
        // structure of a system never changes).
        if ws.inv_order.len() != m {
            let mut edges = Vec::new();
            for bb in &ws.blocks {
                for (x, r) in bb.rows.iter().enumerate() {
                    for c in &bb.rows[..x] {
                        edges.push((*r, *c));
                    }
                }
            }
            let order = min_degree_order(m, &edges);
            ws.inv_order = vec![0; m];
            for (k, &r) in order.iter().enumerate() {
                ws.inv_order[r] = k;
            }
            let inv = &ws.inv_order;
            let permuted: Vec<(usize, usize)> =
                edges.iter().map(|&(r, c)| (inv[r], inv[c])).collect();
            ws.spd.set_pattern(CholPattern::new(m, &permuted));
        }
        let inv = &ws.inv_order;
        ws.a.clear();
        ws.a.resize(m * m, T::zero());
        for bb in &ws.blocks {
            let k = bb.rows.len() + 1;
            for (x, r) in bb.rows.iter().enumerate() {
                for (c, q) in bb.rows[..=x].iter().enumerate() {
                    let (pr, pc) = (inv[*r], inv[*q]);
                    let (hi, lo) = if pr >= pc { (pr, pc) } else { (pc, pr) };
                    ws.a[hi * m + lo] += bb.g[x * k + c];
                }
            }
        }
        let mut ndrop = 0;
        for (r, _) in self.drop.iter().enumerate().take(m).filter(|(_, d)| **d) {
            ndrop += 1;
            let p = inv[r];
            for c in 0..p {
                ws.a[p * m + c] = T::zero();
            }
            for q in p + 1..m {
                ws.a[q * m + p] = T::zero();
            }
            ws.a[p * m + p] = T::one();
            ws.rhs[r] = T::zero();
        }
        let f = T::spd_factor(
            &mut ws.a,
            m,
            &mut ws.scale,
            (RANK_TOL, RANK_REG),
            &mut ws.spd,
        );
        ws.rank = f.rank - ndrop;
        let mut lam = std::mem::take(&mut ws.rhs);
        ws.tmp.clear();
        ws.tmp.resize(m, T::zero());
        for r in 0..m {
            ws.tmp[inv[r]] = lam[r];
        }
        std::mem::swap(&mut lam, &mut ws.tmp);
        T::spd_solve(&ws.a, m, &ws.scale, f, &mut lam, &mut ws.spd);
        ws.tmp.clear();
        ws.tmp.extend((0..m).map(|r| lam[inv[r]]));
        std::mem::swap(&mut lam, &mut ws.tmp);
        // v̇ = M⁻¹Q + Σ_rows (M⁻¹d) λ.
        let mut acc = vec![T::zero(); self.nvel()];
        for (s, bb) in ws.blocks.iter().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            let k = bb.rows.len();
            let out = &mut acc[o..o + d];
            out.copy_from_slice(&bb.w[k * d..(k + 1) * d]);
            for (i, r) in bb.rows.iter().enumerate() {
                let w = &bb.w[i * d..(i + 1) * d];
                for c in 0..d {
                    out[c] += w[c] * lam[*r];
                }
            }
        }
        ws.rhs = lam;
        acc
    }
}

fn dot<T: Scalar>(a: &[T], b: &[T]) -> T {
    a.iter().zip(b).fold(T::zero(), |acc, (x, y)| acc + *x * *y)
}
