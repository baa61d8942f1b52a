//! Applied generalized forces of [`System`]: the gyroscopic terms of
//! rigid bodies, the inertia, elastic and damping forces of flexible
//! bodies ([`super::flexbody`]), and the force elements of
//! [`Model::forces`](crate::mbs::Model) (gravity, loads, the Eq. 32
//! actuator, spring-dampers between markers and along joints, torsion
//! springs on revolute joints), one
//! function per element. Forces are
//! accumulated in the velocity layout of the state (`[ṙ, ω', ẇ]` per
//! body: force in global axes (N), torque in body axes (N·m), modal
//! forces), at a marker through `System::apply_force` and
//! `System::apply_torque`, which add the moment of the marker's offset
//! and the modal work through the node's mode shapes.
//!
//! Every value a sensitivity parameter can replace is read through
//! `pval`, so a dual-number evaluation differentiates it exactly.

use crate::mbs::kinematics::{angle_of, slide_of, wrap_angle};
use crate::mbs::math::{cst, mtv, mv, Scalar};
use crate::mbs::model::{Force, Load, LoadFrame, Param, PiecewiseLaw};
use crate::mbs::system::{bump, pval, System, Workspace};
use nalgebra::Vector3;

impl System {
    /// Applied generalized forces (inertia, elastic, gravity, force
    /// elements) of every moving body at time `t` (into `ws.q`), and the
    /// factored mass matrices of flexible bodies.
    pub(crate) fn applied<T: Scalar>(&self, t: f64, ws: &mut Workspace<T>) {
        ws.q.clear();
        ws.q.resize(self.nvel(), T::zero());
        if self.model.quadratic_velocity {
            self.gyroscopic(ws);
        }
        self.flex_bodies(ws, true);
        for (fi, force) in self.model.forces.iter().enumerate() {
            match force {
                Force::Gravity { g } => self.gravity(ws, g),
                Force::BodyLoad { body, load, frame } => {
                    self.body_load(t, ws, *body, (load, *frame))
                }
                Force::MarkerLoad {
                    marker,
                    load,
                    frame,
                } => self.marker_load(t, ws, *marker, (load, *frame)),
                Force::Rotational {
                    joint,
                    law,
                    damping,
                } => self.rotational(ws, fi, *joint, (law.as_ref(), *damping)),
                Force::SpringDamper {
                    i,
                    j,
                    stiffness,
                    damping,
                    length,
                } => self.spring_damper(ws, fi, [*i, *j], [*stiffness, *damping, *length]),
                Force::JointSpring {
                    joint,
                    stiffness,
                    damping,
                    length,
                    force,
                } => self.joint_spring(ws, fi, *joint, [*stiffness, *damping, *length, *force]),
                Force::TorsionSpring {
                    joint,
                    stiffness,
                    damping,
                    angle,
                    torque,
                } => self.torsion_spring(ws, fi, *joint, [*stiffness, *damping, *angle, *torque]),
            }
        }
    }

    /// Gyroscopic torque `−ω'×(J ω')` of every rigid body (body axes).
    fn gyroscopic<T: Scalar>(&self, ws: &mut Workspace<T>) {
        for (s, &b) in self.moving.iter().enumerate() {
            if self.modes[s] > 0 {
                continue;
            }
            bump(&self.counters.quadratic);
            let body = &self.model.bodies[b];
            let k = &ws.kin[s];
            let jw = mv(&body.inertia.map(cst::<T>), &k.wb);
            let gyro = -k.wb.cross(&jw);
            let o = self.vel_local(s);
            for c in 0..3 {
                ws.q[o + 3 + c] += gyro[c];
            }
        }
    }

    /// Uniform gravity `g` (m/s²): `m g` on every moving body; on a
    /// flexible body also the torque `S × Aᵀg` of its first moment and the
    /// modal forces `i3ᵀ Aᵀg`.
    fn gravity<T: Scalar>(&self, ws: &mut Workspace<T>, g: &Vector3<f64>) {
        bump(&self.counters.gravity);
        let gt = g.map(cst::<T>);
        for (s, &b) in self.moving.iter().enumerate() {
            let o = self.vel_local(s);
            match &ws.inv.get(s).and_then(|i| i.as_ref()) {
                Some(inv) if self.modes[s] > 0 => {
                    let k = &ws.kin[s];
                    let gb = mtv(&k.a, &gt);
                    let sm = inv.first_moment(&k.q);
                    let tq = sm.cross(&gb);
                    let modal = inv.i3t(&gb);
                    for c in 0..3 {
                        ws.q[o + c] += inv.mass * gt[c];
                        ws.q[o + 3 + c] += tq[c];
                    }
                    for (j, f) in modal.iter().enumerate() {
                        ws.q[o + 6 + j] += *f;
                    }
                }
                _ => {
                    let m = pval(&ws.params, Param::Mass(b), self.model.bodies[b].mass);
                    for c in 0..3 {
                        ws.q[o + c] += m * gt[c];
                    }
                }
            }
        }
    }

