//! Equations of motion with Lagrange multipliers (paper Eqs. 2–4, rigid
//! part) solved at every right-hand-side evaluation.
//!
//! State vector `y` (length `13·nb` for `nb` moving bodies):
//! `[r_1, p_1, …, r_nb, p_nb, ṙ_1, ω'_1, …, ṙ_nb, ω'_nb]`
//! (3 + 4 position coordinates, 3 + 3 velocities per body).
//!
//! With `v = [ṙ, ω']` per body the Newton–Euler equations are
//! `M v̇ = Q + Gᵀλ`, `M = diag(m I, J')`, `Q = [f, n' − ω'×J'ω']`, and the
//! constraints are imposed at acceleration level with Baumgarte
//! stabilisation: `G v̇ = γ − 2αΦ̇ − α²Φ`. Because `M` is block diagonal,
//! `v̇ = M⁻¹(Q + Gᵀλ)` and `λ` solves the constraint-space system
//! `(G M⁻¹ Gᵀ) λ = γ − 2αΦ̇ − α²Φ − G M⁻¹ Q`, which is formed from the
//! sparse rows of `G` (each row touches at most two bodies), permuted once
//! into a minimum-degree order (the SAR factor keeps 595 of 2145 entries)
//! and factored by Cholesky after unit-diagonal scaling and a `1e-12`
//! Tikhonov shift ([`RANK_REG`]). Redundant equations give pivots at the
//! shift level and are counted ([`RANK_TOL`]); their multipliers take the
//! minimum-norm split, and the accelerations, which do not depend on that
//! split, stay unique. One factorization per evaluation; the dual-number
//! evaluation differentiates the same factorization (no finite differences).
//!
//! Everything is generic over the scalar `T` so that `num_dual::Dual64`
//! gives exact Jacobian-vector products of the right-hand side.

use super::linalg::{
    cholesky_solve, cst, euler_rate, min_degree_order, ordered_cholesky, rotation, Scalar,
};
use super::model::{Force, JointKind, Model, Param};
use nalgebra::{Matrix3, Vector3};
use std::cell::Cell;

/// Relative pivot threshold for counting the rank of the constraint-space
/// matrix (unit-diagonal scaled): an exactly dependent row gives a pivot at
/// the regularisation level `RANK_REG` plus round-off (~1e-15); a row whose
/// pivot exceeds `RANK_REG + RANK_TOL` is counted as independent. The
/// expected counts of every test mechanism (SAR 6, Andrews 9, four-bar 3,
/// Bricard 1) are reproduced.
pub const RANK_TOL: f64 = 1e-8;

/// Tikhonov regularisation of the scaled constraint-space matrix: keeps
/// the multipliers (and so the accelerations) smooth where the rank
/// changes (singular configurations such as a parallelogram four-bar
/// passing its flat position). It perturbs the accelerations of a
/// well-conditioned mechanism by a relative `O(1e-12/σ²_min)`.
pub const RANK_REG: f64 = 1e-12;

/// One constraint row: value, velocity residual, `γ` and up to two
/// body blocks `(slot, [∂/∂ṙ; ∂/∂ω'])`.
#[derive(Debug, Clone, Copy)]
pub struct Row<T: Scalar> {
    pub phi: T,
    pub phidot: T,
    pub gamma: T,
    pub blocks: [(Option<usize>, [T; 6]); 2],
}

/// A row's block on one body: `(row index, d, M⁻¹ d)`.
pub type RowBlock<T> = (usize, [T; 6], [T; 6]);

/// Scratch storage reused across evaluations (one per scalar type).
#[derive(Debug, Clone)]
pub struct Workspace<T: Scalar> {
    pub rows: Vec<Row<T>>,
    pub a: Vec<T>,
    pub rhs: Vec<T>,
    pub(crate) scale: Vec<T>,
    pub(crate) tmp: Vec<T>,
    pub kin: Vec<BodyKin<T>>,
    /// Per moving body: the rows touching it as `(row, d, M⁻¹d)`.
    pub(crate) by_body: Vec<Vec<RowBlock<T>>>,
    /// Position of each row in the fill-reducing order.
    pub(crate) inv_order: Vec<usize>,
    pub(crate) col: Vec<T>,
    pub(crate) nz: Vec<usize>,
    pub q: Vec<[T; 6]>,
    /// Rank of the last factorization.
    pub rank: usize,
    /// Parameter values overriding the model's (sensitivity analysis);
    /// empty for plain evaluations.
    pub params: Vec<(Param, T)>,
}

