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
    ecnoise_scaled(values, 0.0)
}

/// [`ecnoise`] with the "h too large" spread test relative to
/// `max(|f|, scale)` instead of `|f|`: a constraint is compared with the
/// feasibility tolerance in absolute terms and is near 0 where it matters,
/// so its values' spread is judged against `scale` = 1.
pub fn ecnoise_scaled(values: &[f64], scale: f64) -> Noise {
    let nf = values.len();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if nf < 4 || (hi - lo) > 0.1 * hi.abs().max(lo.abs()).max(scale) {
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

/// The difference table's values: `points` function-only evaluations of
/// `problem` at `x + i h p` (`i = 0..points`), with `p` a direction in the
/// range-scaled variables and `h` the scaled step (a step of 1 spans a
/// variable's range). One column per function: f first, then each
/// constraint.
pub fn table(
    problem: &dyn Problem,
    x: &[f64],
    direction: &[f64],
    h: f64,
    points: usize,
) -> Result<Vec<Vec<f64>>> {
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
                format!("{h:?}"),
                format!(
                    "a step whose {points} points stay inside the bounds (point {i} leaves them)"
                ),
            ));
        }
        if y.iter().zip(x).all(|(a, b)| a == b) && i > 0 {
            return Err(Error::input(
                "noise.step",
                format!("{h:?}"),
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
    Ok(columns)
}

/// The scale of the "h too large" spread test for column `k` of a
/// [`table`]: 0 for f (Moré and Wild's test relative to |f|), 1 for a
/// constraint ([`ecnoise_scaled`]).
fn spread_scale(k: usize) -> f64 {
    if k == 0 {
        0.0
    } else {
        1.0
    }
}

/// How [`estimate`] measures: the table's size, its first step and how
/// often the step may be changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseOptions {
    /// Evaluations per table (at least 4; Moré and Wild use 7–9; default 8).
    pub points: usize,
    /// The first scaled step h (a step of 1 spans a variable's range;
    /// default 1e-4, 0.018° on a 180° ply angle: wide enough to cross the
    /// changes of an adaptive step sequence, narrow against the
    /// curvature).
    pub step: f64,
    /// Further tables after a failed one, each with the step changed by
    /// Moré and Wild's factor 100 (up for "h too small", down for "h too
    /// large"; default 2).
    pub retries: usize,
}

impl Default for NoiseOptions {
    fn default() -> Self {
        NoiseOptions {
            points: 8,
            step: 1e-4,
            retries: 2,
        }
    }
}

/// The noise of f and of every constraint at one design.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The design \[variables' units\].
    pub x: Vec<f64>,
    /// f at the design.
    pub f: f64,
    /// The constraints at the design.
    pub g: Vec<f64>,
    /// The estimate for f.
    pub noise_f: Noise,
    /// The estimate for each constraint.
    pub noise_g: Vec<Noise>,
    /// The scaled step of each table evaluated, in order.
    pub steps: Vec<f64>,
    /// Function-only evaluations spent.
    pub evaluations: usize,
    /// The first-order level σ_1 = sqrt(½ mean (Δf)²) of f in the table
    /// with the smallest step: noise and trend together, an upper bound.
    pub first_order_f: f64,
}

/// A unit direction in the range-scaled variables, drawn from `seed`
/// (components uniform in [−1, 1], normalized; Moré and Wild take a random
/// direction so that no coordinate is favoured).
pub fn direction(n: usize, seed: u64) -> Vec<f64> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut p: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..=1.0)).collect();
    let norm = p.iter().map(|v| v * v).sum::<f64>().sqrt();
    if norm > 0.0 {
        p.iter_mut().for_each(|v| *v /= norm);
    } else if let Some(v) = p.first_mut() {
        *v = 1.0;
    }
    p
}

