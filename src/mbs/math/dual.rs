//! Multi-lane dual numbers for the fused forward sensitivities.
//!
//! `DualN<N>` is `a + Σ_l a_l ε_l` with `ε_k ε_l = 0`: one real part and
//! `N` derivative lanes, stored inline (`[f64; N]`). Every operation
//! applies the first-order chain rule lane by lane,
//! `f(a + Σ a_l ε_l) = f(a) + f'(a) Σ a_l ε_l`, so one evaluation of a
//! generic function gives its value and `N` directional derivatives.
//!
//! It replaces `num_dual::DualSVec64<N>` in the kernel's multi-lane
//! evaluations: that type keeps its lanes behind an `Option` and moves
//! them through nalgebra's generic matrix code at every operation, which
//! made a 2-lane SAR right-hand side cost 3.9 real ones. Here the lanes
//! are plain numbers, and the `N`-wide loops compile to vector
//! instructions.
//!
//! Conventions (those of num-dual, which the kernel was written against):
//! - comparisons (`==`, `<`, `max`, …) and `Zero::is_zero` look at the
//!   real part only, so a branch taken on a value is taken by its
//!   derivatives too ([`super::scalar::Scalar::is_exact_zero`] compares
//!   every component);
//! - functions that are not differentiable at a point (`abs` at 0,
//!   `floor`, …) take the derivative of the branch the real part selects.
//!
//! The traits implemented are those nalgebra asks of a real scalar
//! (`RealField` and what it builds on).

use approx::{AbsDiffEq, RelativeEq, UlpsEq};
use nalgebra::{ComplexField, Field, RealField, SimdValue};
use num_traits::{FromPrimitive, Num, One, Signed, Zero};
use simba::scalar::SubsetOf;
use std::cmp::Ordering;
use std::fmt;
use std::iter::{Product, Sum};
use std::ops::{
    Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Rem, RemAssign, Sub, SubAssign,
};

/// A dual number with `N` derivative lanes (see the module doc).
#[derive(Clone, Copy, Debug)]
pub struct DualN<const N: usize> {
    /// The real part.
    pub re: f64,
    /// The derivative lanes.
    pub eps: [f64; N],
}

impl<const N: usize> DualN<N> {
    /// `re + Σ eps_l ε_l`.
    #[inline(always)]
    pub const fn new(re: f64, eps: [f64; N]) -> Self {
        DualN { re, eps }
    }

    /// A constant: every lane zero.
    #[inline(always)]
    pub const fn cst(re: f64) -> Self {
        DualN { re, eps: [0.0; N] }
    }

    /// `f(self)` given `f0 = f(re)` and `f1 = f'(re)`.
    #[inline(always)]
    fn chain(self, f0: f64, f1: f64) -> Self {
        DualN {
            re: f0,
            eps: self.eps.map(|e| e * f1),
        }
    }

    /// Every lane multiplied by `s`, real part `re`.
    #[inline(always)]
    fn lanes_times(re: f64, a: &[f64; N], s: f64) -> Self {
        DualN {
            re,
            eps: a.map(|e| e * s),
        }
    }
}

/// A real constant (every lane zero).
impl<const N: usize> From<f64> for DualN<N> {
    #[inline(always)]
    fn from(re: f64) -> Self {
        Self::cst(re)
    }
}

impl<const N: usize> Default for DualN<N> {
    fn default() -> Self {
        Self::cst(0.0)
    }
}

// ---------------------------------------------------------------- arithmetic

impl<const N: usize> Add for DualN<N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        DualN {
            re: self.re + o.re,
            eps: std::array::from_fn(|l| self.eps[l] + o.eps[l]),
        }
    }
}

impl<const N: usize> Sub for DualN<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        DualN {
            re: self.re - o.re,
            eps: std::array::from_fn(|l| self.eps[l] - o.eps[l]),
        }
    }
}

/// Product rule: `(ab)' = a'b + b'a`.
#[allow(clippy::suspicious_arithmetic_impl)]
impl<const N: usize> Mul for DualN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        DualN {
            re: self.re * o.re,
            eps: std::array::from_fn(|l| self.eps[l] * o.re + o.eps[l] * self.re),
        }
    }
}

/// Quotient rule: `(a/b)' = (a'b − b'a)/b²`.
impl<const N: usize> Div for DualN<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.re;
        let inv2 = inv * inv;
        DualN {
            re: self.re * inv,
            eps: std::array::from_fn(|l| (self.eps[l] * o.re - o.eps[l] * self.re) * inv2),
        }
    }
}