/// Kinematics of one body at the current state.
#[derive(Debug, Clone, Copy)]
pub struct BodyKin<T: Scalar> {
    pub r: Vector3<T>,
    pub a: Matrix3<T>,
    pub v: Vector3<T>,
    /// Global angular velocity.
    pub w: Vector3<T>,
    /// Body-frame angular velocity.
    pub wb: Vector3<T>,
}

/// Global kinematics of a marker.
#[derive(Debug, Clone, Copy)]
pub struct MarkerKin<T: Scalar> {
    pub slot: Option<usize>,
    /// Global position.
    pub x: Vector3<T>,
    /// Global velocity.
    pub v: Vector3<T>,
    /// Lever arm from the centre of mass (global).
    pub s: Vector3<T>,
    /// Global frame columns.
    pub frame: Matrix3<T>,
    /// Global angular velocity of the carrier body.
    pub w: Vector3<T>,
}

/// Evaluation counters (what is not built is never evaluated).
#[derive(Debug, Default)]
pub struct Counters {
    pub rhs: Cell<u64>,
    pub gravity: Cell<u64>,
    pub actuators: Cell<u64>,
    pub springs: Cell<u64>,
    pub loads: Cell<u64>,
}

/// The assembled system: model + state layout.
#[derive(Debug)]
pub struct System {
    pub model: Model,
    /// Body index → state slot (None for fixed bodies).
    pub slot: Vec<Option<usize>>,
    /// Slot → body index.
    pub moving: Vec<usize>,
    pub counters: Counters,
}

impl System {
    /// Lay out the state of `model`.
    pub fn new(model: Model) -> System {
        let mut slot = Vec::with_capacity(model.bodies.len());
        let mut moving = Vec::new();
        for (k, b) in model.bodies.iter().enumerate() {
            if b.fixed {
                slot.push(None);
            } else {
                slot.push(Some(moving.len()));
                moving.push(k);
            }
        }
        System {
            model,
            slot,
            moving,
            counters: Counters::default(),
        }
    }

    /// Number of moving bodies.
    pub fn nb(&self) -> usize {
        self.moving.len()
    }
    /// State length `13·nb`.
    pub fn nstates(&self) -> usize {
        13 * self.nb()
    }
    /// Offset of the velocity part of the state.
    pub fn voff(&self) -> usize {
        7 * self.nb()
    }

    /// Initial state from the bodies' initial pose and velocity.
    pub fn initial_state(&self) -> Vec<f64> {
        let nb = self.nb();
        let mut y = vec![0.0; 13 * nb];
        for (s, &b) in self.moving.iter().enumerate() {
            let body = &self.model.bodies[b];
            y[7 * s..7 * s + 3].copy_from_slice(body.r0.as_slice());
            y[7 * s + 3..7 * s + 7].copy_from_slice(&body.p0);
            let o = 7 * nb + 6 * s;
            y[o..o + 3].copy_from_slice(body.v0.as_slice());
            y[o + 3..o + 6].copy_from_slice(body.w0.as_slice());
        }
        y
    }

    /// Body kinematics for every moving body.
    pub fn body_kin<T: Scalar>(&self, y: &[T], out: &mut Vec<BodyKin<T>>) {
        out.clear();
        let vo = self.voff();
        for s in 0..self.nb() {
            let a = rotation(&y[7 * s + 3..7 * s + 7]);
            let wb = Vector3::new(y[vo + 6 * s + 3], y[vo + 6 * s + 4], y[vo + 6 * s + 5]);
            out.push(BodyKin {
                r: Vector3::new(y[7 * s], y[7 * s + 1], y[7 * s + 2]),
                a,
                v: Vector3::new(y[vo + 6 * s], y[vo + 6 * s + 1], y[vo + 6 * s + 2]),
                w: a * wb,
                wb,
            });
        }
    }

