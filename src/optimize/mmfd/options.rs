//! [`MmfdOptions`]: the method's parameters, DOT's defaults.

use crate::error::{Error, Result};

/// MMFD parameters. Defaults are DOT's where DOT has the parameter
/// (Vanderplaats R&D, *DOT Users Manual*, parameters RPRM/IPRM).
#[derive(Debug, Clone, PartialEq)]
pub struct MmfdOptions {
    /// Initial constraint thickness CT (< 0): `g_j >= CT` is active.
    /// DOT: −0.03 (3 % from a normalised limit).
    pub ct: f64,
    /// CTMIN (> 0): `g_j > CTMIN` is violated; also the final CT magnitude.
    /// DOT: 0.003.
    pub ctmin: f64,
    /// Factor applied to CT after each iteration (CONMIN-style sharpening of
    /// the active set): 0.5, so CT reaches −CTMIN in about 4 iterations.
    pub ct_reduction: f64,
    /// Relative convergence DELOBJ on |Δf|/|f|. DOT: 0.001.
    pub delobj: f64,
    /// Absolute convergence DABOBJ on |Δf|; `None`: DOT's
    /// `max(1e-4 |f(x0)|, 1e-10)`.
    pub dabobj: Option<f64>,
    /// ITRMOP: consecutive iterations the change must stay below DELOBJ or
    /// DABOBJ. DOT: 2.
    pub itrmop: usize,
    /// Iteration limit (ITMAX). DOT: 100.
    pub max_iterations: usize,
    /// DOBJ1: relative change of f sought by the first step. DOT: 0.1.
    pub dobj1: f64,
    /// DOBJ2: largest relative change of f sought by later first trials.
    /// DOT: 0.2.
    pub dobj2: f64,
    /// DX1: smallest move of the largest-moving variable in the first
    /// trial, as a fraction of its range (so that f ≈ 0 at the start does
    /// not make the DOBJ1 step vanish). DOT: 0.01 (relative to the value).
    pub dx1: f64,
    /// DX2: largest move of any variable per first trial, as a fraction of
    /// its range. DOT: 0.2 (relative to the variable's value there; here to
    /// its range, since the variables are range-scaled).
    pub dx2: f64,
    /// Kuhn–Tucker tolerance on the projected gradient in scaled variables,
    /// relative to `max(|f|, 1)`: 1e-4 (a full-range move then changes f by
    /// less than 0.01 % to first order).
    pub kt_tolerance: f64,
    /// Function calls allowed per line search (excluding corrections): 6.
    pub max_line_evaluations: usize,
    /// Newton pull-backs onto the binding constraints per trial point: 3.
    pub max_corrections: usize,
    /// Constraint following stops when every binding |g_j| is below this:
    /// 3e-5 (CTMIN/100, so the final f is not biased by a violation).
    pub follow_tolerance: f64,
}

impl Default for MmfdOptions {
    fn default() -> Self {
        MmfdOptions {
            ct: -0.03,
            ctmin: 0.003,
            ct_reduction: 0.5,
            delobj: 0.001,
            dabobj: None,
            itrmop: 2,
            max_iterations: 100,
            dobj1: 0.1,
            dobj2: 0.2,
            dx1: 0.01,
            dx2: 0.2,
            kt_tolerance: 1e-4,
            max_line_evaluations: 6,
            max_corrections: 3,
            follow_tolerance: 3e-5,
        }
    }
}

impl MmfdOptions {
    pub(super) fn validate(&self) -> Result<()> {
        let bad = |k: &str, v: f64, e: &str| Err(Error::input(format!("mmfd.{k}"), v, e));
        if !(self.ct < 0.0 && self.ct.is_finite()) {
            return bad("ct", self.ct, "a finite constraint thickness < 0");
        }
        if !(self.ctmin > 0.0 && self.ctmin.is_finite()) {
            return bad("ctmin", self.ctmin, "a finite tolerance > 0");
        }
        if !(self.ct_reduction > 0.0 && self.ct_reduction <= 1.0) {
            return bad("ct_reduction", self.ct_reduction, "a factor in (0, 1]");
        }
        for (k, v) in [
            ("delobj", self.delobj),
            ("dobj1", self.dobj1),
            ("dobj2", self.dobj2),
            ("dx1", self.dx1),
            ("dx2", self.dx2),
            ("kt_tolerance", self.kt_tolerance),
            ("follow_tolerance", self.follow_tolerance),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return bad(k, v, "a finite value > 0");
            }
        }
        if let Some(d) = self.dabobj {
            if !(d > 0.0 && d.is_finite()) {
                return bad("dabobj", d, "a finite value > 0");
            }
        }
        if self.itrmop == 0 || self.max_line_evaluations < 2 {
            return Err(Error::input(
                "mmfd.itrmop/max_line_evaluations",
                format!("{}/{}", self.itrmop, self.max_line_evaluations),
                "itrmop >= 1 and max_line_evaluations >= 2",
            ));
        }
        Ok(())
    }
}
