//! Mass matrix and generalized inertia and elastic forces of a
//! floating-frame flexible body (paper Eq. 6), from the inertia
//! invariants of [`crate::mbs::model::flex`].
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

//!
//! `System::flex_bodies` builds these terms for every flexible body of
//! an evaluation, with the invariants lifted at the design seeds
//! (`crate::mbs::system::invariants`), and factors the mass matrices.

#![allow(clippy::needless_range_loop)] // index-heavy small dense kernels

use crate::mbs::math::{cst, mm, mv, quadratic_form, spd_inverse, sym_times, Scalar};
use crate::mbs::model::{Energy, Force};
use crate::mbs::system::{bump, same_seeds, InvT, System, Workspace, SEED_SPARES};
use nalgebra::{Matrix3, Vector3};

/// Which terms to include.
#[derive(Debug, Clone, Copy)]
pub struct FlexEffects {
    /// Quadratic-velocity terms.
    pub quadratic: bool,
    /// Modal damping ratio (0 = none).
    pub zeta: f64,
    /// Geometric stiffening ([`crate::mbs::model::geometric`]): the
    /// modal geometric stiffness of the inertial prestress (the joint-load
    /// part is in `crate::mbs::constraints::prestress`), when the
    /// invariants carry it.
    pub geometric: bool,
    /// Gravity (global axes, m/s²) for the prestress of the geometric
    /// stiffening (`None`: no gravity).
    pub gravity: Option<Vector3<f64>>,
}

