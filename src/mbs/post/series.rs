//! Reductions of a sampled response series `(t_k, y_k, ∂y_k/∂p)` at the
//! output times to one number with its exact gradient (the gradient of the
//! same discrete functional): the trapezoidal integral, the extreme of
//! the interpolated series, the value at a given time and the first time a
//! level is crossed.
//!
//! - **Interpolation.** Between output times the series is the cubic
//!   Lagrange polynomial `P(t) = Σ_i w_i(t) y_i` through the four samples
//!   around the interval (three or two near the ends of a short series);
//!   its error is `O(Δt⁴)` for an output interval `Δt` well below the
//!   motion's time scale. The sensitivities are interpolated with the same
//!   weights: `∂P/∂p (t) = Σ_i w_i(t) ∂y_i/∂p`.
//! - **Value at a time** `t`: `P(t)` and `Σ_i w_i(t) ∂y_i/∂p` (exact at an
//!   output time).
//! - **Crossing** of a level `L`: the first output interval over which
//!   `y − L` changes sign in the asked direction brackets the root `t*` of
//!   `P(t) = L`, found by bisection to the rounding of `t`. Its derivative
//!   follows from the implicit function theorem applied to `P(t*, p) = L`:
//!   `dt*/dp = −(∂P/∂p)(t*) / Ṗ(t*)`, with `Ṗ = Σ_i ẇ_i(t) y_i`. A series
//!   that never crosses, or crosses with zero slope, has no crossing time.
//! - **Extreme** (largest or smallest value): the extreme of `P` over
//!   the two output intervals beside the extreme sample, at a sample or
//!   where `Ṗ = 0` inside an interval (`Ṗ` is a quadratic there), with
//!   the gradient `Σ_i w_i(t*) ∂y_i/∂p` (the envelope theorem: `Ṗ(t*) = 0`
//!   or `t*` a sample). `P` is one continuous function of the samples, so
//!   the extreme is continuous in the design also when the extreme sample
//!   changes; a parabola through the three samples around the extreme
//!   sample ([`super::responses::peak`], the energies' peaks) jumps there
//!   by its interpolation error, `O(Δt³)`.
//! - **Integral** of an output that is not an energy:
//!   `Σ_k (t_{k+1} − t_k)(y_k + y_{k+1})/2`, error `O(Δt²)` (energies are
//!   integrated states instead, under the integrator's error control).

use super::responses::{Direction, Sense};

/// One sample of a response: time (s), value, gradient per parameter.
pub type Sample = (f64, f64, Vec<f64>);

/// The Lagrange weights `w_i(t)` of the nodes `ts` and their time
/// derivatives `ẇ_i(t)`.
fn lagrange(ts: &[f64], t: f64) -> (Vec<f64>, Vec<f64>) {
    let n = ts.len();
    let mut w = vec![0.0; n];
    let mut dw = vec![0.0; n];
    for i in 0..n {
        let mut num = 1.0;
        let mut den = 1.0;
        let mut dnum = 0.0;
        for j in (0..n).filter(|&j| j != i) {
            // d/dt of Π (t − t_j): product rule, accumulated.
            dnum = dnum * (t - ts[j]) + num;
            num *= t - ts[j];
            den *= ts[i] - ts[j];
        }
        w[i] = num / den;
        dw[i] = dnum / den;
    }
    (w, dw)
}

/// The samples of the cubic through the interval `[k, k + 1]` of a series
/// of `len` samples: four around it, fewer when the series is shorter.
fn window(len: usize, k: usize) -> std::ops::Range<usize> {
    let start = k.saturating_sub(1).min(len.saturating_sub(4));
    start..(start + 4).min(len)
}

/// The interpolant's value, gradient and slope at `t` on the samples
/// `win`.
fn interpolate(win: &[Sample], t: f64) -> (f64, Vec<f64>, f64) {
    let ts: Vec<f64> = win.iter().map(|s| s.0).collect();
    let (w, dw) = lagrange(&ts, t);
    let value = win.iter().zip(&w).map(|(s, w)| w * s.1).sum();
    let slope = win.iter().zip(&dw).map(|(s, w)| w * s.1).sum();
    let m = win.first().map_or(0, |s| s.2.len());
    let grad = (0..m)
        .map(|i| win.iter().zip(&w).map(|(s, w)| w * s.2[i]).sum())
        .collect();
    (value, grad, slope)
}

