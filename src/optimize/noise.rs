//! The noise of an evaluation, measured: Moré and Wild's ECNoise.
//!
//! A response computed by an adaptive integrator is smooth only piecewise:
//! it jumps by a little wherever the accepted step sequence changes. Seen
//! from a distance, `f(x) = f_s(x) + ε(x)` with a smooth `f_s` and a noise
//! `ε` of standard deviation `σ`. ECNoise estimates `σ` from `m + 1`
//! values `f_i = f(x + i h p)`, `i = 0..m` (a few evaluations along one
//! direction `p`, a step `h` large against the jumps' spacing and small
//! against the curvature of `f_s`): the k-th differences `Δᵏf` of the
//! table remove `f_s` up to its k-th derivative, and of white noise they
//! keep the variance `σ² (2k)! / (k!)²`, so
//!
//! ```text
//!   σ_k = sqrt( γ_k · mean_i (Δᵏ f_i)² ),   γ_k = (k!)² / (2k)!
//! ```
//!
//! estimates σ at every order k. The estimate is the first `σ_k` whose
//! neighbours `σ_{k+1}`, `σ_{k+2}` lie within a factor 4 of each other and
//! whose differences `Δᵏf` change sign (noise, not a trend).
//!
//! Failures are answers, never numbers: [`Noise::StepTooSmall`] when at
//! least half the first differences are exactly zero (the values do not
//! resolve the noise: take a larger `h`), [`Noise::StepTooLarge`] when the
//! values spread by more than 10 % of their size or no order settles (the
//! smooth part dominates the differences: take a smaller `h`).
//!
//! Reference: J. J. Moré and S. M. Wild, *Estimating computational noise*,
//! SIAM J. Sci. Comput. 33(3), 1292–1314 (2011), Algorithm ECnoise.

use super::Problem;
use crate::error::{Error, Result};

/// The answer of ECNoise for one function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Noise {
    /// The estimated standard deviation σ of the noise (absolute, in the
    /// function's units), with the difference order k that gave it.
    Level {
        /// σ.
        sigma: f64,
        /// The order k of the differences.
        order: usize,
    },
    /// At least half the first differences are zero: `h` is too small to
    /// see the noise (or the function is exactly smooth at this scale).
    StepTooSmall,
    /// The values spread by more than 10 % or no order settles: `h` is too
    /// large.
    StepTooLarge,
}

impl Noise {
    /// σ when the estimate succeeded.
    pub fn sigma(self) -> Option<f64> {
        match self {
            Noise::Level { sigma, .. } => Some(sigma),
            _ => None,
        }
    }

    /// The word written in tables for a failed estimate (`None` for a
    /// level).
    pub fn failure(self) -> Option<&'static str> {
        match self {
            Noise::Level { .. } => None,
            Noise::StepTooSmall => Some("h_too_small"),
            Noise::StepTooLarge => Some("h_too_large"),
        }
    }
}

/// ECNoise on the values `f_i = f(x + i h p)`, `i = 0..m` (m + 1 >= 4
/// values; Moré and Wild use 7–9).
pub fn ecnoise(values: &[f64]) -> Noise {
    let nf = values.len();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if nf < 4 || (hi - lo) > 0.1 * hi.abs().max(lo.abs()) {
        return Noise::StepTooLarge;
    }
    let mut table = values.to_vec();
    let mut level = vec![0.0; nf - 1];
    let mut sign_change = vec![false; nf - 1];
    let mut gamma = 1.0;
    for j in 1..nf {
        for i in 0..nf - j {
            table[i] = table[i + 1] - table[i];
        }
        let diffs = &table[..nf - j];
        if j == 1 && 2 * diffs.iter().filter(|&&d| d == 0.0).count() >= nf {
            return Noise::StepTooSmall;
        }
        gamma *= 0.5 * (j as f64) / (2 * j - 1) as f64;
        let mean_sq = diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64;
        level[j - 1] = (gamma * mean_sq).sqrt();
        let (dmin, dmax) = diffs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        sign_change[j - 1] = dmin * dmax < 0.0;
    }
    for k in 0..nf.saturating_sub(3) {
        let window = &level[k..k + 3];
        let wmin = window.iter().copied().fold(f64::INFINITY, f64::min);
        let wmax = window.iter().copied().fold(0.0, f64::max);
        if wmax <= 4.0 * wmin && sign_change[k] {
            return Noise::Level {
                sigma: level[k],
                order: k + 1,
            };
        }
    }
    Noise::StepTooLarge
}

