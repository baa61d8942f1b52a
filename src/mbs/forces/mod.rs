//! Applied generalized forces: the flexible bodies' mass matrices with
//! their inertia, elastic and damping forces ([`flexbody`]), and the force
//! elements with the gyroscopic terms of rigid bodies ([`elements`]).

pub mod elements;
pub mod flexbody;
