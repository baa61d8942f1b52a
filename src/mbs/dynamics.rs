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
//! the dense `(6+n)²` matrix of [`super::flexdyn`] for a flexible one),
//! and the constraints imposed at acceleration level with Baumgarte
//! stabilisation: `G v̇ = γ − 2αΦ̇ − α²Φ`. Because `M` is block diagonal,
//! `v̇ = M⁻¹(Q + Gᵀλ)` and `λ` solves the constraint-space system
//! `(G M⁻¹ Gᵀ) λ = γ − 2αΦ̇ − α²Φ − G M⁻¹ Q`, which is formed body by
//! body from the sparse rows of `G` (each row touches at most two bodies:
//! `G M⁻¹ Gᵀ = Σ_b G_b M_b⁻¹ G_bᵀ`, one Gram block per body,
//! [`super::solve`]), permuted once into a minimum-degree order (the SAR
//! factor keeps 595 of 2145 entries)
//! and factored by Cholesky after unit-diagonal scaling and a `1e-12`
//! Tikhonov shift ([`RANK_REG`]). Redundant equations give pivots at the
//! shift level and are counted ([`RANK_TOL`]); their multipliers take the
//! minimum-norm split, and the accelerations, which do not depend on that
//! split, stay unique. One factorization per evaluation (plus the explicit
//! inverse of each flexible body's mass). The solve is real arithmetic for
//! every scalar type: a dual-number evaluation adds its tangent with the
//! same factorizations ([`super::solve`] has the formulas), with no dual
//! arithmetic inside a factorization and no finite differences.
//!
//! Markers on nodes of flexible bodies move with the modes
//! (`x = r + A(s_k + Φ_k w)`) and rotate with them (frame
//! `A R(Ψ_k w) F₀`, `R` the rotation of the rotation vector); their
//! angular velocity is exactly `ω + A T(Ψ_k w) Ψ_k ẇ` with the tangent
//! operator `T` ([`rotation_tangent`]), so that every constraint's
//! Jacobian is the exact derivative of its position-level equation.
//!
//! Everything is generic over the scalar `T` so that `num_dual::Dual64`
//! gives exact Jacobian-vector products of the right-hand side.

use super::energy::quadratic_form;
use super::flexdyn::{flex_terms, FlexEffects, FlexState, InvT};
use super::linalg::{
    cst, euler_rate, mm, mtv, mv, rotation, rotation_tangent, rotation_vector, spd_inverse,
    sym_times, Scalar,
};
use super::model::{Force, JointKind, Model, Param};
use super::planes::ShapePlanes;
use super::rows::joint_rows;
pub use super::rows::{angle_of, slide_of};
pub use super::workspace::{
    BodyKin, Counters, MarkerKin, NodeShapes, Row, Workspace, RANK_REG, RANK_TOL, RIGID,
};
use nalgebra::{Matrix3, Vector3};
use std::cell::Cell;

pub(crate) fn bump(c: &Cell<u64>) {
    c.set(c.get() + 1);
}

/// The assembled system: model + state layout.
#[derive(Debug)]
pub struct System {
    pub model: Model,
    /// Body index → state slot (None for fixed bodies).
    pub slot: Vec<Option<usize>>,
    /// Slot → body index.
    pub moving: Vec<usize>,
    /// Slot → number of modal coordinates (0 for rigid bodies).
    pub modes: Vec<usize>,
    pos: Vec<usize>,
    vel: Vec<usize>,
    npos: usize,
    nvel: usize,
    /// Constraint rows left out of the solve (their multipliers are zero):
    /// equations found redundant at the projected initial state.
    pub(crate) drop: Vec<bool>,
    pub counters: Counters,
}

