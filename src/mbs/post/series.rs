//! The value of a sampled response series `(t_k, y_k, ∂y_k/∂p)` at a
//! given time, with its exact gradient (the gradient of the same discrete
//! functional), and the types of the sampled and the continuous readings.
//! Peaks, crossing times and integrals of outputs are read on the
//! continuous solution instead (`crate::simulate`), not from samples.
//!
//! - **Interpolation.** Between output times the series is the cubic
//!   Lagrange polynomial `P(t) = Σ_i w_i(t) y_i` through the four samples
//!   around the interval (three or two near the ends of a short series);
//!   its error is `O(Δt⁴)` for an output interval `Δt` well below the
//!   motion's time scale. The sensitivities are interpolated with the same
//!   weights: `∂P/∂p (t) = Σ_i w_i(t) ∂y_i/∂p`.
//! - **Value at a time** `t`: `P(t)` and `Σ_i w_i(t) ∂y_i/∂p` (exact at an
//!   output time).

/// One sample of a response: time (s), value, gradient per parameter.
pub type Sample = (f64, f64, Vec<f64>);

/// The Lagrange weights `w_i(t)` of the nodes `ts`.
fn lagrange(ts: &[f64], t: f64) -> Vec<f64> {
    (0..ts.len())
        .map(|i| {
            let (mut num, mut den) = (1.0, 1.0);
            for j in (0..ts.len()).filter(|&j| j != i) {
                num *= t - ts[j];
                den *= ts[i] - ts[j];
            }
            num / den
        })
        .collect()
}

/// The samples of the cubic through the interval `[k, k + 1]` of a series
/// of `len` samples: four around it, fewer when the series is shorter.
fn window(len: usize, k: usize) -> std::ops::Range<usize> {
    let start = k.saturating_sub(1).min(len.saturating_sub(4));
    start..(start + 4).min(len)
}

/// The interpolant's value and gradient at `t` on the samples `win`.
fn interpolate(win: &[Sample], t: f64) -> (f64, Vec<f64>) {
    let ts: Vec<f64> = win.iter().map(|s| s.0).collect();
    let w = lagrange(&ts, t);
    let value = win.iter().zip(&w).map(|(s, w)| w * s.1).sum();
    let m = win.first().map_or(0, |s| s.2.len());
    let grad = (0..m)
        .map(|i| win.iter().zip(&w).map(|(s, w)| w * s.2[i]).sum())
        .collect();
    (value, grad)
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
    Some(interpolate(&series[window(series.len(), k)], t))
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

#[cfg(test)]
mod tests {
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
}
