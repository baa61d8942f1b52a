//! Bodies that never move become fixed bodies.
//!
//! **Locked to the ground.** A locked joint holds the relative pose of
//! its two bodies at the one they start in (its drive keeps the angle at
//! the joint's `angle`, the angle its markers are built with). A rigid
//! body locked to a fixed body (or to `ground`) therefore never moves: in
//! exact arithmetic its state is its initial pose at rest, whatever the
//! rest of the scene does, and the joint's six equations only hold it
//! there. Integrating it costs its 13 states and six rows of every
//! constraint-space solve, and the motion of the other bodies does not
//! depend on it. So the scene builds such a body as a fixed body and
//! leaves the joint out; a body locked to one that became fixed follows
//! (a chain of locked bodies down to the ground).
//!
//! A body or joint the study reads is kept as it is (its outputs,
//! reactions and sensitivities are then computed as before): a body or
//! joint named by an output, the plot, a response or a sensitivity, the
//! joint of a force, the body of a load (or of its marker), and a body with an initial
//! velocity. A flexible body is never grounded this way (its modes still
//! move).
//!
//! **At rest.** Take the moving bodies that remain and join two of them
//! when a joint connects them. A group so joined that starts at rest
//! (no body with an initial velocity; a flexible body starts undeformed),
//! has no force element on any of its bodies (actuator, spring, load: on
//! one of its joints, markers or bodies), no driven joint, and lives in
//! a scene without gravity, stays at rest: its joints tie it only to
//! fixed bodies and to each other, the elastic forces of an undeformed
//! body vanish, and so do the velocity-dependent ones at rest, so zero
//! accelerations with zero multipliers satisfy its equations of motion,
//! whatever the other bodies do. Its bodies are built fixed and its
//! joints left out; a flexible one is built without modes (its basis
//! keeps the nodes and masses, not the eigen-analysis: nothing is
//! computed for it). Its strain and kinetic energies are then exactly 0,
//! its position its initial one, and the sensitivities of these to its
//! ply angles or masses exactly 0, as they were to rounding. A study that
//! reads anything else of the group (a joint's angle or reaction, a modal
//! coordinate, a marker's deflection, a mode frequency) keeps it moving.
//!
//! On the SAR scene (`B4` locked to the satellite `B1`, `B12` to `B4`)
//! the locks leave 53 of 65 constraint equations and 9 of 11 moving
//! bodies; the right-hand side costs 13 % less. In the phase-1 scenes
//! panel 2 (`B2`) and its three struts (`B5`–`B7`) are then such a group:
//! their joints reach only `B1` and `B12`, and no force acts on them. So
//! 26 equations and 5 moving bodies remain, and panel 2's eigen-analysis
//! is not done (`docs/performance.md`). Results move by the integration
//! tolerance only: the bodies were held to the integrator's
//! constraint-stabilisation accuracy, now exactly.

use super::spec::{BodySpec, ForceSpec, JointType, SceneSpec};
use super::Effect;
use std::collections::{HashMap, HashSet};

/// What a study may read of a body at rest (module doc): the part of a
/// read name after `<body>.`.
fn read_at_rest(kind: &str) -> bool {
    matches!(kind, "strain_energy" | "kinetic_energy" | "mass")
        || kind.starts_with("position")
        || kind.starts_with("design.")
}

impl SceneSpec {
    /// Which `[[scene.joints]]` entries are left out and which
    /// `[[scene.bodies]]` entries are built fixed (module doc), by index.
    /// A flexible body marked is at rest (built without modes).
    pub(super) fn grounded(&self) -> (Vec<bool>, Vec<bool>) {
        let (mut skip, mut ground) = self.locked_to_ground();
        let rest = self.at_rest(&skip, &ground);
        let resting: HashSet<&str> = (self.bodies.iter().zip(&rest))
            .filter(|&(_, &r)| r)
            .map(|(b, _)| b.name.as_str())
            .collect();
        for (s, j) in skip.iter_mut().zip(&self.joints) {
            *s |= resting.contains(j.body_i.as_str()) || resting.contains(j.body_j.as_str());
        }
        for (g, r) in ground.iter_mut().zip(&rest) {
            *g |= r;
        }
        (skip, ground)
    }

    /// Rigid bodies locked to the ground (module doc): the joints left
    /// out and the bodies built fixed.
    fn locked_to_ground(&self) -> (Vec<bool>, Vec<bool>) {
        let read = self.names_read();
        let flexible = self.has(Effect::Flexibility);
        let mut fixed: HashSet<&str> = self
            .bodies
            .iter()
            .filter(|b| b.fixed)
            .map(|b| b.name.as_str())
            .collect();
        fixed.insert("ground");
        let can_ground = |b: &BodySpec| {
            !(b.fixed
                || (flexible && b.flexible.is_some())
                || read.contains(b.name.as_str())
                || b.velocity != [0.0; 3]
                || b.angular_velocity != [0.0; 3])
        };
        let mut skip = vec![false; self.joints.len()];
        let mut ground = vec![false; self.bodies.len()];
        loop {
            let mut changed = false;
            for (k, j) in self.joints.iter().enumerate() {
                if skip[k] || j.kind != JointType::Locked || read.contains(j.name.as_str()) {
                    continue;
                }
                let other = match (
                    fixed.contains(j.body_i.as_str()),
                    fixed.contains(j.body_j.as_str()),
                ) {
                    (true, false) => &j.body_j,
                    (false, true) => &j.body_i,
                    _ => continue,
                };
                let Some(b) = self.bodies.iter().position(|b| &b.name == other) else {
                    continue;
                };
                if can_ground(&self.bodies[b]) {
                    skip[k] = true;
                    ground[b] = true;
                    fixed.insert(self.bodies[b].name.as_str());
                    changed = true;
                }
            }
            if !changed {
                return (skip, ground);
            }
        }
    }

