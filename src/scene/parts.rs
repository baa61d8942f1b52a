//! Pieces of the scene builder ([`super::build`]): names to parameters
//! and outputs, markers (snapped to flexible nodes), load tables and
//! flexible bodies.

use super::quantity::{Columns, Quantity, QuantityKind, Subject};
use super::spec::{FlexKind, FlexSpec, ForceSpec};
use crate::beams::Beam;
use crate::error::{Error, Result};
use crate::mbs::math::euler_from_rotation;
use crate::mbs::model::ModalBasis;
use crate::mbs::model::{Body, Flex, Force, Marker, Model, Param};
use crate::mbs::Energy;
use crate::modal::ModeUpdate;
use nalgebra::{Matrix3, Vector3};

/// Builds the modal basis of a `kind = "panel"` body: `(panel name,
/// modes, derivatives, geometric)` → basis, with the modal geometric
/// stiffness of the inertial load cases when `geometric` is given (the
/// scene's `geometric_stiffening`) and the point-force cases at the
/// panel-frame joint points it lists; errors name the study's keys.
/// `modes = 0` asks for the basis of a body at rest (the `ground`
/// module): nodes and lumped masses, no eigen-analysis.
pub type PanelBases<'a> =
    &'a dyn Fn(&str, usize, Option<ModeUpdate>, Stiffening) -> Result<ModalBasis>;

/// The geometric stiffening a panel basis is built with: `None` (none),
/// or the inertial cases and the point cases at these panel-frame joint
/// points (m).
pub type Stiffening<'a> = Option<&'a [Vector3<f64>]>;

fn vec3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

pub(crate) fn finite3(key: String, a: [f64; 3]) -> Result<Vector3<f64>> {
    if a.iter().all(|v| v.is_finite()) {
        Ok(vec3(a))
    } else {
        Err(Error::input(key, format!("{a:?}"), "finite components"))
    }
}

/// The kinds of sensitivity parameter, by the last part of their dotted
/// name: `<body>.mass`, `<force>.stiffness`, `<force>.damping`,
/// `<body>.design.<variable>`, `forces[i].segments[k].anchor`,
/// `forces[i].segments[k].slope`. The one
/// table of these names: [`parse_param`] and its message follow from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum ParamKind {
    /// Mass of a rigid body (kg).
    Mass,
    /// Stiffness of a spring (N/m or N·m/rad).
    Stiffness,
    /// Damping of a spring or an actuator (N·s/m or N·m·s/rad).
    Damping,
    /// A ply-angle design variable of a flexible panel body (rad).
    Design,
    /// Anchor of a segment of an actuator's law.
    Anchor,
    /// Slope of a segment of an actuator's law (N·m/rad).
    Slope,
}

impl ParamKind {
    /// Every kind.
    const ALL: [ParamKind; 6] = [
        ParamKind::Mass,
        ParamKind::Stiffness,
        ParamKind::Damping,
        ParamKind::Design,
        ParamKind::Anchor,
        ParamKind::Slope,
    ];

    /// The name part as written in study files, and the forms it is
    /// written in (for messages).
    fn info(self) -> (&'static str, &'static str) {
        match self {
            ParamKind::Mass => ("mass", "<body>.mass (rigid body)"),
            ParamKind::Stiffness => ("stiffness", "<force name>.stiffness, forces[i].stiffness"),
            ParamKind::Damping => ("damping", "<force name>.damping, forces[i].damping"),
            ParamKind::Design => ("design", "<body>.design.<variable> (flexible body)"),
            ParamKind::Anchor => ("anchor", "forces[i].segments[k].anchor"),
            ParamKind::Slope => ("slope", "forces[i].segments[k].slope"),
        }
    }

    /// The kind written `name`.
    fn find(name: &str) -> Option<ParamKind> {
        ParamKind::ALL.into_iter().find(|k| k.info().0 == name)
    }

    /// The accepted parameter names, for messages.
    pub(super) fn accepted() -> String {
        let forms: Vec<&str> = ParamKind::ALL.iter().map(|k| k.info().1).collect();
        forms.join(", ")
    }
}

