//! The evaluation of the scene's responses after a run: one arm per
//! [`ResponseKind`], the one place where each kind is evaluated.
//!
//! A sum of energies in the energy form ([`ResponseKind::energy_form`])
//! is an integrated state (`integral`: its value at the end, its gradient
//! the state's sensitivities at the end) or the sum at the end state
//! (`final`: the sum with the sensitivities at the end, lane-major
//! `s_end`). A peak (either form), a crossing time and an integral of
//! outputs are read on the continuous solution
//! ([`super::continuous`]: every local extreme in the peak's sense, the
//! extreme first; the first crossing of a level; the quadrature of the
//! steps, the value at a time on the step that holds it, the final value
//! at the end state). A frequency reads the modal basis
//! ([`super::sampled::frequency`]).

use super::continuous::Continuous;
use super::sampled::{frequency, lanes_of};
use crate::error::{Error, Result};
use crate::mbs::responses::{Direction, ResponseKind, ResponseValue};
use crate::mbs::series::NoCrossing;
use crate::mbs::{Param, System};
use crate::scene::{Response, Scene};

/// What a run leaves for the responses: the readings on the continuous
/// solution, the state and the sensitivities (lane-major) at the end.
pub(super) struct RunEnd<'a> {
    /// The peaks, and the crossings, values at a time, final values and
    /// integrals of outputs.
    pub(super) continuous: &'a Continuous,
    /// The state at the end time.
    pub(super) y_end: &'a [f64],
    /// The sensitivities at the end time, lane-major.
    pub(super) s_end: &'a [f64],
}

/// The value of every response of `scene`, in order.
pub(super) fn evaluate_all(
    scene: &Scene,
    sys: &System,
    end: &RunEnd<'_>,
) -> Result<Vec<ResponseValue>> {
    let params: Vec<Param> = scene.params.iter().map(|(_, p)| *p).collect();
    (0..scene.responses.len())
        .map(|k| evaluate(scene, sys, end, (k, &params)))
        .collect()
}

/// Response `k` of `scene` with its gradient along `params` (module doc).
fn evaluate(
    scene: &Scene,
    sys: &System,
    end: &RunEnd<'_>,
    (k, params): (usize, &[Param]),
) -> Result<ResponseValue> {
    let r = &scene.responses[k];
    let energies = r.outputs.is_empty();
    let name = &r.name;
    let fail = |detail: String| {
        Error::numerical("simulate: responses", format!("response {name}: {detail}"))
    };
    let none = || fail("no samples (no output times or no step)".into());
    // The response at the end state, with its gradient (a peak that rises
    // to the end; a crossing not reached by it).
    let at_end = || {
        let lanes = lanes_of(&scene.params, end.s_end, end.y_end.len());
        let t = scene.options.times.last().copied().unwrap_or(0.0);
        let (v, g) = end.continuous.final_value((sys, r, k), end.y_end, &lanes);
        (t, v, g)
    };
    let (time, value, gradient, critical) = match r.kind {
        ResponseKind::Frequency { body, mode } => return frequency(sys, r, (body, mode), params),
        ResponseKind::Integral if energies => {
            let (value, gradient) = integrated(sys, r, end, params.len())?;
            (None, value, gradient, Vec::new())
        }
        ResponseKind::Integral => {
            let (v, g) = end.continuous.integral(k).ok_or_else(none)?;
            (None, v, g, Vec::new())
        }
        ResponseKind::Peak { .. } => {
            let critical = end.continuous.extremes(k, at_end);
            let (t, value, gradient) = critical.first().cloned().ok_or_else(none)?;
            (Some(t), value, gradient, critical)
        }
        ResponseKind::Final => {
            let (t, v, g) = at_end();
            (Some(t), v, g, Vec::new())
        }
        ResponseKind::ValueAt { .. } | ResponseKind::Crossing { .. } if energies => {
            return Err(Error::numerical(
                "simulate: responses",
                format!("{name}: a {} response of energies is sampled", r.kind),
            ))
        }
        ResponseKind::ValueAt { time } => {
            let (_, v, g) = end.continuous.value_at(k).ok_or_else(|| {
                let (t0, t1) = (scene.options.t0, scene.options.times.last().copied());
                fail(format!(
                    "time {time} s is outside the run (t = {t0} s to {} s)",
                    t1.unwrap_or(t0)
                ))
            })?;
            (Some(time), v, g, Vec::new())
        }
        ResponseKind::Crossing { level, direction } => {
            let (t, g) = end
                .continuous
                .crossing(k, at_end)
                .ok_or_else(none)?
                .map_err(|e| fail(no_crossing(r, &scene.options.times, e, (level, direction))))?;
            (Some(t), t, g, Vec::new())
        }
    };
    Ok(ResponseValue {
        name: name.clone(),
        kind: r.kind,
        value,
        unit: r.unit.clone(),
        time,
        gradient,
        critical,
    })
}

/// An integral of energies: its integrated state at the end and that
/// state's sensitivity to each of the `nparams` parameters.
fn integrated(
    sys: &System,
    r: &Response,
    end: &RunEnd<'_>,
    nparams: usize,
) -> Result<(f64, Vec<f64>)> {
    let index = r.integral.ok_or_else(|| {
        Error::numerical(
            "simulate: responses",
            format!("{} has no integrated state", r.name),
        )
    })?;
    let (n, io) = (end.y_end.len(), sys.integral_off());
    let gradient = (0..nparams)
        .map(|i| end.s_end[i * n + io + index])
        .collect();
    Ok((end.y_end[io + index], gradient))
}

/// Why a response has no crossing time: it never crosses the level (with
/// its range over the run between the output times `times`), or touches
/// it with zero slope.
fn no_crossing(
    r: &Response,
    times: &[f64],
    e: NoCrossing,
    (level, dir): (f64, Direction),
) -> String {
    match e {
        NoCrossing::Never(lo, hi) => format!(
            "does not cross level {level} ({dir:?}) between t = {} s and {} s: \
             its range over the run is [{lo:e}, {hi:e}] {}",
            times.first().map_or(0.0, |t| *t),
            times.last().map_or(0.0, |t| *t),
            r.outputs
                .first()
                .map_or("", |o| o.quantity.kind.info().unit)
        ),
        NoCrossing::Flat(t) => format!(
            "touches level {level} at t = {t} s with zero slope: the crossing \
             time has no derivative there"
        ),
    }
}
