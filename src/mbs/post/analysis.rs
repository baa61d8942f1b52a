//! Consistent initial conditions (projection onto the constraints) and
//! per-state outputs: joint angles and rates, reactions, energy and
//! constraint violation.

use crate::error::{Error, Result};
use crate::mbs::kinematics::{angle_of, slide_of, wrap_angle};
use crate::mbs::math::Scalar;
use crate::mbs::model::{Energy, Force};
use crate::mbs::system::{BodyKin, System, Workspace, RANK_REG, RANK_TOL};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Sizes of the corrections made by [`System::project`].
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// Largest position-level residual before the projection.
    pub phi_before: f64,
    /// Largest residual after it.
    pub phi_after: f64,
    /// Euclidean norm of the mass-weighted position correction
    /// (m and rad mixed; `[Δr, Δθ']` stacked).
    pub position_correction: f64,
    /// Euclidean norm of the velocity correction `[Δṙ, Δω']`.
    pub velocity_correction: f64,
    /// Newton iterations on positions.
    pub iterations: usize,
    /// Rank of the constraint Jacobian at the projected state.
    pub rank: usize,
    /// Number of equations.
    pub equations: usize,
    /// Equations found dependent on the others at the projected state
    /// (row indices), for [`System::drop_rows`].
    pub dependent: Vec<usize>,
}

/// Reaction of a joint: force (N) and torque (N·m, about the joint point)
/// exerted on the body of marker `j`, in global axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reaction {
    /// Force on the body of marker `j`, global axes (N).
    pub force: Vector3<f64>,
    /// Torque on the body of marker `j` about the joint point, global axes
    /// (N·m).
    pub torque: Vector3<f64>,
}

/// Tolerance of the position projection on `max |Φ|`.
pub const PROJECTION_TOL: f64 = 1e-12;

impl System {
    /// Project `y` onto the constraints at time `t`: Newton iterations with
    /// the mass-weighted minimum-norm step
    /// `Δx = −M⁻¹Gᵀ(GM⁻¹Gᵀ)⁺Φ` on positions, then the same projection of
    /// the velocities onto `G v = ν`. Inconsistent positions (redundant
    /// equations that contradict each other, or no convergence within 50
    /// iterations) are an input error.
    pub fn project(&self, t: f64, y: &mut [f64]) -> Result<Projection> {
        let mut ws = Workspace::<f64>::empty();
        let nb = self.nb();
        let vo = self.voff();
        let mut before = None;
        let mut poscorr = 0.0;
        let mut iterations = 0;
        let mut after = 0.0;
        for it in 0..=50 {
            self.load(t, y, &mut ws);
            let res = ws.rows.iter().fold(0.0f64, |m, r| m.max(r.phi.abs()));
            if !res.is_finite() {
                return Err(Error::input(
                    "initial state",
                    res,
                    "a configuration where the constraints are defined",
                ));
            }
            before.get_or_insert(res);
            after = res;
            if res <= PROJECTION_TOL || it == 50 {
                break;
            }
            iterations = it + 1;
            for r in ws.rows.iter_mut() {
                r.gamma = -r.phi;
            }
            let dx = self.correction(&mut ws);
            for s in 0..nb {
                let (p, o, n) = (self.pos_off(s), self.vel_local(s), self.modes[s]);
                let d = &dx[o..o + 6 + n];
                poscorr += d.iter().map(|v| v * v).sum::<f64>();
                for c in 0..3 {
                    y[p + c] += d[c];
                }
                for j in 0..n {
                    y[p + 7 + j] += d[6 + j];
                }
                let e = &y[p + 3..p + 7];
                let q = UnitQuaternion::from_quaternion(Quaternion::new(e[0], e[1], e[2], e[3]));
                let dq = UnitQuaternion::from_quaternion(Quaternion::new(
                    1.0,
                    0.5 * d[3],
                    0.5 * d[4],
                    0.5 * d[5],
                ));
                let r = q * dq;
                y[p + 3..p + 7].copy_from_slice(&[r.w, r.i, r.j, r.k]);
            }
        }
        let before = before.unwrap_or(0.0);
        if after > 1e-9 {
            return Err(Error::input(
                "joints",
                format!("max |Φ| = {after:.3e} after projection (was {before:.3e})"),
                "initial positions that satisfy the joints (consistent redundant constraints)",
            ));
        }
        // Velocities.
        self.load(t, y, &mut ws);
        for r in ws.rows.iter_mut() {
            r.gamma = -r.phidot;
        }
        let dv = self.correction(&mut ws);
        let velcorr = dv.iter().map(|v| v * v).sum::<f64>();
        for (k, d) in dv.iter().enumerate() {
            y[vo + k] += d;
        }
        Ok(Projection {
            phi_before: before,
            phi_after: after,
            position_correction: poscorr.sqrt(),
            velocity_correction: velcorr.sqrt(),
            iterations,
            rank: ws.rank,
            equations: ws.rows.len(),
            dependent: self.dependent_rows(&ws),
        })
    }

