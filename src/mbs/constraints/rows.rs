//! Constraint rows of the joints: value, Jacobian blocks per body and the
//! velocity-dependent part `γ` of the constraint accelerations, one
//! function per row type, and the rows of each [`RowBlock`] of a joint
//! kind (`joint_rows`; the kinds' table is `crate::mbs::model::joint`).
//!
//! Every row's rate is written as `P·v_point + W·ω_marker` of the two
//! markers (point velocity, marker frame angular velocity), which
//! [`System::constraints`](crate::mbs::System::constraints) turns into
//! body and modal Jacobian entries.

use crate::mbs::kinematics::angle_of;
use crate::mbs::math::{cst, Scalar};
use crate::mbs::model::{JointKind, RowBlock};
use crate::mbs::system::{MarkerKin, Row, RIGID};
use nalgebra::Vector3;

/// The constraint rows of a joint of kind `kind` between markers `mi` and
/// `mj` at time `t`, appended to `rows`, block by block
/// ([`JointKind::blocks`]):
///
/// | block | rows |
/// |---|---|
/// | point | `x_i − x_j = 0` ([`point_row`], 3) |
/// | line | `x_i·d = 0`, `y_i·d = 0` with `d = x_j − x_i` ([`line_row`], 2) |
/// | parallel | `x_i·z_j = 0`, `y_i·z_j = 0` ([`dot_row`], 2) |
/// | twist | `x_i·y_j = 0` ([`dot_row`], 1) |
/// | angle | `θ − f(t) = 0` ([`angle_row`], 1) |
pub(crate) fn joint_rows<T: Scalar>(
    kind: &JointKind,
    (mi, mj): (&MarkerKin<T>, &MarkerKin<T>),
    t: f64,
    rows: &mut Vec<Row<T>>,
) {
    let col = |m: &MarkerKin<T>, c: usize| -> Vector3<T> { m.frame.column(c).into() };
    let (xi, yi) = (col(mi, 0), col(mi, 1));
    let (yj, zj) = (col(mj, 1), col(mj, 2));
    for block in kind.blocks() {
        match block {
            RowBlock::Point => {
                for k in 0..3 {
                    rows.push(point_row(mi, mj, k));
                }
            }
            RowBlock::Line => {
                rows.push(line_row(mi, mj, &xi));
                rows.push(line_row(mi, mj, &yi));
            }
            RowBlock::Parallel => {
                rows.push(dot_row(mi, mj, &xi, &zj));
                rows.push(dot_row(mi, mj, &yi, &zj));
            }
            RowBlock::Twist => rows.push(dot_row(mi, mj, &xi, &yj)),
            RowBlock::Angle => {
                let drive = kind.drive().expect("an angle block has a drive");
                rows.push(angle_row(mi, mj, drive.eval(t)));
            }
        }
    }
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

/// `a·d = 0` with `a` fixed in marker i's frame and `d = x_j − x_i`
/// (point j on a line or plane of marker i). Rate:
/// `(ω_i×a)·d + a·(v_j − v_i)`, so `P_i = −a`, `W_i = a×d`, `P_j = a`,
/// `W_j = 0`; in body blocks `∂/∂ω_i = a×(d + s_i)`, `∂/∂ω_j = s_j×a`.
/// `γ = −[d·(α_i×a + ω_i×(ω_i×a)) + 2(ω_i×a)·(v_j − v_i)
///       + a·(acc_j − acc_i)]` with the velocity-dependent accelerations
/// [`MarkerKin::acc`] and [`MarkerKin::alpha`].
pub(crate) fn line_row<T: Scalar>(mi: &MarkerKin<T>, mj: &MarkerKin<T>, a: &Vector3<T>) -> Row<T> {
    let d = mj.x - mi.x;
    let wa = mi.w.cross(a);
    let quad = d.dot(&(mi.alpha.cross(a) + mi.w.cross(&wa)))
        + cst::<T>(2.0) * wa.dot(&(mj.v - mi.v))
        + a.dot(&(mj.acc - mi.acc));
    Row {
        phi: a.dot(&d),
        phidot: T::zero(),
        gamma: -quad,
        blocks: [
            block(mi, -*a, a.cross(&(d + mi.s))),
            block(mj, *a, mj.s.cross(a)),
        ],
        markers: [0, 0],
        modal: [RIGID, RIGID],
    }
}
