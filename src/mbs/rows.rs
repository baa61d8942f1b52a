//! Constraint rows of the joints: value, Jacobian blocks per body and the
//! velocity-dependent part `γ` of the constraint accelerations.

use super::linalg::{cst, Scalar};
use super::workspace::{MarkerKin, Row, RIGID};
use nalgebra::Vector3;

/// `θ = atan2(z_i·(x_i × x_j), x_i·x_j)` and `θ̇ = z_i·(ω_j − ω_i)`.
pub fn angle_of<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>) -> (T, T) {
    let xi: Vector3<T> = mi.frame.column(0).into();
    let zi: Vector3<T> = mi.frame.column(2).into();
    let xj: Vector3<T> = mj.frame.column(0).into();
    let th = zi.dot(&xi.cross(&xj)).atan2(xi.dot(&xj));
    (th, zi.dot(&(mj.w - mi.w)))
}

/// Block of a row for a marker: `(slot, [∂/∂ṙ, ∂/∂ω_global])`.
fn block<T: Scalar>(mk: &MarkerKin<T>, dr: Vector3<T>, dw: Vector3<T>) -> (Option<usize>, [T; 6]) {
    (mk.slot, [dr[0], dr[1], dr[2], dw[0], dw[1], dw[2]])
}

/// Component `k` of `x_i − x_j = 0`. Velocity: `ṙ + ω × s`, so the ω
/// block is `e_kᵀ(−s̃) = (s × e_k)ᵀ`; `γ = −e_k·(a_i − a_j)` with the
/// velocity-dependent accelerations [`MarkerKin::acc`]
/// (`ω×(ω×s)` on rigid bodies).
pub(crate) fn point_row<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>, k: usize) -> Row<T> {
    let mut e = Vector3::zeros();
    e[k] = T::one();
    Row {
        phi: mi.x[k] - mj.x[k],
        phidot: T::zero(),
        gamma: -(mi.acc[k] - mj.acc[k]),
        blocks: [block(mi, e, mi.s.cross(&e)), block(mj, -e, -mj.s.cross(&e))],
        markers: [0, 0],
        modal: [RIGID, RIGID],
    }
}

/// `a·b = 0` with `a` fixed in body i and `b` in body j:
/// `d/dt(a·b) = ω_i·(a×b) + ω_j·(b×a)`,
/// `γ = −[b·(ω_i×(ω_i×a)) + 2(ω_i×a)·(ω_j×b) + a·(ω_j×(ω_j×b))
///       + (α_i − α_j)·(a×b)]` (`α` = [`MarkerKin::alpha`]).
pub(crate) fn dot_row<T: Scalar>(
    mi: &MarkerKin<T>,
    mj: &MarkerKin<T>,
    a: &Vector3<T>,
    b: &Vector3<T>,
) -> Row<T> {
    let axb = a.cross(b);
    let wa = mi.w.cross(a);
    let wb = mj.w.cross(b);
    let quad = b.dot(&mi.w.cross(&wa))
        + cst::<T>(2.0) * wa.dot(&wb)
        + a.dot(&mj.w.cross(&wb))
        + (mi.alpha - mj.alpha).dot(&axb);
    Row {
        phi: a.dot(b),
        phidot: T::zero(),
        gamma: -quad,
        blocks: [
            block(mi, Vector3::zeros(), axb),
            block(mj, Vector3::zeros(), -axb),
        ],
        markers: [0, 0],
        modal: [RIGID, RIGID],
    }
}

/// Prescribed angle `θ − f(t) = 0` (wrapped to (−π, π]):
/// `θ̇ = z_i·(ω_j − ω_i)`, `γ = f̈ − (ω_i×z_i)·(ω_j − ω_i) − z_i·(α_j − α_i)`,
/// `ν = ḟ`.
pub(crate) fn angle_row<T: Scalar>(
    mi: &MarkerKin<T>,
    mj: &MarkerKin<T>,
    drive: (f64, f64, f64),
) -> Row<T> {
    let (th, _) = angle_of(mi, mj);
    let zi: Vector3<T> = mi.frame.column(2).into();
    let mut d = th - cst::<T>(drive.0);
    let pi = T::pi();
    let two_pi = T::two_pi();
    while d > pi {
        d -= two_pi;
    }
    while d <= -pi {
        d += two_pi;
    }
    Row {
        phi: d,
        // ν enters with a minus sign: phidot holds −ν until assembled.
        phidot: cst::<T>(drive.1),
        gamma: cst::<T>(drive.2)
            - mi.w.cross(&zi).dot(&(mj.w - mi.w))
            - zi.dot(&(mj.alpha - mi.alpha)),
        blocks: [
            block(mi, Vector3::zeros(), -zi),
            block(mj, Vector3::zeros(), zi),
        ],
        markers: [0, 0],
        modal: [RIGID, RIGID],
    }
}
