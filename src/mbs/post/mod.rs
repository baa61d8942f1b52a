//! After the solve: consistent initial conditions (projection), loads,
//! violations, reactions, momenta and deflections ([`analysis`]), energy
//! sums and the energy error of a run ([`energy`]) and the response
//! functionals with their sensitivity lanes ([`responses`]) and the
//! reductions of sampled responses ([`series`]).

pub mod analysis;
pub mod energy;
pub mod responses;
pub mod series;
