//! Energies of the bodies as functions of the state, generic over the
//! scalar so that a dual-number evaluation gives their exact derivatives
//! with respect to the state and the parameters: the kinetic energy of
//! every moving body and the strain energy of flexible ones. They are the
//! terms ([`Energy`]) of integrated states
//! ([`Integral`](crate::mbs::model::Integral), in the right-hand side),
//! outputs and response functionals (`crate::mbs::post::energy`).
//!
//! Kinetic energy (J), with the velocities `v = [ṙ, ω', ẇ]` of the state:
//! - rigid body, frame at the centre of mass:
//!   `T = ½ m |ṙ|² + ½ ω'ᵀ J ω'` (m read through [`Param::Mass`]);
//! - floating-frame flexible body: `T = ½ vᵀ M(w) v` with the mass
//!   matrix of [`crate::mbs::forces::flexbody`] (configuration-dependent through the
//!   modal coordinates `w`, design-dependent through the lifted
//!   invariants), taken before it is factored (`System::flex_bodies`).
//!
//! Strain energy: `U = ½ wᵀ Λ w` of a flexible body
//! ([`System::strain_energy_dual`]).

use crate::mbs::math::{cst, mv, Scalar};
use crate::mbs::model::{Energy, Param};
use crate::mbs::system::{pval, System, Workspace};

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

    /// Strain energy of flexible slot `s` in any scalar, with design seeds
    /// `(variable, δ)` applied to Λ.
    pub fn strain_energy_dual<T: Scalar>(&self, y: &[T], s: usize, design: &[(usize, T)]) -> T {
        let b = self.moving[s];
        let Some(flex) = self.model.bodies[b].flex.as_ref() else {
            return T::zero();
        };
        let p = self.pos_off(s) + 7;
        let half = nalgebra::convert::<f64, T>(0.5);
        (0..self.modes[s]).fold(T::zero(), |acc, j| {
            let mut l = nalgebra::convert::<f64, T>(flex.inv.lambda[j]);
            for (var, d) in design {
                l += nalgebra::convert::<f64, T>(flex.dinv[*var].lambda[j]) * *d;
            }
            acc + half * l * y[p + j] * y[p + j]
        })
    }

    /// Strain energy `½ wᵀΛw` of flexible slot `s` (J).
    pub fn strain_energy(&self, y: &[f64], s: usize) -> f64 {
        self.strain_energy_dual(y, s, &[])
    }
}