impl System {
    /// Lay out the state of `model`.
    pub fn new(model: Model) -> System {
        let mut slot = Vec::with_capacity(model.bodies.len());
        let mut moving = Vec::new();
        let mut modes = Vec::new();
        let (mut pos, mut vel) = (Vec::new(), Vec::new());
        let (mut npos, mut nvel) = (0, 0);
        for (k, b) in model.bodies.iter().enumerate() {
            if b.fixed {
                slot.push(None);
            } else {
                slot.push(Some(moving.len()));
                moving.push(k);
                let n = b.flex.as_ref().map_or(0, |f| f.n());
                modes.push(n);
                pos.push(npos);
                vel.push(nvel);
                npos += 7 + n;
                nvel += 6 + n;
            }
        }
        System {
            model,
            slot,
            moving,
            modes,
            pos,
            vel,
            npos,
            nvel,
            drop: Vec::new(),
            counters: Counters::default(),
        }
    }

    /// Leave the constraint rows `rows` out of every later solve (their
    /// multipliers are set to zero). For equations that are redundant by
    /// the geometry of the mechanism (found by [`System::project`]): on
    /// the constraint manifold they are implied by the others, so the
    /// accelerations do not change, while off the manifold (trial states
    /// of an implicit integrator) their slightly inconsistent stabilisation
    /// terms no longer meet a near-zero pivot. Transient singularities
    /// are still handled by the regularisation.
    pub fn drop_rows(&mut self, rows: &[usize]) {
        for &r in rows {
            if self.drop.len() <= r {
                self.drop.resize(r + 1, false);
            }
            self.drop[r] = true;
        }
    }

    /// Whether constraint row `r` is left out of the solve.
    pub fn dropped(&self, r: usize) -> bool {
        self.drop.get(r).copied().unwrap_or(false)
    }

    /// Number of moving bodies.
    pub fn nb(&self) -> usize {
        self.moving.len()
    }
    /// State length (positions + velocities + integrals).
    pub fn nstates(&self) -> usize {
        self.npos + self.nvel + self.model.integrals.len()
    }
    /// Offset of the integral states ([`Model::integrals`](super::model::Model)).
    pub fn integral_off(&self) -> usize {
        self.npos + self.nvel
    }
    /// Offset of the velocity part of the state.
    pub fn voff(&self) -> usize {
        self.npos
    }
    /// Number of generalized velocities.
    pub fn nvel(&self) -> usize {
        self.nvel
    }
    /// Offset of body slot `s`'s positions `[r, p, w]` in the state.
    pub fn pos_off(&self, s: usize) -> usize {
        self.pos[s]
    }
    /// Offset of body slot `s`'s velocities `[ṙ, ω', ẇ]` in the state.
    pub fn vel_off(&self, s: usize) -> usize {
        self.npos + self.vel[s]
    }
    /// Offset of slot `s` in the velocity vector.
    pub(crate) fn vel_local(&self, s: usize) -> usize {
        self.vel[s]
    }
    /// Generalized velocities of slot `s` (`6 + modes`).
    pub fn dof(&self, s: usize) -> usize {
        6 + self.modes[s]
    }

