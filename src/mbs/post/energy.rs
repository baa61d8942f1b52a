//! Energies as outputs and response values: sums of energy terms at a
//! state in any scalar (the terms are `crate::mbs::dynamics::energy`'s),
//! the total kinetic energy, and the energy error of a conservative run
//! ([`EnergyMonitor`]).
//!
//! The energy error of a run is `max_t |E(t) − E0| / S` with the scale
//! `S = max(max_t |E(t)|, max_t T(t), max_t V(t) − min_t V(t))` over the
//! observed states (including the first), `E` the mechanical energy
//! ([`System::energy`]), `T` the kinetic energy and `V = E − T` the
//! potential (gravity, strain, springs). `S` vanishes only when nothing
//! moves and `E ≡ 0`; then the error is 0. A run from rest at the
//! potential's zero (free fall, a pendulum released at the datum) keeps
//! `E ≈ 0` and is measured against the kinetic energy it gains, not
//! against `|E|`.

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

/// Running energy error of a conservative run (module doc for the
/// definition): feed it every output state with [`EnergyMonitor::observe`].
#[derive(Debug, Clone)]
pub struct EnergyMonitor {
    /// Energy at the start (J).
    e0: f64,
    /// Largest `|E − E0|` so far (J).
    change: f64,
    /// Largest `|E|` and `T` so far (J), with `|E0|`.
    largest: f64,
    /// Smallest and largest potential `V = E − T` so far (J).
    potential: (f64, f64),
}

impl EnergyMonitor {
    /// A monitor for a run that starts with energy `e0` (J).
    pub fn new(e0: f64) -> EnergyMonitor {
        EnergyMonitor {
            e0,
            change: 0.0,
            largest: e0.abs(),
            potential: (f64::INFINITY, f64::NEG_INFINITY),
        }
    }

    /// Record the state `y`; returns its energy `E` (J). Leaves `ws` as
    /// [`System::energy`] alone does (the kinetic energy is summed first).
    pub fn observe(&mut self, sys: &System, y: &[f64], ws: &mut Workspace<f64>) -> f64 {
        let t = sys.kinetic_energy(y, ws);
        let e = sys.energy(y, ws);
        self.change = self.change.max((e - self.e0).abs());
        self.largest = self.largest.max(e.abs()).max(t);
        let v = e - t;
        self.potential = (self.potential.0.min(v), self.potential.1.max(v));
        e
    }

    /// The energy error so far: `max |E − E0| / S` (0 when `S` = 0).
    pub fn error(&self) -> f64 {
        let range = (self.potential.1 - self.potential.0).max(0.0);
        let scale = self.largest.max(range);
        if scale > 0.0 {
            self.change / scale
        } else {
            0.0
        }
    }
}