/// `a mod b = a − trunc(a/b)·b`, differentiated with `trunc` constant.
impl<const N: usize> Rem for DualN<N> {
    type Output = Self;
    #[inline]
    fn rem(self, o: Self) -> Self {
        let q = (self.re / o.re).trunc();
        DualN {
            re: self.re % o.re,
            eps: std::array::from_fn(|l| self.eps[l] - q * o.eps[l]),
        }
    }
}

impl<const N: usize> Neg for DualN<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        DualN {
            re: -self.re,
            eps: self.eps.map(|e| -e),
        }
    }
}

macro_rules! assign_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl<const N: usize> $trait for DualN<N> {
            #[inline(always)]
            fn $method(&mut self, o: Self) {
                *self = *self $op o;
            }
        }
    };
}
assign_op!(AddAssign, add_assign, +);
assign_op!(SubAssign, sub_assign, -);
assign_op!(MulAssign, mul_assign, *);
assign_op!(DivAssign, div_assign, /);
assign_op!(RemAssign, rem_assign, %);

impl<const N: usize> Sum for DualN<N> {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::cst(0.0), |a, b| a + b)
    }
}

impl<'a, const N: usize> Sum<&'a DualN<N>> for DualN<N> {
    fn sum<I: Iterator<Item = &'a Self>>(iter: I) -> Self {
        iter.fold(Self::cst(0.0), |a, b| a + *b)
    }
}

impl<const N: usize> Product for DualN<N> {
    fn product<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::cst(1.0), |a, b| a * b)
    }
}

impl<'a, const N: usize> Product<&'a DualN<N>> for DualN<N> {
    fn product<I: Iterator<Item = &'a Self>>(iter: I) -> Self {
        iter.fold(Self::cst(1.0), |a, b| a * *b)
    }
}

// ------------------------------------------------ comparisons and printing

/// Real parts only (see the module doc).
impl<const N: usize> PartialEq for DualN<N> {
    #[inline]
    fn eq(&self, o: &Self) -> bool {
        self.re == o.re
    }
}

/// Real parts only (see the module doc).
impl<const N: usize> PartialOrd for DualN<N> {
    #[inline]
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        self.re.partial_cmp(&o.re)
    }
}

impl<const N: usize> fmt::Display for DualN<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.re)?;
        for (l, e) in self.eps.iter().enumerate() {
            write!(f, " + {e}ε{l}")?;
        }
        Ok(())
    }
}

impl<const N: usize> AbsDiffEq for DualN<N> {
    type Epsilon = Self;
    fn default_epsilon() -> Self {
        Self::cst(f64::EPSILON)
    }
    fn abs_diff_eq(&self, o: &Self, epsilon: Self) -> bool {
        self.re.abs_diff_eq(&o.re, epsilon.re)
    }
}

impl<const N: usize> RelativeEq for DualN<N> {
    fn default_max_relative() -> Self {
        Self::cst(f64::EPSILON)
    }
    fn relative_eq(&self, o: &Self, epsilon: Self, max_relative: Self) -> bool {
        self.re.relative_eq(&o.re, epsilon.re, max_relative.re)
    }
}

impl<const N: usize> UlpsEq for DualN<N> {
    fn default_max_ulps() -> u32 {
        4
    }
    fn ulps_eq(&self, o: &Self, epsilon: Self, max_ulps: u32) -> bool {
        self.re.ulps_eq(&o.re, epsilon.re, max_ulps)
    }
}

// ------------------------------------------------------------- num-traits

impl<const N: usize> Zero for DualN<N> {
    #[inline(always)]
    fn zero() -> Self {
        Self::cst(0.0)
    }
    /// Real part only (as num-dual).
    #[inline]
    fn is_zero(&self) -> bool {
        self.re == 0.0
    }
}

impl<const N: usize> One for DualN<N> {
    #[inline(always)]
    fn one() -> Self {
        Self::cst(1.0)
    }
}

impl<const N: usize> Num for DualN<N> {
    type FromStrRadixErr = <f64 as Num>::FromStrRadixErr;
    fn from_str_radix(s: &str, radix: u32) -> Result<Self, Self::FromStrRadixErr> {
        f64::from_str_radix(s, radix).map(Self::cst)
    }
}

impl<const N: usize> FromPrimitive for DualN<N> {
    fn from_i64(n: i64) -> Option<Self> {
        Some(Self::cst(n as f64))
    }
    fn from_u64(n: u64) -> Option<Self> {
        Some(Self::cst(n as f64))
    }
    fn from_f64(n: f64) -> Option<Self> {
        Some(Self::cst(n))
    }
}

