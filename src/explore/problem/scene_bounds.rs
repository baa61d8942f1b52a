//! The constraints of a scene problem (`[[scene_problem.constraints]]`):
//! bounds on a response in its own unit, or relative to its value at the
//! start design.
//!
//! ```toml
//! [[scene_problem.constraints]]
//! response = "deploy_time"
//! upper = 1.5              # s: g = (R − 1.5) / 1.5 <= 0
//! [[scene_problem.constraints]]
//! response = "f1"
//! lower = 2.0              # Hz: g = (2.0 − R) / 2.0 <= 0
//! upper = 8.0              # both sides: two constraints, in this order
//! [[scene_problem.constraints]]
//! response = "u3_peak"
//! upper_relative = 1.0     # c = 1.0 × R(start): g = R / c − 1 <= 0
//! ```
//!
//! Each bound `c` gives one constraint, normalized by a positive scale
//! `s` so that the optimizer's feasibility tolerance (MMFD's, on `g`) is
//! a fraction of the bound rather than an absolute amount in the
//! response's unit: `g = (R − c_upper) / s` and `g = (c_lower − R) / s`,
//! with `s = scale` when given, else `|c|` (a bound of 0 needs `scale`).
//! For an upper bound `c > 0` with `s = c` the constraint is written
//! `R / c − 1`, the same number the relative bounds always gave. The
//! upper bound comes before the lower one in `g` when both are given.
//!
//! A bound on a `peak` response may name `critical_points = K` (default
//! 1): its side of the peak (`upper` for `sense = "max"`, `lower` for
//! `"min"`) then gives `K` constraints, one per critical time point of the
//! response, largest first (every local maximum, located on the continuous solution):
//! `g_k = (R(t*_k) − c) / s`. Where the response has fewer than `K`
//! local maxima the missing ones repeat the peak. The feasible set is the
//! same as with the peak alone (every critical point is at most the
//! peak), but where two local maxima in time are equal, the peak has a
//! kink and its gradient jumps; with `K ≥ 2` the optimizer sees both
//! branches as constraints of their own, so that its direction finding,
//! its restoration and its Kuhn–Tucker test work at the kink.

use crate::error::Result;
use crate::mbs::responses::Sense;
use crate::study::Study;
use serde::Deserialize;

/// One `[[scene_problem.constraints]]` entry: bounds on one response.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    /// A `[[scene.responses]]` name.
    pub response: String,
    /// Absolute upper bound (the response's unit, finite).
    pub upper: Option<f64>,
    /// Absolute lower bound (the response's unit, finite).
    pub lower: Option<f64>,
    /// Upper bound as a factor (> 0) of the response at the start design.
    pub upper_relative: Option<f64>,
    /// Normalization `s > 0` of `g` (the response's unit; default `|c|`).
    pub scale: Option<f64>,
    /// For a `peak` response: how many of its critical time points (the
    /// largest local extremes in time, in its sense) are constrained, each
    /// as a constraint of its own (module doc); default 1, the peak.
    pub critical_points: Option<usize>,
}

/// One constraint `g <= 0` on a response (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Bound {
    /// The response's name.
    pub response: String,
    /// A lower bound (`c − R`) rather than an upper one (`R − c`).
    pub lower: bool,
    /// The bound `c` (the response's unit).
    pub c: f64,
    /// The normalization `s > 0` (the response's unit).
    pub scale: f64,
    /// Which critical time point of a peak response is bounded: 0 the
    /// peak itself, `k` the `k+1`-th largest local extreme (module doc).
    pub point: usize,
}

impl Bound {
    /// `g` at response value `v`.
    pub fn g(&self, v: f64) -> f64 {
        if self.lower {
            (self.c - v) / self.scale
        } else if self.scale == self.c {
            v / self.c - 1.0
        } else {
            (v - self.c) / self.scale
        }
    }

    /// `dg` for a response derivative `dv`.
    pub fn dg(&self, dv: f64) -> f64 {
        if self.lower {
            -dv / self.scale
        } else {
            dv / self.scale
        }
    }

    /// The constraint's label in reports: the response's name, followed
    /// by `(lower bound)` for a lower bound.
    pub fn label(&self) -> String {
        let point = match self.point {
            0 => String::new(),
            k => format!(" (critical point {})", k + 1),
        };
        if self.lower {
            format!("{}{point} (lower bound)", self.response)
        } else {
            format!("{}{point}", self.response)
        }
    }
}

/// An input error on `scene_problem.constraints[j]<suffix>`.
fn bad(study: &Study, j: usize, suffix: &str, v: impl std::fmt::Display, e: &str) -> crate::Error {
    study.error(format!("scene_problem.constraints[{j}]{suffix}"), v, e)
}

