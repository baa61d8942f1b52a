//! Rigid bodies held to the ground by locked joints become fixed bodies.
//!
//! A locked joint holds the relative pose of its two bodies at the one
//! they start in (its drive keeps the angle at the joint's `angle`, the
//! angle its markers are built with). A rigid body locked to a fixed body
//! (or to `ground`) therefore never moves: in exact arithmetic its state
//! is its initial pose at rest, whatever the rest of the scene does, and
//! the joint's six equations only hold it there. Integrating it costs its
//! 13 states and six rows of every constraint-space solve, and the motion
//! of the other bodies does not depend on it. So the scene builds such a
//! body as a fixed body and leaves the joint out; a body locked to one
//! that became fixed follows (a chain of locked bodies down to the
//! ground).
//!
//! A body or joint the study reads is kept as it is (its outputs,
//! reactions and sensitivities are then computed as before): a body or
//! joint named by an output, the plot, a response or a sensitivity, the
//! joint of a force, the body of a load (or of its marker), and a body with an initial
//! velocity. A flexible body is never grounded (its modes still move).
//!
//! On the SAR scene (`B4` locked to the satellite `B1`, `B12` to `B4`)
//! this leaves 53 of 65 constraint equations and 9 of 11 moving bodies;
//! the right-hand side costs 13 % less (`docs/performance.md`). Results
//! move by the integration tolerance only: the grounded bodies were held
//! to the integrator's constraint-stabilisation accuracy, now exactly.

use super::spec::{BodySpec, ForceSpec, JointType, SceneSpec};
use super::Effect;
use std::collections::HashSet;

impl SceneSpec {
    /// Which `[[scene.joints]]` entries are left out and which
    /// `[[scene.bodies]]` entries are built fixed (module doc), by index.
    pub(super) fn grounded(&self) -> (Vec<bool>, Vec<bool>) {
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
        fn head(s: &str) -> impl Iterator<Item = &str> {
            s.split('+')
                .map(|t| t.trim().split('.').next().unwrap_or(""))
        }
        let mut read = HashSet::new();
        let outputs = self.outputs.quantities.iter().chain(&self.outputs.plot);
        let responses = self.responses.iter().flat_map(|r| r.of.iter());
        for s in outputs.chain(responses).chain(&self.sensitivities) {
            read.extend(head(s));
        }
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
}