    /// Initial state from the bodies' initial pose and velocity (modal
    /// coordinates and rates zero: undeformed at rest relative to the
    /// frame).
    pub fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.nstates()];
        for (s, &b) in self.moving.iter().enumerate() {
            let body = &self.model.bodies[b];
            let p = self.pos_off(s);
            y[p..p + 3].copy_from_slice(body.r0.as_slice());
            y[p + 3..p + 7].copy_from_slice(&body.p0);
            let o = self.vel_off(s);
            y[o..o + 3].copy_from_slice(body.v0.as_slice());
            y[o + 3..o + 6].copy_from_slice(body.w0.as_slice());
        }
        y
    }

    /// Body kinematics for every moving body; `params` supplies the design
    /// seeds of flexible bodies ([`Param::Design`]).
    pub fn body_kin<T: Scalar>(&self, y: &[T], params: &[(Param, T)], out: &mut Vec<BodyKin<T>>) {
        out.truncate(self.nb());
        for s in 0..self.nb() {
            let p = self.pos_off(s);
            let o = self.vel_off(s);
            let a = rotation(&y[p + 3..p + 7]);
            let wb = Vector3::new(y[o + 3], y[o + 4], y[o + 5]);
            let n = self.modes[s];
            let r = Vector3::new(y[p], y[p + 1], y[p + 2]);
            let v = Vector3::new(y[o], y[o + 1], y[o + 2]);
            if s == out.len() {
                out.push(BodyKin {
                    r,
                    a,
                    v,
                    w: a * wb,
                    wb,
                    q: Vec::new(),
                    qd: Vec::new(),
                    design: Vec::new(),
                });
            }
            let k = &mut out[s];
            k.r = r;
            k.a = a;
            k.v = v;
            k.w = mv(&a, &wb);
            k.wb = wb;
            k.q.clear();
            k.q.extend_from_slice(&y[p + 7..p + 7 + n]);
            k.qd.clear();
            k.qd.extend_from_slice(&y[o + 6..o + 6 + n]);
            k.design.clear();
            if n > 0 {
                let b = self.moving[s];
                for (par, val) in params {
                    if let Some(var) = par.design_of(&self.model, b) {
                        let re = cst::<T>(val.to_subset().unwrap_or(0.0));
                        let delta = *val - re;
                        if !delta.is_exact_zero() {
                            k.design.push((var, delta));
                        }
                    }
                }
            }
        }
    }

    /// Translational and rotational mode-shape rows `(Φ_k, Ψ_k)` of node
    /// `node` of body `b` (n columns each), with the design seeds of `kin`.
    pub fn node_shapes<T: Scalar>(
        &self,
        kin: &BodyKin<T>,
        b: usize,
        node: usize,
    ) -> (Vec<Vector3<T>>, Vec<Vector3<T>>) {
        let flex = self.model.bodies[b]
            .flex
            .as_ref()
            .expect("node markers exist only on flexible bodies");
        let basis = &flex.basis;
        let n = basis.n_modes;
        let mut phi = vec![Vector3::<T>::zeros(); n];
        let mut psi = vec![Vector3::<T>::zeros(); n];
        for c in 0..6 {
            for j in 0..n {
                let i = (node * 6 + c) * n + j;
                let mut e = cst::<T>(basis.shapes[i]);
                for (var, d) in &kin.design {
                    e += cst::<T>(basis.derivatives[*var].shapes[i]) * *d;
                }
                if c < 3 {
                    phi[j][c] = e;
                } else {
                    psi[j][c - 3] = e;
                }
            }
        }
        (phi, psi)
    }

    /// The node shapes of marker `m` (empty unless it sits on a node of a
    /// moving flexible body).
    fn marker_shapes<T: Scalar>(&self, kin: &[BodyKin<T>], m: usize) -> NodeShapes<T> {
        let mk = &self.model.markers[m];
        match (mk.node, mk.body) {
            (Some(node), Some(b)) => match self.slot[b] {
                Some(s) if !kin[s].q.is_empty() => self.node_shapes(&kin[s], b, node),
                _ => (Vec::new(), Vec::new()),
            },
            _ => (Vec::new(), Vec::new()),
        }
    }

    /// Global kinematics of marker `m`.
    pub fn marker_kin<T: Scalar>(&self, kin: &[BodyKin<T>], m: usize) -> MarkerKin<T> {
        let (phi, psi) = self.marker_shapes(kin, m);
        self.marker_kin_with(kin, m, &ShapePlanes::new(&phi, &psi), true)
    }

    /// Which markers' node rotations something in the model reads (by
    /// marker index): the frame, angular velocity and angular acceleration
    /// of a marker on a flexible node enter the rows of every joint kind
    /// but the spherical one (whose rows read the point alone, and whose
    /// modal entries `Ψ_kᵀTᵀAᵀ(ω-block − s × v-block)` vanish: that
    /// difference is exactly zero for a point row), the forces tied to a
    /// joint's axes, marker loads (torques) and spring-dampers (kept for
    /// safety). A node marker that only spherical joints use gets the
    /// body frame's rotation in its [`MarkerKin`] instead.
    pub fn node_rotations(&self, out: &mut Vec<bool>) {
        out.clear();
        out.resize(self.model.markers.len(), false);
        for joint in &self.model.joints {
            if !matches!(joint.kind, JointKind::Spherical) {
                out[joint.i] = true;
                out[joint.j] = true;
            }
        }
        for force in &self.model.forces {
            match force {
                Force::Rotational { joint, .. } | Force::JointSpring { joint, .. } => {
                    let jt = &self.model.joints[*joint];
                    out[jt.i] = true;
                    out[jt.j] = true;
                }
                Force::SpringDamper { i, j, .. } => {
                    out[*i] = true;
                    out[*j] = true;
                }
                Force::MarkerLoad { marker, .. } => out[*marker] = true,
                Force::Gravity { .. } | Force::BodyLoad { .. } => {}
            }
        }
    }

    /// [`System::marker_kin`] with the marker's node shapes given (as
    /// planes); `rotation`: whether to include a flexible node's rotation
    /// (see [`System::node_rotations`]; without it the frame, angular
    /// velocity, its rate term and the tangent are the body frame's).
    fn marker_kin_with<T: Scalar>(
        &self,
        kin: &[BodyKin<T>],
        m: usize,
        planes: &ShapePlanes,
        rotation: bool,
    ) -> MarkerKin<T> {
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
                        (body.r0.map(cst::<T>) + mv(&a, &pos), mm(&a, &frame))
                    }
                };
                MarkerKin {
                    slot: None,
                    x,
                    v: Vector3::zeros(),
                    s: Vector3::zeros(),
                    frame: f,
                    w: Vector3::zeros(),
                    acc: Vector3::zeros(),
                    alpha: Vector3::zeros(),
                    node: None,
                    tangent: Matrix3::identity(),
                }
            }
            Some(s) => {
                let k = &kin[s];
                match (mk.node, mk.body) {
                    (Some(node), Some(b)) if !k.q.is_empty() => {
                        let (du, th) = planes.combine(&k.q);
                        let (vd, wd) = planes.combine(&k.qd);
                        let sg = mv(&k.a, &(pos + du));
                        let vdg = mv(&k.a, &vd);
                        let acc = k.w.cross(&k.w.cross(&sg)) + k.w.cross(&vdg) * cst::<T>(2.0);
                        if !rotation {
                            return MarkerKin {
                                slot: Some(s),
                                x: k.r + sg,
                                v: k.v + k.w.cross(&sg) + vdg,
                                s: sg,
                                frame: mm(&k.a, &frame),
                                w: k.w,
                                acc,
                                alpha: Vector3::zeros(),
                                node: Some((b, node)),
                                tangent: Matrix3::identity(),
                            };
                        }
                        // Exact angular velocity of the node frame
                        // A R(θ) F₀: ω + A T(θ) θ̇, and its rate terms.
                        let (tm, tdot) = rotation_tangent(&th, &wd);
                        let wdg = mv(&k.a, &mv(&tm, &wd));
                        MarkerKin {
                            slot: Some(s),
                            x: k.r + sg,
                            v: k.v + k.w.cross(&sg) + vdg,
                            s: sg,
                            frame: mm(&k.a, &mm(&rotation_vector(&th), &frame)),
                            w: k.w + wdg,
                            acc,
                            alpha: k.w.cross(&wdg) + mv(&k.a, &tdot),
                            node: Some((b, node)),
                            tangent: tm,
                        }
                    }
                    _ => {
                        let sg = mv(&k.a, &pos);
                        MarkerKin {
                            slot: Some(s),
                            x: k.r + sg,
                            v: k.v + k.w.cross(&sg),
                            s: sg,
                            frame: mm(&k.a, &frame),
                            w: k.w,
                            acc: k.w.cross(&k.w.cross(&sg)),
                            alpha: Vector3::zeros(),
                            node: None,
                            tangent: Matrix3::identity(),
                        }
                    }
                }
            }
        }
    }

    /// Kinematics of every marker into `ws.mk`, and their node shapes
    /// into `ws.shapes` and `ws.planes` (from `ws.kin`).
    ///
    /// The node shapes depend on the design seeds alone, not on the
    /// state: they are built again only when a body's seeds differ from
    /// those of the current shapes and of the `SEED_SPARES` sets built
    /// before (fused sensitivities seed the same unit lanes at every
    /// stage; the staggered ones cycle through a few sets).
    pub fn markers_kin<T: Scalar>(&self, ws: &mut Workspace<T>) {
        let nm = self.model.markers.len();
        ws.mk.clear();
        ws.shapes.resize_with(nm, || (Vec::new(), Vec::new()));
        ws.shape_seeds.resize_with(nm, || None);
        ws.planes.resize_with(nm, ShapePlanes::default);
        ws.shape_spare.resize_with(nm, Vec::new);
        let mut rotations = std::mem::take(&mut ws.rotations);
        self.node_rotations(&mut rotations);
        ws.rotations = rotations;
        for m in 0..nm {
            let mk = &self.model.markers[m];
            let seeds = match (mk.node, mk.body.and_then(|b| self.slot[b])) {
                (Some(_), Some(s)) if !ws.kin[s].q.is_empty() => Some(&ws.kin[s].design),
                _ => None,
            };
            let built_for = |sd: &Option<Vec<(usize, T)>>, shapes: &NodeShapes<T>| match (sd, seeds)
            {
                (Some(old), Some(new)) => same_seeds(old, new),
                (None, None) => shapes.0.is_empty(),
                _ => false,
            };
            if !built_for(&ws.shape_seeds[m], &ws.shapes[m]) {
                // Earlier shapes are kept for seeds that cycle (as the
                // invariants are, `System::invariants`).
                let spare = &mut ws.shape_spare[m];
                let cached = match spare.iter().position(|e| built_for(&e.0, &e.1)) {
                    Some(i) => spare.remove(i),
                    None => {
                        let (phi, psi) = self.marker_shapes(&ws.kin, m);
                        let planes = ShapePlanes::new(&phi, &psi);
                        (seeds.cloned(), (phi, psi), planes)
                    }
                };
                let old = (
                    std::mem::replace(&mut ws.shape_seeds[m], cached.0),
                    std::mem::replace(&mut ws.shapes[m], cached.1),
                    std::mem::replace(&mut ws.planes[m], cached.2),
                );
                ws.shape_spare[m].insert(0, old);
                ws.shape_spare[m].truncate(SEED_SPARES);
            }
            let k = self.marker_kin_with(&ws.kin, m, &ws.planes[m], ws.rotations[m]);
            ws.mk.push(k);
        }
    }

    /// Relative angle `θ` of joint `jt` and its rate `θ̇ = z_i·(ω_j − ω_i)`.
    pub fn joint_angle<T: Scalar>(&self, kin: &[BodyKin<T>], jt: usize) -> (T, T) {
        let joint = &self.model.joints[jt];
        let mi = self.marker_kin(kin, joint.i);
        let mj = self.marker_kin(kin, joint.j);
        angle_of(&mi, &mj)
    }

    /// Displacement `s` (m) of prismatic or cylindrical joint `jt` along
    /// its axis and its rate `ṡ` (m/s) ([`slide_of`]).
    pub fn joint_slide<T: Scalar>(&self, kin: &[BodyKin<T>], jt: usize) -> (T, T) {
        let joint = &self.model.joints[jt];
        let mi = self.marker_kin(kin, joint.i);
        let mj = self.marker_kin(kin, joint.j);
        slide_of(&mi, &mj)
    }

    /// Assemble all constraint rows at time `t` into `ws.rows` (marker
    /// kinematics from `ws.mk`).
    pub fn constraints<T: Scalar>(&self, t: f64, ws: &mut Workspace<T>) {
        ws.rows.clear();
        ws.mjac.clear();
        let alpha = self.model.baumgarte;
        for joint in &self.model.joints {
            let first = ws.rows.len();
            let markers = (&ws.mk[joint.i], &ws.mk[joint.j]);
            joint_rows(&joint.kind, markers, t, &mut ws.rows);
            for row in &mut ws.rows[first..] {
                row.markers = [joint.i, joint.j];
            }
        }
        // Modal entries of flexible sides, ω-global blocks to ω' body-frame
        // blocks, and Φ̇.
        let mut rows = std::mem::take(&mut ws.rows);
        for row in rows.iter_mut() {
            let mut phidot = -row.phidot; // holds −ν on entry
            for side in 0..2 {
                let (slot, blk) = &mut row.blocks[side];
                let Some(s) = *slot else { continue };
                let k = &ws.kin[s];
                let dv = Vector3::new(blk[0], blk[1], blk[2]);
                let wg = Vector3::new(blk[3], blk[4], blk[5]);
                let mk = &ws.mk[row.markers[side]];
                if mk.node.is_some() {
                    // ∂/∂ẇ_j = (Aᵀdv)·Φ_kj + (Tᵀ Aᵀ(dw_g − s×dv))·Ψ_kj.
                    let av = mtv(&k.a, &dv);
                    // Without the node's rotation (spherical joints only)
                    // ω-block − s × v-block is exactly zero.
                    let aw = if ws.rotations[row.markers[side]] {
                        mtv(&mk.tangent, &mtv(&k.a, &(wg - mk.s.cross(&dv))))
                    } else {
                        Vector3::zeros()
                    };
                    row.modal[side] = ws.mjac.len();
                    let planes = &ws.planes[row.markers[side]];
                    phidot += planes.row_entries((&av, &aw), &k.qd, &mut ws.mjac);
                }
                let wb = mtv(&k.a, &wg);
                blk[3] = wb[0];
                blk[4] = wb[1];
                blk[5] = wb[2];
                phidot += dv.dot(&k.v) + wg.dot(&k.w);
            }
            row.phidot = phidot;
            // Stabilised acceleration right-hand side.
            let a = cst::<T>(alpha);
            row.gamma -= cst::<T>(2.0) * a * phidot + a * a * row.phi;
        }
        ws.rows = rows;
    }

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
                let v: Vec<T> = (k.v.iter().chain(k.wb.iter()).chain(&k.qd))
                    .copied()
                    .collect();
                ws.kinetic[s] = quadratic_form(&mass, &v, d);
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

    /// Kinematics (bodies and markers) of `y` into `ws`.
    pub fn kinematics<T: Scalar>(&self, y: &[T], ws: &mut Workspace<T>) {
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &ws.params, &mut kin);
        ws.kin = kin;
        self.markers_kin(ws);
    }

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
        let vo = self.voff();
        dy[vo..vo + self.nvel].copy_from_slice(&acc);
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

/// How many earlier lifts of the invariants and node shapes a workspace
/// keeps besides the current ones: the staggered sensitivities cycle
/// through one set of design seeds per lane plus the empty set (`J·s`), so
/// three cover two design variables and the empty set with one to spare.
const SEED_SPARES: usize = 3;

/// Whether two lists of design seeds `(variable, δ)` are the same, every
/// dual component compared (`PartialEq` of num-dual's numbers compares the
/// real parts alone, which are zero for every seed).
pub(crate) fn same_seeds<T: Scalar>(a: &[(usize, T)], b: &[(usize, T)]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|((i, x), (j, y))| i == j && (*x - *y).is_exact_zero())
}

/// The value of parameter `which`: the override in `params` if present,
/// else the model's `default`.
#[inline]
pub(crate) fn pval<T: Scalar>(params: &[(Param, T)], which: Param, default: f64) -> T {
    params
        .iter()
        .find(|(p, _)| *p == which)
        .map_or_else(|| cst::<T>(default), |(_, v)| *v)
}
