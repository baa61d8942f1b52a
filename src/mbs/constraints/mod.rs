//! Constraints: the rows of every joint kind's blocks ([`rows`]), their
//! assembly with modal entries and Baumgarte stabilisation
//! ([`assemble`]), and the constraint-space solve for the multipliers and
//! accelerations, with its exact tangent for dual evaluations ([`solve`]).

pub mod assemble;
pub mod rows;
pub mod solve;
