//! Numbers and small linear algebra of the kernel: the scalar trait over
//! `f64` and dual numbers ([`scalar`], [`dual`], with their lanes in
//! `lanes`), rotations and 3 × 3 products ([`mod@rotation`]), dense SPD
//! kernels ([`dense`]), the sparse rank-counting Cholesky ([`sparse`]) and
//! real planes of dual mode shapes ([`planes`]). Nothing here knows of
//! bodies or joints.

pub mod dense;
pub mod dual;
mod lanes;
pub mod planes;
pub mod rotation;
pub mod scalar;
pub mod sparse;

pub use dense::{
    dense_cholesky, dense_cholesky_solve, fdot, gram, quadratic_form, spd_inverse, sym_times,
};
pub use dual::DualN;
pub use planes::ShapePlanes;
pub use rotation::{
    axis_angle, euler_from_rotation, euler_rate, frame_from_axis, mm, mtv, mv, rotation,
    rotation_tangent, rotation_vector,
};
pub use scalar::{cst, Scalar, MAX_LANES};
pub use sparse::{
    cholesky_solve, min_degree_order, ordered_cholesky, spd_factor, spd_solve, spd_solve_many,
    CholPattern, Factored, SpdScratch,
};