    /// The load `(f, τ)` at time `t` in global axes: as given, or turned
    /// from the axes of slot `s` (`A f`, `A τ`).
    fn load_global<T: Scalar>(
        &self,
        t: f64,
        ws: &Workspace<T>,
        s: usize,
        (load, frame): (&Load, LoadFrame),
    ) -> (Vector3<T>, Vector3<T>) {
        let (f, tau) = load.eval(t);
        let (f, tau) = (f.map(cst::<T>), tau.map(cst::<T>));
        match frame {
            LoadFrame::Global => (f, tau),
            LoadFrame::Body => (mv(&ws.kin[s].a, &f), mv(&ws.kin[s].a, &tau)),
        }
    }

    /// A force (N) at the centre of mass and a torque (N·m) on `body`
    /// ([`Force::BodyLoad`]). On a flexible body the force is distributed
    /// in proportion to mass (modal forces `i3ᵀ Aᵀf / m`, torque of the
    /// centre of mass's offset from the frame origin).
    fn body_load<T: Scalar>(
        &self,
        t: f64,
        ws: &mut Workspace<T>,
        body: usize,
        load: (&Load, LoadFrame),
    ) {
        bump(&self.counters.loads);
        let Some(s) = self.slot[body] else { return };
        let (force, torque) = self.load_global(t, ws, s, load);
        let tb = mtv(&ws.kin[s].a, &torque);
        let o = self.vel_local(s);
        // A flexible body's frame origin is not its centre of mass: the
        // force acts at the centre of mass.
        let arm = match ws.inv.get(s).and_then(|i| i.as_ref()) {
            Some(inv) if self.modes[s] > 0 => Some(inv.first_moment(&ws.kin[s].q) / inv.mass),
            _ => None,
        };
        let fb = mtv(&ws.kin[s].a, &force);
        let extra = arm.map_or(Vector3::zeros(), |c| c.cross(&fb));
        for c in 0..3 {
            ws.q[o + c] += force[c];
            ws.q[o + 3 + c] += tb[c] + extra[c];
        }
        if let Some(inv) = ws.inv.get(s).and_then(|i| i.as_ref()) {
            if self.modes[s] > 0 {
                let modal = inv.i3t(&fb);
                let m = inv.mass;
                for (j, f) in modal.iter().enumerate() {
                    ws.q[o + 6 + j] += *f / m;
                }
            }
        }
    }

    /// A force (N) at the point of `marker` and a torque (N·m) on its body
    /// ([`Force::MarkerLoad`]): [`System::apply_force`] adds the moment
    /// of the marker's offset and the modal forces of a flexible node.
    fn marker_load<T: Scalar>(
        &self,
        t: f64,
        ws: &mut Workspace<T>,
        marker: usize,
        load: (&Load, LoadFrame),
    ) {
        bump(&self.counters.loads);
        let Some(s) = ws.mk[marker].slot else { return };
        let (force, torque) = self.load_global(t, ws, s, load);
        self.apply_force(ws, marker, &force);
        self.apply_torque(ws, marker, &torque);
    }

