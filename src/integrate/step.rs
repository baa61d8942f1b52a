//! [`Step`]: one accepted step of an integration with its dense output,
//! handed to a step watcher ([`super::integrate_stepped`],
//! [`super::integrate_sens_stepped`]) so that a functional can be read on
//! the continuous solution (a peak located between output times, a
//! crossing time, a quadrature) instead of on the output samples.

use crate::error::Result;

/// The state and its sensitivities (lane-major; empty without) at a time.
pub type DenseState = (Vec<f64>, Vec<f64>);

/// A watcher of the accepted steps ([`super::integrate_stepped`]).
pub type StepWatch<'w> = dyn FnMut(&Step<'_>) -> Result<()> + 'w;

/// One accepted step `[t0, t1]` of the method: `t1` is the located event
/// time when the step found one, so a step never spans a change of piece.
/// [`Step::at`] evaluates the method's own interpolant (its dense output,
/// of the method's order) anywhere in the span; steps follow each other
/// without gap from the start time to the end time.
pub struct Step<'a> {
    /// Start and end of the step (s).
    pub span: (f64, f64),
    pub(super) dense: &'a dyn Fn(f64) -> Result<DenseState>,
}

impl Step<'_> {
    /// The state and its sensitivities at `t` in [`Step::span`].
    pub fn at(&self, t: f64) -> Result<DenseState> {
        (self.dense)(t)
    }

    /// A step over which the state is constant (a scene in which nothing
    /// moves): `at` returns `(y, s)` everywhere.
    pub fn constant<'a>(
        span: (f64, f64),
        dense: &'a dyn Fn(f64) -> Result<DenseState>,
    ) -> Step<'a> {
        Step { span, dense }
    }
}
