//! `[[scene.responses]]` → [`Response`]: the outputs a response sums, the
//! keys of its kind, and its unit.
//!
//! Sums of energies reduced by `integral`, `peak` (the largest value) or
//! `final` keep the energy form (integrals as integrated states, the same
//! numbers as before the other kinds existed); every other response is in
//! the sampled form: `scale · Σ` scalar outputs with sensitivities, of one
//! unit, evaluated at the output times and reduced by
//! `crate::mbs::series`. `frequency` reads a flexible body's basis.
//! Reactions are refused: their derivatives need the sensitivities of the
//! Lagrange multipliers, which the kernel does not compute.

use super::parts::{parse_energy, parse_quantity};
use super::quantity::{Columns, QuantityKind, Response, ScalarOutput, Subject};
use super::spec::ResponseSpec;
use crate::error::{Error, Result};
use crate::mbs::model::{Integral, Model};
use crate::mbs::responses::{ResponseKind, ResponseKindName};

/// Build `[[scene.responses]]` against the model (integrals of energies
/// become model states); `times` are the output times.
pub(super) fn build_responses(
    specs: &[ResponseSpec],
    model: &mut Model,
    flex_names: &[&str],
    times: &[f64],
) -> Result<Vec<Response>> {
    let mut out: Vec<Response> = Vec::new();
    for (k, r) in specs.iter().enumerate() {
        let key = format!("responses[{k}]");
        if r.name.is_empty() || out.iter().any(|o| o.name() == r.name) {
            return Err(Error::input(
                format!("{key}.name"),
                &r.name,
                "a unique, non-empty name",
            ));
        }
        if !(r.scale.is_finite() && r.scale != 0.0) {
            return Err(Error::input(
                format!("{key}.scale"),
                r.scale,
                "a finite, nonzero factor (0 makes the response identically 0)",
            ));
        }
        if r.of.is_empty() {
            return Err(Error::input(
                format!("{key}.of"),
                "[]",
                "at least one output",
            ));
        }
        let kind = kind_of(&key, r, times, model)?;
        let mut resp = Response {
            name: r.name.clone(),
            kind,
            terms: Vec::new(),
            scale: r.scale,
            integral: None,
            outputs: Vec::new(),
            unit: String::new(),
        };
        if let ResponseKind::Frequency { .. } = kind {
            resp.unit = kind.unit_of("");
            out.push(resp);
            continue;
        }
        let energies: Option<Vec<_>> =
            r.of.iter()
                .map(|q| parse_energy(model, flex_names, q))
                .collect();
        match energies {
            Some(terms) if kind.energy_form() => {
                resp.terms = terms.into_iter().flatten().collect();
                resp.unit = kind.unit_of("J");
                if kind == ResponseKind::Integral {
                    model.integrals.push(Integral {
                        terms: resp.terms.clone(),
                        scale: r.scale,
                    });
                    resp.integral = Some(model.integrals.len() - 1);
                }
            }
            _ => {
                let mut unit: Option<&str> = None;
                for (i, q) in r.of.iter().enumerate() {
                    let qkey = format!("{key}.of[{i}]");
                    let s = scalar_output(model, flex_names, &qkey, q)?;
                    let u = s.quantity.kind.info().unit;
                    if unit.is_some_and(|v| v != u) {
                        return Err(Error::input(
                            qkey,
                            q,
                            format!(
                                "an output in {} like the ones before it (a response sums outputs of one unit)",
                                unit.unwrap_or_default()
                            ),
                        ));
                    }
                    unit = Some(u);
                    resp.outputs.push(s);
                }
                resp.unit = kind.unit_of(unit.unwrap_or("-"));
            }
        }
        out.push(resp);
    }
    Ok(out)
}