impl<const N: usize> Signed for DualN<N> {
    #[inline]
    fn abs(&self) -> Self {
        if self.re < 0.0 {
            -*self
        } else {
            *self
        }
    }
    fn abs_sub(&self, o: &Self) -> Self {
        if self.re <= o.re {
            Self::cst(0.0)
        } else {
            *self - *o
        }
    }
    fn signum(&self) -> Self {
        Self::cst(self.re.signum())
    }
    fn is_positive(&self) -> bool {
        self.re > 0.0
    }
    fn is_negative(&self) -> bool {
        self.re < 0.0
    }
}

// ------------------------------------------------------- simba / nalgebra

impl<const N: usize> SimdValue for DualN<N> {
    const LANES: usize = 1;
    type Element = Self;
    type SimdBool = bool;
    #[inline(always)]
    fn splat(val: Self) -> Self {
        val
    }
    #[inline(always)]
    fn extract(&self, _: usize) -> Self {
        *self
    }
    #[inline(always)]
    unsafe fn extract_unchecked(&self, _: usize) -> Self {
        *self
    }
    #[inline(always)]
    fn replace(&mut self, _: usize, val: Self) {
        *self = val;
    }
    #[inline(always)]
    unsafe fn replace_unchecked(&mut self, _: usize, val: Self) {
        *self = val;
    }
    #[inline(always)]
    fn select(self, cond: bool, other: Self) -> Self {
        if cond {
            self
        } else {
            other
        }
    }
}

impl<const N: usize> Field for DualN<N> {}

impl<const N: usize> SubsetOf<DualN<N>> for DualN<N> {
    #[inline(always)]
    fn to_superset(&self) -> Self {
        *self
    }
    #[inline(always)]
    fn from_superset_unchecked(d: &Self) -> Self {
        *d
    }
    #[inline(always)]
    fn is_in_subset(_: &Self) -> bool {
        true
    }
}

/// Real constants: every lane zero. A dual number is a real one when its
/// lanes are zero.
macro_rules! real_subset {
    ($t:ty) => {
        impl<const N: usize> SubsetOf<DualN<N>> for $t {
            #[inline(always)]
            fn to_superset(&self) -> DualN<N> {
                DualN::cst(*self as f64)
            }
            #[inline(always)]
            fn from_superset_unchecked(d: &DualN<N>) -> $t {
                d.re as $t
            }
            #[inline(always)]
            fn is_in_subset(d: &DualN<N>) -> bool {
                d.eps.iter().all(|e| *e == 0.0)
            }
        }
    };
}
real_subset!(f64);
real_subset!(f32);

impl<const N: usize> ComplexField for DualN<N> {
    type RealField = Self;