/// Kinematic state of one flexible body.
pub struct FlexState<'a, T: Scalar> {
    /// Rotation matrix `A` of the floating frame (frame axes → global).
    pub a: &'a Matrix3<T>,
    /// Angular velocity in frame axes.
    pub wb: &'a Vector3<T>,
    /// Modal coordinates `w` (length n).
    pub w: &'a [T],
    /// Modal rates `ẇ` (length n).
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
    for (j, (pj, qj)) in inv
        .p
        .chunks_exact(9)
        .zip(inv.q.chunks_exact(9 * n.max(1)))
        .enumerate()
    {
        let pj = Matrix3::from_fn(|r, c| pj[3 * r + c]);
        // Σ_i Q_ji w_i, entry (r, c) at 3r + c, summed over i in order.
        let mut acc = [T::zero(); 9];
        for (qji, wi) in qj.chunks_exact(9).zip(w) {
            for (a, q) in acc.iter_mut().zip(qji) {
                *a += *q * *wi;
            }
        }
        let qw = Matrix3::from_fn(|r, c| acc[3 * r + c]);
        e += (pj + pj.transpose() + qw) * w[j];
        h.push(pj + qw);
    }
    let j_tr = Matrix3::identity() * e.trace() - e;
    // M_ωw columns: ls_j + Σ_i w_i V_ij + c_rot_j.
    let mut mwq = vec![Vector3::<T>::zeros(); n];
    for (j, col) in mwq.iter_mut().enumerate() {
        let mut acc = [T::zero(); 3];
        for (c, a) in acc.iter_mut().enumerate() {
            *a = inv.ls[c * n + j] + inv.c_rot[c * n + j];
        }
        // Σ_i w_i V_ij, in order of i (V_ij at (i n + j) · 3).
        for (vi, wi) in inv.v.chunks_exact(3 * n).zip(w) {
            for (a, v) in acc.iter_mut().zip(&vi[3 * j..3 * j + 3]) {
                *a += *v * *wi;
            }
        }
        *col = Vector3::new(acc[0], acc[1], acc[2]);
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
    if eff.geometric && !inv.kg.is_empty() {
        geometric_terms(inv, st, eff.gravity, mass, force);
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
        let mut acc = [T::zero(); 3];
        for (vi, wdi) in inv.v.chunks_exact(3 * n).zip(wd) {
            for (a, v) in acc.iter_mut().zip(&vi[3 * j..3 * j + 3]) {
                *a += *v * *wdi;
            }
        }
        let vs = Vector3::new(acc[0], acc[1], acc[2]);
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

/// The geometric stiffening of a flexible body
/// ([`crate::mbs::model::geometric`]): with `K_k w` of each unit load
/// case, the `ω̇` and frame-acceleration cases go into the mass matrix
/// (`M[w_j, ω_c] += (K_{6+c} w)_j`, `M[w_j, ṙ_c] −= (A Σ_a e_a (K_{9+a}
/// w)_j)_c`, both symmetric), the `ω_aω_b` and gravity cases into the
/// modal forces (`Q_j −= Σ_k c_k (K_k w)_j`).
fn geometric_terms<T: Scalar>(
    inv: &InvT<T>,
    st: &FlexState<T>,
    gravity: Option<Vector3<f64>>,
    mass: &mut [T],
    force: &mut [T],
) {
    let n = inv.n;
    let (d, nn) = (6 + n, n * n);
    let (a, om, w) = (st.a, st.wb, st.w);
    let kw = |k: usize, j: usize| -> T {
        let row = &inv.kg[k * nn + j * n..k * nn + j * n + n];
        row.iter()
            .zip(w)
            .fold(T::zero(), |acc, (kij, wi)| acc + *kij * *wi)
    };
    let g = gravity.map(|g| mv(&a.transpose(), &g.map(cst::<T>)));
    let c = [
        om.x * om.x,
        om.y * om.y,
        om.z * om.z,
        om.x * om.y,
        om.y * om.z,
        om.z * om.x,
    ];
    for j in 0..n {
        let kt = Vector3::new(kw(9, j), kw(10, j), kw(11, j));
        let akt = mv(a, &kt);
        for col in 0..3 {
            let r = 6 + j;
            let v = mass[r * d + 3 + col] + kw(6 + col, j);
            mass[r * d + 3 + col] = v;
            mass[(3 + col) * d + r] = v;
            let v = mass[r * d + col] - akt[col];
            mass[r * d + col] = v;
            mass[col * d + r] = v;
        }
        let mut q = T::zero();
        for (k, ck) in c.iter().enumerate() {
            q += *ck * kw(k, j);
        }
        if let Some(g) = &g {
            q += g.dot(&kt);
        }
        force[6 + j] -= q;
    }
}

impl System {
    /// The invariants of flexible slot `s` in `T`, lifted again only when
    /// the design seeds differ from those of the current copy and of the
    /// `SEED_SPARES` copies lifted before.
    fn invariants<T: Scalar>(&self, s: usize, ws: &mut Workspace<T>) {
        let flex = self.model.bodies[self.moving[s]].flex.as_ref();
        let Some(flex) = flex else { return };
        ws.inv.resize_with(self.nb(), || None);
        ws.inv_seeds.resize_with(self.nb(), Vec::new);
        ws.inv_spare.resize_with(self.nb(), Vec::new);
        let design = &ws.kin[s].design;
        if ws.inv[s].is_some() && same_seeds(&ws.inv_seeds[s], design) {
            return;
        }
        // Earlier lifts are kept for evaluations that cycle through a few
        // sets of seeds (the staggered sensitivities: J·s without design
        // seeds, ∂f/∂p with one variable's).
        let spare = &mut ws.inv_spare[s];
        let (seeds, inv) = match spare.iter().position(|(sd, _)| same_seeds(sd, design)) {
            Some(i) => spare.remove(i),
            None => (design.clone(), InvT::lift(flex, design)),
        };
        let old_seeds = std::mem::replace(&mut ws.inv_seeds[s], seeds);
        if let Some(old) = ws.inv[s].replace(inv) {
            ws.inv_spare[s].insert(0, (old_seeds, old));
            ws.inv_spare[s].truncate(SEED_SPARES);
        }
    }

    /// Mass matrices of the flexible bodies (factored into `ws.mfac`) and,
    /// when `forces` is set, their inertia, elastic and damping forces
    /// (added to `ws.q`). `ws.q` must be sized.
    pub(crate) fn flex_bodies<T: Scalar>(&self, ws: &mut Workspace<T>, forces: bool) {
        ws.mfac.resize_with(self.nb(), Vec::new);
        ws.kinetic.resize(self.nb(), T::zero());
        for s in 0..self.nb() {
            let n = self.modes[s];
            if n == 0 {
                continue;
            }
            bump(&self.counters.flexible);
            self.invariants(s, ws);
            let body = &self.model.bodies[self.moving[s]];
            let zeta = body.flex.as_ref().map_or(0.0, |f| f.zeta);
            let eff = FlexEffects {
                quadratic: self.model.quadratic_velocity && forces,
                zeta: if forces { zeta } else { 0.0 },
                geometric: self.model.geometric_stiffening,
                gravity: self.model.forces.iter().find_map(|f| match f {
                    Force::Gravity { g } => Some(*g),
                    _ => None,
                }),
            };
            if eff.quadratic {
                bump(&self.counters.quadratic);
            }
            if eff.zeta != 0.0 {
                bump(&self.counters.modal_damping);
            }
            let d = 6 + n;
            let o = self.vel_local(s);
            let mut fq = vec![T::zero(); d];
            let mut mass = std::mem::take(&mut ws.mfac[s]);
            {
                let k = &ws.kin[s];
                let inv = ws.inv[s].as_ref().expect("invariants built above");
                let st = FlexState {
                    a: &k.a,
                    wb: &k.wb,
                    w: &k.q,
                    wd: &k.qd,
                };
                flex_terms(inv, &st, eff, &mut mass, &mut fq);
                if !forces || self.kinetic_integrated(self.moving[s]) {
                    let v: Vec<T> = (k.v.iter().chain(k.wb.iter()).chain(&k.qd))
                        .copied()
                        .collect();
                    ws.kinetic[s] = quadratic_form(&mass, &v, d);
                }
            }
            // A non-positive pivot leaves a NaN in the factor, which the
            // integrator reports with the time.
            if !T::dense_factor(&mut mass, d) {
                mass[0] = cst::<T>(f64::NAN);
            }
            ws.mfac[s] = mass;
            if forces {
                for (q, f) in ws.q[o..o + d].iter_mut().zip(&fq) {
                    *q += *f;
                }
            }
        }
    }

    /// Whether an integrated state of the model
    /// ([`Integral`](crate::mbs::model::Integral)) reads the kinetic energy
    /// of body `b`: only then does a right-hand side form `½vᵀMv` of a
    /// flexible body (an energy sum, through [`System::mass_factors`],
    /// always does).
    fn kinetic_integrated(&self, b: usize) -> bool {
        self.model
            .integrals
            .iter()
            .any(|i| i.terms.contains(&Energy::Kinetic(b)))
    }

    /// Factored mass matrices of the flexible bodies at the kinematics in
    /// `ws` (no forces).
    pub(crate) fn mass_factors<T: Scalar>(&self, ws: &mut Workspace<T>) {
        self.flex_bodies(ws, false);
    }

    /// `M v` of flexible slot `s` from its factor, which holds `M⁻¹`
    /// ([`Scalar::dense_factor`]): `M` is that inverse inverted again (a
    /// diagnostic, used for the angular momentum; `M` is well conditioned,
    /// so the round trip costs a few ulps).
    pub(crate) fn flex_mass_times(&self, s: usize, ws: &Workspace<f64>, v: &[f64]) -> Vec<f64> {
        let d = self.dof(s);
        let mut m = ws.mfac[s].clone();
        spd_inverse(&mut m, d);
        let mut out = vec![0.0; d];
        sym_times(&m, d, v, &mut out);
        out
    }
}
