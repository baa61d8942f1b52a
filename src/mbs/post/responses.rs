//! Response functionals of a simulation (paper §4–§6, Eqs. 29–34) over a
//! sum of energies ([`Energy`]: strain energies, kinetic energies): its
//! time integral (the objective Ψ₀ = ∫ 2U dt, Eq. 33; the IDAS
//! slider-crank's G = ∫ T dt), its peak over the run (the constraints
//! max U ≤ c, Eq. 34) and its final value, with their sensitivities.
//!
//! - **Integrals** are extra states of the integration
//!   ([`crate::mbs::model::Integral`]): value and sensitivities come with
//!   the motion under the same error control (docs/numerics.md).
//! - **Peaks** use the critical time point: a raw maximum over time is not
//!   differentiable where the time of the peak jumps, but at an interior
//!   maximum `t*` (where `U̇ = 0`) the envelope theorem gives
//!   `d max_t U / dp = ∂U/∂p (t*)`. `t*` is located from the integrator's
//!   dense output at the output times: the largest sample and the vertex
//!   of the parabola through it and its two neighbours (error `O(Δt³)` in
//!   the value for an output interval `Δt` well below the oscillation
//!   period; the study's `dt_out` controls it). The sensitivities are
//!   interpolated to `t*` by the same three-point rule. When the largest
//!   sample is the first or the last, the parabola through the three end
//!   samples is used the same way: its vertex when it is concave (the
//!   maximum lies between the end sample and its neighbour), else the end
//!   sample itself (a boundary maximum, whose time does not move with the
//!   parameters). The located peak is then continuous when the largest
//!   sample moves to or from an end: the same three samples give the peak
//!   on both sides. (Taking the end sample whenever it was the largest
//!   made the peak jump by the parabola's bump there, a step in the
//!   constraint that no optimizer can cross and no Kuhn–Tucker test can
//!   certify.)
//! - **Final values** are the sum at the end time, with the derivative
//!   `dE/dp = ∂E/∂y · s(t_end) + ∂E/∂p` ([`energy_lanes`]).

use crate::mbs::model::{Energy, Param};
use crate::mbs::system::{System, Workspace};
use num_dual::Dual64;

/// The name of a response kind, as written in `[[scene.responses]] kind`
/// and in `responses.csv`: `integral`, `peak`, `final`, `value_at`,
/// `crossing` or `frequency` ([`ResponseKind`] carries its parameters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ResponseKindName {
    /// [`ResponseKind::Integral`].
    Integral,
    /// [`ResponseKind::Peak`].
    Peak,
    /// [`ResponseKind::Final`].
    Final,
    /// [`ResponseKind::ValueAt`].
    ValueAt,
    /// [`ResponseKind::Crossing`].
    Crossing,
    /// [`ResponseKind::Frequency`].
    Frequency,
}

impl std::fmt::Display for ResponseKindName {
    /// The name written in study files and `responses.csv`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ResponseKindName::Integral => "integral",
            ResponseKindName::Peak => "peak",
            ResponseKindName::Final => "final",
            ResponseKindName::ValueAt => "value_at",
            ResponseKindName::Crossing => "crossing",
            ResponseKindName::Frequency => "frequency",
        })
    }
}

/// The kind of a response functional (paper Eqs. 33–34) with its own
/// parameters: how the series `scale·Σ y(t)` is reduced to one number,
/// or a natural frequency. Each kind is evaluated in one place,
/// `crate::simulate`'s evaluation of responses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ResponseKind {
    /// `∫ scale·Σ y dt` over the run: an integrated state for energies
    /// (Eq. 33), the trapezoidal rule over the output times otherwise.
    Integral,
    /// `max_t` (or `min_t`) of `scale·Σ y(t)` at its critical time point
    /// (Eq. 34).
    Peak {
        /// The largest or the smallest value.
        sense: Sense,
    },
    /// `scale·Σ y(t_end)`.
    Final,
    /// `scale·Σ y(t)` at `time`, interpolated between output times.
    ValueAt {
        /// The time (s), within the output times.
        time: f64,
    },
    /// The first time (s) at which `scale·Σ y` crosses `level`.
    Crossing {
        /// The level, in the unit of the outputs.
        level: f64,
        /// Which crossings count.
        direction: Direction,
    },
    /// A natural frequency `√λ_k / (2π)` (Hz) of a flexible body's modal
    /// basis; no time integration.
    Frequency {
        /// The body (index in the model).
        body: usize,
        /// The 0-based mode of its basis.
        mode: usize,
    },
}