    #[inline(always)]
    fn from_real(re: Self) -> Self {
        re
    }
    #[inline(always)]
    fn real(self) -> Self {
        self
    }
    #[inline(always)]
    fn imaginary(self) -> Self {
        Self::cst(0.0)
    }
    #[inline]
    fn modulus(self) -> Self {
        Signed::abs(&self)
    }
    #[inline]
    fn modulus_squared(self) -> Self {
        self * self
    }
    fn argument(self) -> Self {
        Self::cst(if self.re < 0.0 {
            std::f64::consts::PI
        } else {
            0.0
        })
    }
    #[inline]
    fn norm1(self) -> Self {
        Signed::abs(&self)
    }
    #[inline]
    fn scale(self, factor: Self) -> Self {
        self * factor
    }
    #[inline]
    fn unscale(self, factor: Self) -> Self {
        self / factor
    }
    fn floor(self) -> Self {
        Self::cst(self.re.floor())
    }
    fn ceil(self) -> Self {
        Self::cst(self.re.ceil())
    }
    fn round(self) -> Self {
        Self::cst(self.re.round())
    }
    fn trunc(self) -> Self {
        Self::cst(self.re.trunc())
    }
    /// `x − trunc(x)`: derivative 1.
    fn fract(self) -> Self {
        DualN {
            re: self.re.fract(),
            eps: self.eps,
        }
    }
    #[inline]
    fn mul_add(self, a: Self, b: Self) -> Self {
        self * a + b
    }
    #[inline]
    fn abs(self) -> Self {
        Signed::abs(&self)
    }
    /// `√(a² + b²)`, derivative `(a a' + b b')/√(a² + b²)` (zero lanes at
    /// the origin).
    fn hypot(self, o: Self) -> Self {
        let h = self.re.hypot(o.re);
        let inv = if h > 0.0 { 1.0 / h } else { 0.0 };
        DualN {
            re: h,
            eps: std::array::from_fn(|l| (self.re * self.eps[l] + o.re * o.eps[l]) * inv),
        }
    }
    #[inline]
    fn recip(self) -> Self {
        let r = 1.0 / self.re;
        self.chain(r, -r * r)
    }
    #[inline(always)]
    fn conjugate(self) -> Self {
        self
    }
    #[inline]
    fn sin(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(s, c)
    }
    #[inline]
    fn cos(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(c, -s)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.re.sin_cos();
        (self.chain(s, c), self.chain(c, -s))
    }
    /// `tan' = 1 + tan²`.
    fn tan(self) -> Self {
        let t = self.re.tan();
        self.chain(t, 1.0 + t * t)
    }
    /// `asin' = 1/√(1 − x²)`.
    fn asin(self) -> Self {
        self.chain(self.re.asin(), 1.0 / (1.0 - self.re * self.re).sqrt())
    }
    /// `acos' = −1/√(1 − x²)`.
    fn acos(self) -> Self {
        self.chain(self.re.acos(), -1.0 / (1.0 - self.re * self.re).sqrt())
    }
    /// `atan' = 1/(1 + x²)`.
    fn atan(self) -> Self {
        self.chain(self.re.atan(), 1.0 / (1.0 + self.re * self.re))
    }
    fn sinh(self) -> Self {
        self.chain(self.re.sinh(), self.re.cosh())
    }
    fn cosh(self) -> Self {
        self.chain(self.re.cosh(), self.re.sinh())
    }
    /// `tanh' = 1 − tanh²`.
    fn tanh(self) -> Self {
        let t = self.re.tanh();
        self.chain(t, 1.0 - t * t)
    }
    /// `asinh' = 1/√(x² + 1)`.
    fn asinh(self) -> Self {
        self.chain(self.re.asinh(), 1.0 / (self.re * self.re + 1.0).sqrt())
    }
    /// `acosh' = 1/√(x² − 1)`.
    fn acosh(self) -> Self {
        self.chain(self.re.acosh(), 1.0 / (self.re * self.re - 1.0).sqrt())
    }
    /// `atanh' = 1/(1 − x²)`.
    fn atanh(self) -> Self {
        self.chain(self.re.atanh(), 1.0 / (1.0 - self.re * self.re))
    }
    /// `log_b x = ln x / ln b`, both dual.
    fn log(self, base: Self) -> Self {
        self.ln() / base.ln()
    }
    fn log2(self) -> Self {
        self.chain(self.re.log2(), 1.0 / (self.re * std::f64::consts::LN_2))
    }
    fn log10(self) -> Self {
        self.chain(self.re.log10(), 1.0 / (self.re * std::f64::consts::LN_10))
    }
    #[inline]
    fn ln(self) -> Self {
        self.chain(self.re.ln(), 1.0 / self.re)
    }
    fn ln_1p(self) -> Self {
        self.chain(self.re.ln_1p(), 1.0 / (1.0 + self.re))
    }
    /// `√x' = 1/(2√x)`.
    #[inline]
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, 0.5 / s)
    }
    #[inline]
    fn exp(self) -> Self {
        let e = self.re.exp();
        self.chain(e, e)
    }
    fn exp2(self) -> Self {
        let e = self.re.exp2();
        self.chain(e, e * std::f64::consts::LN_2)
    }
    fn exp_m1(self) -> Self {
        self.chain(self.re.exp_m1(), self.re.exp())
    }
    /// `(xⁿ)' = n xⁿ⁻¹`.
    #[inline]
    fn powi(self, n: i32) -> Self {
        if n == 0 {
            return Self::cst(1.0);
        }
        let p = self.re.powi(n - 1);
        self.chain(p * self.re, f64::from(n) * p)
    }
    /// `(xⁿ)' = n xⁿ⁻¹ x' + xⁿ ln x · n'`; the second term only when `n`
    /// carries lanes (so that a negative `x` to a constant power works).
    fn powf(self, n: Self) -> Self {
        let v = self.re.powf(n.re);
        let dx = if self.re == 0.0 && n.re >= 1.0 {
            if n.re == 1.0 {
                1.0
            } else {
                0.0
            }
        } else {
            n.re * self.re.powf(n.re - 1.0)
        };
        let mut out = Self::lanes_times(v, &self.eps, dx);
        if n.eps.iter().any(|e| *e != 0.0) {
            let dn = v * self.re.ln();
            for (o, e) in out.eps.iter_mut().zip(&n.eps) {
                *o += dn * e;
            }
        }
        out
    }
    fn powc(self, n: Self) -> Self {
        self.powf(n)
    }
    /// `∛x' = ∛x / (3x)`.
    fn cbrt(self) -> Self {
        let c = self.re.cbrt();
        self.chain(c, c / (3.0 * self.re))
    }
    fn is_finite(&self) -> bool {
        self.re.is_finite() && self.eps.iter().all(|e| e.is_finite())
    }
    fn try_sqrt(self) -> Option<Self> {
        (self.re >= 0.0).then(|| self.sqrt())
    }
}