/// ECNoise at `x` along the direction drawn from `seed` (f judged by
/// Moré and Wild's spread test, the constraints by [`ecnoise_scaled`]
/// with scale 1), with retries:
/// a table of `options.points` evaluations at the step `options.step`;
/// while f's estimate fails, another table with the step multiplied by 100
/// ("h too small") or divided by 100 ("h too large"), at most
/// `options.retries` more. Each function keeps the first level any table
/// gave it, else the failure of the last table. Each component of the
/// direction of a bounded variable points to the farther bound (the table
/// runs into the box, not out of it).
pub fn estimate(
    problem: &dyn Problem,
    x: &[f64],
    seed: u64,
    options: &NoiseOptions,
) -> Result<Measured> {
    let vars = problem.variables();
    let mut p = direction(vars.len(), seed);
    for ((pk, v), &xk) in p.iter_mut().zip(vars).zip(x) {
        let (up, down) = (v.upper - xk, xk - v.lower);
        if v.period.is_none() && ((*pk > 0.0 && up < down) || (*pk < 0.0 && down < up)) {
            *pk = -*pk;
        }
    }
    let n = 1 + problem.n_constraints();
    let mut found: Vec<Option<Noise>> = vec![None; n];
    let mut last = vec![Noise::StepTooLarge; n];
    let (mut steps, mut evaluations) = (Vec::new(), 0);
    let (mut f0, mut g0) = (f64::NAN, Vec::new());
    let (mut h, mut first_order_f, mut narrowest) = (options.step, f64::NAN, f64::INFINITY);
    for _ in 0..=options.retries {
        let columns = table(problem, x, &p, h, options.points)?;
        evaluations += options.points;
        steps.push(h);
        if f0.is_nan() {
            f0 = columns[0][0];
            g0 = columns[1..].iter().map(|c| c[0]).collect();
        }
        if h < narrowest {
            narrowest = h;
            first_order_f = first_order(&columns[0]);
        }
        for (k, c) in columns.iter().enumerate() {
            last[k] = ecnoise_scaled(c, spread_scale(k));
            if found[k].is_none() && last[k].sigma().is_some() {
                found[k] = Some(last[k]);
            }
        }
        h *= match found[0].unwrap_or(last[0]) {
            Noise::Level { .. } => break,
            Noise::StepTooSmall => 100.0,
            Noise::StepTooLarge => 0.01,
        };
    }
    let pick = |k: usize| found[k].unwrap_or(last[k]);
    Ok(Measured {
        x: x.to_vec(),
        f: f0,
        g: g0,
        noise_f: pick(0),
        noise_g: (1..n).map(pick).collect(),
        steps,
        evaluations,
        first_order_f,
    })
}

/// σ_1 = sqrt(½ mean (Δf)²) of one column.
fn first_order(values: &[f64]) -> f64 {
    let d: Vec<f64> = values.windows(2).map(|w| w[1] - w[0]).collect();
    (0.5 * d.iter().map(|v| v * v).sum::<f64>() / d.len().max(1) as f64).sqrt()
}

impl Measured {
    /// σ_f relative to `max(|f|, tiny)`, when measured.
    pub fn relative_f(&self) -> Option<f64> {
        self.noise_f
            .sigma()
            .map(|s| s / self.f.abs().max(f64::MIN_POSITIVE))
    }

    /// The largest σ of the constraints (absolute: constraints are
    /// normalized), when every one was measured; `None` without
    /// constraints or when one failed.
    pub fn max_g(&self) -> Option<f64> {
        let sigmas: Option<Vec<f64>> = self.noise_g.iter().map(|n| n.sigma()).collect();
        sigmas.and_then(|s| s.into_iter().reduce(f64::max))
    }

