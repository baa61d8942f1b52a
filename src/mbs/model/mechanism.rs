//! The whole model: bodies, markers, joints and force elements, the
//! Baumgarte rate and effects, the energy terms of outputs and integrated
//! states ([`Energy`], [`Integral`]) and tied design variables.

use super::body::{Body, Marker};
use super::force::Force;
use super::joint::Joint;

/// The whole rigid model.
#[derive(Debug, Clone, Default)]
pub struct Model {
    /// Bodies (rigid, flexible or fixed); markers, loads and design ties
    /// refer to them by index.
    pub bodies: Vec<Body>,
    /// Markers; joints, spring-dampers and marker loads refer to them by
    /// index.
    pub markers: Vec<Marker>,
    /// Joints; their constraint rows are assembled in this order.
    pub joints: Vec<Joint>,
    /// Force elements (only those of the scene's effects).
    pub forces: Vec<Force>,
    /// Baumgarte rate α (1/s): the constraint acceleration equation is
    /// `Φ̈ + 2αΦ̇ + α²Φ = 0` (critically damped drift).
    pub baumgarte: f64,
    /// Quadratic-velocity inertia terms (gyroscopic `ω×Jω` of rigid
    /// bodies; centrifugal and Coriolis couplings of flexible ones): the
    /// scene's `quadratic_velocity` effect.
    pub quadratic_velocity: bool,
    /// Geometric stiffening of the flexible bodies by their inertial
    /// prestress ([`super::geometric`]): the scene's
    /// `geometric_stiffening` effect.
    pub geometric_stiffening: bool,
    /// Time integrals carried as extra states (after the velocities), so
    /// that their sensitivities come with the integration
    /// (docs/numerics.md, "Responses and optimization").
    pub integrals: Vec<Integral>,
    /// Groups of `(body, design variable)` that [`Param::Tied`](crate::mbs::Param::Tied) lanes move
    /// together.
    pub ties: Vec<Vec<(usize, usize)>>,
    /// Divergence guard: an integration ends when a flexible body's
    /// modal deflection bound exceeds this factor times the body's size
    /// (`crate::mbs::watch`); `None` (or infinite): no guard.
    pub divergence_limit: Option<f64>,
    /// Fast-rotation warning: a flexible body without geometric
    /// stiffening warns when its frame turns faster than this fraction
    /// of its first modal frequency (`crate::simulate::spin`); `None`:
    /// [`SPIN_WARNING_FRACTION`].
    pub spin_warning_fraction: Option<f64>,
}

/// The default fraction of a flexible body's first modal frequency above
/// which its frame's angular speed draws the fast-rotation warning
/// (`crate::simulate::spin`; the scene's `spin_warning_fraction`).
pub const SPIN_WARNING_FRACTION: f64 = 0.3;

/// `∫ scale · Σ terms dt` over energy terms (strain and kinetic energies
/// of bodies, [`Energy`]): the paper's objective Ψ₀ = ∫ 2U dt (Eq. 33) is
/// the strain energies of the flexible bodies with `scale = 2`; the
/// IDAS slider-crank's `G = ∫ T dt` the kinetic energies with 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Integral {
    /// Energy terms summed under the integral.
    pub terms: Vec<Energy>,
    /// Factor applied to the sum (2 for the paper's Ψ₀ = ∫ 2U dt).
    pub scale: f64,
}

impl Model {
    /// Index of a marker by name.
    pub fn marker(&self, name: &str) -> Option<usize> {
        self.markers.iter().position(|m| m.name == name)
    }
    /// Index of a body by name.
    pub fn body(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }
    /// Index of a joint by name.
    pub fn joint(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }
    /// Total number of constraint equations.
    pub fn equations(&self) -> usize {
        self.joints.iter().map(|j| j.kind.equations()).sum()
    }
    /// Label of constraint row `r` (rows are assembled joint by joint in
    /// the order of [`Model::joints`]): `<joint>.<equation>` with the
    /// equation named by [`JointKind::row_names`](crate::mbs::JointKind::row_names), e.g. `S3.z`; `None`
    /// past the last row.
    pub fn row_label(&self, r: usize) -> Option<String> {
        let mut first = 0;
        for j in &self.joints {
            let n = j.kind.equations();
            if r < first + n {
                let name = j.kind.row_names().nth(r - first)?;
                return Some(format!("{}.{}", j.name, name));
            }
            first += n;
        }
        None
    }
}

/// One energy term (J), evaluated by `crate::mbs::dynamics::energy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Energy {
    /// Strain energy `½ wᵀΛw` of body `bodies[i]` (zero for a rigid or
    /// fixed body).
    Strain(usize),
    /// Kinetic energy of body `bodies[i]` (zero for a fixed body).
    Kinetic(usize),
}

impl Energy {
    /// The kinetic energy of every body of `model` (fixed bodies give 0).
    pub fn kinetic_total(model: &Model) -> Vec<Energy> {
        (0..model.bodies.len())
            .filter(|&b| !model.bodies[b].fixed)
            .map(Energy::Kinetic)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::model::{Drive, JointKind};

    #[test]
    fn row_names_match_the_equation_counts_and_label_rows_in_joint_order() {
        let kinds = [
            JointKind::Spherical,
            JointKind::Revolute,
            JointKind::Driven(Drive::Polynomial(vec![0.0])),
            JointKind::Fixed,
            JointKind::Cylindrical,
            JointKind::Prismatic,
        ];
        for k in &kinds {
            assert_eq!(k.row_names().count(), k.equations(), "{k:?}");
        }
        let joint = |name: &str, kind: JointKind| Joint {
            name: name.into(),
            kind,
            i: 0,
            j: 0,
        };
        let model = Model {
            joints: vec![
                joint("R", JointKind::Revolute),
                joint("S", JointKind::Spherical),
            ],
            ..Model::default()
        };
        let labels: Vec<Option<String>> = (0..9).map(|r| model.row_label(r)).collect();
        assert_eq!(labels[0].as_deref(), Some("R.x"));
        assert_eq!(labels[4].as_deref(), Some("R.yi.zj"));
        assert_eq!(labels[5].as_deref(), Some("S.x"));
        assert_eq!(labels[7].as_deref(), Some("S.z"));
        assert_eq!(labels[8], None);
    }
}
