//! Mass matrix and generalized inertia and elastic forces of a
//! floating-frame flexible body (paper Eq. 6), from the inertia
//! invariants of [`super::flex`].
//!
//! Velocities are `v = [ṙ (global), ω' (frame axes), ẇ]` (`6 + n`). With
//! `S = s0 + i3·w` (first moment), `E = e0 + Σ_j w_j (P_j + P_jᵀ) +
//! Σ_ij w_i w_j Q_ij` (second moment), `J = tr(E) I − E + j_rot` and
//! `H_j = P_j + Σ_i w_i Q_ji`, the mass matrix is
//!
//! ```text
//!       ⎡ m I      −A S̃     A i3              ⎤
//!   M = ⎢ S̃ Aᵀ     J        ls + Σ_i w_i V_i· + c_rot ⎥
//!       ⎣ sym.     sym.     mww               ⎦
//! ```
//!
//! and, with `d = i3 ẇ` and `G = Σ_j ẇ_j H_j`, the quadratic-velocity
//! forces (d'Alembert forces of the lumped masses, exact) are
//!
//! ```text
//!   Q_r = −A [ω×(ω×S) + 2 ω×d]
//!   Q_ω = −[ω×(J_tr ω) + 2(ω tr G − G ω) + ω×(j_rot ω + c_rot ẇ)]
//!   Q_j = −[ωᵀH_j ω − |ω|² tr H_j + 2 ω·Σ_i ẇ_i V_ij]
//! ```
//!
//! plus the elastic and damping forces `−Λw − 2ζ√Λ ẇ` (Eq. 6). The
//! rotary inertia of the nodes is taken as fixed in the frame (its
//! rotation by the small nodal rotations is neglected, consistently with
//! the linear finite element model); with that kinetic energy the terms
//! above conserve energy exactly, which the tests check.

#![allow(clippy::needless_range_loop)] // index-heavy small dense kernels

use super::flex::Invariants;
use super::linalg::{cst, mm, mv, Scalar};
use super::model::Flex;
use nalgebra::{Matrix3, Vector3};

/// The invariants in the scalar type of an evaluation, with the design
/// derivatives folded in: each entry is `x + Σ_v (∂x/∂b_v) δ_v` where
/// `δ_v` is the dual part of design variable `v` (zero in plain
/// evaluations, which never build this lifted copy).
#[derive(Debug, Clone)]
pub struct InvT<T: Scalar> {
    pub n: usize,
    pub mass: T,
    pub s0: Vector3<T>,
    pub e0: Matrix3<T>,
    pub i3: Vec<T>,
    pub ls: Vec<T>,
    pub p: Vec<T>,
    pub q: Vec<T>,
    pub v: Vec<T>,
    pub j_rot: Matrix3<T>,
    pub c_rot: Vec<T>,
    pub mww: Vec<T>,
    pub lambda: Vec<T>,
}

impl<T: Scalar> InvT<T> {
    /// Lift the invariants of `flex` with the design seeds `deltas`
    /// (`(variable, δ)` pairs).
    pub fn lift(flex: &Flex, deltas: &[(usize, T)]) -> InvT<T> {
        let inv = &flex.inv;
        let d: Vec<(&Invariants, T)> = deltas.iter().map(|(k, t)| (&flex.dinv[*k], *t)).collect();
        let vec = |f: &dyn Fn(&Invariants) -> &Vec<f64>| -> Vec<T> {
            let base = f(inv);
            (0..base.len())
                .map(|i| {
                    d.iter().fold(cst::<T>(base[i]), |acc, (di, t)| {
                        acc + cst::<T>(f(di)[i]) * *t
                    })
                })
                .collect()
        };
        let m3 = |f: &dyn Fn(&Invariants) -> Matrix3<f64>| -> Matrix3<T> {
            d.iter().fold(f(inv).map(cst::<T>), |acc, (di, t)| {
                acc + f(di).map(cst::<T>) * *t
            })
        };
        InvT {
            n: inv.n,
            mass: cst::<T>(inv.mass),
            s0: inv.s0.map(cst::<T>),
            e0: m3(&|i| i.e0),
            i3: vec(&|i| &i.i3),
            ls: vec(&|i| &i.ls),
            p: vec(&|i| &i.p),
            q: vec(&|i| &i.q),
            v: vec(&|i| &i.v),
            j_rot: m3(&|i| i.j_rot),
            c_rot: vec(&|i| &i.c_rot),
            mww: vec(&|i| &i.mww),
            lambda: vec(&|i| &i.lambda),
        }
    }

    /// First moment `S = s0 + i3·w` (frame axes).
    pub fn first_moment(&self, w: &[T]) -> Vector3<T> {
        let n = self.n;
        let mut s = self.s0;
        for c in 0..3 {
            for j in 0..n {
                s[c] += self.i3[c * n + j] * w[j];
            }
        }
        s
    }

    /// `i3ᵀ g` (length n) for a frame-axes vector `g`.
    pub fn i3t(&self, g: &Vector3<T>) -> Vec<T> {
        let n = self.n;
        (0..n)
            .map(|j| self.i3[j] * g[0] + self.i3[n + j] * g[1] + self.i3[2 * n + j] * g[2])
            .collect()
    }
}

/// Which terms to include.
#[derive(Debug, Clone, Copy)]
pub struct FlexEffects {
    /// Quadratic-velocity terms.
    pub quadratic: bool,
    /// Modal damping ratio (0 = none).
    pub zeta: f64,
}