    /// The rise of f that a stop among designs within the noise tolerates,
    /// relative to `max(|f|, 1)`: 3σ_f (the difference of two values with
    /// noise σ has the deviation √2σ, and stays within 3σ ≈ 2.1·√2σ about
    /// 96 % of the time for Gaussian noise). Where f is smooth at every
    /// step tried ("h too small"), nothing is tolerated; where no step
    /// resolved the noise ("h too large"), the first-order level of the
    /// narrowest table is the bound (it holds the trend as well as the
    /// noise, so it errs high).
    pub fn allowance(&self) -> f64 {
        let scale = self.f.abs().max(1.0);
        match self.noise_f {
            Noise::Level { sigma, .. } => 3.0 * sigma / scale,
            Noise::StepTooSmall => 0.0,
            Noise::StepTooLarge => self.first_order_f / scale,
        }
    }

    /// The constraints' allowance, absolute: 3σ of the noisiest constraint
    /// with a level (0 without constraints or without any level).
    pub fn allowance_g(&self) -> f64 {
        3.0 * self.max_g().unwrap_or(0.0)
    }
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

    /// A piecewise constant f: a smooth part plus a value drawn afresh in
    /// each cell of width `cell` (the way an adaptive integrator's result
    /// jumps where its step sequence changes), and a smooth constraint.
    struct Jumpy {
        vars: Vec<crate::optimize::Variable>,
        cell: f64,
        amplitude: f64,
    }

    impl Problem for Jumpy {
        fn variables(&self) -> &[crate::optimize::Variable] {
            &self.vars
        }
        fn n_constraints(&self) -> usize {
            1
        }
        fn evaluate(&self, x: &[f64], _: bool) -> Result<crate::optimize::Evaluation> {
            let cell = (x[0] / self.cell).floor() as i64 as u64;
            let u = uniform(cell.wrapping_mul(2654435761).wrapping_add(17), 1)[0];
            Ok(crate::optimize::Evaluation {
                f: 1.0 + self.amplitude * u,
                g: vec![x[0] - 0.9],
                grad_f: None,
                grad_g: None,
            })
        }
    }

    /// Inside one cell the values do not change ("h too small"); the
    /// retry with a step 100 times larger puts every point in a cell of
    /// its own and recovers σ = a/√12 within a factor 3. The linear
    /// constraint's only noise is rounding: its level is that of
    /// `f64::EPSILON` times its size.
    #[test]
    fn estimate_widens_the_step_until_the_noise_shows() {
        let problem = Jumpy {
            vars: vec![crate::optimize::Variable::bounded("x", 0.0, 1.0).unwrap()],
            cell: 1e-3,
            amplitude: 1e-6,
        };
        let sigma = 1e-6 / 12f64.sqrt();
        let options = NoiseOptions {
            points: 8,
            step: 1e-5,
            retries: 2,
        };
        let m = estimate(&problem, &[0.3], 7, &options).unwrap();
        assert_eq!(m.steps, vec![1e-5, 1e-3]);
        assert_eq!(m.evaluations, 16);
        let est = m.noise_f.sigma().expect("a level");
        assert!(est > sigma / 3.0 && est < 3.0 * sigma, "{est}");
        let g_sigma = m.noise_g[0].sigma().expect("a level");
        assert!(g_sigma < 4.0 * f64::EPSILON, "{:?}", m.noise_g);
        assert!((m.allowance() - 3.0 * est / m.f.abs().max(1.0)).abs() < 1e-18);
        assert_eq!(m.relative_f(), Some(est / m.f));
    }

    /// The direction is a unit vector, the same for the same seed; at
    /// either bound the table runs into the box.
    #[test]
    fn the_direction_is_seeded_and_stays_inside_the_bounds() {
        let p = direction(3, 11);
        assert_eq!(p, direction(3, 11));
        assert!((p.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-15);
        let problem = Jumpy {
            vars: vec![crate::optimize::Variable::bounded("x", 0.0, 1.0).unwrap()],
            cell: 1e-3,
            amplitude: 1e-6,
        };
        for x in [1e-9, 1.0 - 1e-9] {
            let m = estimate(&problem, &[x], 3, &NoiseOptions::default()).unwrap();
            assert!(m.evaluations >= 8);
        }
    }
}
