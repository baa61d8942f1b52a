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
//!   -> ModalBasis (modes + derivatives) -> multibody System -> Integrator
//!   -> Responses -> Evaluator -> Optimizers -> Drivers -> Reports
//! ```
//!
//! Each arrow is a module boundary; a module knows the ones before it and
//! none after it.
//!
//! ## Modules
//! - [`error`]: the one error type ([`Error`]).
//! - [`study`]: study files, validation, error locations.
//! - [`laminate`]: orthotropic plies, ABD and shear stiffness, exact ply-angle
//!   derivatives.
//! - [`fe`]: panel mesh, laminated shell triangle, sparse assembly, supports.
//! - [`modal`]: lowest modes, eigenvalue and eigenvector derivatives.
//! - [`panels`]: the panel modal-analysis study (`plyscape modes`), and the
//!   panel's modal basis for a flexible body ([`panels::panel_basis`]).
//! - [`optimize`]: the evaluation interface, MMFD, CMA-ES.
//! - [`explore`]: multistart, evolutionary comparison, maps, sharding.
//! - [`report`]: CSV, SVG and terminal output (observers only).
//! - [`cli`]: the command line.
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