/// The response's kind with its parameters, from `kind` and the keys that
/// belong to it: `sense` with `peak`, `time` with `value_at` (required,
/// within the output times), `level` (required) and `direction` with
/// `crossing`, `mode` (required; with `of`, one flexible body) with
/// `frequency`. A key of another kind is refused, naming its kind.
fn kind_of(key: &str, r: &ResponseSpec, times: &[f64], model: &Model) -> Result<ResponseKind> {
    check_kind_keys(key, r, times)?;
    // The required keys are present here (checked above).
    Ok(match r.kind {
        ResponseKindName::Integral => ResponseKind::Integral,
        ResponseKindName::Peak => ResponseKind::Peak {
            sense: r.sense.unwrap_or_default(),
        },
        ResponseKindName::Final => ResponseKind::Final,
        ResponseKindName::ValueAt => ResponseKind::ValueAt {
            time: r.time.unwrap_or(0.0),
        },
        ResponseKindName::Crossing => ResponseKind::Crossing {
            level: r.level.unwrap_or(0.0),
            direction: r.direction.unwrap_or_default(),
        },
        ResponseKindName::Frequency => {
            let (body, mode) = frequency_mode(key, r, model)?;
            ResponseKind::Frequency { body, mode }
        }
    })
}

/// The keys that belong to each kind ([`kind_of`]): a stray key, or a
/// missing or out-of-range required one, is an input error.
fn check_kind_keys(key: &str, r: &ResponseSpec, times: &[f64]) -> Result<()> {
    let kind = r.kind;
    let stray = |k: &str, v: String, owner: &str| {
        Error::input(
            format!("{key}.{k}"),
            v,
            format!("no `{k}` for kind = \"{kind}\" (it belongs to kind = \"{owner}\")"),
        )
    };
    if r.sense.is_some() && kind != ResponseKindName::Peak {
        return Err(stray("sense", format!("{:?}", r.sense), "peak"));
    }
    if r.direction.is_some() && kind != ResponseKindName::Crossing {
        return Err(stray("direction", format!("{:?}", r.direction), "crossing"));
    }
    match (kind, r.time) {
        (ResponseKindName::ValueAt, None) => {
            return Err(Error::input(
                format!("{key}.time"),
                "(missing)",
                "the time (s) of a value_at response",
            ))
        }
        (ResponseKindName::ValueAt, Some(t)) => {
            let (a, b) = (
                times.first().copied().unwrap_or(0.0),
                times.last().copied().unwrap_or(0.0),
            );
            if !(t >= a && t <= b) {
                return Err(Error::input(
                    format!("{key}.time"),
                    t,
                    format!("a time within the run's output times [{a}, {b}] s"),
                ));
            }
        }
        (_, Some(t)) => return Err(stray("time", t.to_string(), "value_at")),
        _ => {}
    }
    match (kind, r.level) {
        (ResponseKindName::Crossing, None) => {
            return Err(Error::input(
                format!("{key}.level"),
                "(missing)",
                "the level crossed, in the unit of the outputs",
            ))
        }
        (ResponseKindName::Crossing, Some(l)) if !l.is_finite() => {
            return Err(Error::input(format!("{key}.level"), l, "a finite level"))
        }
        (ResponseKindName::Crossing, _) => {}
        (_, Some(l)) => return Err(stray("level", l.to_string(), "crossing")),
        _ => {}
    }
    match (kind, r.mode) {
        (ResponseKindName::Frequency, None) => Err(Error::input(
            format!("{key}.mode"),
            "(missing)",
            "the mode (1 = lowest) of a frequency response",
        )),
        (ResponseKindName::Frequency, _) | (_, None) => Ok(()),
        (_, Some(m)) => Err(stray("mode", m.to_string(), "frequency")),
    }
}