    /// The Eq. 32 spring-damper-actuator `forces[fi]` on revolute joint
    /// `joint`: torque `τ = −(c·θ̇ + law(θ))` (N·m) about `z_i` on marker
    /// j, the reaction on marker i.
    fn rotational<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        fi: usize,
        joint: usize,
        (law, damping): (Option<&PiecewiseLaw>, f64),
    ) {
        bump(&self.counters.actuators);
        let jt = &self.model.joints[joint];
        let mi = ws.mk[jt.i];
        let mj = ws.mk[jt.j];
        let (th, thd) = angle_of(&mi, &mj);
        let mut m = pval(&ws.params, Param::Damping(fi), damping) * thd;
        if let Some(law) = law {
            let k = match ws.segments.get(fi) {
                Some(&k) if k < law.segments.len() => k,
                _ => law.segment_index(th.to_subset().unwrap_or(f64::NAN)),
            };
            let seg = &law.segments[k];
            let anchor = pval(&ws.params, Param::Anchor(fi, k), seg.anchor);
            let slope = pval(&ws.params, Param::Slope(fi, k), seg.slope);
            m += cst::<T>(seg.value) + slope * (anchor - th);
        }
        let axis: Vector3<T> = mi.frame.column(2).into();
        let tau = axis * (-m);
        self.apply_torque(ws, jt.j, &tau);
        self.apply_torque(ws, jt.i, &(-tau));
    }

    /// Linear spring-damper `forces[fi]` between markers `i` and `j`:
    /// tension `F = k(l − l0) + c·l̇` (N) along the line of the points,
    /// pulling them together when positive.
    fn spring_damper<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        fi: usize,
        [i, j]: [usize; 2],
        [stiffness, damping, length]: [f64; 3],
    ) {
        bump(&self.counters.springs);
        let mi = ws.mk[i];
        let mj = ws.mk[j];
        let d = mj.x - mi.x;
        let l = d.norm();
        let u = d / l;
        let ldot = u.dot(&(mj.v - mi.v));
        let k = pval(&ws.params, Param::Stiffness(fi), stiffness);
        let c = pval(&ws.params, Param::Damping(fi), damping);
        let tension = k * (l - cst::<T>(length)) + c * ldot;
        let f = u * tension; // on i, towards j
        self.apply_force(ws, i, &f);
        self.apply_force(ws, j, &(-f));
    }

    /// Spring-damper-actuator `forces[fi]` along the axis of prismatic or
    /// cylindrical joint `joint` ([`Force::JointSpring`]): tension
    /// `T = k(s − s0) − f + c·ṡ` (N); `−T z_i` at marker j, `+T z_i` at
    /// marker i, torque `−T z_i×d` on marker i (`d = x_j − x_i`), so that
    /// the generalized force is exactly `−T ∂s/∂q`.
    fn joint_spring<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        fi: usize,
        joint: usize,
        [stiffness, damping, length, force]: [f64; 4],
    ) {
        bump(&self.counters.springs);
        let jt = &self.model.joints[joint];
        let (mi, mj) = (ws.mk[jt.i], ws.mk[jt.j]);
        let (s, sdot) = slide_of(&mi, &mj);
        let k = pval(&ws.params, Param::Stiffness(fi), stiffness);
        let c = pval(&ws.params, Param::Damping(fi), damping);
        let tension = k * (s - cst::<T>(length)) - cst::<T>(force) + c * sdot;
        let zi: Vector3<T> = mi.frame.column(2).into();
        let f = zi * tension;
        self.apply_force(ws, jt.i, &f);
        self.apply_force(ws, jt.j, &(-f));
        let d = mj.x - mi.x;
        self.apply_torque(ws, jt.i, &(-zi.cross(&d) * tension));
    }

    /// Torsion spring-damper `forces[fi]` on revolute joint `joint`
    /// ([`Force::TorsionSpring`]): torque `τ = −k·wrap(θ − θ0) − c·θ̇ + τ0`
    /// (N·m) about `z_i` on marker j, the reaction on marker i; `wrap`
    /// takes the angle difference into (−π, π].
    fn torsion_spring<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        fi: usize,
        joint: usize,
        [stiffness, damping, angle, torque]: [f64; 4],
    ) {
        bump(&self.counters.springs);
        let jt = &self.model.joints[joint];
        let (mi, mj) = (ws.mk[jt.i], ws.mk[jt.j]);
        let (th, thd) = angle_of(&mi, &mj);
        let d = wrap_angle(th - cst::<T>(angle));
        let k = pval(&ws.params, Param::Stiffness(fi), stiffness);
        let c = pval(&ws.params, Param::Damping(fi), damping);
        let m = cst::<T>(torque) - k * d - c * thd;
        let axis: Vector3<T> = mi.frame.column(2).into();
        let tau = axis * m;
        self.apply_torque(ws, jt.j, &tau);
        self.apply_torque(ws, jt.i, &(-tau));
    }

    /// Add a global torque on the carrier of marker `m` (and on the modes
    /// through `Ψ_kᵀ` for a flexible node).
    pub(crate) fn apply_torque<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        m: usize,
        tau: &Vector3<T>,
    ) {
        let mk = ws.mk[m];
        let Some(s) = mk.slot else { return };
        let o = self.vel_local(s);
        let tb = mtv(&ws.kin[s].a, tau);
        for c in 0..3 {
            ws.q[o + 3 + c] += tb[c];
        }
        if mk.node.is_some() {
            let tt = mtv(&mk.tangent, &tb);
            for (j, p) in ws.shapes[m].1.iter().enumerate() {
                ws.q[o + 6 + j] += p.dot(&tt);
            }
        }
    }

    /// Add a global force `f` at marker `m`: the force on the carrier, the
    /// moment `s × f` of the marker's lever arm `s` from the frame origin,
    /// and the modal forces `Φ_kᵀ Aᵀf` of a flexible node.
    pub(crate) fn apply_force<T: Scalar>(&self, ws: &mut Workspace<T>, m: usize, f: &Vector3<T>) {
        let mk = ws.mk[m];
        let Some(s) = mk.slot else { return };
        let o = self.vel_local(s);
        let at = ws.kin[s].a.transpose();
        let tb = at * mk.s.cross(f);
        for c in 0..3 {
            ws.q[o + c] += f[c];
            ws.q[o + 3 + c] += tb[c];
        }
        if mk.node.is_some() {
            let fb = at * f;
            for (j, p) in ws.shapes[m].0.iter().enumerate() {
                ws.q[o + 6 + j] += p.dot(&fb);
            }
        }
    }
}
