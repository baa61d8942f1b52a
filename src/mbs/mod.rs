//! Flexible multibody kernel (issue 3): rigid spatial bodies with Euler
//! parameters, floating-frame flexible bodies with modal coordinates
//! (paper Eqs. 5–6; [`flex`], [`flexdyn`], bases from closed-form beams
//! [`beam`] or from composite panels `crate::panels::panel_basis`),
//! markers (on flexible bodies: on mesh nodes, moving and rotating with the
//! modes), joints (spherical, revolute, driven/locked revolute, fixed,
//! prismatic, cylindrical), force elements ([`forces`]: gravity, the
//! paper's Eq. 32 spring-damper-actuator, linear spring-dampers between
//! markers or along a sliding joint, constant or time-tabulated loads at
//! a centre of mass or a marker, in global or body axes), the equations
//! of motion with Lagrange multipliers, consistent initial conditions,
//! energies ([`energy`]: kinetic and strain, as outputs and response
//! terms) and outputs. It knows nothing of files: scenes are built by
//! [`crate::scene`], simulated by [`crate::simulate`].
//!
//! ## Method
//! The equations of motion are the index-3 DAE of the paper (Eqs. 2–4, 6),
//! reduced at every right-hand-side evaluation to an ODE in positions and
//! velocities by solving for accelerations and multipliers ([`dynamics`]).
//! The mass matrix is block diagonal by body (dense `(6+n)²` blocks for
//! flexible bodies, from the inertia invariants), so only the
//! constraint-space matrix `G M⁻¹ Gᵀ` (size = number of equations) is
//! formed, from the sparse rows of `G`, and factored by a Cholesky in a
//! minimum-degree order with a tiny Tikhonov shift: redundant equations are
//! detected and counted from the pivots, the ones redundant at the start
//! are left out of the solve, the accelerations stay unique, and the
//! solution stays smooth where the rank changes. Drift is controlled by
//! Baumgarte stabilisation (critically damped, rate `α` from the scene),
//! which keeps the state an ordinary ODE for any integrator (BDF, explicit
//! and SDIRK Runge–Kutta), unlike projection, which would have to restart
//! multistep histories. Initial conditions are projected onto the
//! constraints ([`analysis`]). Forward sensitivities (stiffness, damping,
//! mass, Eq. 32 breakpoints, ply angles of flexible bodies through
//! `dΛ/dθ` and `dX/dθ`, one angle shared by several bodies as a tied
//! lane: [`Param`]) come from [`crate::integrate::integrate_sens`], with
//! exact products from dual-number evaluations of the same right-hand
//! side; the system is an [`crate::integrate::OdeModel`] ([`ode`]) and its
//! Eq. 32 segment changes are the model's events ([`segments`]).
//!
//! Where things go: a new joint type is a [`JointKind`] variant with its
//! equation count in [`model`] and its constraint rows in [`rows`]
//! (assembled in [`dynamics`]); a new force element is a [`Force`] variant
//! applied in [`forces`]; the scene names both ([`crate::scene`]).
//!
//! ## Limitations
//! - Linear elasticity in a floating frame: no geometric stiffening, so a
//!   fast-spinning flexible body softens by about `Ω²/ω₁²` (the classic
//!   spin-up limitation of the linear floating frame; the beam spin-up
//!   study shows the size).
//! - A revolute relative angle is measured in (−π, π]; marker frames are
//!   set so that the scene's initial angle sits inside that range. A
//!   driven joint's prescribed angle is compared modulo 2π.
//! - Change-point singularities (a parallelogram four-bar passing its flat
//!   position, where two motion branches cross) are solved without
//!   failure thanks to the regularisation, but the motion is not
//!   guaranteed to continue on the physical branch. Singular positions of
//!   ordinary mechanisms (rocker dead points) are fine.
//! - Sensitivities assume an initial state independent of the
//!   parameters.

pub mod analysis;
pub mod beam;
pub mod dual;
pub mod dynamics;
pub mod energy;
pub mod flex;
pub mod flexdyn;
pub mod forces;
pub mod linalg;
pub mod model;
pub mod ode;
pub mod planes;
pub mod responses;
pub mod rows;
pub mod segments;
pub mod solve;
pub mod workspace;

pub use analysis::{Projection, Reaction};
pub use dynamics::{System, Workspace};
pub use energy::Energy;
pub use flex::{BasisDerivative, DroppedMode, Invariants, ModalBasis, RigidScreen};
pub use model::{
    Body, Drive, Force, Joint, JointKind, Load, LoadFrame, Marker, Model, Param, PiecewiseLaw,
    Segment,
};
