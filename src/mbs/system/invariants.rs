//! The inertia invariants of a flexible body in the scalar type of an
//! evaluation, with the design derivatives folded in (the lift a dual
//! evaluation seeds with the ply-angle lanes).

#![allow(clippy::needless_range_loop)] // index-heavy small dense kernels

use crate::mbs::math::{cst, Scalar};
use crate::mbs::model::{Flex, Invariants};
use nalgebra::{Matrix3, Vector3};

/// The invariants in the scalar type of an evaluation, with the design
/// derivatives folded in: each entry is `x + Σ_v (∂x/∂b_v) δ_v` where
/// `δ_v` is the dual part of design variable `v` (zero in plain
/// evaluations, which never build this lifted copy).
#[derive(Debug, Clone)]
pub struct InvT<T: Scalar> {
    /// Number of modes `n`.
    pub n: usize,
    /// Total mass `Σ m_k` (kg).
    pub mass: T,
    /// First moment `Σ m_k s_k`, frame axes (kg·m).
    pub s0: Vector3<T>,
    /// Second moment `Σ m_k s_k s_kᵀ`, frame axes (kg·m²).
    pub e0: Matrix3<T>,
    /// `Σ m_k Φ_k`, 3 × n row-major: `[c·n + j]`.
    pub i3: Vec<T>,
    /// `Σ m_k s_k × Φ_kj`, 3 × n row-major: `[c·n + j]`.
    pub ls: Vec<T>,
    /// `P_j = Σ m_k Φ_kj s_kᵀ`, n blocks of 3 × 3: `[j·9 + 3r + c]`.
    pub p: Vec<T>,
    /// `Q_ij = Σ m_k Φ_ki Φ_kjᵀ`, n² blocks of 3 × 3: `[(i·n + j)·9 + 3r + c]`.
    pub q: Vec<T>,
    /// `V_ij = Σ m_k Φ_ki × Φ_kj`, n² vectors of 3: `[(i·n + j)·3 + c]`.
    pub v: Vec<T>,
    /// Sum of the nodal rotary inertias `Σ J_k`, frame axes (kg·m²).
    pub j_rot: Matrix3<T>,
    /// `Σ J_k Ψ_k`, 3 × n row-major: `[c·n + j]`.
    pub c_rot: Vec<T>,
    /// Modal mass `Σ m_k Φ_kᵀΦ_k + Ψ_kᵀJ_kΨ_k`, n × n row-major: `[i·n + j]`.
    pub mww: Vec<T>,
    /// Eigenvalues Λ (1/s²), length n.
    pub lambda: Vec<T>,
    /// The modal geometric stiffness of the unit load cases
    /// ([`crate::mbs::model::geometric`]), `CASES` blocks of n × n; empty
    /// when the body has none.
    pub kg: Vec<T>,
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
            // Constant unless a variable moves the node masses (a ply
            // thickness): then lifted like the others.
            mass: d.iter().fold(cst::<T>(inv.mass), |acc, (di, t)| {
                if di.mass == 0.0 {
                    acc
                } else {
                    acc + cst::<T>(di.mass) * *t
                }
            }),
            s0: d.iter().fold(inv.s0.map(cst::<T>), |acc, (di, t)| {
                if di.s0 == Vector3::zeros() {
                    acc
                } else {
                    acc + di.s0.map(cst::<T>) * *t
                }
            }),
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
            kg: vec(&|i| &i.kg),
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
