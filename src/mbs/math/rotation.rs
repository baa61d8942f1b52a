//! Rotations and 3 × 3 helpers: products written out for any scalar,
//! the rotation matrix and rate of Euler parameters, the rotation vector
//! and its tangent operator (flexible nodes), and set-up frames.

use super::scalar::{cst, Scalar};
use nalgebra::{Matrix3, Vector3};

/// `A v` for a 3 × 3 matrix, written out. nalgebra's generic product
/// forms `α A v + β y` with `α = 1`, `β = 0` for any scalar type: two
/// more products per entry, which a dual number pays in full (on `f64`
/// the result is the same to the bit: the sums run in the same order).
#[inline(always)]
pub fn mv<T: Scalar>(a: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    Vector3::from_fn(|i, _| a[(i, 0)] * v[0] + a[(i, 1)] * v[1] + a[(i, 2)] * v[2])
}

/// `Aᵀ v` for a 3 × 3 matrix, written out (see [`mv`]).
#[inline(always)]
pub fn mtv<T: Scalar>(a: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    Vector3::from_fn(|i, _| a[(0, i)] * v[0] + a[(1, i)] * v[1] + a[(2, i)] * v[2])
}

/// `A B` for 3 × 3 matrices, written out (see [`mv`]).
#[inline(always)]
pub fn mm<T: Scalar>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    Matrix3::from_fn(|i, j| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)] + a[(i, 2)] * b[(2, j)])
}

/// Rotation matrix `A(p)` of the Euler parameters `p = (e0, e1, e2, e3)`
/// (Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Eq. 6.19),
/// computed from the normalized `p / |p|` so that a drift of `|p|` never
/// changes the physics. Maps body-frame vectors to global ones.
pub fn rotation<T: Scalar>(p: &[T]) -> Matrix3<T> {
    let n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
    let inv = T::one() / n2;
    let (e0, e1, e2, e3) = (p[0], p[1], p[2], p[3]);
    let two = cst::<T>(2.0);
    Matrix3::new(
        (e0 * e0 + e1 * e1 - e2 * e2 - e3 * e3) * inv,
        two * (e1 * e2 - e0 * e3) * inv,
        two * (e1 * e3 + e0 * e2) * inv,
        two * (e1 * e2 + e0 * e3) * inv,
        (e0 * e0 - e1 * e1 + e2 * e2 - e3 * e3) * inv,
        two * (e2 * e3 - e0 * e1) * inv,
        two * (e1 * e3 - e0 * e2) * inv,
        two * (e2 * e3 + e0 * e1) * inv,
        (e0 * e0 - e1 * e1 - e2 * e2 + e3 * e3) * inv,
    )
}

/// Time derivative of the Euler parameters for a body-frame angular
/// velocity `w`: `ṗ = ½ p ⊗ (0, w)` (4 components). It is orthogonal to `p`,
/// so `|p|` is an invariant of the exact flow, and the normalized `p̂`
/// rotates with exactly `w` whatever `|p|` is.
pub fn euler_rate<T: Scalar>(p: &[T], w: &Vector3<T>) -> [T; 4] {
    let h = cst::<T>(0.5);
    let e = Vector3::new(p[1], p[2], p[3]);
    let v = (w * p[0] + e.cross(w)) * h;
    [-(e.dot(w)) * h, v[0], v[1], v[2]]
}

/// Euler parameters of a proper rotation matrix (Shepperd's method,
/// numerically safe for every angle). `f64` only (set-up code).
pub fn euler_from_rotation(a: &Matrix3<f64>) -> [f64; 4] {
    let q = nalgebra::UnitQuaternion::from_matrix(a);
    [q.w, q.i, q.j, q.k]
}

/// Rotation matrix of the rotation vector `θ` (Rodrigues:
/// `I + (sin φ/φ) θ̃ + ((1 − cos φ)/φ²) θ̃²`, `φ = |θ|`), with the
/// coefficients from their Taylor series for `φ² < 1e-4` (error below
/// 1e-22) so that dual numbers stay finite at `θ = 0`.
pub fn rotation_vector<T: Scalar>(th: &Vector3<T>) -> Matrix3<T> {
    let p2 = th.norm_squared();
    let (a, b) = if p2 < cst::<T>(1e-4) {
        let c = |k: f64| cst::<T>(k);
        (
            T::one() - p2 / c(6.0) + p2 * p2 / c(120.0) - p2 * p2 * p2 / c(5040.0),
            c(0.5) - p2 / c(24.0) + p2 * p2 / c(720.0) - p2 * p2 * p2 / c(40320.0),
        )
    } else {
        let phi = p2.sqrt();
        (phi.sin() / phi, (T::one() - phi.cos()) / p2)
    };
    let k = th.cross_matrix();
    Matrix3::identity() + k * a + mm(&k, &k) * b
}

