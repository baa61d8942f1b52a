//! The right-hand side of the equations of motion: the flexible bodies'
//! mass matrices and inertia, elastic and damping forces ([`flexbody`]),
//! the energy terms of integrated states ([`energy`]), and `ẏ = f(t, y)`
//! ([`rhs`]).

pub mod energy;
pub mod flexbody;
pub mod rhs;