/// The body and 0-based mode of a `frequency` response: `of` is one
/// flexible body of the built model, `mode` within its basis.
fn frequency_mode(key: &str, r: &ResponseSpec, model: &Model) -> Result<(usize, usize)> {
    let flexible: Vec<&str> = model
        .bodies
        .iter()
        .filter(|b| b.flex.is_some())
        .map(|b| b.name.as_str())
        .collect();
    let body = match r.of.as_slice() {
        [b] => model.body(b).filter(|&i| model.bodies[i].flex.is_some()),
        _ => None,
    };
    let Some(b) = body else {
        return Err(Error::input(
            format!("{key}.of"),
            format!("{:?}", r.of),
            format!(
                "one flexible body of a scene with the flexibility effect ({})",
                if flexible.is_empty() {
                    "none here".to_string()
                } else {
                    flexible.join(", ")
                }
            ),
        ));
    };
    let n = model.bodies[b].flex.as_ref().map_or(0, |f| f.n());
    match r.mode {
        Some(m) if (1..=n).contains(&m) => Ok((b, m - 1)),
        m => Err(Error::input(
            format!("{key}.mode"),
            format!("{m:?}"),
            format!("a mode from 1 to {n} (the modes of {}'s basis)", r.of[0]),
        )),
    }
}

/// An output name of a sampled response → [`ScalarOutput`]: a one-column
/// output with sensitivities, or `<name>.<kind>_x|y|z` of a three-column
/// one. Reactions, `energy`, `violation` and modal coordinates are
/// refused with what is accepted.
fn scalar_output(model: &Model, flex_names: &[&str], key: &str, q: &str) -> Result<ScalarOutput> {
    const ACCEPTED: &str = "a scalar output with sensitivities: <joint>.angle, <joint>.rate, \
         <joint>.displacement, <joint>.velocity, <body>.position_x|y|z, \
         <marker>.deflection_x|y|z, <body>.strain_energy, <body>.kinetic_energy, kinetic_energy";
    let (head, what) = q.rsplit_once('.').unwrap_or(("", q));
    if what == "reaction" || what.starts_with("force_") || what.starts_with("torque_") {
        return Err(Error::input(
            key,
            q,
            format!(
                "{ACCEPTED} (joint reactions have no sensitivities: their derivatives need \
                 those of the Lagrange multipliers, which are not computed; list \
                 {head}.reaction in [scene.outputs] to see them)"
            ),
        ));
    }
    let (name, component) = match what.rsplit_once('_') {
        Some((base, c @ ("x" | "y" | "z")))
            if QuantityKind::find(base, true).is_some_and(|k| k.info().columns == Columns::Xyz) =>
        {
            (
                format!("{head}.{base}"),
                ["x", "y", "z"].iter().position(|a| *a == c),
            )
        }
        _ => (q.to_string(), None),
    };
    let quantity = parse_quantity(model, flex_names, key, &name)
        .map_err(|_| Error::input(key, q, ACCEPTED))?;
    let info = quantity.kind.info();
    let ok = info.sensitivity
        && match info.columns {
            Columns::One => component.is_none(),
            Columns::Xyz => component.is_some(),
            _ => false,
        };
    if !ok || (info.subject == Subject::Scene && quantity.kind != QuantityKind::TotalKineticEnergy)
    {
        return Err(Error::input(key, q, ACCEPTED));
    }
    Ok(ScalarOutput {
        quantity,
        component: component.unwrap_or(0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::responses::{Direction, Sense};

    #[test]
    fn response_units_follow_the_output_and_the_kind() {
        let peak = ResponseKind::Peak { sense: Sense::Min };
        let crossing = ResponseKind::Crossing {
            level: 0.5,
            direction: Direction::Up,
        };
        let frequency = ResponseKind::Frequency { body: 1, mode: 0 };
        assert_eq!(ResponseKind::Integral.unit_of("rad"), "rad*s");
        assert_eq!(peak.unit_of("m"), "m");
        assert_eq!(crossing.unit_of("rad"), "s");
        assert_eq!(frequency.unit_of(""), "Hz");
        assert_eq!(ResponseKind::ValueAt { time: 0.1 }.unit_of("m"), "m");
        // The energy form keeps the units it had.
        assert_eq!(
            ResponseKind::Integral.unit_of("J"),
            ResponseKind::Integral.unit()
        );
        assert_eq!(Direction::default(), Direction::Either);
    }
}
