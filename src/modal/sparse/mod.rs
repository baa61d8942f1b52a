//! Sparse symmetric storage for the pencil `K − s·M` and its factorizations.
//!
//! Every matrix the modal code factors has the pattern of `K` plus the
//! diagonal (the lumped mass is diagonal): `K − σM` for shift-invert and
//! `K − λᵢM` (with some rows and columns replaced by the identity) for the
//! eigenvector derivatives. [`Pencil`] stores that one pattern, computes the
//! fill-reducing ordering and the symbolic Cholesky structure once (faer,
//! AMD ordering), and every numeric factorization reuses it.
//!
//! Performance choices (measured on the SAR panel, 4152 DOFs):
//! - the AMD permutation is applied once to the pattern (`pattern::Ordered`): the
//!   symbolic structure is computed on the permuted pattern with identity
//!   ordering, numeric values are written straight into the permuted lower
//!   triangle through a position map, and the solves permute the right-hand
//!   sides themselves, so faer does not re-permute `A` at every numeric
//!   factorization (15 per design with eigenvector derivatives);
//! - products with `K` are gathers over columns (symmetric full storage),
//!   4 right-hand sides per pass over `K` ([`sym_mul_block`]);
//! - a new design's stiffness on the same input pattern is taken through a
//!   precomputed map (`pattern::InputMap`) with the same checks, without re-sorting.
//!
//! Files: `pattern` (stored patterns and orderings), `pencil` ([`Pencil`]:
//! construction, new values, blocks), `product` (products with `K` and
//! `K − s·M`), `factor` ([`Factor`]: `LLᵀ`/`LDLᵀ` and solves), `gmres`
//! (Krylov refinement with a factor as preconditioner).

mod factor;
mod gmres;
mod pattern;
mod pencil;
mod product;

pub(crate) use factor::Factor;
pub(crate) use gmres::{gmres_refine, Refine};
pub(crate) use pencil::Pencil;
pub(crate) use product::{spmv, sym_mul_block};