/// The noise of f and of every constraint of `problem` at `x`, from
/// `points` function-only evaluations at `x + i h p` (`i = 0..points`),
/// with `p` a unit direction in the range-scaled variables and `h` the
/// scaled step (a step of 1 spans a variable's range). Returns the
/// estimate for f first, then one per constraint.
pub fn measure(
    problem: &dyn Problem,
    x: &[f64],
    direction: &[f64],
    h: f64,
    points: usize,
) -> Result<Vec<Noise>> {
    let vars = problem.variables();
    if x.len() != vars.len() || direction.len() != vars.len() {
        return Err(Error::input(
            "noise.direction",
            direction.len(),
            format!("{} values, one per variable", vars.len()),
        ));
    }
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::input("noise.step", h, "a finite step > 0"));
    }
    if points < 4 {
        return Err(Error::input(
            "noise.points",
            points,
            "at least 4 evaluations",
        ));
    }
    let moved: Vec<Vec<f64>> = (0..points)
        .map(|i| {
            vars.iter()
                .enumerate()
                .map(|(k, v)| {
                    let range = v.period.unwrap_or(v.upper - v.lower);
                    x[k] + i as f64 * h * direction[k] * range
                })
                .collect()
        })
        .collect();
    for (i, y) in moved.iter().enumerate() {
        let outside = vars
            .iter()
            .zip(y)
            .any(|(v, &yk)| v.period.is_none() && (yk < v.lower || yk > v.upper));
        if outside {
            return Err(Error::input(
                "noise.step",
                h,
                format!(
                    "a step whose {points} points stay inside the bounds (point {i} leaves them)"
                ),
            ));
        }
        if y.iter().zip(x).all(|(a, b)| a == b) && i > 0 {
            return Err(Error::input(
                "noise.step",
                h,
                "a step that moves the design (it underflows against x)",
            ));
        }
    }
    let mut columns: Vec<Vec<f64>> = vec![Vec::with_capacity(points); 1 + problem.n_constraints()];
    for y in &moved {
        let wrapped: Vec<f64> = vars.iter().zip(y).map(|(v, &yk)| v.wrap(yk)).collect();
        let e = problem.evaluate(&wrapped, false)?;
        columns[0].push(e.f);
        for (c, g) in columns[1..].iter_mut().zip(&e.g) {
            c.push(*g);
        }
    }
    Ok(columns.iter().map(|c| ecnoise(c)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform pseudo-random numbers in [−½, ½) (a 64-bit LCG, Knuth's
    /// MMIX constants), deterministic for the test.
    fn uniform(seed: u64, n: usize) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// A smooth cubic plus uniform noise of standard deviation σ = a/√12:
    /// ECNoise recovers σ within a factor 3 (Moré & Wild report estimates
    /// within a factor of a few from 7–9 values), at every seed tried.
    #[test]
    fn recovers_a_known_noise_level() {
        let sigma = 1e-7;
        let a = sigma * 12f64.sqrt();
        for seed in 1..=20u64 {
            let e = uniform(seed, 8);
            let values: Vec<f64> = (0..8)
                .map(|i| {
                    let t = 1e-4 * i as f64;
                    1.0 + 0.3 * t - 2.0 * t * t + 5.0 * t * t * t + a * e[i]
                })
                .collect();
            let est = ecnoise(&values).sigma().expect("a level");
            assert!(est > sigma / 3.0 && est < 3.0 * sigma, "seed {seed}: {est}");
        }
    }

    /// Exactly smooth at the scale of the step: differences of a constant
    /// are zero, which is "h too small", never a number.
    #[test]
    fn constant_values_say_the_step_is_too_small() {
        assert_eq!(ecnoise(&[2.0; 8]), Noise::StepTooSmall);
    }

    /// A smooth function over a wide step, without noise: the values spread
    /// by more than 10 %, "h too large".
    #[test]
    fn a_trend_says_the_step_is_too_large() {
        let values: Vec<f64> = (0..8).map(|i| (0.5 * i as f64).exp()).collect();
        assert_eq!(ecnoise(&values), Noise::StepTooLarge);
    }

    /// The difference-table weights γ_k = (k!)²/(2k)!: for white noise of
    /// variance σ², E[(Δᵏf)²] = σ² (2k)!/(k!)², so γ_k E[(Δᵏf)²] = σ².
    /// Checked through the estimate on alternating values ±c, whose first
    /// differences are ±2c: σ_1 = sqrt(½ · 4c²) = √2 c.
    #[test]
    fn first_order_level_has_the_closed_form() {
        let c = 1e-8;
        let values: Vec<f64> = (0..8)
            .map(|i| 1.0 + if i % 2 == 0 { c } else { -c })
            .collect();
        // Alternating values are pure noise at every order: levels
        // σ_k = sqrt(γ_k) 2^k c, which grow (√2 c, 1.63 c, 1.79 c, ...)
        // within the factor 4, so order 1 is taken.
        match ecnoise(&values) {
            Noise::Level { sigma, order } => {
                assert_eq!(order, 1);
                assert!((sigma - 2f64.sqrt() * c).abs() < 1e-6 * c, "{sigma}");
            }
            other => panic!("{other:?}"),
        }
    }
}