/// `∫ y dt` by the trapezoidal rule over the samples, with its gradient;
/// `None` for an empty series (one sample: zero).
pub fn trapezoid(series: &[Sample]) -> Option<(f64, Vec<f64>)> {
    let first = series.first()?;
    let mut value = 0.0;
    let mut grad = vec![0.0; first.2.len()];
    for pair in series.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let h = 0.5 * (b.0 - a.0);
        value += h * (a.1 + b.1);
        for (g, (ga, gb)) in grad.iter_mut().zip(a.2.iter().zip(&b.2)) {
            *g += h * (ga + gb);
        }
    }
    Some((value, grad))
}

/// The largest (`Sense::Max`) or smallest (`Sense::Min`) value of the
/// interpolated series, `(t*, value, gradient)` (module doc); `None` for
/// an empty series.
pub fn extreme(series: &[Sample], sense: Sense) -> Option<Sample> {
    match sense {
        Sense::Max => interpolated_max(series),
        Sense::Min => {
            let neg: Vec<Sample> = series
                .iter()
                .map(|(t, v, g)| (*t, -v, g.iter().map(|x| -x).collect()))
                .collect();
            let (t, v, g) = interpolated_max(&neg)?;
            Some((t, -v, g.iter().map(|x| -x).collect()))
        }
    }
}

/// The largest value of the cubic interpolant `P` over the (at most two)
/// output intervals beside the largest sample, with its time and
/// gradient. On an interval `[a, b]` the slope `Ṗ` is a quadratic, given
/// exactly by its values at `a`, the midpoint and `b`; its roots inside
/// the interval are the candidates beside the sample itself.
fn interpolated_max(series: &[Sample]) -> Option<Sample> {
    let n = series.len();
    let k = (0..n).max_by(|&a, &b| series[a].1.total_cmp(&series[b].1))?;
    let mut best = series[k].clone();
    for iv in [k.checked_sub(1), Some(k)].into_iter().flatten() {
        if iv + 1 >= n {
            continue;
        }
        let win = &series[window(n, iv)];
        let (a, b) = (series[iv].0, series[iv + 1].0);
        let h = b - a;
        let slope = |t: f64| interpolate(win, t).2;
        let (sa, sm, sb) = (slope(a), slope(a + 0.5 * h), slope(b));
        // Ṗ(a + s h) = sa + c1 s + c2 s², s ∈ [0, 1].
        let c2 = 2.0 * (sa - 2.0 * sm + sb);
        let c1 = sb - sa - c2;
        for s in quadratic_roots(c2, c1, sa) {
            if s > 0.0 && s < 1.0 {
                let t = a + s * h;
                let (v, g, _) = interpolate(win, t);
                if v > best.1 {
                    best = (t, v, g);
                }
            }
        }
    }
    Some(best)
}

/// The real roots of `c2 s² + c1 s + c0` (a linear or constant
/// polynomial when the leading coefficients vanish relative to the
/// others), by the cancellation-free form of the quadratic formula.
fn quadratic_roots(c2: f64, c1: f64, c0: f64) -> Vec<f64> {
    let size = c2.abs().max(c1.abs()).max(c0.abs());
    if size == 0.0 || !size.is_finite() {
        return Vec::new();
    }
    if c2.abs() <= 1e-12 * size {
        return if c1.abs() > 1e-12 * size {
            vec![-c0 / c1]
        } else {
            Vec::new()
        };
    }
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc < 0.0 {
        return Vec::new();
    }
    let q = -0.5 * (c1 + c1.signum() * disc.sqrt());
    if q == 0.0 {
        return vec![0.0];
    }
    vec![q / c2, c0 / q]
}

/// The interpolated value and gradient at time `t`; `None` when `t` lies
/// outside the sampled times.
pub fn value_at(series: &[Sample], t: f64) -> Option<(f64, Vec<f64>)> {
    let (first, last) = (series.first()?, series.last()?);
    if !(t >= first.0 && t <= last.0) {
        return None;
    }
    if let Some(s) = series.iter().find(|s| s.0 == t) {
        return Some((s.1, s.2.clone()));
    }
    let k = series.partition_point(|s| s.0 <= t) - 1;
    let (v, g, _) = interpolate(&series[window(series.len(), k)], t);
    Some((v, g))
}

