//! The model as data: bodies and markers ([`body`]), modal bases and
//! their inertia invariants ([`flex`]), the geometric stiffness of
//! their inertial and joint-load prestress ([`geometric`]), joints and the table of joint
//! kinds ([`joint`]) with the prescribed motion of driven joints
//! ([`drive`]), force elements ([`force`]), the whole model with its
//! energy terms ([`mechanism`]) and sensitivity parameters ([`param`]),
//! with their validation. SI units throughout. Nothing here depends on
//! the state.

pub mod body;
pub mod drive;
pub mod flex;
pub mod force;
pub mod geometric;
pub mod joint;
pub mod mechanism;
pub mod param;

pub use body::{Body, Flex, Marker};
pub use drive::{Drive, Harmonic, Piece, Spline};
pub use flex::{BasisDerivative, DroppedMode, Invariants, ModalBasis, RigidScreen};
pub use force::{Force, Load, LoadFrame, PiecewiseLaw, Segment};
pub use joint::{Joint, JointKind, RowBlock};
pub use mechanism::{Energy, Integral, Model, SPIN_WARNING_FRACTION};
pub use param::Param;
