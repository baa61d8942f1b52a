//! Kinematics of the bodies and markers at a state: body poses and
//! velocities from the state vector, node shapes of flexible bodies at the
//! design seeds, marker positions, frames, velocities and the
//! velocity-dependent parts of their accelerations, and the relative
//! angle and slide of two markers.
//!
//! Markers on nodes of flexible bodies move with the modes
//! (`x = r + A(s_k + Φ_k w)`) and rotate with them (frame
//! `A R(Ψ_k w) F₀`, `R` the rotation of the rotation vector); their
//! angular velocity is exactly `ω + A T(Ψ_k w) Ψ_k ẇ` with the tangent
//! operator `T` ([`rotation_tangent`]), so that every constraint's
//! Jacobian is the exact derivative of its position-level equation.

use crate::mbs::math::{
    cst, mm, mv, rotation, rotation_tangent, rotation_vector, Scalar, ShapePlanes,
};
use crate::mbs::model::{Force, Param};
use crate::mbs::system::{
    same_seeds, BodyKin, MarkerKin, NodeShapes, System, Workspace, SEED_SPARES,
};
use nalgebra::{Matrix3, Vector3};

impl System {
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
    /// whose row blocks read the marker frames
    /// ([`JointKind::reads_frames`](crate::mbs::JointKind::reads_frames):
    /// all but the spherical one, whose point rows read the point alone
    /// and whose modal entries `Ψ_kᵀTᵀAᵀ(ω-block − s × v-block)` vanish:
    /// that difference is exactly zero for a point row), the forces tied
    /// to a joint's axes, marker loads (torques) and spring-dampers (kept
    /// for safety). A node marker that only point-row joints use gets the
    /// body frame's rotation in its [`MarkerKin`] instead.
    pub fn node_rotations(&self, out: &mut Vec<bool>) {
        out.clear();
        out.resize(self.model.markers.len(), false);
        for joint in &self.model.joints {
            if joint.kind.reads_frames() {
                out[joint.i] = true;
                out[joint.j] = true;
            }
        }
        for force in &self.model.forces {
            match force {
                Force::Rotational { joint, .. }
                | Force::JointSpring { joint, .. }
                | Force::TorsionSpring { joint, .. } => {
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

    /// Kinematics (bodies and markers) of `y` into `ws`.
    pub fn kinematics<T: Scalar>(&self, y: &[T], ws: &mut Workspace<T>) {
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &ws.params, &mut kin);
        ws.kin = kin;
        self.markers_kin(ws);
    }
}

/// Displacement along the axis `s = z_i·(x_j − x_i)` (m) and its rate
/// `ṡ = (ω_i×z_i)·(x_j − x_i) + z_i·(v_j − v_i)` (m/s), with `ω_i` the
/// angular velocity of marker i's frame. Zero at the start of a scene
/// joint, whose two markers are made at the joint point.
pub fn slide_of<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>) -> (T, T) {
    let zi: Vector3<T> = mi.frame.column(2).into();
    let d = mj.x - mi.x;
    (zi.dot(&d), mi.w.cross(&zi).dot(&d) + zi.dot(&(mj.v - mi.v)))
}

/// `θ = atan2(z_i·(x_i × x_j), x_i·x_j)` and `θ̇ = z_i·(ω_j − ω_i)`.
pub fn angle_of<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>) -> (T, T) {
    let xi: Vector3<T> = mi.frame.column(0).into();
    let zi: Vector3<T> = mi.frame.column(2).into();
    let xj: Vector3<T> = mj.frame.column(0).into();
    let th = zi.dot(&xi.cross(&xj)).atan2(xi.dot(&xj));
    (th, zi.dot(&(mj.w - mi.w)))
}

/// `a` shifted by a multiple of 2π into (−π, π].
pub(crate) fn wrap_angle<T: Scalar>(mut a: T) -> T {
    let (pi, two_pi) = (T::pi(), T::two_pi());
    while a > pi {
        a -= two_pi;
    }
    while a <= -pi {
        a += two_pi;
    }
    a
}