/// A sensitivity parameter name → [`Param`], if it names an existing,
/// built model value.
/// Segment indices are those of the scene file; the model's law is sorted
/// by `lower`, so they are translated through the segment bounds.
pub(super) fn parse_param(
    model: &Model,
    forces: &[ForceSpec],
    force_index: &[Option<usize>],
    name: &str,
) -> Option<Param> {
    let (head, last) = name.rsplit_once('.')?;
    let spring = |kind: ParamKind, fi: usize| match kind {
        ParamKind::Stiffness => Some(Param::Stiffness(fi)),
        ParamKind::Damping => Some(Param::Damping(fi)),
        _ => None,
    };
    match ParamKind::find(last) {
        Some(ParamKind::Mass) => {
            let b = model.body(head)?;
            return model.bodies[b].flex.is_none().then_some(Param::Mass(b));
        }
        Some(kind @ (ParamKind::Stiffness | ParamKind::Damping)) => {
            if let Some(k) = forces.iter().position(|f| f.name() == Some(head)) {
                let p = spring(kind, (*force_index.get(k)?)?)?;
                return p.value(model).map(|_| p);
            }
        }
        _ => {}
    }
    let design = format!(".{}.", ParamKind::Design.info().0);
    if let Some((body, var)) = name.split_once(design.as_str()) {
        let b = model.body(body)?;
        let flex = model.bodies[b].flex.as_ref()?;
        let k = flex.basis.derivatives.iter().position(|d| d.name == var)?;
        return Some(Param::Design(b, k));
    }
    let rest = name.strip_prefix("forces[")?;
    let (idx, rest) = rest.split_once(']')?;
    let k_spec = idx.parse::<usize>().ok()?;
    let fi = (*force_index.get(k_spec)?)?;
    let p = match rest.strip_prefix('.').and_then(ParamKind::find) {
        Some(kind @ (ParamKind::Stiffness | ParamKind::Damping)) => spring(kind, fi)?,
        _ => {
            let (seg, kind) = rest.strip_prefix(".segments[")?.rsplit_once("].")?;
            let kind = ParamKind::find(kind)?;
            if !matches!(kind, ParamKind::Anchor | ParamKind::Slope) {
                return None;
            }
            let seg: usize = seg.parse().ok()?;
            let ForceSpec::Actuator { segments, .. } = forces.get(k_spec)? else {
                return None;
            };
            let spec = segments.get(seg)?;
            let Force::Rotational { law: Some(law), .. } = &model.forces[fi] else {
                return None;
            };
            let sorted = law
                .segments
                .iter()
                .position(|s| s.lower == spec.lower && s.upper == spec.upper)?;
            if kind == ParamKind::Slope {
                Param::Slope(fi, sorted)
            } else {
                Param::Anchor(fi, sorted)
            }
        }
    };
    p.value(model).map(|_| p)
}

/// An output name → [`Quantity`], by the table of [`QuantityKind`]. Bodies
/// named in `flex_names` have a `flexible` table: their modal outputs stay
/// valid when the scene runs them rigid (no columns for `modal`, zero
/// strain energy and deflection).
pub(super) fn parse_quantity(
    model: &Model,
    flex_names: &[&str],
    key: &str,
    q: &str,
) -> Result<Quantity> {
    if let Some(kind) = QuantityKind::find(q, false) {
        return Ok(Quantity::new(kind, 0));
    }
    let bad = || Error::input(key, q, QuantityKind::accepted());
    let (name, what) = q.rsplit_once('.').ok_or_else(bad)?;
    let kind = QuantityKind::find(what, true).ok_or_else(bad)?;
    let mut out = Quantity::new(kind, 0);
    out.of = match kind.info().subject {
        Subject::Scene => return Err(bad()),
        subject @ (Subject::AngleJoint | Subject::SlideJoint | Subject::Joint) => {
            let j = model.joint(name).ok_or_else(bad)?;
            let joint = &model.joints[j].kind;
            if subject == Subject::SlideJoint && !joint.has_slide() {
                return Err(Error::input(
                    key,
                    q,
                    "a displacement or velocity of a prismatic or cylindrical joint",
                ));
            }
            if subject == Subject::AngleJoint && !joint.has_angle() {
                return Err(Error::input(
                    key,
                    q,
                    "an angle or rate of a revolute, locked or driven joint",
                ));
            }
            j
        }
        Subject::Body => model.body(name).ok_or_else(bad)?,
        Subject::FlexBody => {
            let b = model.body(name).ok_or_else(bad)?;
            let n = match &model.bodies[b].flex {
                Some(f) => f.n(),
                None if flex_names.contains(&name) => 0,
                None => return Err(bad()),
            };
            if kind.info().columns == Columns::Modes {
                out.modes = n;
            }
            b
        }
        Subject::FlexMarker => {
            let m = model.marker(name).ok_or_else(bad)?;
            let on_flex = model.markers[m]
                .body
                .is_some_and(|b| flex_names.contains(&model.bodies[b].name.as_str()));
            if model.markers[m].node.is_none() && !on_flex {
                return Err(bad());
            }
            m
        }
    };
    Ok(out)
}