impl std::fmt::Display for ResponseKind {
    /// The name written in study files and `responses.csv`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.name().fmt(f)
    }
}

impl ResponseKind {
    /// The kind's name.
    pub fn name(&self) -> ResponseKindName {
        match self {
            ResponseKind::Integral => ResponseKindName::Integral,
            ResponseKind::Peak { .. } => ResponseKindName::Peak,
            ResponseKind::Final => ResponseKindName::Final,
            ResponseKind::ValueAt { .. } => ResponseKindName::ValueAt,
            ResponseKind::Crossing { .. } => ResponseKindName::Crossing,
            ResponseKind::Frequency { .. } => ResponseKindName::Frequency,
        }
    }

    /// Whether a sum of energies of this kind keeps the energy form
    /// (integrals as integrated states, the largest value by
    /// [`critical_points`], the final value from the end state): integrals,
    /// final values and peaks of the largest value; every other response
    /// is sampled.
    pub fn energy_form(&self) -> bool {
        matches!(
            self,
            ResponseKind::Integral | ResponseKind::Final | ResponseKind::Peak { sense: Sense::Max }
        )
    }

    /// SI unit of a response of this kind over energies (J) with a
    /// dimensionless scale: `J*s` for an integral, `s` for a crossing
    /// time, `Hz` for a frequency, `J` otherwise.
    pub fn unit(&self) -> &'static str {
        match self {
            ResponseKind::Integral => "J*s",
            ResponseKind::Crossing { .. } => "s",
            ResponseKind::Frequency { .. } => "Hz",
            ResponseKind::Peak { .. } | ResponseKind::Final | ResponseKind::ValueAt { .. } => "J",
        }
    }

    /// SI unit of a response of this kind over an output in unit `base`:
    /// `<base>*s` for an integral, `s` for a crossing time, `Hz` for a
    /// frequency, `base` otherwise (`J` gives [`ResponseKind::unit`]).
    pub fn unit_of(&self, base: &str) -> String {
        match self {
            ResponseKind::Integral => format!("{base}*s"),
            ResponseKind::Crossing { .. } => "s".into(),
            ResponseKind::Frequency { .. } => "Hz".into(),
            ResponseKind::Peak { .. } | ResponseKind::Final | ResponseKind::ValueAt { .. } => {
                base.into()
            }
        }
    }
}

/// Which extreme a `peak` response takes: `sense = "max"` (default) or
/// `"min"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sense {
    /// The largest value over the run.
    #[default]
    Max,
    /// The smallest value over the run.
    Min,
}

/// Which crossings of `level` a `crossing` response counts:
/// `direction = "up"`, `"down"` or `"either"` (default).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// From below the level to at or above it.
    Up,
    /// From above the level to at or below it.
    Down,
    /// Either way.
    #[default]
    Either,
}

/// One evaluated response.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseValue {
    /// The `[[scene.responses]] name`.
    pub name: String,
    /// The response's kind.
    pub kind: ResponseKind,
    /// The response's value, in [`ResponseValue::unit`].
    pub value: f64,
    /// SI unit of the value (`J*s` for an integral of energies, `rad` for
    /// a peak of an angle, `s` for a crossing time, `Hz` for a frequency).
    pub unit: String,
    /// Time of the peak, of the value or of the crossing, or the end
    /// time (s); `None` for integrals and frequencies.
    pub time: Option<f64>,
    /// `d value / d p` for each sensitivity parameter of the scene.
    pub gradient: Vec<f64>,
    /// A peak's critical time points `(t*, value, gradient)`: every local
    /// extreme in its sense ([`critical_points`]), this peak first; empty
    /// for the other kinds.
    pub critical: Vec<(f64, f64, Vec<f64>)>,
}