/// Tangent operator of the rotation vector and its rate term: for
/// `R(θ) = exp(θ̃)`, `Ṙ Rᵀ = (T(θ) θ̇)~` with
/// `T = I + b θ̃ + c θ̃²`, `b = (1 − cos φ)/φ²`, `c = (φ − sin φ)/φ³`,
/// and `Ṫ θ̇ = ḃ (θ×θ̇) + ċ θ×(θ×θ̇) + c θ̇×(θ×θ̇)` with
/// `ḃ = 2 b'(φ²)(θ·θ̇)`, `ċ = 2 c'(φ²)(θ·θ̇)` (derivatives with respect to
/// `u = φ²`). Returns `(T, Ṫ θ̇)`. Series in `u` for `φ < 0.1`
/// (truncation below 1e-16), closed forms above.
pub fn rotation_tangent<T: Scalar>(th: &Vector3<T>, thd: &Vector3<T>) -> (Matrix3<T>, Vector3<T>) {
    let u = th.norm_squared();
    let c = |k: f64| cst::<T>(k);
    let (b, cc, db, dc) = if u < c(1e-2) {
        let u2 = u * u;
        let u3 = u2 * u;
        let u4 = u3 * u;
        (
            c(0.5) - u / c(24.0) + u2 / c(720.0) - u3 / c(40320.0) + u4 / c(3628800.0),
            c(1.0 / 6.0) - u / c(120.0) + u2 / c(5040.0) - u3 / c(362880.0) + u4 / c(39916800.0),
            c(-1.0 / 24.0) + u * c(2.0 / 720.0) - u2 * c(3.0 / 40320.0) + u3 * c(4.0 / 3628800.0),
            c(-1.0 / 120.0) + u * c(2.0 / 5040.0) - u2 * c(3.0 / 362880.0)
                + u3 * c(4.0 / 39916800.0),
        )
    } else {
        let phi = u.sqrt();
        let (s, co) = (phi.sin(), phi.cos());
        let phi5 = u * u * phi;
        (
            (T::one() - co) / u,
            (phi - s) / (u * phi),
            (phi * s * c(0.5) - (T::one() - co)) / (u * u),
            ((T::one() - co) * phi * c(0.5) - (phi - s) * c(1.5)) / phi5,
        )
    };
    let k = th.cross_matrix();
    let tmat = Matrix3::identity() + k * b + mm(&k, &k) * cc;
    let two_dot = c(2.0) * th.dot(thd);
    let txd = th.cross(thd);
    let rate = txd * (db * two_dot) + th.cross(&txd) * (dc * two_dot) + thd.cross(&txd) * cc;
    (tmat, rate)
}

/// An orthonormal frame whose z axis is the unit `axis` (x chosen
/// perpendicular to it, deterministic). `axis` must be non-zero.
pub fn frame_from_axis(axis: &Vector3<f64>) -> Matrix3<f64> {
    let z = axis.normalize();
    let trial = if z.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let x = (trial - z * z.dot(&trial)).normalize();
    let y = z.cross(&x);
    Matrix3::from_columns(&[x, y, z])
}

/// Rotation by `angle` about the unit vector `axis` (Rodrigues).
pub fn axis_angle(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(*axis), angle).into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_orthonormal_and_matches_quaternion() {
        // Reference: nalgebra's UnitQuaternion::to_rotation_matrix.
        let p = [0.3, -0.5, 0.7, 0.2];
        let a = rotation(&p);
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            p[0], p[1], p[2], p[3],
        ));
        let r = q.to_rotation_matrix().into_inner();
        assert!((a - r).norm() < 1e-14);
        assert!((a.transpose() * a - Matrix3::identity()).norm() < 1e-14);
    }

    #[test]
    fn rotation_vector_matches_axis_angle_on_both_branches() {
        // Reference: nalgebra's Rotation3::from_scaled_axis.
        for th in [
            Vector3::new(0.001, -0.002, 0.003),
            Vector3::new(0.3, -0.5, 0.7),
        ] {
            let r = nalgebra::Rotation3::from_scaled_axis(th).into_inner();
            assert!((rotation_vector(&th) - r).norm() < 1e-15);
        }
    }

    #[test]
    fn rotation_tangent_matches_finite_differences_on_both_branches() {
        // Ṙ Rᵀ = (T θ̇)~ and d/dt(T θ̇) at fixed θ̇ = Ṫ θ̇, by central
        // differences along θ(t) = θ0 + t θ̇.
        for (th, thd) in [
            (
                Vector3::new(0.01, -0.02, 0.03),
                Vector3::new(0.5, 0.2, -0.7),
            ),
            (Vector3::new(0.4, -0.5, 0.7), Vector3::new(0.5, 0.2, -0.7)),
        ] {
            let h = 1e-6;
            let rp = rotation_vector(&(th + thd * h));
            let rm = rotation_vector(&(th - thd * h));
            let w = (rp - rm) / (2.0 * h) * rotation_vector(&th).transpose();
            let axial = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
            let (t, rate) = rotation_tangent(&th, &thd);
            assert!((axial - t * thd).norm() < 1e-8, "{:?}", axial - t * thd);
            let (tp, _) = rotation_tangent(&(th + thd * h), &thd);
            let (tm, _) = rotation_tangent(&(th - thd * h), &thd);
            let fd = (tp - tm) / (2.0 * h) * thd;
            assert!((fd - rate).norm() < 1e-8, "{:?}", fd - rate);
        }
    }
}
