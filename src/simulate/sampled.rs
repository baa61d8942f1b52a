//! A response at one state, and frequency responses.
//!
//! A response in the sampled form `scale · Σ y_i` over scalar outputs
//! ([`crate::scene::ScalarOutput`]) is evaluated at a state with its
//! derivative along each sensitivity lane `(∂y/∂p, p)`: one dual-number
//! evaluation of each output at `y + ε ∂y/∂p` with the design seed of `p`
//! (so `dX/dθ` and `dΛ/dθ` enter explicitly), as the columns of
//! `sensitivities.csv`; one in the energy form is the sum of its energies
//! with their lanes ([`crate::mbs::responses::energy_lanes`])
//! ([`response_lanes`]). Joint angles are unwrapped as in `history.csv`.
//! The responses over time are read on the continuous solution with it
//! (`super::continuous`).
//!
//! A frequency response is `f_k = scale · √λ_k / (2π)` of a flexible
//! body's basis, with `df_k/dp = scale · (dλ_k/dp) / (4π √λ_k)` for a
//! lane `p` that seeds one of the body's design variables (the basis's
//! eigenvalue derivatives, `crate::modal::derivatives`, repeated
//! eigenvalues included), zero for every other lane: it needs no
//! integration.

use crate::error::{Error, Result};
use crate::mbs::responses::{energy_lanes, ResponseKind, ResponseValue};
use crate::mbs::{Energy, Param, System, Workspace};
use crate::scene::{QuantityKind, Response, ScalarOutput, Scene};
use num_dual::Dual64;

/// One scalar output at the dual state `yd` with the parameter seeds.
fn eval(sys: &System, out: &ScalarOutput, yd: &[Dual64], seeds: &[(Param, Dual64)]) -> Dual64 {
    let (i, c) = (out.quantity.of, out.component);
    let mut kin = Vec::new();
    sys.body_kin(yd, seeds, &mut kin);
    let kinetic = |terms: Vec<Energy>| {
        let mut ws = Workspace::empty();
        ws.params = seeds.to_vec();
        sys.energy_sum(&terms, yd, &mut ws)
    };
    match out.quantity.kind {
        QuantityKind::Angle => sys.joint_angle(&kin, i).0,
        QuantityKind::Rate => sys.joint_angle(&kin, i).1,
        QuantityKind::Displacement => sys.joint_slide(&kin, i).0,
        QuantityKind::Velocity => sys.joint_slide(&kin, i).1,
        QuantityKind::Position => match sys.slot[i] {
            Some(k) => yd[sys.pos_off(k) + c],
            None => Dual64::from(sys.model.bodies[i].r0[c]),
        },
        QuantityKind::StrainEnergy => match sys.slot[i] {
            Some(k) => sys.strain_energy_dual(yd, k, &kin[k].design),
            None => Dual64::from(0.0),
        },
        QuantityKind::KineticEnergy => kinetic(vec![Energy::Kinetic(i)]),
        QuantityKind::TotalKineticEnergy => kinetic(Energy::kinetic_total(&sys.model)),
        QuantityKind::Deflection => sys.deflection_kin(&kin, i)[c],
        // Refused in a response when the scene is built
        // (`scene::responses`).
        QuantityKind::Reaction
        | QuantityKind::Modal
        | QuantityKind::Energy
        | QuantityKind::Violation => Dual64::from(f64::NAN),
    }
}

/// The value of one output at `y` and its derivative along each lane.
fn output_lanes(
    sys: &System,
    out: &ScalarOutput,
    y: &[f64],
    lanes: &[(&[f64], Param)],
) -> (f64, Vec<f64>) {
    let y0: Vec<Dual64> = y.iter().map(|&a| Dual64::from(a)).collect();
    let value = eval(sys, out, &y0, &[]).re;
    let grad = lanes
        .iter()
        .map(|(lane, p)| {
            let yd: Vec<Dual64> = y
                .iter()
                .zip(*lane)
                .map(|(&a, &b)| Dual64::new(a, b))
                .collect();
            let seed = (*p, Dual64::new(p.value(&sys.model).unwrap_or(0.0), 1.0));
            eval(sys, out, &yd, &[seed]).eps
        })
        .collect();
    (value, grad)
}