    /// Global kinematics of marker `m`.
    pub fn marker_kin<T: Scalar>(&self, kin: &[BodyKin<T>], m: usize) -> MarkerKin<T> {
        let mk = &self.model.markers[m];
        let pos = mk.pos.map(cst::<T>);
        let frame = mk.frame.map(cst::<T>);
        let slot = mk.body.and_then(|b| self.slot[b]);
        match slot {
            None => {
                // Ground or fixed body: its markers' data are global.
                let (x, f) = match mk.body {
                    None => (pos, frame),
                    Some(b) => {
                        let body = &self.model.bodies[b];
                        let a =
                            nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                                body.p0[0], body.p0[1], body.p0[2], body.p0[3],
                            ))
                            .to_rotation_matrix()
                            .into_inner()
                            .map(cst::<T>);
                        (body.r0.map(cst::<T>) + a * pos, a * frame)
                    }
                };
                MarkerKin {
                    slot: None,
                    x,
                    v: Vector3::zeros(),
                    s: Vector3::zeros(),
                    frame: f,
                    w: Vector3::zeros(),
                }
            }
            Some(s) => {
                let k = &kin[s];
                let sg = k.a * pos;
                MarkerKin {
                    slot: Some(s),
                    x: k.r + sg,
                    v: k.v + k.w.cross(&sg),
                    s: sg,
                    frame: k.a * frame,
                    w: k.w,
                }
            }
        }
    }

    /// Relative angle `θ` of joint `jt` and its rate `θ̇ = z_i·(ω_j − ω_i)`.
    pub fn joint_angle<T: Scalar>(&self, kin: &[BodyKin<T>], jt: usize) -> (T, T) {
        let joint = &self.model.joints[jt];
        let mi = self.marker_kin(kin, joint.i);
        let mj = self.marker_kin(kin, joint.j);
        angle_of(&mi, &mj)
    }

    /// Assemble all constraint rows at time `t` into `ws.rows`.
    pub fn constraints<T: Scalar>(&self, t: f64, ws: &mut Workspace<T>) {
        ws.rows.clear();
        let alpha = self.model.baumgarte;
        for joint in &self.model.joints {
            let mi = self.marker_kin(&ws.kin, joint.i);
            let mj = self.marker_kin(&ws.kin, joint.j);
            for k in 0..3 {
                ws.rows.push(point_row(&mi, &mj, k));
            }
            let (xi, yi) = (mi.frame.column(0).into(), mi.frame.column(1).into());
            let (yj, zj) = (mj.frame.column(1).into(), mj.frame.column(2).into());
            match &joint.kind {
                JointKind::Spherical => {}
                JointKind::Revolute => {
                    ws.rows.push(dot_row(&mi, &mj, &xi, &zj));
                    ws.rows.push(dot_row(&mi, &mj, &yi, &zj));
                }
                JointKind::Fixed => {
                    ws.rows.push(dot_row(&mi, &mj, &xi, &zj));
                    ws.rows.push(dot_row(&mi, &mj, &yi, &zj));
                    ws.rows.push(dot_row(&mi, &mj, &xi, &yj));
                }
                JointKind::Driven(drive) => {
                    ws.rows.push(dot_row(&mi, &mj, &xi, &zj));
                    ws.rows.push(dot_row(&mi, &mj, &yi, &zj));
                    let (f, df, ddf) = drive.eval(t);
                    ws.rows.push(angle_row(&mi, &mj, (f, df, ddf)));
                }
            }
        }
        // Convert ω-global blocks to ω' body-frame blocks and add Φ̇.
        for row in ws.rows.iter_mut() {
            let mut phidot = -row.phidot; // holds −ν on entry
            for (slot, blk) in row.blocks.iter_mut() {
                if let Some(s) = slot {
                    let k = &ws.kin[*s];
                    let wg = Vector3::new(blk[3], blk[4], blk[5]);
                    let wb = k.a.transpose() * wg;
                    blk[3] = wb[0];
                    blk[4] = wb[1];
                    blk[5] = wb[2];
                    phidot += blk[0] * k.v[0] + blk[1] * k.v[1] + blk[2] * k.v[2];
                    phidot += wg.dot(&k.w);
                }
            }
            row.phidot = phidot;
            // Stabilised acceleration right-hand side.
            let a = cst::<T>(alpha);
            row.gamma -= cst::<T>(2.0) * a * phidot + a * a * row.phi;
        }
    }

    /// Applied generalized forces `Q = [f, n' − ω'×J'ω']` per moving body
    /// at time `t` (into `ws.q`).
    pub(crate) fn applied<T: Scalar>(&self, ws: &mut Workspace<T>) {
        ws.q.clear();
        for (s, &b) in self.moving.iter().enumerate() {
            let body = &self.model.bodies[b];
            let k = &ws.kin[s];
            let jw = body.inertia.map(cst::<T>) * k.wb;
            let gyro = -k.wb.cross(&jw);
            ws.q.push([T::zero(), T::zero(), T::zero(), gyro[0], gyro[1], gyro[2]]);
        }
        for (fi, force) in self.model.forces.iter().enumerate() {
            match force {
                Force::Gravity { g } => {
                    self.counters.gravity.set(self.counters.gravity.get() + 1);
                    for (s, &b) in self.moving.iter().enumerate() {
                        let m = pval(&ws.params, Param::Mass(b), self.model.bodies[b].mass);
                        for c in 0..3 {
                            ws.q[s][c] += m * cst::<T>(g[c]);
                        }
                    }
                }
                Force::BodyLoad {
                    body,
                    force,
                    torque,
                } => {
                    self.counters.loads.set(self.counters.loads.get() + 1);
                    if let Some(s) = self.slot[*body] {
                        let tb = ws.kin[s].a.transpose() * torque.map(cst::<T>);
                        for c in 0..3 {
                            ws.q[s][c] += cst::<T>(force[c]);
                            ws.q[s][3 + c] += tb[c];
                        }
                    }
                }
                Force::Rotational {
                    joint,
                    law,
                    damping,
                } => {
                    self.counters
                        .actuators
                        .set(self.counters.actuators.get() + 1);
                    let jt = &self.model.joints[*joint];
                    let mi = self.marker_kin(&ws.kin, jt.i);
                    let mj = self.marker_kin(&ws.kin, jt.j);
                    let (th, thd) = angle_of(&mi, &mj);
                    let mut m = pval(&ws.params, Param::Damping(fi), *damping) * thd;
                    if let Some(law) = law {
                        let k = law.segment_index(th.to_subset().unwrap_or(f64::NAN));
                        let seg = &law.segments[k];
                        let anchor = pval(&ws.params, Param::Anchor(fi, k), seg.anchor);
                        m += cst::<T>(seg.value) + cst::<T>(seg.slope) * (anchor - th);
                    }
                    let axis: Vector3<T> = mi.frame.column(2).into();
                    let tau = axis * (-m);
                    apply_torque(ws, mj.slot, &tau);
                    apply_torque(ws, mi.slot, &(-tau));
                }
                Force::SpringDamper {
                    i,
                    j,
                    stiffness,
                    damping,
                    length,
                } => {
                    self.counters.springs.set(self.counters.springs.get() + 1);
                    let mi = self.marker_kin(&ws.kin, *i);
                    let mj = self.marker_kin(&ws.kin, *j);
                    let d = mj.x - mi.x;
                    let l = d.norm();
                    let u = d / l;
                    let ldot = u.dot(&(mj.v - mi.v));
                    let k = pval(&ws.params, Param::Stiffness(fi), *stiffness);
                    let c = pval(&ws.params, Param::Damping(fi), *damping);
                    let tension = k * (l - cst::<T>(*length)) + c * ldot;
                    let f = u * tension; // on i, towards j
                    apply_force(ws, &mi, &f);
                    apply_force(ws, &mj, &(-f));
                }
            }
        }
    }

    /// Right-hand side `ẏ = f(t, y)`; also leaves the multipliers in
    /// `ws.rhs` (length = number of equations) and the rank in `ws.rank`.
    /// `t` is a plain `f64`: time never carries a derivative here.
    pub fn rhs<T: Scalar>(&self, t: f64, y: &[T], dy: &mut [T], ws: &mut Workspace<T>) {
        self.counters.rhs.set(self.counters.rhs.get() + 1);
        let nb = self.nb();
        let vo = self.voff();
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &mut kin);
        ws.kin = kin;
        // Position derivatives.
        for s in 0..nb {
            let k = &ws.kin[s];
            dy[7 * s] = k.v[0];
            dy[7 * s + 1] = k.v[1];
            dy[7 * s + 2] = k.v[2];
            let pd = euler_rate(&y[7 * s + 3..7 * s + 7], &k.wb);
            dy[7 * s + 3..7 * s + 7].copy_from_slice(&pd);
        }
        self.constraints(t, ws);
        self.applied(ws);
        let acc = self.solve(ws);
        for s in 0..nb {
            dy[vo + 6 * s..vo + 6 * s + 6].copy_from_slice(&acc[s]);
        }
    }

    /// Solve for the multipliers and accelerations with the rows and
    /// applied forces in `ws`. Returns `v̇` per body; `ws.rhs` = λ.
    pub(crate) fn solve<T: Scalar>(&self, ws: &mut Workspace<T>) -> Vec<[T; 6]> {
        let m = ws.rows.len();
        let minv: Vec<(T, Matrix3<T>)> = self
            .moving
            .iter()
            .map(|&b| {
                let body = &self.model.bodies[b];
                let m = pval(&ws.params, Param::Mass(b), body.mass);
                (T::one() / m, body.inv_inertia.map(cst::<T>))
            })
            .collect();
        let apply_minv = |s: usize, x: &[T; 6]| -> [T; 6] {
            let (im, ij) = &minv[s];
            let w = *ij * Vector3::new(x[3], x[4], x[5]);
            [x[0] * *im, x[1] * *im, x[2] * *im, w[0], w[1], w[2]]
        };
        let mq: Vec<[T; 6]> =
            ws.q.iter()
                .enumerate()
                .map(|(s, q)| apply_minv(s, q))
                .collect();
        // Rows touching each body, with M⁻¹ dᵀ.
        let nb = self.nb();
        let mut by_body = std::mem::take(&mut ws.by_body);
        by_body.resize_with(nb, Vec::new);
        for list in by_body.iter_mut() {
            list.clear();
        }
        ws.rhs.clear();
        for (r, row) in ws.rows.iter().enumerate() {
            let mut b = row.gamma;
            for (slot, blk) in &row.blocks {
                if let Some(s) = slot {
                    b -= dot6(blk, &mq[*s]);
                    by_body[*s].push((r, *blk, apply_minv(*s, blk)));
                }
            }
            ws.rhs.push(b);
        }
        // Fill-reducing order, computed once per workspace (the row
        // structure of a system never changes).
        if ws.inv_order.len() != m {
            let mut edges = Vec::new();
            for list in &by_body {
                for (x, (r, _, _)) in list.iter().enumerate() {
                    for (c, _, _) in list.iter().take(x) {
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
        for list in &by_body {
            for (x, (r, d, _)) in list.iter().enumerate() {
                for (c, _, w) in list.iter().take(x + 1) {
                    let (pr, pc) = (inv[*r], inv[*c]);
                    let (hi, lo) = if pr >= pc { (pr, pc) } else { (pc, pr) };
                    ws.a[hi * m + lo] += dot6(d, w);
                }
            }
        }
        let f = ordered_cholesky(
            &mut ws.a,
            m,
            &mut ws.scale,
            (RANK_TOL, RANK_REG),
            &mut ws.col,
            &mut ws.nz,
        );
        ws.rank = f.rank;
        let mut lam = std::mem::take(&mut ws.rhs);
        ws.tmp.clear();
        ws.tmp.resize(m, T::zero());
        for r in 0..m {
            ws.tmp[inv[r]] = lam[r];
        }
        std::mem::swap(&mut lam, &mut ws.tmp);
        cholesky_solve(&ws.a, m, &ws.scale, f.accepted, &mut lam, &mut ws.tmp);
        ws.tmp.clear();
        ws.tmp.extend((0..m).map(|r| lam[inv[r]]));
        std::mem::swap(&mut lam, &mut ws.tmp);
        let mut acc = mq;
        for (s, list) in by_body.iter().enumerate() {
            for (r, _, w) in list {
                for c in 0..6 {
                    acc[s][c] += w[c] * lam[*r];
                }
            }
        }
        ws.rhs = lam;
        ws.by_body = by_body;
        acc
    }
}

/// The value of parameter `which`: the override in `params` if present,
/// else the model's `default`.
#[inline]
fn pval<T: Scalar>(params: &[(Param, T)], which: Param, default: f64) -> T {
    params
        .iter()
        .find(|(p, _)| *p == which)
        .map_or_else(|| cst::<T>(default), |(_, v)| *v)
}

fn dot6<T: Scalar>(a: &[T; 6], b: &[T; 6]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}

fn apply_torque<T: Scalar>(ws: &mut Workspace<T>, slot: Option<usize>, tau: &Vector3<T>) {
    if let Some(s) = slot {
        let tb = ws.kin[s].a.transpose() * tau;
        for c in 0..3 {
            ws.q[s][3 + c] += tb[c];
        }
    }
}

fn apply_force<T: Scalar>(ws: &mut Workspace<T>, mk: &MarkerKin<T>, f: &Vector3<T>) {
    if let Some(s) = mk.slot {
        let tb = ws.kin[s].a.transpose() * mk.s.cross(f);
        for c in 0..3 {
            ws.q[s][c] += f[c];
            ws.q[s][3 + c] += tb[c];
        }
    }
}

/// `θ = atan2(z_i·(x_i × x_j), x_i·x_j)` and `θ̇ = z_i·(ω_j − ω_i)`.
pub fn angle_of<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>) -> (T, T) {
    let xi: Vector3<T> = mi.frame.column(0).into();
    let zi: Vector3<T> = mi.frame.column(2).into();
    let xj: Vector3<T> = mj.frame.column(0).into();
    let th = zi.dot(&xi.cross(&xj)).atan2(xi.dot(&xj));
    (th, zi.dot(&(mj.w - mi.w)))
}

/// Block of a row for a marker: `(slot, [∂/∂ṙ, ∂/∂ω_global])`.
fn block<T: Scalar>(mk: &MarkerKin<T>, dr: Vector3<T>, dw: Vector3<T>) -> (Option<usize>, [T; 6]) {
    (mk.slot, [dr[0], dr[1], dr[2], dw[0], dw[1], dw[2]])
}

/// Component `k` of `x_i − x_j = 0`. Velocity: `ṙ + ω × s`, so the ω
/// block is `e_kᵀ(−s̃) = (s × e_k)ᵀ`; `γ = −e_k·(ω_i×(ω_i×s_i) − ω_j×(ω_j×s_j))`.
fn point_row<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>, k: usize) -> Row<T> {
    let mut e = Vector3::zeros();
    e[k] = T::one();
    let ci = mi.w.cross(&mi.w.cross(&mi.s));
    let cj = mj.w.cross(&mj.w.cross(&mj.s));
    Row {
        phi: mi.x[k] - mj.x[k],
        phidot: T::zero(),
        gamma: -(ci[k] - cj[k]),
        blocks: [block(mi, e, mi.s.cross(&e)), block(mj, -e, -mj.s.cross(&e))],
    }
}

/// `a·b = 0` with `a` fixed in body i and `b` in body j:
/// `d/dt(a·b) = ω_i·(a×b) + ω_j·(b×a)`,
/// `γ = −[b·(ω_i×(ω_i×a)) + 2(ω_i×a)·(ω_j×b) + a·(ω_j×(ω_j×b))]`.
fn dot_row<T: Scalar>(
    mi: &MarkerKin<T>,
    mj: &MarkerKin<T>,
    a: &Vector3<T>,
    b: &Vector3<T>,
) -> Row<T> {
    let axb = a.cross(b);
    let wa = mi.w.cross(a);
    let wb = mj.w.cross(b);
    let quad = b.dot(&mi.w.cross(&wa)) + cst::<T>(2.0) * wa.dot(&wb) + a.dot(&mj.w.cross(&wb));
    Row {
        phi: a.dot(b),
        phidot: T::zero(),
        gamma: -quad,
        blocks: [
            block(mi, Vector3::zeros(), axb),
            block(mj, Vector3::zeros(), -axb),
        ],
    }
}

/// Prescribed angle `θ − f(t) = 0` (wrapped to (−π, π]):
/// `θ̇ = z_i·(ω_j − ω_i)`, `γ = f̈ − (ω_i×z_i)·(ω_j − ω_i)`, `ν = ḟ`.
fn angle_row<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>, drive: (f64, f64, f64)) -> Row<T> {
    let (th, _) = angle_of(mi, mj);
    let zi: Vector3<T> = mi.frame.column(2).into();
    let mut d = th - cst::<T>(drive.0);
    let pi = T::pi();
    let two_pi = T::two_pi();
    while d > pi {
        d -= two_pi;
    }
    while d <= -pi {
        d += two_pi;
    }
    Row {
        phi: d,
        // ν enters with a minus sign: phidot holds −ν until assembled.
        phidot: cst::<T>(drive.1),
        gamma: cst::<T>(drive.2) - mi.w.cross(&zi).dot(&(mj.w - mi.w)),
        blocks: [
            block(mi, Vector3::zeros(), -zi),
            block(mj, Vector3::zeros(), zi),
        ],
    }
}
