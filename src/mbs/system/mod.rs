//! The assembled system and the data of one evaluation: [`System`] (the
//! model with its state layout and counters, [`state`]), the
//! [`Workspace`] with its row and kinematics types ([`workspace`]), and
//! the invariants lifted at the design seeds ([`invariants`]).

pub mod invariants;
pub mod state;
pub mod workspace;

pub use invariants::InvT;
pub(crate) use state::{bump, pval, same_seeds, SEED_SPARES};
pub use state::{Counters, System};
pub use workspace::{
    BodyBlock, BodyKin, MarkerKin, NodeShapes, Row, SolveScratch, Workspace, RANK_REG, RANK_TOL,
    RIGID,
};