/// An energy name → its terms, by the table of [`QuantityKind`]:
/// `kinetic_energy` (every moving body), `<body>.kinetic_energy`, or
/// `<body>.strain_energy` of a body named in `flex_names` (a `flexible`
/// table; zero when the scene runs it rigid).
pub(super) fn parse_energy(model: &Model, flex_names: &[&str], q: &str) -> Option<Vec<Energy>> {
    if QuantityKind::find(q, false) == Some(QuantityKind::TotalKineticEnergy) {
        return Some(Energy::kinetic_total(model));
    }
    let (b, what) = q.rsplit_once('.')?;
    match QuantityKind::find(what, true)? {
        QuantityKind::KineticEnergy => Some(vec![Energy::Kinetic(model.body(b)?)]),
        QuantityKind::StrainEnergy if flex_names.contains(&b) => {
            Some(vec![Energy::Strain(model.body(b)?)])
        }
        _ => None,
    }
}

/// A marker `(name, body)` at the global point `p` with global frame
/// `frame`, expressed in the body's initial frame. On a flexible body the
/// point must be a node of its basis (within 1e-6 of the body's size);
/// `key` names the point in errors.
pub(super) fn make_marker(
    model: &Model,
    key: &str,
    named: (&str, Option<usize>),
    p: Vector3<f64>,
    frame: Matrix3<f64>,
) -> Result<Marker> {
    let (name, body) = named;
    let Some(b) = body else {
        return Ok(Marker {
            name: name.to_string(),
            body,
            pos: p,
            frame,
            node: None,
        });
    };
    let bd = &model.bodies[b];
    let a0 = bd.orientation();
    let local = a0.transpose() * (p - bd.r0);
    let mut marker = Marker {
        name: name.to_string(),
        body,
        pos: local,
        frame: a0.transpose() * frame,
        node: None,
    };
    if let Some(flex) = &bd.flex {
        let (k, dist) = flex.basis.nearest_node(&local);
        let size = flex
            .basis
            .nodes
            .iter()
            .fold(0.0f64, |m, s| m.max(s.norm()))
            .max(1e-3);
        if dist > 1e-6 * size {
            return Err(Error::input(
                key,
                format!("{:?}", p.as_slice()),
                format!(
                    "a node of flexible body '{}' (nearest node {k} is {dist:.3e} m away)",
                    bd.name
                ),
            ));
        }
        marker.pos = flex.basis.nodes[k];
        marker.node = Some(k);
    }
    Ok(marker)
}

/// Validate a load table: rows `[t, fx, fy, fz, tx, ty, tz]`, finite,
/// strictly increasing times.
pub(super) fn load_table(key: &str, rows: &[[f64; 7]]) -> Result<Vec<(f64, [f64; 6])>> {
    if rows.is_empty() {
        return Err(Error::input(
            key,
            "[]",
            "at least one row [t, fx, fy, fz, tx, ty, tz]",
        ));
    }
    let mut out: Vec<(f64, [f64; 6])> = Vec::with_capacity(rows.len());
    for (k, r) in rows.iter().enumerate() {
        let increasing = out.last().is_none_or(|(t, _)| r[0] > *t);
        if r.iter().any(|v| !v.is_finite()) || !increasing {
            return Err(Error::input(
                format!("{key}[{k}]"),
                format!("{r:?}"),
                "finite rows [t (s), fx, fy, fz (N), tx, ty, tz (N·m)] with increasing t",
            ));
        }
        let mut v = [0.0; 6];
        v.copy_from_slice(&r[1..]);
        out.push((r[0], v));
    }
    Ok(out)
}