/// Why a series has no crossing time.
#[derive(Debug, Clone, PartialEq)]
pub enum NoCrossing {
    /// The series never crosses the level in the asked direction; its
    /// range is `(min, max)`.
    Never(f64, f64),
    /// It crosses at `t` (s) with zero slope: the crossing time has no
    /// derivative there.
    Flat(f64),
}

/// The first time `t*` at which the series crosses `level` in direction
/// `dir`, and `dt*/dp = −(∂y/∂p)(t*) / ẏ(t*)` (module doc).
pub fn crossing(
    series: &[Sample],
    level: f64,
    dir: Direction,
) -> Result<(f64, Vec<f64>), NoCrossing> {
    let crosses = |a: f64, b: f64| {
        let up = a < level && b >= level;
        let down = a > level && b <= level;
        match dir {
            Direction::Up => up,
            Direction::Down => down,
            Direction::Either => up || down,
        }
    };
    let Some(k) =
        (0..series.len().saturating_sub(1)).find(|&k| crosses(series[k].1, series[k + 1].1))
    else {
        let (lo, hi) = series
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s.1), hi.max(s.1))
            });
        return Err(NoCrossing::Never(lo, hi));
    };
    let win = &series[window(series.len(), k)];
    let ts: Vec<f64> = win.iter().map(|s| s.0).collect();
    let p = |t: f64| {
        let (w, _) = lagrange(&ts, t);
        win.iter().zip(&w).map(|(s, w)| w * s.1).sum::<f64>() - level
    };
    // Bisection on [t_k, t_{k+1}], where P − L changes sign (P passes
    // through the samples).
    let (mut a, mut b) = (series[k].0, series[k + 1].0);
    let mut fa = series[k].1 - level;
    if series[k + 1].1 == level {
        a = b;
    }
    while b - a > 4.0 * f64::EPSILON * b.abs().max(a.abs()).max(1e-300) {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let fm = p(m);
        if (fm < 0.0) == (fa < 0.0) && fm != 0.0 {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    let t = if a == b { a } else { 0.5 * (a + b) };
    let (_, grad, slope) = interpolate(win, t);
    if slope == 0.0 || !slope.is_finite() {
        return Err(NoCrossing::Flat(t));
    }
    Ok((t, grad.iter().map(|g| -g / slope).collect()))
}

#[cfg(test)]
mod tests {
    use super::super::responses::peak;
    use super::*;

    /// Samples of `y(t) = f(t)`, `dy/dp = g(t)` at `n` times on [0, 1].
    fn sampled(n: usize, f: impl Fn(f64) -> f64, g: impl Fn(f64) -> f64) -> Vec<Sample> {
        (0..n)
            .map(|k| {
                let t = k as f64 / (n - 1) as f64;
                (t, f(t), vec![g(t)])
            })
            .collect()
    }

    #[test]
    fn cubics_are_interpolated_exactly() {
        // y = 1 + t − 2t² + t³, dy/dp = t² (closed forms): the cubic
        // through four samples reproduces both at any time.
        let y = |t: f64| 1.0 + t - 2.0 * t * t + t * t * t;
        let s = sampled(11, y, |t| t * t);
        for t in [0.0, 0.03, 0.437, 0.95, 1.0] {
            let (v, g) = value_at(&s, t).unwrap();
            assert!((v - y(t)).abs() < 1e-14 && (g[0] - t * t).abs() < 1e-14);
        }
        assert!(value_at(&s, 1.0 + 1e-9).is_none() && value_at(&s, -0.1).is_none());
    }

    #[test]
    fn crossing_time_and_its_derivative_match_the_closed_form() {
        // y(t; p) = p t² with p = 2: y = L at t* = √(L/p), and
        // dt*/dp = −t*/(2p) (closed form); dy/dp = t². Cubic interpolation
        // of a quadratic is exact, so both are exact to rounding.
        let (p, level) = (2.0, 0.7);
        let s = sampled(21, |t| p * t * t, |t| t * t);
        let (t, g) = crossing(&s, level, Direction::Up).unwrap();
        let ts = (level / p).sqrt();
        assert!((t - ts).abs() < 1e-14, "{t} {ts}");
        assert!((g[0] + ts / (2.0 * p)).abs() < 1e-13, "{g:?}");
        // Downward only: no crossing of a rising series.
        assert_eq!(
            crossing(&s, level, Direction::Down),
            Err(NoCrossing::Never(0.0, 2.0))
        );
        // A sine's first downward crossing of 0.5 after its peak: t with
        // sin(πt) = 0.5 past 0.5, i.e. 5/6; interpolation error O(Δt⁴).
        let s = sampled(41, |t| (std::f64::consts::PI * t).sin(), |_| 0.0);
        let (t, _) = crossing(&s, 0.5, Direction::Down).unwrap();
        assert!((t - 5.0 / 6.0).abs() < 1e-6, "{t}");
        let (t, _) = crossing(&s, 0.5, Direction::Either).unwrap();
        assert!((t - 1.0 / 6.0).abs() < 1e-6, "{t}");
    }

    #[test]
    fn the_extreme_is_continuous_when_the_largest_sample_changes() {
        // y = f(t − p) with the lopsided f(u) = cos 3u + 0.2 sin 6u,
        // dy/dp = −f'(t − p), sampled every 0.1 on [0, 1]: the largest
        // value max f = 1.068688 (dense search) is the same for every p (a
        // shift), so d(max)/dp = 0. As p moves from 0.1 to 0.4 the largest
        // sample changes three times; between neighbouring p (1e-5 apart)
        // the extreme may only move by the smooth change of its
        // interpolation error (below 1e-3, so about 6e-7 per step), while
        // the parabola through the three samples around the largest
        // sample (`responses::peak`) jumps by its interpolation error.
        let f = |u: f64| (3.0 * u).cos() + 0.2 * (6.0 * u).sin();
        let df = |u: f64| -3.0 * (3.0 * u).sin() + 1.2 * (6.0 * u).cos();
        let at = |p: f64| sampled(11, |t| f(t - p), |t| -df(t - p));
        let (mut jump, mut parabola_jump) = (0.0f64, 0.0f64);
        let mut prev: Option<(f64, f64)> = None;
        for i in 0..=30_000 {
            let p = 0.1 + i as f64 * 1e-5;
            let s = at(p);
            let (t, v, g) = extreme(&s, Sense::Max).unwrap();
            let pv = peak(&s).unwrap().1;
            if let Some((v0, pv0)) = prev {
                jump = jump.max((v - v0).abs());
                parabola_jump = parabola_jump.max((pv - pv0).abs());
            }
            prev = Some((v, pv));
            // Cubic interpolation: within O(Δt⁴) of the closed form, the
            // gradient (envelope) near 0.
            assert!(
                (v - 1.068688).abs() < 2e-3 && g[0].abs() < 5e-2,
                "{p}: {t} {v} {g:?}"
            );
        }
        println!("largest change between neighbours: {jump:e} (parabola {parabola_jump:e})");
        assert!(jump < 2e-6, "{jump:e}");
        assert!(parabola_jump > 1e-4, "{parabola_jump:e}");
    }

    #[test]
    fn trapezoid_and_minimum() {
        // ∫₀¹ t dt = 1/2 exactly by the trapezoidal rule; the minimum of
        // (t − 0.3)² − 1 at t = 0.3 (vertex of a parabola, exact).
        let s = sampled(5, |t| t, |t| 2.0 * t);
        let (v, g) = trapezoid(&s).unwrap();
        assert!((v - 0.5).abs() < 1e-15 && (g[0] - 1.0).abs() < 1e-15);
        let s = sampled(11, |t| (t - 0.3).powi(2) - 1.0, |t| t);
        let (t, v, g) = extreme(&s, Sense::Min).unwrap();
        assert!((t - 0.3).abs() < 1e-12 && (v + 1.0).abs() < 1e-12);
        assert!((g[0] - 0.3).abs() < 1e-12);
        assert!(trapezoid(&[]).is_none());
    }
}