/// Check entry `j` without evaluating anything: which bounds it has and
/// that they are valid numbers. `peak` is the response's sense when it
/// is a `peak` (`critical_points` needs one, and a bound on its side).
pub fn check(study: &Study, j: usize, c: &ConstraintSpec, peak: Option<Sense>) -> Result<()> {
    check_critical_points(study, j, c, peak)?;
    if c.upper.is_some() && c.upper_relative.is_some() {
        return Err(bad(
            study,
            j,
            "",
            "(table)",
            "exactly one of `upper` (absolute) and `upper_relative` (factor of the start value)",
        ));
    }
    if c.upper.is_none() && c.upper_relative.is_none() && c.lower.is_none() {
        return Err(bad(
            study,
            j,
            "",
            "(table)",
            "a bound: `upper` or `lower` (absolute, in the response's unit) or \
             `upper_relative` (factor of the start value)",
        ));
    }
    if let Some(u) = c.upper_relative {
        if !(u.is_finite() && u > 0.0) {
            return Err(bad(study, j, ".upper_relative", u, "a finite bound > 0"));
        }
    }
    if let Some(s) = c.scale {
        if !(s.is_finite() && s > 0.0) {
            return Err(bad(study, j, ".scale", s, "a finite scale > 0"));
        }
    }
    for (key, v) in [("upper", c.upper), ("lower", c.lower)] {
        let Some(v) = v else { continue };
        if !v.is_finite() {
            return Err(bad(study, j, &format!(".{key}"), v, "a finite bound"));
        }
        if v == 0.0 && c.scale.is_none() {
            return Err(bad(
                study,
                j,
                &format!(".{key}"),
                v,
                "a nonzero bound, or a `scale` beside it (g is normalized by |bound| by default)",
            ));
        }
    }
    if let (Some(u), Some(l)) = (c.upper, c.lower) {
        if l > u {
            return Err(bad(
                study,
                j,
                ".lower",
                l,
                &format!("a lower bound at most the upper bound {u}"),
            ));
        }
    }
    Ok(())
}

/// `critical_points` is a count from 1 to [`MAX_CRITICAL_POINTS`] on a
/// peak response with a bound on the peak's side.
fn check_critical_points(
    study: &Study,
    j: usize,
    c: &ConstraintSpec,
    peak: Option<Sense>,
) -> Result<()> {
    let Some(k) = c.critical_points else {
        return Ok(());
    };
    let key = ".critical_points";
    if !(1..=MAX_CRITICAL_POINTS).contains(&k) {
        let e = format!("a count from 1 to {MAX_CRITICAL_POINTS}");
        return Err(bad(study, j, key, k, &e));
    }
    let side = match peak {
        None => return Err(bad(study, j, key, k, "a `peak` response (it has none)")),
        Some(Sense::Max) => c.upper.is_some() || c.upper_relative.is_some(),
        Some(Sense::Min) => c.lower.is_some(),
    };
    if !side {
        let e = "a bound on the peak's side (`upper` or `upper_relative` for a \
                 maximum, `lower` for `sense = \"min\"`)";
        return Err(bad(study, j, key, k, e));
    }
    Ok(())
}

/// The largest `critical_points` accepted.
pub const MAX_CRITICAL_POINTS: usize = 16;

/// The bounds of checked entry `j`, given the response's value at the
/// start design (the reference of `upper_relative`): the upper bound
/// first.
/// A bound on the peak's side gives one constraint per critical point
/// (`peak` is the response's sense when it is a peak).
pub fn resolve(
    study: &Study,
    j: usize,
    c: &ConstraintSpec,
    (at_start, peak): (f64, Option<Sense>),
) -> Result<Vec<Bound>> {
    let mut out = Vec::new();
    let k = c.critical_points.unwrap_or(1);
    let mut bound = |lower: bool, c_: f64| {
        let points = match (peak, lower) {
            (Some(Sense::Max), false) | (Some(Sense::Min), true) => k,
            _ => 1,
        };
        out.extend((0..points).map(|point| Bound {
            response: c.response.clone(),
            lower,
            c: c_,
            scale: c.scale.unwrap_or(c_.abs()),
            point,
        }))
    };
    if let Some(u) = c.upper_relative {
        let v = u * at_start;
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(
                study,
                j,
                ".upper_relative",
                u,
                &format!(
                    "a bound > 0: {} at the start design is {v:e}, so the constraint is degenerate",
                    c.response
                ),
            ));
        }
        bound(false, v);
    }
    if let Some(u) = c.upper {
        bound(false, u);
    }
    if let Some(l) = c.lower {
        bound(true, l);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_normalize_by_the_bound_or_the_scale() {
        let b = |lower, c, scale| Bound {
            response: "r".into(),
            lower,
            c,
            scale,
            point: 0,
        };
        // Upper bound 2 with its own scale: the relative form R/c − 1.
        assert_eq!(b(false, 2.0, 2.0).g(3.0), 0.5);
        assert_eq!(b(false, 2.0, 2.0).dg(1.0), 0.5);
        // Lower bound 2 Hz at 1.5 Hz: violated by a quarter of the bound.
        assert_eq!(b(true, 2.0, 2.0).g(1.5), 0.25);
        assert_eq!(b(true, 2.0, 2.0).dg(1.0), -0.5);
        // Negative bound, scale given: (R − c)/s.
        assert_eq!(b(false, -1.0, 0.5).g(-0.5), 1.0);
        assert_eq!(b(true, -1.0, 1.0).label(), "r (lower bound)");
    }
}