    /// Rows whose pivot in the last factorization of `ws` was at the
    /// regularisation level (dependent on the rows before them in the
    /// elimination order), excluding rows already dropped.
    fn dependent_rows(&self, ws: &Workspace<f64>) -> Vec<usize> {
        let m = ws.rows.len();
        let mut out: Vec<usize> = (0..m)
            .filter(|&r| {
                let k = ws.inv_order[r];
                let l = ws.a[k * m + k];
                !self.dropped(r) && l * l - RANK_REG <= RANK_TOL
            })
            .collect();
        out.sort_unstable();
        out
    }

    /// Kinematics and constraint rows of `y` at `t` into `ws`.
    pub fn load(&self, t: f64, y: &[f64], ws: &mut Workspace<f64>) {
        self.kinematics(y, ws);
        self.constraints(t, ws);
    }

    /// `M⁻¹Gᵀ(GM⁻¹Gᵀ)⁺γ` with the rows' `gamma` as right-hand side
    /// (velocity layout).
    fn correction(&self, ws: &mut Workspace<f64>) -> Vec<f64> {
        ws.q.clear();
        ws.q.resize(self.nvel(), 0.0);
        self.mass_factors(ws);
        self.solve(ws)
    }

    /// Largest `|Φ|` of the state.
    pub fn violation(&self, t: f64, y: &[f64], ws: &mut Workspace<f64>) -> f64 {
        self.load(t, y, ws);
        ws.rows.iter().fold(0.0f64, |m, r| m.max(r.phi.abs()))
    }

    /// Mechanical energy: kinetic + strain (`½ wᵀΛw`) + gravity
    /// potential + linear springs between markers and along joints +
    /// torsion springs `½k·wrap(θ − θ0)²` (J).
    pub fn energy(&self, y: &[f64], ws: &mut Workspace<f64>) -> f64 {
        let mut terms = Energy::kinetic_total(&self.model);
        terms.extend(self.moving.iter().map(|&b| Energy::Strain(b)));
        // With a flexible body, its kinetic term also builds the invariants
        // that `mass_centre` reads; the springs need the markers.
        let mut e = self.energy_sum(&terms, y, ws);
        self.markers_kin(ws);
        for f in &self.model.forces {
            match f {
                Force::Gravity { g } => {
                    for s in 0..self.nb() {
                        e -= g.dot(&self.mass_centre(s, ws)) * self.body_mass(s, ws);
                    }
                }
                Force::SpringDamper {
                    i,
                    j,
                    stiffness,
                    length,
                    ..
                } => {
                    let l = (ws.mk[*j].x - ws.mk[*i].x).norm();
                    e += 0.5 * stiffness * (l - length).powi(2);
                }
                Force::JointSpring {
                    joint,
                    stiffness,
                    length,
                    ..
                } => {
                    let jt = &self.model.joints[*joint];
                    let (s, _) = slide_of(&ws.mk[jt.i], &ws.mk[jt.j]);
                    e += 0.5 * stiffness * (s - length).powi(2);
                }
                Force::TorsionSpring {
                    joint,
                    stiffness,
                    angle,
                    ..
                } => {
                    let jt = &self.model.joints[*joint];
                    let (th, _) = angle_of(&ws.mk[jt.i], &ws.mk[jt.j]);
                    e += 0.5 * stiffness * wrap_angle(th - angle).powi(2);
                }
                _ => {}
            }
        }
        e
    }

    /// Mass of slot `s` (kg).
    fn body_mass(&self, s: usize, ws: &Workspace<f64>) -> f64 {
        match ws.inv.get(s).and_then(|i| i.as_ref()) {
            Some(inv) if self.modes[s] > 0 => inv.mass,
            _ => self.model.bodies[self.moving[s]].mass,
        }
    }

    /// Global position of the (deformed) centre of mass of slot `s` at
    /// state `y`.
    pub fn centre_of_mass(&self, y: &[f64], s: usize) -> Vector3<f64> {
        let mut ws = Workspace::empty();
        self.kinematics(y, &mut ws);
        self.mass_factors(&mut ws);
        self.mass_centre(s, &ws)
    }

    /// [`System::centre_of_mass`] from the kinematics and flexible
    /// invariants already in `ws`.
    pub fn mass_centre(&self, s: usize, ws: &Workspace<f64>) -> Vector3<f64> {
        let k = &ws.kin[s];
        match ws.inv.get(s).and_then(|i| i.as_ref()) {
            Some(inv) if self.modes[s] > 0 => k.r + k.a * (inv.first_moment(&k.q) / inv.mass),
            _ => k.r,
        }
    }

    /// Elastic displacement `Φ_k w` (body frame axes, m) of marker `m`
    /// (zero for a marker that is not on a flexible node).
    pub fn deflection(&self, y: &[f64], m: usize) -> Vector3<f64> {
        let mut kin = Vec::new();
        self.body_kin(y, &[], &mut kin);
        self.deflection_kin(&kin, m)
    }