/// `scale · Σ terms` at state `y` and its derivatives along each
/// sensitivity lane `(∂y/∂p, p)`: `∂E/∂y · ∂y/∂p + ∂E/∂p`, exact from one
/// dual-number evaluation per lane with `y + ε ∂y/∂p` and `p + ε` (so a
/// mass enters the kinetic energy explicitly, a ply angle the strain
/// energy through `dΛ/dθ` and the flexible mass matrix through the
/// invariants' derivatives).
pub fn energy_lanes(
    sys: &System,
    (terms, scale): (&[Energy], f64),
    y: &[f64],
    lanes: &[(&[f64], Param)],
) -> (f64, Vec<f64>) {
    let value = sys.energy_sum(terms, y, &mut Workspace::empty()) * scale;
    let mut ws = Workspace::<Dual64>::empty();
    let grad = lanes
        .iter()
        .map(|(lane, p)| {
            let yd: Vec<Dual64> = y
                .iter()
                .zip(*lane)
                .map(|(&a, &b)| Dual64::new(a, b))
                .collect();
            let v = p.value(&sys.model).unwrap_or(0.0);
            ws.params = vec![(*p, Dual64::new(v, 1.0))];
            sys.energy_sum(terms, &yd, &mut ws).eps * scale
        })
        .collect();
    (value, grad)
}

/// The critical time point of a sampled response `(t, value, gradient)`:
/// `(t*, value, gradient)` at the refined maximum (see the module doc).
/// `None` for an empty series.
pub fn peak(series: &[(f64, f64, Vec<f64>)]) -> Option<(f64, f64, Vec<f64>)> {
    Some(refine(series, largest(series)?))
}

/// The index of the largest sample (the last of equal ones).
fn largest(series: &[(f64, f64, Vec<f64>)]) -> Option<usize> {
    (0..series.len()).max_by(|&a, &b| series[a].1.total_cmp(&series[b].1))
}

/// Every critical time point of a sampled response: each local maximum
/// of the samples (a sample at least its predecessor and above its
/// successor; an end sample above its neighbour), refined as [`peak`]
/// refines the largest. The largest ([`peak`]'s) comes first, then the
/// others by decreasing value.
///
/// A constraint `max_t U ≤ c` is not differentiable where two local
/// maxima in time are equal (a kink: the time of the peak jumps from one
/// to the other). Taking the `K` largest critical points as `K`
/// constraints `U(t*_k) ≤ c` (Haug & Arora, *Applied Optimal Design*,
/// 1979, §5.2: point-wise constraints at the critical time points) keeps
/// the feasible set and gives a linearisation of each branch, so that the
/// optimizer's direction subproblem and its Kuhn–Tucker test see both
/// sides of the kink.
pub fn critical_points(series: &[(f64, f64, Vec<f64>)]) -> Vec<(f64, f64, Vec<f64>)> {
    let Some(first) = largest(series) else {
        return Vec::new();
    };
    let n = series.len();
    let v = |k: usize| series[k].1;
    let mut others: Vec<_> = (0..n)
        .filter(|&k| k != first)
        .filter(|&k| (k == 0 || v(k) >= v(k - 1)) && (k + 1 == n || v(k) > v(k + 1)))
        .map(|k| refine(series, k))
        .collect();
    others.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut out = vec![refine(series, first)];
    out.extend(others);
    out
}

/// [`critical_points`] of the largest (`Sense::Max`) or of the smallest
/// (`Sense::Min`, the critical points of `−y`) values: the extreme first.
pub fn critical_extremes(
    series: &[(f64, f64, Vec<f64>)],
    sense: Sense,
) -> Vec<(f64, f64, Vec<f64>)> {
    let flip = |s: &(f64, f64, Vec<f64>)| (s.0, -s.1, s.2.iter().map(|x| -x).collect());
    match sense {
        Sense::Max => critical_points(series),
        Sense::Min => {
            let neg: Vec<_> = series.iter().map(flip).collect();
            critical_points(&neg).iter().map(flip).collect()
        }
    }
}

