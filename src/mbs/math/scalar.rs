//! The scalar types of the kernel: `f64` and dual numbers behind one
//! trait ([`Scalar`]), so that the same code runs on `f64` and on dual
//! numbers (exact Jacobian-vector products). Branches (segment choice,
//! rank counting) compare values, which for dual numbers compares the real
//! parts: the derivative follows the same branch as the value. Structural
//! zeros are detected on all components ([`Scalar::is_exact_zero`]). The
//! implementations for `f64`, `num_dual::Dual64` and
//! [`DualN`](super::dual::DualN) are in `super::lanes`.

use nalgebra::RealField;

/// The scalar types of the kernel: `f64`, and dual numbers with `NL`
/// derivative lanes (`num_dual::Dual64`, [`DualN<N>`](super::dual::DualN)).
/// `is_exact_zero` is true only when every component is exactly zero.
///
/// The two symmetric positive definite solves of a right-hand side (the
/// constraint-space matrix and the dense mass of a flexible body) are not
/// run in dual arithmetic: the solve is real, and a dual evaluation adds
/// its tangent with the same factorizations (`crate::mbs::constraints::tangent`,
/// docs/numerics.md); the parts accessors below split a number into its
/// real part and lanes for that.
pub trait Scalar: RealField + Copy {
    /// Number of derivative lanes (0 for `f64`).
    const NL: usize;

    /// True when every component (real part and all `NL` lanes) is exactly
    /// zero: a structural zero.
    fn is_exact_zero(&self) -> bool;

    /// The real part.
    fn re_part(&self) -> f64;

    /// Derivative lane `l < NL`.
    fn lane_part(&self, l: usize) -> f64;

    /// The number with real part `re` and lanes `lanes` (length `NL`).
    fn from_parts(re: f64, lanes: &[f64]) -> Self;

    /// Factor a dense SPD matrix (row-major `n × n`, both triangles) in
    /// place; `false` at a non-positive pivot. The real parts become the
    /// explicit inverse `A⁻¹` ([`spd_inverse`](super::dense::spd_inverse)), so that every later solve
    /// is a matrix–vector product of independent sums instead of a pair
    /// of triangular solves, whose sequential divisions dominate at the
    /// flexible bodies' `n` ≈ 20 (one solve per constraint row touching
    /// the body); the lanes of a dual number keep `A'`.
    fn dense_factor(a: &mut [Self], n: usize) -> bool;
}

/// Most derivative lanes of a [`Scalar`] type (fixed-size lane buffers
/// of the kernel; the multi-lane evaluations use 2 or 4).
pub const MAX_LANES: usize = 8;

/// `f64` constant converted into the scalar type `T`.
#[inline]
pub fn cst<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert(x)
}
