//! The right-hand side of the equations of motion: the energy terms of
//! integrated states ([`energy`]) and `ẏ = f(t, y)` ([`rhs`]).

pub mod energy;
pub mod rhs;