/// A flexible body from its `flexible` table: basis, invariants, frame
/// placement; `geometric`: panel bases with their geometric stiffness,
/// and the point-force cases of the joint-load prestress at the nodes of
/// the global points `joints` (the body's joint points).
pub(super) fn flexible_body(
    key: &str,
    name: &str,
    f: &FlexSpec,
    (damping, geometric): (bool, bool),
    joints: &[Vector3<f64>],
    (panels, rest): (PanelBases, bool),
) -> Result<Body> {
    let fk = format!("{key}.flexible");
    if f.modes == 0 {
        return Err(Error::input(format!("{fk}.modes"), 0, "at least one mode"));
    }
    if !(f.damping.is_finite() && (0.0..1.0).contains(&f.damping)) {
        return Err(Error::input(
            format!("{fk}.damping"),
            f.damping,
            "a modal damping ratio in [0, 1)",
        ));
    }
    let origin = finite3(format!("{fk}.origin"), f.origin)?;
    let x = finite3(format!("{fk}.x_axis"), f.x_axis)?;
    let y = finite3(format!("{fk}.y_axis"), f.y_axis)?;
    if x.norm() < 1e-12
        || (y - x * (x.dot(&y) / x.norm_squared())).norm() < 1e-9 * y.norm().max(1e-300)
    {
        return Err(Error::input(
            format!("{fk}.y_axis"),
            format!("{:?} with x_axis {:?}", f.y_axis, f.x_axis),
            "non-zero, non-parallel x and y axis directions",
        ));
    }
    let ex = x.normalize();
    let ey = (y - ex * ex.dot(&y)).normalize();
    let a0 = Matrix3::from_columns(&[ex, ey, ex.cross(&ey)]);
    // The joint points in the body frame: their nodes get the point-force
    // cases of the joint-load prestress (geometric stiffening only).
    let local: Vec<Vector3<f64>> = if geometric {
        joints
            .iter()
            .map(|p| a0.transpose() * (p - origin))
            .collect()
    } else {
        Vec::new()
    };
    let basis = match f.kind {
        FlexKind::Beam => beam_basis(&fk, f, &local)?,
        FlexKind::Panel => {
            let panel = f.panel.as_deref().ok_or_else(|| {
                Error::input(
                    format!("{fk}.panel"),
                    "(missing)",
                    "the name of a [[panels]] entry",
                )
            })?;
            let limit = f
                .rigid_limit
                .unwrap_or(crate::panels::basis::RIGID_CONTENT_LIMIT);
            if !(limit > 0.0 && limit <= 1.0) {
                return Err(Error::input(
                    format!("{fk}.rigid_limit"),
                    limit,
                    "a rigid-body content share in (0, 1] (1 keeps every mode)",
                ));
            }
            // A body at rest (`ground` module) takes a basis without
            // modes: its nodes and masses, no eigen-analysis.
            let (modes, geometric) = if rest {
                (0, false)
            } else {
                (f.modes, geometric)
            };
            panels(panel, modes, f.derivatives, geometric.then_some(&local[..]))
                .map_err(|e| match e {
                    // The mode count is this body's key, not the panel's.
                    Error::Input { key, expected, .. } if key.ends_with("n_modes") => {
                        Error::input(format!("{fk}.modes"), f.modes, expected)
                    }
                    e => e,
                })?
                .screened(limit)?
        }
    };
    basis.validate(&fk)?;
    let design = vec![0.0; basis.derivatives.len()];
    let flex = Flex::new(basis, if damping { f.damping } else { 0.0 }, design);
    let inv = &flex.inv;
    let c = inv.s0 / inv.mass;
    // Inertia about the centre of mass (frame axes), for reports.
    let j_o = Matrix3::identity() * inv.e0.trace() - inv.e0 + inv.j_rot;
    let j_c = j_o - (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * inv.mass;
    let inv_inertia = j_c.try_inverse().unwrap_or_else(Matrix3::zeros);
    Ok(Body {
        name: name.to_string(),
        mass: inv.mass,
        inertia: j_c,
        inv_inertia,
        r0: origin,
        p0: euler_from_rotation(&a0),
        v0: Vector3::zeros(),
        w0: Vector3::zeros(),
        fixed: false,
        flex: Some(flex),
    })
}

/// The closed-form cantilever basis of a `kind = "beam"` body (`fk` is
/// the key of its `flexible` table), with the rotary inertia about the
/// beam axis lumped like the mass, and the point-force cases
/// ([`Beam::point_cases`]) at the nodes of the body-frame points `joints`
/// (points that are no node are left to the marker's own check).
fn beam_basis(fk: &str, f: &FlexSpec, joints: &[Vector3<f64>]) -> Result<ModalBasis> {
    let get = |what: &str, v: Option<f64>| {
        v.ok_or_else(|| Error::input(format!("{fk}.{what}"), "(missing)", "a beam property"))
    };
    let beam = Beam {
        length: get("length", f.length)?,
        ei_y: get("ei_y", f.ei_y)?,
        ei_z: get("ei_z", f.ei_z)?,
        rho_a: get("rho_a", f.rho_a)?,
    };
    beam.validate(fk)?;
    use crate::study::memory;
    memory::require_fits(
        &format!("{fk}.modes"),
        f.modes,
        &format!("a closed-form beam with {} modes per plane", f.modes),
        memory::beam_bytes(f.modes),
        memory::available_bytes(),
    )?;
    let rho_ip = f.rho_ip.unwrap_or(0.0);
    if !(rho_ip.is_finite() && rho_ip > 0.0) {
        return Err(Error::input(
            format!("{fk}.rho_ip"),
            rho_ip,
            "a polar mass moment per length > 0 (kg·m): the frame needs a rotary inertia about the beam axis",
        ));
    }
    let segments = Beam::segments_for(f.modes);
    let mut b = beam.basis(f.modes, segments)?.truncated(f.modes);
    let nodes = joint_nodes(&b, joints);
    if let Some(g) = b.geometric.as_mut() {
        if !nodes.is_empty() {
            let order: Vec<_> = beam
                .mode_order(f.modes)
                .into_iter()
                .take(b.n_modes)
                .collect();
            let cases: Vec<f64> = nodes
                .iter()
                .flat_map(|&k| beam.point_cases(&order, segments, b.nodes[k].x))
                .collect();
            g.add_points(&nodes, &cases, &[]);
        }
    }
    // Rotary inertia about the beam axis, lumped like the mass.
    for (k, m) in b.node_mass.iter().enumerate() {
        b.node_inertia[k].x = rho_ip * m / beam.rho_a;
    }
    Ok(b)
}

/// The distinct nodes of `basis` at the body-frame points `points`
/// (within `1e-6` of the body's size, the rule of [`make_marker`]), in
/// the order first met.
pub(crate) fn joint_nodes(basis: &ModalBasis, points: &[Vector3<f64>]) -> Vec<usize> {
    let size = basis
        .nodes
        .iter()
        .fold(0.0f64, |m, s| m.max(s.norm()))
        .max(1e-3);
    let mut out = Vec::new();
    for p in points {
        let (k, dist) = basis.nearest_node(p);
        if dist <= 1e-6 * size && !out.contains(&k) {
            out.push(k);
        }
    }
    out
}

pub(super) fn initial_distance(model: &Model, i: usize, j: usize) -> f64 {
    let g = |m: &Marker| match m.body {
        Some(b) => model.bodies[b].r0 + model.bodies[b].orientation() * m.pos,
        None => m.pos,
    };
    (g(&model.markers[j]) - g(&model.markers[i])).norm()
}
