//! [`MmfdOptions`]: the method's parameters, DOT's defaults, and the
//! presets the drivers use.
//!
//! - [`MmfdOptions::dot`] (= `default()`): DOT's settings, including its
//!   absolute-change exit DABOBJ = `1e-4 |f(x0)|`, which stops a run whose
//!   start had a large |f| far from stationarity (on HS 100 from a start
//!   with f(x0) = 7.7e6: DABOBJ = 772, runs stop up to 374 above f*).
//! - [`MmfdOptions::standard`]: DOT's settings without that exit, and the
//!   Kuhn–Tucker test relative to the gradient (as the certificate of
//!   [`crate::optimize::kkt`] states it) instead of to |f|.
//! - [`MmfdOptions::polish`] / [`MmfdOptions::polish_for`]: a continuation
//!   from a run's end at tight tolerances, which stops when the
//!   certificate's Kuhn–Tucker test passes (or when no further progress
//!   is possible).
//!
//! [`MmfdOptions::with_feasibility`] sets CTMIN to a study's feasibility
//! tolerance (and the constraint-following tolerance below it).

use crate::error::{Error, Result};
use crate::optimize::kkt::KktTolerances;

/// What the Kuhn–Tucker test's tolerance is relative to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KtScale {
    /// `|S| <= kt_tolerance · max(|f|, 1)` (scaled variables).
    Objective,
    /// `|S| <= kt_tolerance · max(|∇f|, 1)` with the scaled gradient: the
    /// scale of [`crate::optimize::kkt`]'s residual.
    Gradient,
}

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
    /// relative to `max(|f|, 1)` (see `kt_scale`): 1e-4 (a full-range move
    /// then changes f by less than 0.01 % to first order).
    pub kt_tolerance: f64,
    /// What `kt_tolerance` is relative to: `Objective` (default, as
    /// above) or `Gradient`.
    pub kt_scale: KtScale,
    /// Function calls allowed per line search (excluding corrections): 6.
    pub max_line_evaluations: usize,
    /// Newton pull-backs onto the binding constraints per trial point: 3.
    pub max_corrections: usize,
    /// Constraint following stops when every binding |g_j| is below this:
    /// 3e-5 (CTMIN/100, so the final f is not biased by a violation).
    pub follow_tolerance: f64,
    /// When the line search finds no decrease of f, search along `S` by
    /// the slope `∇fᵀS` of the exact gradients instead (module doc of
    /// [`super`], step 5b): off in DOT's settings, on in the polish, where
    /// the decreases left near an optimum fall below the evaluation's noise.
    pub slope_search: bool,
    /// The relative noise of f (of `max(|f|, 1)`) that the slope search
    /// tolerates as a rise and below which a predicted decrease ends the
    /// run (exit `at_noise`, step 6 of [`super`]): 0 for a function exact
    /// to rounding (DOT's settings and the polish's own); the drivers give
    /// the noise they measured (ECNoise, `crate::optimize::noise`) with
    /// [`MmfdOptions::with_noise`].
    pub noise: f64,
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
            kt_scale: KtScale::Objective,
            max_line_evaluations: 6,
            max_corrections: 3,
            follow_tolerance: 3e-5,
            slope_search: false,
            noise: 0.0,
        }
    }
}

impl MmfdOptions {
    /// DOT's settings (the same as `default()`).
    pub fn dot() -> MmfdOptions {
        MmfdOptions::default()
    }

    /// DOT's settings without the absolute-change exit DABOBJ (which
    /// depends on |f(x0)|) and with the Kuhn–Tucker test relative to the
    /// gradient; the relative-change exit DELOBJ = 1e-3 stays, and the
    /// drivers' polish certifies or continues what it stops.
    pub fn standard() -> MmfdOptions {
        MmfdOptions {
            dabobj: Some(f64::MIN_POSITIVE),
            kt_scale: KtScale::Gradient,
            ..MmfdOptions::default()
        }
    }

    /// The polish for the default certificate tolerances
    /// ([`KktTolerances::default`]); see [`MmfdOptions::polish_for`].
    pub fn polish() -> MmfdOptions {
        MmfdOptions::polish_for(&KktTolerances::default())
    }

    /// Options to continue from a run's end until the certificate with
    /// tolerances `tol` passes: the active set `g_j >= −tol.active` from
    /// the first iteration (CT = −active, no sharpening), CTMIN the
    /// feasibility tolerance, the Kuhn–Tucker exit at half the
    /// certificate's stationarity tolerance relative to the gradient (so
    /// that the certificate at the end passes), the change exits at
    /// round-off level (DELOBJ 1e-12 for 3 iterations, no DABOBJ), a first
    /// step that seeks 1 % of |f| and moves each variable at most 5 % of
    /// its range per trial, 200 iterations, and the slope search where f's
    /// decrease is lost in its noise (none tolerated until
    /// [`MmfdOptions::with_noise`] says how much there is).
    pub fn polish_for(tol: &KktTolerances) -> MmfdOptions {
        MmfdOptions {
            ct: -tol.active.max(1e-12),
            ct_reduction: 1.0,
            delobj: 1e-12,
            dabobj: Some(f64::MIN_POSITIVE),
            itrmop: 3,
            max_iterations: 200,
            dobj1: 0.01,
            dx2: 0.05,
            kt_tolerance: 0.5 * tol.stationarity,
            kt_scale: KtScale::Gradient,
            slope_search: true,
            ..MmfdOptions::default()
        }
        .with_feasibility(tol.feasibility)
    }

    /// The slope search tolerating a rise of f of `noise · max(|f|, 1)`,
    /// and the exit at that noise:
    /// the evaluation's measured noise (3σ of f relative,
    /// `crate::optimize::noise::Measured::allowance`).
    pub fn with_noise(mut self, noise: f64) -> MmfdOptions {
        self.noise = noise;
        self
    }

    /// CTMIN set to the feasibility tolerance `tol` (at least 1e-12, as
    /// CTMIN must be positive), the constraint-following tolerance to at
    /// most CTMIN/100, and CT to at most −CTMIN.
    pub fn with_feasibility(mut self, tol: f64) -> MmfdOptions {
        self.ctmin = tol.max(1e-12);
        self.follow_tolerance = self.follow_tolerance.min(self.ctmin / 100.0);
        self.ct = self.ct.min(-self.ctmin);
        self
    }

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
        if !(self.noise >= 0.0 && self.noise.is_finite()) {
            return bad("noise", self.noise, "a finite relative noise >= 0");
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
