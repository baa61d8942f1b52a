//! Energies as outputs and response values: sums of energy terms at a
//! state in any scalar (the terms are `crate::mbs::dynamics::energy`'s),
//! and the total kinetic energy.

use crate::mbs::math::Scalar;
use crate::mbs::model::Energy;
use crate::mbs::system::{System, Workspace};

impl System {
    /// `Σ terms` at state `y` (J), in any scalar: the parameters (and
    /// design seeds) are those in `ws.params`. Fills the body kinematics
    /// of `ws` (not the markers': energies need none) and, when a term
    /// needs them, the flexible mass matrices.
    pub fn energy_sum<T: Scalar>(&self, terms: &[Energy], y: &[T], ws: &mut Workspace<T>) -> T {
        let mut kin = std::mem::take(&mut ws.kin);
        self.body_kin(y, &ws.params, &mut kin);
        ws.kin = kin;
        let flexible_kinetic = terms.iter().any(|t| match t {
            Energy::Kinetic(b) => self.slot[*b].is_some_and(|s| self.modes[s] > 0),
            Energy::Strain(_) => false,
        });
        if flexible_kinetic {
            self.mass_factors(ws);
        }
        terms
            .iter()
            .fold(T::zero(), |acc, t| acc + self.energy_term(*t, y, ws))
    }

    /// Total kinetic energy of the moving bodies (J) at state `y`.
    pub fn kinetic_energy(&self, y: &[f64], ws: &mut Workspace<f64>) -> f64 {
        self.energy_sum(&Energy::kinetic_total(&self.model), y, ws)
    }
}
