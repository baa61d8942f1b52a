//! The evaluation of the scene's responses after a run: one arm per
//! [`ResponseKind`], the one place where each kind is evaluated.
//!
//! A sum of energies in the energy form ([`ResponseKind::energy_form`])
//! is an integrated state (`integral`: its value at the end, its gradient
//! the state's sensitivities at the end), the sum at the end state
//! (`final`: [`energy_lanes`] with the sensitivities at the end, lane-major
//! `s_end`) or its largest value at the critical time points of its
//! sampled series (`peak`: [`critical_points`], the largest first). A
//! response in the sampled form reduces the series of its outputs
//! ([`crate::mbs::series`]: the trapezoidal integral, the extreme of the
//! interpolated series with every critical point in its sense, the last
//! sample, the value at a time, the first crossing of a level). A
//! frequency reads the modal basis ([`super::sampled::frequency`]).

use super::sampled::{frequency, Sampler};
use crate::error::{Error, Result};
use crate::mbs::responses::{
    critical_extremes, critical_points, energy_lanes, Direction, ResponseKind, ResponseValue,
};
use crate::mbs::series::{crossing, extreme, trapezoid, value_at, NoCrossing, Sample};
use crate::mbs::{Param, System};
use crate::scene::{Response, Scene};

/// What a run leaves for the responses: the sampled series, the state and
/// the sensitivities (lane-major) at the end.
pub(super) struct RunEnd<'a> {
    /// The series of the sampled responses and of the energy peaks.
    pub(super) sampler: &'a Sampler,
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
    let series = end.sampler.series(k);
    let energies = r.outputs.is_empty();
    let name = &r.name;
    let fail = |detail: String| {
        Error::numerical("simulate: responses", format!("response {name}: {detail}"))
    };
    let none = || fail("no samples (no output times)".into());
    let (time, value, gradient, critical) = match r.kind {
        ResponseKind::Frequency { body, mode } => return frequency(sys, r, (body, mode), params),
        ResponseKind::Integral if energies => {
            let (value, gradient) = integrated(sys, r, end, params.len())?;
            (None, value, gradient, Vec::new())
        }
        ResponseKind::Integral => {
            let (v, g) = trapezoid(series).ok_or_else(none)?;
            (None, v, g, Vec::new())
        }
        ResponseKind::Peak { .. } if energies => {
            let critical = critical_points(series);
            let (t, value, gradient) = critical.first().cloned().ok_or_else(|| {
                Error::numerical("simulate: responses", format!("no samples for {name}"))
            })?;
            (Some(t), value, gradient, critical)
        }
        ResponseKind::Peak { sense } => {
            let (t, v, g) = extreme(series, sense).ok_or_else(none)?;
            (Some(t), v, g, critical_extremes(series, sense))
        }
        ResponseKind::Final if energies => {
            let (value, gradient) = end_value(sys, r, end, params);
            (
                scene.options.times.last().copied(),
                value,
                gradient,
                Vec::new(),
            )
        }
        ResponseKind::Final => {
            let (t, v, g) = series.last().cloned().ok_or_else(none)?;
            (Some(t), v, g, Vec::new())
        }
        ResponseKind::ValueAt { .. } | ResponseKind::Crossing { .. } if energies => {
            return Err(Error::numerical(
                "simulate: responses",
                format!("{name}: a {} response of energies is sampled", r.kind),
            ))
        }
        ResponseKind::ValueAt { time } => {
            let (v, g) = value_at(series, time)
                .ok_or_else(|| fail(format!("time {time} s is outside the output times")))?;
            (Some(time), v, g, Vec::new())
        }
        ResponseKind::Crossing { level, direction } => {
            let (t, g) = crossing(series, level, direction)
                .map_err(|e| fail(no_crossing(r, series, e, (level, direction))))?;
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

/// A sum of energies at the end state, with its derivative along the lane
/// of each parameter of `params` (the sensitivities at the end).
fn end_value(sys: &System, r: &Response, end: &RunEnd<'_>, params: &[Param]) -> (f64, Vec<f64>) {
    let n = end.y_end.len();
    let lanes: Vec<(&[f64], Param)> = params
        .iter()
        .enumerate()
        .map(|(i, p)| (&end.s_end[i * n..(i + 1) * n], *p))
        .collect();
    energy_lanes(sys, (&r.terms, r.scale), end.y_end, &lanes)
}

/// Why a series has no crossing time: it never crosses the level (with
/// its range over the run), or touches it with zero slope.
fn no_crossing(
    r: &Response,
    series: &[Sample],
    e: NoCrossing,
    (level, dir): (f64, Direction),
) -> String {
    match e {
        NoCrossing::Never(lo, hi) => format!(
            "does not cross level {level} ({dir:?}) between t = {} s and {} s: \
             its range over the run is [{lo:e}, {hi:e}] {}",
            series.first().map_or(0.0, |s| s.0),
            series.last().map_or(0.0, |s| s.0),
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