/// Sample `k` of a series refined to the vertex of the parabola through
/// it and its neighbours (the three end samples at an end; the module
/// doc gives the rule).
fn refine(series: &[(f64, f64, Vec<f64>)], k: usize) -> (f64, f64, Vec<f64>) {
    if series.len() < 3 {
        let (t, v, g) = &series[k];
        return (*t, *v, g.clone());
    }
    // The three samples around sample k, the three end samples when it
    // is an end.
    let c = k.clamp(1, series.len() - 2);
    let (t0, v0, g0) = &series[c - 1];
    let (t1, v1, g1) = &series[c];
    let (t2, v2, g2) = &series[c + 1];
    // Lagrange basis on (t0, t1, t2), evaluated at the vertex.
    let l = |t: f64| {
        [
            (t - t1) * (t - t2) / ((t0 - t1) * (t0 - t2)),
            (t - t0) * (t - t2) / ((t1 - t0) * (t1 - t2)),
            (t - t0) * (t - t1) / ((t2 - t0) * (t2 - t1)),
        ]
    };
    // Vertex of the parabola: zero of its derivative.
    let d0 = v0 / ((t0 - t1) * (t0 - t2));
    let d1 = v1 / ((t1 - t0) * (t1 - t2));
    let d2 = v2 / ((t2 - t0) * (t2 - t1));
    let a = d0 + d1 + d2;
    let b = -(d0 * (t1 + t2) + d1 * (t0 + t2) + d2 * (t0 + t1));
    let ts = if a < 0.0 {
        (-b / (2.0 * a)).clamp(*t0, *t2)
    } else {
        series[k].0
    };
    let w = l(ts);
    let value = w[0] * v0 + w[1] * v1 + w[2] * v2;
    let grad = (0..g1.len())
        .map(|i| w[0] * g0[i] + w[1] * g1[i] + w[2] * g2[i])
        .collect();
    (ts, value, grad)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kind's name is the one study files give it (serde's), and
    /// the name of each kind with its parameters is its own.
    #[test]
    fn kind_names_are_the_study_file_names() {
        #[derive(serde::Deserialize)]
        struct Spec {
            kind: ResponseKindName,
        }
        let kinds = [
            ("integral", ResponseKind::Integral),
            ("peak", ResponseKind::Peak { sense: Sense::Min }),
            ("final", ResponseKind::Final),
            ("value_at", ResponseKind::ValueAt { time: 0.25 }),
            (
                "crossing",
                ResponseKind::Crossing {
                    level: 1.0,
                    direction: Direction::Down,
                },
            ),
            ("frequency", ResponseKind::Frequency { body: 2, mode: 1 }),
        ];
        for (name, kind) in kinds {
            let spec: Spec = toml::from_str(&format!("kind = \"{name}\"")).unwrap();
            assert_eq!(spec.kind, kind.name(), "{name}");
            assert_eq!(kind.to_string(), name);
        }
        assert!(ResponseKind::Peak { sense: Sense::Max }.energy_form());
        assert!(!ResponseKind::Peak { sense: Sense::Min }.energy_form());
        assert!(!ResponseKind::ValueAt { time: 0.0 }.energy_form());
    }

    #[test]
    fn peak_of_a_sampled_parabola_is_exact() {
        // U(t) = 3 − 2(t − 0.537)², dU/dp = t (closed forms): the vertex
        // and the interpolated gradient are exact for quadratics.
        let series: Vec<(f64, f64, Vec<f64>)> = (0..11)
            .map(|k| {
                let t = k as f64 * 0.1;
                (t, 3.0 - 2.0 * (t - 0.537f64).powi(2), vec![t])
            })
            .collect();
        let (t, v, g) = peak(&series).unwrap();
        assert!((t - 0.537).abs() < 1e-12);
        assert!((v - 3.0).abs() < 1e-12);
        assert!((g[0] - 0.537).abs() < 1e-12);
        // A maximum at the end of a series that rises without a maximum
        // (linear: no concave parabola) stays there.
        let rising: Vec<(f64, f64, Vec<f64>)> =
            (0..5).map(|k| (k as f64, k as f64, vec![1.0])).collect();
        assert_eq!(peak(&rising).unwrap().0, 4.0);
        assert!(peak(&[]).is_none());
        // The vertex between the last two samples (0.96 in 0.9..1.0) is
        // found exactly, with its gradient, although the last sample is
        // the largest; the same at the start (vertex 0.03).
        for (vertex, end) in [(0.96, 1.0), (0.03, 0.0)] {
            let s: Vec<(f64, f64, Vec<f64>)> = (0..11)
                .map(|k| {
                    let t = k as f64 * 0.1;
                    (t, 3.0 - 2.0 * (t - vertex).powi(2), vec![t])
                })
                .collect();
            let (t, v, g) = peak(&s).unwrap();
            assert!(s.iter().all(|x| x.1 <= s[(end * 10.0) as usize].1));
            assert!((t - vertex).abs() < 1e-12 && (v - 3.0).abs() < 1e-12);
            assert!((g[0] - vertex).abs() < 1e-12);
        }
    }

    /// The located peak is continuous as the largest sample moves to the
    /// last one: U(t) = 1 − (t − c)² sampled at 0, 0.1, …, 1 for a vertex c
    /// sweeping across 0.95, where the largest sample changes from 0.9 to
    /// 1.0. Before, the peak dropped from ≈1 to U(1.0) = 1 − 0.05² there.
    #[test]
    fn peak_is_continuous_when_the_largest_sample_reaches_the_end() {
        let at = |c: f64| {
            let s: Vec<(f64, f64, Vec<f64>)> = (0..11)
                .map(|k| {
                    let t = k as f64 * 0.1;
                    (t, 1.0 - (t - c).powi(2), vec![])
                })
                .collect();
            peak(&s).unwrap().1
        };
        let (below, above) = (at(0.95 - 1e-9), at(0.95 + 1e-9));
        assert!((below - above).abs() < 1e-12, "{below} {above}");
        assert!((above - 1.0).abs() < 1e-12);
    }

    /// U(t) = cos 3t + 0.1 t on [0, 4] (closed form): local maxima where
    /// sin 3t = 1/30, at t₀ = asin(1/30)/3 and t₁ = t₀ + 2π/3, and a rising
    /// end at t = 4. The critical points are the end first (the largest),
    /// then t₁, then t₀, each with its value and the gradient dU/dp = t
    /// interpolated to it.
    #[test]
    fn critical_points_are_every_local_maximum_largest_first() {
        let u = |t: f64| (3.0 * t).cos() + 0.1 * t;
        let series: Vec<(f64, f64, Vec<f64>)> = (0..=400)
            .map(|k| {
                let t = k as f64 * 0.01;
                (t, u(t), vec![t])
            })
            .collect();
        let t0 = (1.0f64 / 30.0).asin() / 3.0;
        let t1 = t0 + 2.0 * std::f64::consts::PI / 3.0;
        let c = critical_points(&series);
        assert_eq!(c.len(), 3, "{c:?}");
        assert_eq!(c[0], peak(&series).unwrap());
        for ((t, v, g), want) in c.iter().zip([4.0, t1, t0]) {
            assert!((t - want).abs() < 1e-3, "{t} {want}");
            assert!((v - u(want)).abs() < 1e-5, "{v} {}", u(want));
            assert!((g[0] - want).abs() < 1e-3);
        }
        // One sample, two samples, none.
        assert_eq!(critical_points(&series[..1]).len(), 1);
        assert_eq!(critical_points(&series[..2]).len(), 1);
        assert!(critical_points(&[]).is_empty());
    }

    #[test]
    fn peak_of_a_sampled_sine_converges_at_third_order() {
        // U = sin t near its maximum at π/2 (closed form): the located
        // value's error falls ~8× per halving of the sampling interval.
        let err = |dt: f64| {
            let s: Vec<(f64, f64, Vec<f64>)> = (0..((3.0 / dt) as usize))
                .map(|k| {
                    let t = 0.1 + k as f64 * dt;
                    (t, t.sin(), vec![])
                })
                .collect();
            (peak(&s).unwrap().1 - 1.0).abs()
        };
        let (e1, e2) = (err(0.1), err(0.05));
        assert!(e1 < 1e-3 && e2 < e1 / 6.0, "{e1:e} {e2:e}");
    }
}
