//! # plyscape
//!
//! Design-space exploration of flexible multibody systems whose bodies
//! include laminated composite panels: find the ply angles that make a
//! mechanism behave best. The reference application is the deployment of the
//! ERS-1 SAR antenna (Neto, Ambrósio, Leal, *Optimization of a satellite with
//! composite materials*), whose two flexible panels should deform as little
//! as possible while they unfold.
//!
//! ## The road data travels
//!
//! ```text
//! study file (TOML) -> Study -> Laminate (ABD + d/dθ) -> Panel FE (K, M + dK/dθ)
//!   -> ModalBasis (modes + derivatives) -> Scene (multibody System) -> Integrator
//!   -> Responses -> Evaluator (Problem) -> Optimizers -> Drivers -> Reports
//! ```
//!
//! Each arrow is a module boundary; a module knows the ones before it and
//! none after it.
//!
//! The road in a few lines: a study with a scene (a pendulum released
//! horizontally under gravity, its hinge 1 m above the datum of the
//! potential energy), built, simulated, checked against energy
//! conservation:
//!
//! ```
//! use plyscape::study::Study;
//!
//! let text = r#"
//! [scene]
//! effects = ["gravity"]
//! [[scene.bodies]]
//! name = "bob"
//! mass = 2.0
//! com = [0.5, 0.0, 1.0]
//! inertia = [[1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]]
//! [[scene.joints]]
//! name = "hinge"
//! type = "revolute"
//! body_i = "ground"
//! body_j = "bob"
//! point = [0.0, 0.0, 1.0]
//! axis = [0.0, 1.0, 0.0]
//! [scene.integrator]
//! t_end = 1.0
//! dt_out = 0.1
//! rtol = 1e-9
//! atol = 1e-11
//! [scene.outputs]
//! quantities = ["hinge.angle", "energy"]
//! "#;
//! let study = Study::parse("pendulum.toml", text)?;
//! let scene = plyscape::scene::load_scene(&study)?;
//! let (_, sim) = plyscape::simulate::simulate(&scene)?;
//! assert_eq!(sim.headers, ["t [s]", "hinge.angle [rad]", "energy [J]"]);
//! assert!(sim.energy_error.unwrap() < 1e-6);
//! # Ok::<(), plyscape::Error>(())
//! ```
//!
//! ## Modules
//! In the order of the road; each imports only modules above it.
//! - [`error`]: the one error type ([`Error`]).
//! - [`study`]: study files, validation, error locations.
//! - [`laminate`]: orthotropic plies, ABD and shear stiffness, exact ply-angle
//!   derivatives.
//! - [`fe`]: panel mesh, laminated shell triangle, sparse assembly, supports.
//! - [`modal`]: lowest modes, eigenvalue and eigenvector derivatives.
//! - [`integrate`]: time integration of any [`integrate::OdeModel`] (BDF,
//!   explicit and SDIRK Runge–Kutta) with forward sensitivities and events.
//! - [`mbs`]: the multibody kernel: bodies (rigid, floating-frame flexible
//!   with a [`mbs::ModalBasis`]), joints, forces, equations of motion and
//!   their constraint-space solve, outputs; no files.
//! - [`beams`]: closed-form Euler–Bernoulli cantilever beams as a
//!   [`mbs::ModalBasis`] (reference flexible bodies).
//! - [`panels`]: a panel's modal analysis reused across lay-ups and its
//!   modes as a [`mbs::ModalBasis`] ([`panels::BasisBuilder`]).
//! - [`scene`]: the `[scene]` section: parsed data → model
//!   ([`scene::SceneSpec`], [`scene::Scene`]) and [`scene::ScenePlan`], the
//!   road of a design (ply angles as numbers, panel analyses built once).
//! - [`simulate`]: integrate a built scene, outputs, responses and their
//!   sensitivities.
//! - [`optimize`]: the evaluation interface, MMFD, CMA-ES.
//! - [`explore`]: multistart, evolutionary comparison, maps, sharding; the
//!   scene as an optimization problem.
//! - [`sections`]: study sections that tabulate or measure (panel modes,
//!   kernel and events benchmarks, scene convergence).
//! - [`report`]: every writer: CSV tables, SVG plots, manifest, progress.
//! - [`cli`]: the command line.
//!
//! Where to add things: a joint type in [`mbs::model::joint`] (its row
//! blocks; see [`mbs`]), named in [`scene::build`]; a force element in
//! [`mbs::model::force`] and [`mbs::forces`]; an output or response in [`scene::quantity`] (parsed
//! in [`scene::parts`]) and evaluated in [`simulate`]; a study section in
//! [`sections`] with its entry in [`cli`]; an optimizer in [`optimize`]
//! behind [`optimize::Problem`], selectable in [`explore::local::solvers`].
//!
//! ## Glossary
//! FE finite element; FFRF floating frame of reference; CMS component mode
//! synthesis; DOF degree of freedom; ABD membrane/coupling/bending laminate
//! stiffness; MMFD modified method of feasible directions; CMA-ES covariance
//! matrix adaptation evolution strategy; LHS Latin hypercube sampling.
//!
//! ## Limitations
//! - The SAR geometry is a reconstruction (see `studies/` and the README):
//!   results are comparable with the paper in shape, not digit by digit.

#![warn(missing_docs)]

pub mod beams;
pub mod cli;
pub mod error;
pub mod explore;
pub mod fe;
pub mod integrate;
pub mod laminate;
pub mod mbs;
pub mod modal;
pub mod optimize;
pub mod panels;
pub mod report;
pub mod scene;
pub mod sections;
pub mod simulate;
pub mod study;

pub use error::{Error, Result};
