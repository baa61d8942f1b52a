//! Constraints: the rows of every joint kind's blocks ([`rows`]), their
//! assembly with modal entries and Baumgarte stabilisation
//! ([`assemble`]), and the constraint-space solve for the multipliers and
//! accelerations ([`solve`]) with its exact tangent for dual evaluations
//! ([`tangent`]),
//! including the joint-load prestress of geometric stiffening
//! ([`prestress`]).

pub mod assemble;
pub mod prestress;
pub mod rows;
pub mod solve;
pub mod tangent;
