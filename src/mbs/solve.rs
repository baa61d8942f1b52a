//! The per-evaluation linear algebra of [`System`]: `M⁻¹` per body and
//! the constraint-space solve for the multipliers and accelerations (see
//! the method in [`super::dynamics`]).

use super::dynamics::{pval, System, Workspace, RANK_REG, RANK_TOL, RIGID};
use super::linalg::{cst, min_degree_order, Scalar};
use super::model::Param;
use nalgebra::Vector3;

impl System {
    /// `M⁻¹ x` for slot `s` (in place).
    fn apply_minv<T: Scalar>(
        &self,
        ws_mfac: &[Vec<T>],
        params: &[(Param, T)],
        s: usize,
        x: &mut [T],
    ) {
        if self.modes[s] > 0 {
            T::dense_solve(&ws_mfac[s], self.dof(s), x);
            return;
        }
        let b = self.moving[s];
        let body = &self.model.bodies[b];
        let im = T::one() / pval(params, Param::Mass(b), body.mass);
        let w = body.inv_inertia.map(cst::<T>) * Vector3::new(x[3], x[4], x[5]);
        for c in 0..3 {
            x[c] *= im;
            x[3 + c] = w[c];
        }
    }

    /// Solve for the multipliers and accelerations with the rows, applied
    /// forces and mass factors in `ws`. Returns `v̇` (velocity layout);
    /// `ws.rhs` = λ.
    pub(crate) fn solve<T: Scalar>(&self, ws: &mut Workspace<T>) -> Vec<T> {
        let m = ws.rows.len();
        let nb = self.nb();
        let mut mq = ws.q.clone();
        for s in 0..nb {
            let o = self.vel_local(s);
            self.apply_minv(&ws.mfac, &ws.params, s, &mut mq[o..o + self.dof(s)]);
        }
        // Rows touching each body, with d and M⁻¹d in the arena.
        let mut by_body = std::mem::take(&mut ws.by_body);
        by_body.resize_with(nb, Vec::new);
        for list in by_body.iter_mut() {
            list.clear();
        }
        let mut arena = std::mem::take(&mut ws.arena);
        arena.clear();
        ws.rhs.clear();
        for (r, row) in ws.rows.iter().enumerate() {
            let mut b = row.gamma;
            for (side, (slot, blk)) in row.blocks.iter().enumerate() {
                let Some(s) = *slot else { continue };
                let d = self.dof(s);
                let off = arena.len();
                arena.extend_from_slice(blk);
                if d > 6 {
                    let mo = row.modal[side];
                    if mo == RIGID {
                        arena.extend(std::iter::repeat_n(T::zero(), d - 6));
                    } else {
                        arena.extend_from_slice(&ws.mjac[mo..mo + d - 6]);
                    }
                }
                arena.extend_from_within(off..off + d);
                self.apply_minv(&ws.mfac, &ws.params, s, &mut arena[off + d..off + 2 * d]);
                let o = self.vel_local(s);
                b -= dot(&arena[off..off + d], &mq[o..o + d]);
                by_body[s].push((r, off));
            }
            ws.rhs.push(b);
        }
        // Fill-reducing order, computed once per workspace (the row
        // structure of a system never changes).
        if ws.inv_order.len() != m {
            let mut edges = Vec::new();
            for list in &by_body {
                for (x, (r, _)) in list.iter().enumerate() {
                    for (c, _) in list.iter().take(x) {
                        edges.push((*r, *c));
                    }
                }
            }
            let order = min_degree_order(m, &edges);
            ws.inv_order = vec![0; m];
            for (k, &r) in order.iter().enumerate() {
                ws.inv_order[r] = k;
            }
        }
        let inv = &ws.inv_order;
        ws.a.clear();
        ws.a.resize(m * m, T::zero());
        for (s, list) in by_body.iter().enumerate() {
            let d = self.dof(s);
            for (x, (r, od)) in list.iter().enumerate() {
                for (c, ow) in list.iter().take(x + 1) {
                    let (pr, pc) = (inv[*r], inv[*c]);
                    let (hi, lo) = if pr >= pc { (pr, pc) } else { (pc, pr) };
                    ws.a[hi * m + lo] += dot(&arena[*od..*od + d], &arena[ow + d..ow + 2 * d]);
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
        let mut acc = mq;
        for (s, list) in by_body.iter().enumerate() {
            let d = self.dof(s);
            let o = self.vel_local(s);
            for (r, off) in list {
                let w = &arena[off + d..off + 2 * d];
                for c in 0..d {
                    acc[o + c] += w[c] * lam[*r];
                }
            }
        }
        ws.rhs = lam;
        ws.by_body = by_body;
        ws.arena = arena;
        acc
    }
}

fn dot<T: Scalar>(a: &[T], b: &[T]) -> T {
    a.iter().zip(b).fold(T::zero(), |acc, (x, y)| acc + *x * *y)
}
