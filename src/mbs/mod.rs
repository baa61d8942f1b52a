//! Flexible multibody kernel: rigid spatial bodies with Euler
//! parameters, floating-frame flexible bodies with modal coordinates
//! (paper Eqs. 5–6; bases from closed-form beams `crate::beams` or from
//! composite panels `crate::panels::panel_basis`), markers (on flexible
//! bodies: on mesh nodes, moving and rotating with the modes), joints
//! (spherical, revolute, driven/locked revolute, fixed, prismatic,
//! cylindrical), force elements (gravity, the paper's Eq. 32
//! spring-damper-actuator, linear spring-dampers between markers or along
//! a sliding joint, constant or time-tabulated loads at a centre of mass
//! or a marker, in global or body axes), the equations of motion with
//! Lagrange multipliers, consistent initial conditions, energies (kinetic
//! and strain, as outputs and response terms) and outputs. It knows
//! nothing of files: scenes are built by [`crate::scene`], simulated by
//! [`crate::simulate`].
//!
//! ## Layers
//! Top-down; every file imports only layers below it (methods of
//! [`System`] are added by the layers above [`system`]):
//! - [`ode`], [`segments`], [`watch`]: the system as an
//!   [`crate::integrate::OdeModel`] (plain, directional and multi-lane
//!   right-hand sides) and its events: the Eq. 32 segment changes, the
//!   dropped constraint rows chosen anew when one drifts, and the
//!   divergence guard of the flexible bodies.
//! - [`post`]: projection onto the constraints, loads, reactions, momenta,
//!   deflections, energy sums, responses and their sensitivity lanes.
//! - [`dynamics`]: the right-hand side `ẏ = f(t, y)` and the energy
//!   terms of integrated states.
//! - [`forces`]: applied generalized forces: the flexible bodies' mass
//!   matrices with their inertia, elastic and damping forces, the force
//!   elements.
//! - [`constraints`]: the rows of the joint kinds' row blocks, their
//!   assembly with Baumgarte stabilisation, the constraint-space solve.
//! - [`kinematics`]: body and marker kinematics at a state, joint angles
//!   and slides.
//! - [`system`]: [`System`] (the model, its state layout, counters) and
//!   the [`Workspace`] of one evaluation.
//! - [`model`]: bodies, markers, joints (the table of joint kinds), forces,
//!   parameters and energy terms as data; modal bases and invariants.
//! - [`math`]: scalar and dual-number traits, rotations and 3 × 3 helpers,
//!   dense and sparse Cholesky.
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
//! constraints ([`post::analysis`]). Forward sensitivities (stiffness, damping,
//! mass, Eq. 32 breakpoints, ply angles of flexible bodies through
//! `dΛ/dθ` and `dX/dθ`, one angle shared by several bodies as a tied
//! lane: [`Param`]) come from [`crate::integrate::integrate_sens`], with
//! exact products from dual-number evaluations of the same right-hand
//! side; the system is an [`crate::integrate::OdeModel`] ([`ode`]) and its
//! Eq. 32 segment changes are the model's events ([`segments`]).
//!
//! ## Where to add things
//! - A joint kind: a [`JointKind`] variant and its list of row blocks in
//!   [`JointKind::blocks`] (`model/joint.rs`, the one match over the
//!   kinds): the equation count, row names, the angle and slide flags and
//!   the node rotations it needs follow from the blocks, and
//!   [`constraints::rows`] assembles each block. A kind that needs a new
//!   kind of row adds a [`RowBlock`] variant (its names in
//!   [`RowBlock::names`]) and its row function in [`constraints::rows`].
//!   The scene then names the kind (`crate::scene`, the joint `type`).
//! - A force element: a [`Force`] variant (data, `model/force.rs`) and
//!   its generalized forces in [`forces::elements`] (`System::applied`); if it
//!   reads a marker's rotation on a flexible node, list it in
//!   `System::node_rotations` ([`kinematics`]); the scene names it
//!   (`crate::scene::forces`).
//!
//! ## Limitations
//! - Linear elasticity in a floating frame: without the effect
//!   `geometric_stiffening` a fast-spinning flexible body softens by about
//!   `Ω²/ω₁²` (the classic spin-up limitation of the linear floating frame;
//!   the beam spin-up study shows the size); with it the geometric
//!   stiffness of the inertial and joint-load prestress is kept to first
//!   order ([`model::geometric`]), joint moments not loaded.
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

pub mod constraints;
pub mod dynamics;
pub mod forces;
pub mod kinematics;
pub mod math;
pub mod model;
pub mod ode;
pub mod post;
pub mod segments;
pub mod system;
pub mod watch;

pub use math::DualN;
pub use model::{
    BasisDerivative, Body, Drive, DroppedMode, Energy, Flex, Force, Integral, Invariants, Joint,
    JointKind, Load, LoadFrame, Marker, ModalBasis, Model, Param, PiecewiseLaw, RigidScreen,
    RowBlock, Segment,
};
pub use post::analysis::{Projection, Reaction};
pub use post::responses;
pub use post::series;
pub use system::{System, Workspace};
