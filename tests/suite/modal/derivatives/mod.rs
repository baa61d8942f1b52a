//! Eigenvalue and eigenvector derivatives: central finite differences and
//! modal expansion for distinct modes (Nelson) ([`distinct`]), a
//! constructed repeated eigenvalue with known adjacent eigenvectors and
//! derivatives and a generic repeated one against branch-wise differences
//! ([`repeated`]), a near-crossing, the error paths and determinism
//! ([`edge_cases`]).
mod distinct;
mod edge_cases;
mod repeated;
