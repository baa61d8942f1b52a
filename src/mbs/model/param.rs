//! Sensitivity parameters: the model values a forward sensitivity can
//! differentiate with respect to, read and set by index.

use super::force::Force;
use super::mechanism::Model;

/// A model value that can be a sensitivity parameter. In the right-hand
/// side it is read through [`crate::mbs::Workspace::params`], so that a
/// dual-number value gives the exact parameter derivative `∂f/∂p`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Param {
    /// Stiffness `k` of the spring-damper `forces[i]` (N/m), between
    /// markers or along a joint, or of a torsion spring (N·m/rad).
    Stiffness(usize),
    /// Damping of `forces[i]`: `c` of a spring-damper (N·s/m) or of a
    /// rotational actuator or torsion spring (N·m·s).
    Damping(usize),
    /// Mass of `bodies[i]` (kg): translational inertia and weight (the
    /// inertia tensor is a separate datum).
    Mass(usize),
    /// Anchor (breakpoint) of segment `k` of the law of the actuator
    /// `forces[i]`: the `3.12` in `0.10 + 9.00(3.12 − θ)` (rad).
    Anchor(usize, usize),
    /// Slope of segment `k` of the law of the actuator `forces[i]`: the
    /// `9.00` in `0.10 + 9.00(3.12 − θ)` (N·m/rad), the law's spring rate
    /// on that segment.
    Slope(usize, usize),
    /// Design variable `k` (a ply angle, rad) of the modal basis of the
    /// flexible body `bodies[i]`: its exact effect on Λ and the mode
    /// shapes comes from the basis's derivatives (`dΛ/dθ`, `dX/dθ`).
    Design(usize, usize),
    /// One ply angle shared by several flexible bodies (rad): the design
    /// variables `Model::ties[g]` (`(body, variable)` pairs) move
    /// together, so one sensitivity lane gives the derivative with respect
    /// to the shared angle (the sum of the members' lanes).
    Tied(usize),
}

impl Param {
    /// The model's current value of this parameter, if it exists.
    pub fn value(&self, model: &Model) -> Option<f64> {
        match *self {
            Param::Mass(b) => model.bodies.get(b).map(|b| b.mass),
            Param::Stiffness(f) => match model.forces.get(f) {
                Some(Force::SpringDamper { stiffness, .. })
                | Some(Force::JointSpring { stiffness, .. })
                | Some(Force::TorsionSpring { stiffness, .. }) => Some(*stiffness),
                _ => None,
            },
            Param::Damping(f) => match model.forces.get(f) {
                Some(Force::SpringDamper { damping, .. })
                | Some(Force::JointSpring { damping, .. })
                | Some(Force::TorsionSpring { damping, .. })
                | Some(Force::Rotational { damping, .. }) => Some(*damping),
                _ => None,
            },
            Param::Anchor(f, k) => match model.forces.get(f) {
                Some(Force::Rotational { law: Some(l), .. }) => l.segments.get(k).map(|s| s.anchor),
                _ => None,
            },
            Param::Slope(f, k) => match model.forces.get(f) {
                Some(Force::Rotational { law: Some(l), .. }) => l.segments.get(k).map(|s| s.slope),
                _ => None,
            },
            Param::Design(b, k) => model
                .bodies
                .get(b)
                .and_then(|b| b.flex.as_ref())
                .and_then(|f| f.design.get(k).copied()),
            Param::Tied(g) => {
                let &(b, k) = model.ties.get(g)?.first()?;
                Param::Design(b, k).value(model)
            }
        }
    }

    /// The design variable of flexible body `body` that this parameter
    /// seeds, if any ([`Param::Design`] of that body, or a member of a
    /// [`Param::Tied`] group).
    pub fn design_of(&self, model: &Model, body: usize) -> Option<usize> {
        match *self {
            Param::Design(b, k) if b == body => Some(k),
            Param::Tied(g) => model
                .ties
                .get(g)?
                .iter()
                .find(|(b, _)| *b == body)
                .map(|(_, k)| *k),
            _ => None,
        }
    }

    /// Whether this is a ply-angle parameter (design or tied design).
    pub fn is_design(&self) -> bool {
        matches!(self, Param::Design(..) | Param::Tied(_))
    }

    /// Set this parameter to `v` in `model` (for finite differences and
    /// studies). A [`Param::Design`] variable only records `v`: the modal
    /// basis must be rebuilt for the new design (its derivatives describe
    /// the old one).
    pub fn set(&self, model: &mut Model, v: f64) {
        match *self {
            Param::Mass(b) => model.bodies[b].mass = v,
            Param::Stiffness(f) => match &mut model.forces[f] {
                Force::SpringDamper { stiffness, .. }
                | Force::JointSpring { stiffness, .. }
                | Force::TorsionSpring { stiffness, .. } => *stiffness = v,
                _ => {}
            },
            Param::Damping(f) => match &mut model.forces[f] {
                Force::SpringDamper { damping, .. }
                | Force::JointSpring { damping, .. }
                | Force::TorsionSpring { damping, .. }
                | Force::Rotational { damping, .. } => *damping = v,
                _ => {}
            },
            Param::Anchor(f, k) => {
                if let Force::Rotational { law: Some(l), .. } = &mut model.forces[f] {
                    l.segments[k].anchor = v;
                }
            }
            Param::Slope(f, k) => {
                if let Force::Rotational { law: Some(l), .. } = &mut model.forces[f] {
                    l.segments[k].slope = v;
                }
            }
            Param::Design(b, k) => {
                if let Some(f) = model.bodies[b].flex.as_mut() {
                    f.design[k] = v;
                }
            }
            Param::Tied(g) => {
                for (b, k) in model.ties[g].clone() {
                    Param::Design(b, k).set(model, v);
                }
            }
        }
    }
}
