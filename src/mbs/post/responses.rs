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
//!   `d max_t U / dp = ∂U/∂p (t*)`. `t*` is located on the integrator's
//!   dense output (`crate::simulate`, step by step), and every local
//!   maximum is a critical time point: a constraint `max_t U ≤ c` is not
//!   differentiable where two local maxima are equal (the time of the peak
//!   jumps from one to the other), and taking the `K` largest critical
//!   points as `K` constraints `U(t*_k) ≤ c` (Haug & Arora, *Applied
//!   Optimal Design*, 1979, §5.2: point-wise constraints at the critical
//!   time points) keeps the feasible set and gives a linearisation of each
//!   branch.
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
    /// its critical time points, the final value from the end state): integrals,
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
    /// extreme in its sense (located on the continuous solution), this peak first; empty
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
}
