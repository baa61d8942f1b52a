//! Energies of the bodies as functions of the state, generic over the
//! scalar so that a dual-number evaluation gives their exact derivatives
//! with respect to the state and the parameters: the kinetic energy of
//! every moving body and the strain energy of flexible ones. They are the
//! terms ([`Energy`]) of outputs, integrated states
//! ([`super::model::Integral`]) and response functionals.
//!
//! Kinetic energy (J), with the velocities `v = [ṙ, ω', ẇ]` of the state:
//! - rigid body, frame at the centre of mass:
//!   `T = ½ m |ṙ|² + ½ ω'ᵀ J ω'` (m read through [`Param::Mass`]);
//! - floating-frame flexible body: `T = ½ vᵀ M(w) v` with the mass
//!   matrix of [`super::flexdyn`] (configuration-dependent through the
//!   modal coordinates `w`, design-dependent through the lifted
//!   invariants), taken before it is factored (`System::flex_bodies`).
//!
//! Strain energy: `U = ½ wᵀ Λ w` of a flexible body
//! ([`System::strain_energy_dual`]).

use super::dynamics::{pval, System, Workspace};
use super::linalg::{cst, mv, Scalar};
use super::model::Param;

/// One energy term (J).
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
    pub fn kinetic_total(model: &super::model::Model) -> Vec<Energy> {
        (0..model.bodies.len())
            .filter(|&b| !model.bodies[b].fixed)
            .map(Energy::Kinetic)
            .collect()
    }
}

/// `½ vᵀ M v` of a dense row-major `d × d` matrix `m`.
pub(crate) fn quadratic_form<T: Scalar>(m: &[T], v: &[T], d: usize) -> T {
    let mut e = T::zero();
    for r in 0..d {
        let row = &m[r * d..(r + 1) * d];
        let mv = row
            .iter()
            .zip(v)
            .fold(T::zero(), |acc, (a, b)| acc + *a * *b);
        e += v[r] * mv;
    }
    e * cst::<T>(0.5)
}

impl System {
    /// Value of `term` at state `y` with the kinematics in `ws` (and, for
    /// the kinetic energy of a flexible body, its mass matrix: after
    /// [`System::rhs`] or [`System::energy_sum`]).
    pub(crate) fn energy_term<T: Scalar>(&self, term: Energy, y: &[T], ws: &Workspace<T>) -> T {
        match term {
            Energy::Strain(b) => self.slot[b].map_or(T::zero(), |s| {
                self.strain_energy_dual(y, s, &ws.kin[s].design)
            }),
            Energy::Kinetic(b) => self.slot[b].map_or(T::zero(), |s| self.kinetic_of(s, ws)),
        }
    }

    /// Kinetic energy of slot `s` (J) from the kinematics in `ws`.
    fn kinetic_of<T: Scalar>(&self, s: usize, ws: &Workspace<T>) -> T {
        if self.modes[s] > 0 {
            return ws.kinetic[s];
        }
        let b = self.moving[s];
        let body = &self.model.bodies[b];
        let k = &ws.kin[s];
        let m = pval(&ws.params, Param::Mass(b), body.mass);
        let jw = mv(&body.inertia.map(cst::<T>), &k.wb);
        (m * k.v.norm_squared() + k.wb.dot(&jw)) * cst::<T>(0.5)
    }

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
