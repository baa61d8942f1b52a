//! Equations of motion with Lagrange multipliers (paper Eqs. 2–4, 6)
//! solved at every right-hand-side evaluation, for rigid bodies and
//! floating-frame flexible bodies.
//!
//! State vector `y`: the positions of every moving body, then their
//! velocities. Body `s` has positions `[r, p, w]` (3 + 4 + n: frame
//! origin, Euler parameters, modal coordinates; `n = 0` for a rigid body)
//! at [`System::pos_off`] and velocities `v_s = [ṙ, ω', ẇ]` (3 + 3 + n)
//! at [`System::vel_off`].
//!
//! The equations are `M v̇ = Q + Gᵀλ` with `M` block diagonal (per body:
//! `diag(m I, J')` for a rigid body with its frame at the centre of mass,
//! the dense `(6+n)²` matrix of [`crate::mbs::forces::flexbody`] for a flexible one),
//! and the constraints imposed at acceleration level with Baumgarte
//! stabilisation: `G v̇ = γ − 2αΦ̇ − α²Φ`. Because `M` is block diagonal,
//! `v̇ = M⁻¹(Q + Gᵀλ)` and `λ` solves the constraint-space system
//! `(G M⁻¹ Gᵀ) λ = γ − 2αΦ̇ − α²Φ − G M⁻¹ Q`, which is formed body by
//! body from the sparse rows of `G` (each row touches at most two bodies:
//! `G M⁻¹ Gᵀ = Σ_b G_b M_b⁻¹ G_bᵀ`, one Gram block per body,
//! `crate::mbs::constraints::solve`), permuted once into a minimum-degree order (the SAR
//! factor keeps 595 of 2145 entries)
//! and factored by Cholesky after unit-diagonal scaling and a `1e-12`
//! Tikhonov shift ([`RANK_REG`](crate::mbs::system::RANK_REG)). Redundant equations give pivots at the
//! shift level and are counted ([`RANK_TOL`](crate::mbs::system::RANK_TOL)); their multipliers take the
//! minimum-norm split, and the accelerations, which do not depend on that
//! split, stay unique. One factorization per evaluation (plus the explicit
//! inverse of each flexible body's mass). The solve is real arithmetic for
//! every scalar type: a dual-number evaluation adds its tangent with the
//! same factorizations (`crate::mbs::constraints::tangent` has the formulas), with no dual
//! arithmetic inside a factorization and no finite differences.
//!
//! Everything is generic over the scalar `T` so that `num_dual::Dual64`
//! gives exact Jacobian-vector products of the right-hand side.

use crate::mbs::math::{cst, euler_rate, Scalar};
use crate::mbs::system::{bump, System, Workspace};

impl System {
    /// Right-hand side `ẏ = f(t, y)`; also leaves the multipliers in
    /// `ws.rhs` (length = number of equations) and the rank in `ws.rank`.
    /// `t` is a plain `f64`: time never carries a derivative here.
    pub fn rhs<T: Scalar>(&self, t: f64, y: &[T], dy: &mut [T], ws: &mut Workspace<T>) {
        bump(&self.counters.rhs);
        self.kinematics(y, ws);
        for s in 0..self.nb() {
            let p = self.pos_off(s);
            let o = self.vel_off(s);
            let k = &ws.kin[s];
            dy[p] = k.v[0];
            dy[p + 1] = k.v[1];
            dy[p + 2] = k.v[2];
            let pd = euler_rate(&y[p + 3..p + 7], &k.wb);
            dy[p + 3..p + 7].copy_from_slice(&pd);
            let n = self.modes[s];
            dy[p + 7..p + 7 + n].copy_from_slice(&y[o + 6..o + 6 + n]);
        }
        self.constraints(t, ws);
        self.applied(t, ws);
        let acc = self.solve(ws);
        if let Some(f) = self.counters.prestress_failure.borrow_mut().as_mut() {
            if f.0.is_nan() {
                f.0 = t;
            }
        }
        let vo = self.voff();
        dy[vo..vo + self.nvel()].copy_from_slice(&acc);
        let io = self.integral_off();
        for (i, integral) in self.model.integrals.iter().enumerate() {
            let v = integral
                .terms
                .iter()
                .fold(T::zero(), |acc, e| acc + self.energy_term(*e, y, ws));
            dy[io + i] = v * cst::<T>(integral.scale);
        }
    }
}