/// The sensitivity lanes `(∂y/∂p_i, p_i)` of the lane-major `s` (state
/// length `n`); none when `s` is empty.
pub fn lanes_of<'a>(params: &[(String, Param)], s: &'a [f64], n: usize) -> Vec<(&'a [f64], Param)> {
    if s.is_empty() {
        return Vec::new();
    }
    params
        .iter()
        .enumerate()
        .map(|(i, (_, p))| (&s[i * n..(i + 1) * n], *p))
        .collect()
}

/// Response `r` at state `y` with its derivative along each lane: the
/// sum of its energies (the energy form, [`energy_lanes`]) or `scale ·
/// Σ y_i` of its outputs, each joint angle unwrapped against its last
/// value in `unwrap` (which it updates).
pub fn response_lanes(
    sys: &System,
    r: &Response,
    y: &[f64],
    lanes: &[(&[f64], Param)],
    unwrap: &mut [Option<f64>],
) -> (f64, Vec<f64>) {
    if r.outputs.is_empty() {
        return energy_lanes(sys, (&r.terms, r.scale), y, lanes);
    }
    let turn = 2.0 * std::f64::consts::PI;
    let mut value = 0.0;
    let mut grad = vec![0.0; lanes.len()];
    for (out, prev) in r.outputs.iter().zip(unwrap.iter_mut()) {
        let (mut v, g) = output_lanes(sys, out, y, lanes);
        if out.quantity.kind == QuantityKind::Angle {
            if let Some(p) = *prev {
                v += turn * ((p - v) / turn).round();
            }
        }
        *prev = Some(v);
        value += v;
        for (a, b) in grad.iter_mut().zip(&g) {
            *a += b;
        }
    }
    let s = r.scale;
    (s * value, grad.iter().map(|g| s * g).collect())
}

/// A frequency response of the built model (module doc): mode `j`
/// (0-based) of body `b`, with its derivative along each sensitivity
/// parameter.
pub fn frequency(
    sys: &System,
    r: &Response,
    (b, j): (usize, usize),
    params: &[Param],
) -> Result<ResponseValue> {
    let fail = |detail: String| {
        Error::numerical(
            "simulate: responses",
            format!("response {}: {detail}", r.name),
        )
    };
    let flex = sys.model.bodies[b]
        .flex
        .as_ref()
        .ok_or_else(|| fail("the body has no modal basis".into()))?;
    let lambda = flex.basis.eigenvalues[j];
    if !(lambda > 0.0 && lambda.is_finite()) {
        return Err(fail(format!(
            "eigenvalue {lambda:e} 1/s² of mode {} is not positive",
            j + 1
        )));
    }
    let two_pi = 2.0 * std::f64::consts::PI;
    let value = r.scale * lambda.sqrt() / two_pi;
    let gradient = params
        .iter()
        .map(|p| match p.design_of(&sys.model, b) {
            Some(k) => {
                let dl = flex.dinv.get(k).map_or(0.0, |d| d.lambda[j]);
                r.scale * dl / (2.0 * two_pi * lambda.sqrt())
            }
            None => 0.0,
        })
        .collect();
    Ok(ResponseValue {
        name: r.name.clone(),
        kind: r.kind,
        value,
        unit: r.unit.clone(),
        time: None,
        gradient,
        critical: Vec::new(),
    })
}

/// The frequency responses of a built scene, without integrating it
/// (the other responses are left out).
pub fn frequencies(scene: &Scene) -> Result<Vec<ResponseValue>> {
    let sys = System::new(scene.model.clone());
    let params: Vec<Param> = scene.params.iter().map(|(_, p)| *p).collect();
    scene
        .responses
        .iter()
        .filter_map(|r| match r.kind {
            ResponseKind::Frequency { body, mode } => {
                Some(frequency(&sys, r, (body, mode), &params))
            }
            _ => None,
        })
        .collect()
}