impl<const N: usize> RealField for DualN<N> {
    fn is_sign_positive(&self) -> bool {
        self.re.is_sign_positive()
    }
    fn is_sign_negative(&self) -> bool {
        self.re.is_sign_negative()
    }
    fn copysign(self, sign: Self) -> Self {
        if self.re.is_sign_negative() == sign.re.is_sign_negative() {
            self
        } else {
            -self
        }
    }
    #[inline]
    fn max(self, o: Self) -> Self {
        if o.re > self.re {
            o
        } else {
            self
        }
    }
    #[inline]
    fn min(self, o: Self) -> Self {
        if o.re < self.re {
            o
        } else {
            self
        }
    }
    fn clamp(self, min: Self, max: Self) -> Self {
        RealField::min(RealField::max(self, min), max)
    }
    /// `atan2(y, x)`, derivative `(x y' − y x')/(x² + y²)`.
    fn atan2(self, x: Self) -> Self {
        let r2 = self.re * self.re + x.re * x.re;
        let inv = if r2 > 0.0 { 1.0 / r2 } else { 0.0 };
        DualN {
            re: self.re.atan2(x.re),
            eps: std::array::from_fn(|l| (x.re * self.eps[l] - self.re * x.eps[l]) * inv),
        }
    }
    fn min_value() -> Option<Self> {
        Some(Self::cst(f64::MIN))
    }
    fn max_value() -> Option<Self> {
        Some(Self::cst(f64::MAX))
    }
    fn pi() -> Self {
        Self::cst(std::f64::consts::PI)
    }
    fn two_pi() -> Self {
        Self::cst(std::f64::consts::TAU)
    }
    fn frac_pi_2() -> Self {
        Self::cst(std::f64::consts::FRAC_PI_2)
    }
    fn frac_pi_3() -> Self {
        Self::cst(std::f64::consts::FRAC_PI_3)
    }
    fn frac_pi_4() -> Self {
        Self::cst(std::f64::consts::FRAC_PI_4)
    }
    fn frac_pi_6() -> Self {
        Self::cst(std::f64::consts::FRAC_PI_6)
    }
    fn frac_pi_8() -> Self {
        Self::cst(std::f64::consts::FRAC_PI_8)
    }
    fn frac_1_pi() -> Self {
        Self::cst(std::f64::consts::FRAC_1_PI)
    }
    fn frac_2_pi() -> Self {
        Self::cst(std::f64::consts::FRAC_2_PI)
    }
    fn frac_2_sqrt_pi() -> Self {
        Self::cst(std::f64::consts::FRAC_2_SQRT_PI)
    }
    fn e() -> Self {
        Self::cst(std::f64::consts::E)
    }
    fn log2_e() -> Self {
        Self::cst(std::f64::consts::LOG2_E)
    }
    fn log10_e() -> Self {
        Self::cst(std::f64::consts::LOG10_E)
    }
    fn ln_2() -> Self {
        Self::cst(std::f64::consts::LN_2)
    }
    fn ln_10() -> Self {
        Self::cst(std::f64::consts::LN_10)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type D = DualN<2>;

    /// `x` with lane 0 seeded (`x + ε₀`) and lane 1 carrying `0.5`.
    fn seed(x: f64) -> D {
        D::new(x, [1.0, 0.5])
    }

    /// The lanes of `f(seed(x))` against central differences of the real
    /// function `g` (step 1e-6, error O(h²) ≈ 1e-12 relative, plus
    /// round-off ≈ 1e-10 relative).
    fn check(name: &str, f: impl Fn(D) -> D, g: impl Fn(f64) -> f64, x: f64) {
        let h = 1e-6;
        let fd = (g(x + h) - g(x - h)) / (2.0 * h);
        let d = f(seed(x));
        assert_eq!(d.re, g(x), "{name}: real part at {x}");
        let tol = 1e-8 * (1.0 + fd.abs());
        assert!(
            (d.eps[0] - fd).abs() < tol,
            "{name}'({x}) = {} vs {fd}",
            d.eps[0]
        );
        assert!((d.eps[1] - 0.5 * fd).abs() < tol, "{name}: lane 1 at {x}");
    }

    #[test]
    fn elementary_functions_match_central_differences() {
        for x in [0.3, 0.7, 1.9] {
            check("sqrt", |d| d.sqrt(), f64::sqrt, x);
            check("sin", |d| d.sin(), f64::sin, x);
            check("cos", |d| d.cos(), f64::cos, x);
            check("tan", |d| d.tan(), f64::tan, x);
            check("exp", |d| d.exp(), f64::exp, x);
            check("ln", |d| d.ln(), f64::ln, x);
            check("log10", |d| d.log10(), f64::log10, x);
            check("atan", |d| d.atan(), f64::atan, x);
            check("sinh", |d| d.sinh(), f64::sinh, x);
            check("tanh", |d| d.tanh(), f64::tanh, x);
            check("cbrt", |d| d.cbrt(), f64::cbrt, x);
            check("recip", |d| d.recip(), |v| 1.0 / v, x);
            check("powi", |d| d.powi(3), |v| v.powi(3), x);
            check("powi-2", |d| d.powi(-2), |v| v.powi(-2), x);
            check("powf", |d| d.powf(D::cst(2.5)), |v| v.powf(2.5), x);
            check("x^x", |d| d.powf(d), |v| v.powf(v), x);
            check("atan2", |d| d.atan2(D::cst(0.4)), |v| v.atan2(0.4), x);
            check("atan2 x", |d| D::cst(0.4).atan2(d), |v| 0.4f64.atan2(v), x);
            check("hypot", |d| d.hypot(D::cst(0.4)), |v| v.hypot(0.4), x);
        }
        for x in [-0.6, 0.2, 0.8] {
            check("asin", |d| d.asin(), f64::asin, x);
            check("acos", |d| d.acos(), f64::acos, x);
            check("abs", ComplexField::abs, f64::abs, x);
        }
    }

    #[test]
    fn arithmetic_follows_the_product_and_quotient_rules() {
        // a = 1.5 + (2, −1)ε, b = −0.5 + (0.25, 3)ε.
        let a = D::new(1.5, [2.0, -1.0]);
        let b = D::new(-0.5, [0.25, 3.0]);
        let p = a * b;
        assert_eq!(p.re, -0.75);
        assert_eq!(p.eps, [2.0 * -0.5 + 0.25 * 1.5, -1.0 * -0.5 + 3.0 * 1.5]);
        let q = a / b;
        assert_eq!(q.re, -3.0);
        for l in 0..2 {
            let want = (a.eps[l] * b.re - b.eps[l] * a.re) / (b.re * b.re);
            assert!((q.eps[l] - want).abs() < 1e-15 * want.abs().max(1.0));
        }
        assert_eq!((a - b).eps, [1.75, -4.0]);
        assert_eq!((-a).eps, [-2.0, 1.0]);
        let mut c = a;
        c *= b;
        c += a;
        assert_eq!(c.re, p.re + a.re);
        // nalgebra products agree with the written-out rules.
        let m = nalgebra::Matrix2::new(a, b, b, a);
        let v = nalgebra::Vector2::new(b, a);
        let mv = m * v;
        let want = a * b + b * a;
        assert_eq!(mv[0].re, want.re);
        assert_eq!(mv[0].eps, want.eps);
    }

    #[test]
    fn comparisons_read_the_real_part_and_constants_have_no_lanes() {
        let a = D::new(1.0, [5.0, 0.0]);
        let b = D::new(1.0, [0.0, 7.0]);
        assert!(a == b);
        assert!(D::new(0.0, [1.0, 1.0]).is_zero());
        assert!(a < D::new(1.5, [0.0; 2]));
        assert_eq!(RealField::max(a, D::cst(2.0)).eps, [0.0; 2]);
        let c: D = nalgebra::convert(2.5);
        assert_eq!((c.re, c.eps), (2.5, [0.0; 2]));
        assert!(nalgebra::try_convert::<D, f64>(a).is_none());
        assert_eq!(nalgebra::try_convert::<D, f64>(c), Some(2.5));
    }
}