    /// Names of bodies and joints the study reads: the first dotted part
    /// of every output, the plot, the responses' outputs and the
    /// sensitivities (each term of a tied lane), the joints of forces and
    /// the bodies of loads (or of their markers).
    fn names_read(&self) -> HashSet<&str> {
        let mut read: HashSet<&str> = (self.reads())
            .map(|t| t.split('.').next().unwrap_or(""))
            .collect();
        for f in &self.forces {
            let (joint, body) = match f {
                ForceSpec::Actuator { joint, .. } => (Some(joint), None),
                ForceSpec::Spring { joint, .. } => (joint.as_ref(), None),
                ForceSpec::Load { body, marker, .. } => {
                    let on = self
                        .markers
                        .iter()
                        .find(|m| Some(&m.name) == marker.as_ref());
                    read.extend(on.map(|m| m.body.as_str()));
                    (None, body.as_ref())
                }
            };
            read.extend(joint.into_iter().chain(body).map(String::as_str));
        }
        read
    }

    /// The moving bodies (neither fixed nor in `ground`) that stay at
    /// rest (module doc), by index; `skip`: joints already left out.
    fn at_rest(&self, skip: &[bool], ground: &[bool]) -> Vec<bool> {
        let n = self.bodies.len();
        let index: HashMap<&str, usize> = (self.bodies.iter().enumerate())
            .filter(|&(k, b)| !(b.fixed || ground[k]))
            .map(|(k, b)| (b.name.as_str(), k))
            .collect();
        if self.has(Effect::Gravity) || index.is_empty() {
            return vec![false; n];
        }
        let body_of = |name: &str| index.get(name).copied();
        // Groups: union-find over the moving bodies joined by joints.
        let mut root: Vec<usize> = (0..n).collect();
        fn find(root: &mut [usize], mut k: usize) -> usize {
            while root[k] != k {
                root[k] = root[root[k]];
                k = root[k];
            }
            k
        }
        for (j, _) in self.joints.iter().zip(skip).filter(|&(_, &s)| !s) {
            if let (Some(a), Some(b)) = (body_of(&j.body_i), body_of(&j.body_j)) {
                let (ra, rb) = (find(&mut root, a), find(&mut root, b));
                root[ra] = rb;
            }
        }
        let mut moves = vec![false; n];
        for k in self.bodies_that_move() {
            if let Some(b) = body_of(k) {
                let r = find(&mut root, b);
                moves[r] = true;
            }
        }
        let moving: HashSet<usize> = index.values().copied().collect();
        (0..n)
            .map(|k| moving.contains(&k) && !moves[find(&mut root, k)])
            .collect()
    }

    /// Names of the bodies that move or whose group must stay built
    /// (module doc, "At rest"): with an initial velocity, under a force
    /// element, on a driven joint, or read beyond its energies, position,
    /// mass and ply-angle sensitivities (a joint's, a marker's or any
    /// other reading names the bodies it sits on).
    fn bodies_that_move(&self) -> Vec<&str> {
        let mut out: Vec<&str> = (self.bodies.iter())
            .filter(|b| b.velocity != [0.0; 3] || b.angular_velocity != [0.0; 3])
            .map(|b| b.name.as_str())
            .collect();
        let joint_bodies = |name: &str| -> Vec<&str> {
            (self.joints.iter())
                .filter(|j| j.name == name)
                .flat_map(|j| [j.body_i.as_str(), j.body_j.as_str()])
                .collect()
        };
        let marker_body = |name: &str| {
            (self.markers.iter())
                .find(|m| m.name == name)
                .map(|m| m.body.as_str())
        };
        for j in &self.joints {
            if j.drive.is_some() {
                out.extend([j.body_i.as_str(), j.body_j.as_str()]);
            }
        }
        for f in &self.forces {
            match f {
                ForceSpec::Actuator { joint, .. } => out.extend(joint_bodies(joint)),
                ForceSpec::Spring {
                    joint,
                    marker_i,
                    marker_j,
                    ..
                } => {
                    out.extend(joint.iter().flat_map(|j| joint_bodies(j)));
                    let markers = marker_i.iter().chain(marker_j);
                    out.extend(markers.filter_map(|m| marker_body(m)));
                }
                ForceSpec::Load { body, marker, .. } => {
                    out.extend(body.as_deref());
                    out.extend(marker.as_deref().and_then(marker_body));
                }
            }
        }
        for part in self.reads() {
            let (head, kind) = part.split_once('.').unwrap_or((part, ""));
            if self.bodies.iter().any(|b| b.name == head) {
                if !read_at_rest(kind) {
                    out.push(head);
                }
            } else {
                out.extend(joint_bodies(head).into_iter().chain(marker_body(head)));
            }
        }
        out
    }

    /// Every name the study reads: each output, the plot, each response's
    /// outputs and each sensitivity, a tied lane term by term, trimmed.
    fn reads(&self) -> impl Iterator<Item = &str> {
        let outputs = self.outputs.quantities.iter().chain(&self.outputs.plot);
        let responses = self.responses.iter().flat_map(|r| r.of.iter());
        (outputs.chain(responses).chain(&self.sensitivities))
            .flat_map(|s| s.split('+'))
            .map(str::trim)
    }
}