    /// [`System::deflection`] from body kinematics (any scalar).
    pub fn deflection_kin<T: Scalar>(&self, kin: &[BodyKin<T>], m: usize) -> Vector3<T> {
        let mk = &self.model.markers[m];
        let (Some(b), Some(node)) = (mk.body, mk.node) else {
            return Vector3::zeros();
        };
        let Some(s) = self.slot[b] else {
            return Vector3::zeros();
        };
        let (phi, _) = self.node_shapes(&kin[s], b, node);
        phi.iter()
            .zip(&kin[s].q)
            .fold(Vector3::zeros(), |acc, (p, w)| acc + p * *w)
    }

    /// Whether [`System::energy`] is conserved by the exact flow: no
    /// dampers, actuators, loads or driven joints.
    pub fn conservative(&self) -> bool {
        let forces_ok = self.model.forces.iter().all(|f| match f {
            Force::Gravity { .. } => true,
            Force::SpringDamper { damping, .. } => *damping == 0.0,
            Force::JointSpring { damping, force, .. } => *damping == 0.0 && *force == 0.0,
            Force::TorsionSpring {
                damping, torque, ..
            } => *damping == 0.0 && *torque == 0.0,
            _ => false,
        });
        let modal_ok = self
            .model
            .bodies
            .iter()
            .all(|b| b.flex.as_ref().is_none_or(|f| f.zeta == 0.0));
        let joints_ok = self
            .model
            .joints
            .iter()
            .all(|j| j.kind.drive().is_none_or(|d| d.is_constant()));
        forces_ok && joints_ok && modal_ok
    }

    /// Angular momentum about the global origin (N·m·s), meaningful for
    /// free systems.
    pub fn angular_momentum(&self, y: &[f64], ws: &mut Workspace<f64>) -> Vector3<f64> {
        self.kinematics(y, ws);
        self.mass_factors(ws);
        let mut h = Vector3::zeros();
        for (s, &b) in self.moving.iter().enumerate() {
            let body = &self.model.bodies[b];
            let k = &ws.kin[s];
            match ws.inv.get(s).and_then(|i| i.as_ref()) {
                Some(_) if self.modes[s] > 0 => {
                    // H = r × p + A·(∂T/∂ω'), p = ∂T/∂ṙ: rows 0..6 of M v.
                    let d = self.dof(s);
                    let o = self.vel_off(s);
                    let v = &y[o..o + d];
                    let mv = self.flex_mass_times(s, ws, v);
                    let p = Vector3::new(mv[0], mv[1], mv[2]);
                    let hw = Vector3::new(mv[3], mv[4], mv[5]);
                    h += k.r.cross(&p) + k.a * hw;
                }
                _ => {
                    h += k.r.cross(&(k.v * body.mass)) + k.a * (body.inertia * k.wb);
                }
            }
        }
        h
    }

    /// Relative angle (rad) and rate (rad/s) of a revolute joint.
    pub fn angle(&self, y: &[f64], joint: usize, ws: &mut Workspace<f64>) -> (f64, f64) {
        self.kinematics(y, ws);
        let j = &self.model.joints[joint];
        angle_of(&ws.mk[j.i], &ws.mk[j.j])
    }

    /// Displacement (m) and rate (m/s) of a prismatic or cylindrical
    /// joint along its axis.
    pub fn slide(&self, y: &[f64], joint: usize, ws: &mut Workspace<f64>) -> (f64, f64) {
        self.kinematics(y, ws);
        let j = &self.model.joints[joint];
        slide_of(&ws.mk[j.i], &ws.mk[j.j])
    }

    /// Reactions of every joint at `(t, y)` (one right-hand-side solve).
    pub fn reactions(&self, t: f64, y: &[f64], ws: &mut Workspace<f64>) -> Vec<Reaction> {
        let mut dy = vec![0.0; y.len()];
        self.rhs(t, y, &mut dy, ws);
        let mut out = Vec::with_capacity(self.model.joints.len());
        let mut r0 = 0;
        for joint in &self.model.joints {
            let ne = joint.kind.equations();
            let mj = ws.mk[joint.j];
            let mi = ws.mk[joint.i];
            // Use the moving side; the ground side gets the opposite.
            let (side, mk, sign) = if mj.slot.is_some() {
                (1, mj, 1.0)
            } else {
                (0, mi, -1.0)
            };
            let mut f = Vector3::zeros();
            let mut nb = Vector3::zeros();
            for r in r0..r0 + ne {
                let blk = ws.rows[r].blocks[side].1;
                let lam = ws.rhs[r];
                f += Vector3::new(blk[0], blk[1], blk[2]) * lam;
                nb += Vector3::new(blk[3], blk[4], blk[5]) * lam;
            }
            let torque_com = match mk.slot {
                Some(s) => ws.kin[s].a * nb,
                None => Vector3::zeros(),
            };
            let torque = torque_com - mk.s.cross(&f);
            out.push(Reaction {
                force: f * sign,
                torque: torque * sign,
            });
            r0 += ne;
        }
        out
    }
}