/// Kinematic state of one flexible body.
pub struct FlexState<'a, T: Scalar> {
    pub a: &'a Matrix3<T>,
    /// Angular velocity in frame axes.
    pub wb: &'a Vector3<T>,
    pub w: &'a [T],
    pub wd: &'a [T],
}

/// Mass matrix (row-major `(6+n)²`, into `mass`) and the generalized
/// quadratic-velocity, elastic and damping forces (added to `force`,
/// length `6+n`) of a flexible body.
pub fn flex_terms<T: Scalar>(
    inv: &InvT<T>,
    st: &FlexState<T>,
    eff: FlexEffects,
    mass: &mut Vec<T>,
    force: &mut [T],
) {
    let n = inv.n;
    let d = 6 + n;
    let (a, wb, w, wd) = (st.a, st.wb, st.w, st.wd);
    let s = inv.first_moment(w);
    // H_j = P_j + Σ_i w_i Q_ji, then the second moment
    // E = e0 + Σ_j w_j (P_j + P_jᵀ) + Σ_j w_j (H_j − P_j) (the double sum
    // Σ_ij w_i w_j Q_ij once, through the H_j the quadratic-velocity
    // forces use too) and J_tr = tr(E) I − E.
    let mut h = Vec::with_capacity(n);
    let mut e = inv.e0;
    for j in 0..n {
        let pj = Matrix3::from_fn(|r, c| inv.p[j * 9 + 3 * r + c]);
        let mut qw = Matrix3::<T>::zeros();
        for i in 0..n {
            let o = (j * n + i) * 9;
            for r in 0..3 {
                for c in 0..3 {
                    qw[(r, c)] += inv.q[o + 3 * r + c] * w[i];
                }
            }
        }
        e += (pj + pj.transpose() + qw) * w[j];
        h.push(pj + qw);
    }
    let j_tr = Matrix3::identity() * e.trace() - e;
    // M_ωw columns: ls_j + Σ_i w_i V_ij + c_rot_j.
    let mut mwq = vec![Vector3::<T>::zeros(); n];
    for (j, col) in mwq.iter_mut().enumerate() {
        for c in 0..3 {
            col[c] = inv.ls[c * n + j] + inv.c_rot[c * n + j];
        }
        for i in 0..n {
            let o = (i * n + j) * 3;
            for c in 0..3 {
                col[c] += inv.v[o + c] * w[i];
            }
        }
    }
    mass.clear();
    mass.resize(d * d, T::zero());
    let put = |m: &mut Vec<T>, r: usize, c: usize, v: T| {
        m[r * d + c] = v;
        m[c * d + r] = v;
    };
    for k in 0..3 {
        put(mass, k, k, inv.mass);
    }
    let ast = -mm(a, &s.cross_matrix());
    for r in 0..3 {
        for c in 0..3 {
            put(mass, r, 3 + c, ast[(r, c)]);
            put(mass, 3 + r, 3 + c, j_tr[(r, c)] + inv.j_rot[(r, c)]);
        }
    }
    for j in 0..n {
        let col = Vector3::new(inv.i3[j], inv.i3[n + j], inv.i3[2 * n + j]);
        let ac = mv(a, &col);
        for r in 0..3 {
            put(mass, r, 6 + j, ac[r]);
            put(mass, 3 + r, 6 + j, mwq[j][r]);
        }
        for i in 0..=j {
            put(mass, 6 + i, 6 + j, inv.mww[i * n + j]);
        }
    }
    // Elastic and damping forces.
    let two = cst::<T>(2.0);
    for j in 0..n {
        force[6 + j] -= inv.lambda[j] * w[j];
        if eff.zeta != 0.0 {
            force[6 + j] -= two * cst::<T>(eff.zeta) * inv.lambda[j].sqrt() * wd[j];
        }
    }
    if !eff.quadratic {
        return;
    }
    let om = *wb;
    let dvec = {
        let mut v = Vector3::<T>::zeros();
        for c in 0..3 {
            for j in 0..n {
                v[c] += inv.i3[c * n + j] * wd[j];
            }
        }
        v
    };
    let qr = mv(a, &(om.cross(&om.cross(&s)) + om.cross(&dvec) * two));
    // H_j and G = Σ ẇ_j H_j.
    let mut g = Matrix3::<T>::zeros();
    let mut crot = Vector3::<T>::zeros();
    for (j, h) in h.iter().enumerate() {
        g += h * wd[j];
        // Σ_i ẇ_i V_ij.
        let mut vs = Vector3::<T>::zeros();
        for i in 0..n {
            let o = (i * n + j) * 3;
            for c in 0..3 {
                vs[c] += inv.v[o + c] * wd[i];
            }
        }
        let qj = om.dot(&mv(h, &om)) - om.norm_squared() * h.trace() + two * om.dot(&vs);
        force[6 + j] -= qj;
        for c in 0..3 {
            crot[c] += inv.c_rot[c * n + j] * wd[j];
        }
    }
    let qw = om.cross(&mv(&j_tr, &om))
        + (om * g.trace() - mv(&g, &om)) * two
        + om.cross(&(mv(&inv.j_rot, &om) + crot));
    for c in 0..3 {
        force[c] -= qr[c];
        force[3 + c] -= qw[c];
    }
}
