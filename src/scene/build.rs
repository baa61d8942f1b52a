//! `[scene]` data → [`Scene`]: bodies (rigid, or flexible with a modal
//! basis), markers, joints, forces, integrator options, outputs,
//! responses and sensitivity parameters, in that order; each step names
//! the key below `scene` in its errors.

use super::parts::{
    finite3, flexible_body, make_marker, parse_param, parse_quantity, PanelBases, ParamKind,
};
use super::quantity::{Columns, Quantity, Response};
use super::responses::build_responses;
use super::spec::{DriveSpec, Effect, JointSpec, JointType, SceneSpec};
use crate::error::{Error, Result};
use crate::integrate::{Options, SensitivityForm};
use crate::mbs::math::{axis_angle, frame_from_axis};
use crate::mbs::model::{Body, Drive, Harmonic, Joint, JointKind, Model, Param, Piece};
use nalgebra::{Matrix3, Vector3};

/// A built scene: the system model, integrator options and outputs.
#[derive(Debug)]
pub struct Scene {
    /// The multibody model.
    pub model: Model,
    /// Integrator options (method, tolerances, output times, events).
    pub options: Options,
    /// Output columns: the name as written and what it is.
    pub outputs: Vec<(String, Quantity)>,
    /// The plotted output's name, if any.
    pub plot: Option<String>,
    /// File stem of the plot (`<plot_file>.svg`).
    pub plot_file: Option<String>,
    /// The effects the scene switches on.
    pub effects: Vec<Effect>,
    /// Sensitivity parameters with their names from the scene file.
    pub params: Vec<(String, Param)>,
    /// Response functionals.
    pub responses: Vec<Response>,
    /// The model force built from each `[[scene.forces]]` entry (`None`
    /// where the scene's effects build none), to resolve parameter names.
    pub force_index: Vec<Option<usize>>,
}

impl SceneSpec {
    /// Build the model of a scene without panel bodies. Errors name the
    /// key below `scene` (e.g. `joints[2].body_i`); callers attach the
    /// file with `Error::in_file`.
    pub fn build(&self) -> Result<Scene> {
        self.build_with(&|name, _, _, _| {
            Err(Error::input(
                "flexible.panel",
                name,
                "a scene loaded from a study with a [[panels]] section",
            ))
        })
    }

    /// Build the model; `panels` supplies the bases of panel bodies (only
    /// called when the scene lists `flexibility`).
    pub fn build_with(&self, panels: PanelBases) -> Result<Scene> {
        self.check_settings()?;
        let mut model = Model {
            baumgarte: self.baumgarte,
            quadratic_velocity: self.has(Effect::QuadraticVelocity),
            divergence_limit: Some(self.divergence_limit),
            spin_warning_fraction: Some(self.spin_warning_fraction),
            geometric_stiffening: self.has(Effect::GeometricStiffening),
            ..Model::default()
        };
        let (skip, ground) = self.grounded();
        self.add_bodies(&mut model, panels, &ground)?;
        self.add_markers(&mut model)?;
        self.add_joints(&mut model, &skip)?;
        let force_index = self.add_forces(&mut model)?;
        let options = self.options()?;
        let flex_names: Vec<&str> = self
            .bodies
            .iter()
            .filter(|b| b.flexible.is_some())
            .map(|b| b.name.as_str())
            .collect();
        let outputs = self.outputs(&model, &flex_names)?;
        let responses = build_responses(&self.responses, &mut model, &flex_names, &options.times)?;
        let params = self.params(&mut model, &force_index)?;
        Ok(Scene {
            model,
            options,
            outputs,
            plot: self.outputs.plot.clone(),
            plot_file: self.outputs.plot_file.clone(),
            effects: self.effects.clone(),
            params,
            responses,
            force_index,
        })
    }

    /// The model parameter a sensitivity name (`forces[0].damping`,
    /// `B5.mass`, ... as in `[scene] sensitivities`, ply angles excluded)
    /// names in `scene`, built from this spec, whether or not it is a
    /// sensitivity lane; `None` if it names none.
    pub fn param_of(&self, scene: &Scene, name: &str) -> Option<Param> {
        parse_param(&scene.model, &self.forces, &scene.force_index, name).filter(|p| !p.is_design())
    }

    /// Whether the scene lists effect `e`.
    pub(super) fn has(&self, e: Effect) -> bool {
        self.effects.contains(&e)
    }

    /// A valid Baumgarte rate and divergence limit (the effects are
    /// checked by serde).
    fn check_settings(&self) -> Result<()> {
        if !(self.baumgarte >= 0.0 && self.baumgarte.is_finite()) {
            return Err(Error::input(
                "baumgarte",
                self.baumgarte,
                "a finite rate ≥ 0 (1/s)",
            ));
        }
        // NaN is refused too (it is not > 0).
        if self.divergence_limit.is_nan() || self.divergence_limit <= 0.0 {
            return Err(Error::input(
                "divergence_limit",
                self.divergence_limit,
                "a factor > 0 of the body size (inf: no divergence guard)",
            ));
        }
        if self.spin_warning_fraction.is_nan() || self.spin_warning_fraction <= 0.0 {
            return Err(Error::input(
                "spin_warning_fraction",
                self.spin_warning_fraction,
                "a fraction > 0 of the first modal frequency (inf: no warning)",
            ));
        }
        Ok(())
    }

    /// Rigid bodies, and flexible ones (with `flexibility`) whose bases
    /// come from `panels` or the closed-form beam; those marked in
    /// `ground` fixed (`ground` module).
    fn add_bodies(&self, model: &mut Model, panels: PanelBases, ground: &[bool]) -> Result<()> {
        for (k, b) in self.bodies.iter().enumerate() {
            let key = format!("bodies[{k}]");
            if model.body(&b.name).is_some() || b.name == "ground" {
                return Err(Error::input(
                    format!("{key}.name"),
                    &b.name,
                    "a unique body name other than 'ground'",
                ));
            }
            let mut body = match (&b.flexible, self.has(Effect::Flexibility)) {
                (Some(f), true) => {
                    if b.fixed {
                        return Err(Error::input(
                            format!("{key}.fixed"),
                            "true",
                            "a moving body (a fixed body cannot be flexible)",
                        ));
                    }
                    // Joint points on this body (for the joint-load prestress).
                    let joints: Vec<Vector3<f64>> = self
                        .joints
                        .iter()
                        .filter(|j| j.body_i == b.name || j.body_j == b.name)
                        .map(|j| Vector3::from(j.point))
                        .collect();
                    flexible_body(
                        &key,
                        &b.name,
                        f,
                        (
                            self.has(Effect::Damping),
                            self.has(Effect::GeometricStiffening),
                        ),
                        &joints,
                        (panels, ground[k]),
                    )?
                }
                _ => {
                    let need = |what: &str| {
                        Error::input(
                            format!("{key}.{what}"),
                            "(missing)",
                            "mass, com and inertia of a rigid body (or a `flexible` table \
                         with `flexibility` in scene.effects)",
                        )
                    };
                    let mass = b.mass.ok_or_else(|| need("mass"))?;
                    let com = finite3(format!("{key}.com"), b.com.ok_or_else(|| need("com"))?)?;
                    let i = b.inertia.ok_or_else(|| need("inertia"))?;
                    let inertia = Matrix3::from_fn(|r, c| i[r][c]);
                    Body::new(&key, &b.name, mass, inertia, (com, [1.0, 0.0, 0.0, 0.0]))?
                }
            };
            body.fixed = b.fixed || ground[k];
            body.v0 = finite3(format!("{key}.velocity"), b.velocity)?;
            body.w0 = body.orientation().transpose()
                * finite3(format!("{key}.angular_velocity"), b.angular_velocity)?;
            model.bodies.push(body);
        }
        Ok(())
    }

    /// Extra markers (`[[scene.markers]]`).
    fn add_markers(&self, model: &mut Model) -> Result<()> {
        for (k, m) in self.markers.iter().enumerate() {
            let key = format!("markers[{k}]");
            let body = find_body(format!("{key}.body"), &m.body, model)?;
            let p = finite3(format!("{key}.point"), m.point)?;
            let mk = make_marker(
                model,
                &format!("{key}.point"),
                (&m.name, body),
                p,
                Matrix3::identity(),
            )?;
            model.markers.push(mk);
        }
        Ok(())
    }

    /// Joints with their two markers each, but those marked in `skip`
    /// (checked, not built: `ground` module).
    fn add_joints(&self, model: &mut Model, skip: &[bool]) -> Result<()> {
        for (k, j) in self.joints.iter().enumerate() {
            let key = format!("joints[{k}]");
            let bi = find_body(format!("{key}.body_i"), &j.body_i, model)?;
            let bj = find_body(format!("{key}.body_j"), &j.body_j, model)?;
            if bi == bj {
                return Err(Error::input(
                    format!("{key}.body_j"),
                    &j.body_j,
                    "a body other than body_i",
                ));
            }
            let point = finite3(format!("{key}.point"), j.point)?;
            let kind = joint_kind(&key, j)?;
            let axis = joint_axis(&key, j, &kind)?;
            if !j.angle.is_finite() || j.angle.abs() >= std::f64::consts::PI {
                return Err(Error::input(
                    format!("{key}.angle"),
                    j.angle,
                    "an initial angle in (−π, π) rad",
                ));
            }
            let fi = frame_from_axis(&axis);
            let fj = axis_angle(&axis.normalize(), j.angle) * fi;
            let n = model.markers.len();
            let pk = format!("{key}.point");
            let mi = make_marker(model, &pk, (&format!("{}.i", j.name), bi), point, fi)?;
            let mj = make_marker(model, &pk, (&format!("{}.j", j.name), bj), point, fj)?;
            model.markers.push(mi);
            model.markers.push(mj);
            if self.joints[..k].iter().any(|o| o.name == j.name) {
                return Err(Error::input(
                    format!("{key}.name"),
                    &j.name,
                    "a unique joint name",
                ));
            }
            if skip[k] {
                continue;
            }
            model.joints.push(Joint {
                name: j.name.clone(),
                kind,
                i: n,
                j: n + 1,
            });
        }
        Ok(())
    }

    /// Integrator options with the output times `0, dt_out, .., t_end`.
    fn options(&self) -> Result<Options> {
        let it = &self.integrator;
        if !(it.dt_out > 0.0 && it.dt_out.is_finite()) {
            return Err(Error::input(
                "integrator.dt_out",
                it.dt_out,
                "an output interval > 0 (s)",
            ));
        }
        if !(it.t_end > 0.0 && it.t_end.is_finite()) {
            return Err(Error::input(
                "integrator.t_end",
                it.t_end,
                "an end time > 0 (s)",
            ));
        }
        if it.t_end / it.dt_out > 1e7 {
            return Err(Error::input(
                "integrator.dt_out",
                it.dt_out,
                format!(
                    "an output interval of at least t_end / 1e7 = {:e} s (at most 1e7 \
                     rows of history.csv; responses do not depend on it)",
                    it.t_end / 1e7
                ),
            ));
        }
        let nout = (it.t_end / it.dt_out).round().max(1.0) as usize;
        let mut times: Vec<f64> = (0..=nout)
            .map(|k| (k as f64 * it.dt_out).min(it.t_end))
            .collect();
        times.dedup();
        if *times.last().unwrap_or(&0.0) < it.t_end {
            times.push(it.t_end);
        }
        let options = Options {
            method: it.method,
            rtol: it.rtol,
            atol: it.atol,
            t0: 0.0,
            times,
            events: it.events,
            sensitivity: it
                .sensitivity_form
                .unwrap_or(SensitivityForm::default_for(it.method)),
        };
        options.validate()?;
        Ok(options)
    }

    /// Output columns, the plotted output and its file stem.
    fn outputs(&self, model: &Model, flex_names: &[&str]) -> Result<Vec<(String, Quantity)>> {
        let mut outputs = Vec::new();
        for (k, q) in self.outputs.quantities.iter().enumerate() {
            outputs.push((
                q.clone(),
                parse_quantity(model, flex_names, &format!("outputs.quantities[{k}]"), q)?,
            ));
        }
        if let Some(p) = &self.outputs.plot {
            let plotted = parse_quantity(model, flex_names, "outputs.plot", p)?;
            if !self.outputs.quantities.iter().any(|q| q == p) {
                return Err(Error::input(
                    "outputs.plot",
                    p,
                    format!(
                        "one of outputs.quantities ({}): the plot draws a column of history.csv",
                        if self.outputs.quantities.is_empty() {
                            "none listed".to_string()
                        } else {
                            self.outputs.quantities.join(", ")
                        }
                    ),
                ));
            }
            if plotted.kind.info().columns != Columns::One {
                return Err(Error::input(
                    "outputs.plot",
                    p,
                    "a scalar output (angle, rate, displacement, velocity, strain or \
                     kinetic energy, energy, violation)",
                ));
            }
        }
        if let Some(f) = &self.outputs.plot_file {
            if self.outputs.plot.is_none()
                || f.is_empty()
                || f.contains(['/', '\\'])
                || f == "."
                || f == ".."
            {
                return Err(Error::input(
                    "outputs.plot_file",
                    format!("\"{f}\""),
                    "a file name without path separators, together with outputs.plot",
                ));
            }
        }
        Ok(outputs)
    }

    /// Sensitivity parameters by name (`[scene] sensitivities`).
    fn params(
        &self,
        model: &mut Model,
        force_index: &[Option<usize>],
    ) -> Result<Vec<(String, Param)>> {
        let mut params = Vec::new();
        for (k, name) in self.sensitivities.iter().enumerate() {
            let key = format!("sensitivities[{k}]");
            if name.contains('+') {
                let p = tie(model, &key, name)?;
                params.push((name.clone(), p));
                continue;
            }
            let p = parse_param(model, &self.forces, force_index, name).ok_or_else(|| {
                Error::input(
                    &key,
                    name,
                    format!(
                        "{} of a force the effects list builds",
                        ParamKind::accepted()
                    ),
                )
            })?;
            if params.iter().any(|(_, q)| *q == p) {
                return Err(Error::input(key, name, "each parameter once"));
            }
            params.push((name.clone(), p));
        }
        Ok(params)
    }
}

/// A body by name: `None` for `"ground"`; an unknown name is an input
/// error on `key`.
pub(super) fn find_body(key: String, name: &str, model: &Model) -> Result<Option<usize>> {
    if name == "ground" {
        return Ok(None);
    }
    model.body(name).map(Some).ok_or_else(|| {
        Error::input(
            key,
            name,
            "the name of a body in scene.bodies, or \"ground\"",
        )
    })
}

/// The joint kind of `[[scene.joints]]` entry `j` (`key` = `joints[k]`).
fn joint_kind(key: &str, j: &JointSpec) -> Result<JointKind> {
    Ok(match j.kind {
        JointType::Spherical => JointKind::Spherical,
        JointType::Revolute => JointKind::Revolute,
        JointType::Fixed => JointKind::Fixed,
        JointType::Cylindrical => JointKind::Cylindrical,
        JointType::Prismatic if j.angle != 0.0 => {
            return Err(Error::input(
                format!("{key}.angle"),
                j.angle,
                "0 for a prismatic joint (its frames stay parallel)",
            ))
        }
        JointType::Prismatic => JointKind::Prismatic,
        JointType::Locked => JointKind::Driven(Drive::Polynomial(vec![j.angle])),
        JointType::Driven => {
            JointKind::Driven(drive_of(&format!("{key}.drive"), j.drive.as_ref())?)
        }
    })
}

/// The law of a driven joint's `drive` (`key` = `joints[k].drive`).
fn drive_of(key: &str, spec: Option<&DriveSpec>) -> Result<Drive> {
    let law = match spec {
        None => {
            return Err(Error::input(
                key,
                "(missing)",
                "a drive: [c0, c1, ..], { pieces = [..] } or { table = [[t, θ], ..] }",
            ))
        }
        Some(DriveSpec::Polynomial(c)) => return Drive::polynomial(key, c.clone()),
        Some(DriveSpec::Law(law)) => law,
    };
    match (&law.pieces, &law.table) {
        (Some(pieces), None) => Drive::pieces(
            key,
            pieces
                .iter()
                .map(|p| {
                    let harmonics = p
                        .harmonics
                        .iter()
                        .map(|h| Harmonic {
                            amplitude: h.amplitude,
                            omega: h.omega,
                            phase: h.phase,
                        })
                        .collect();
                    let piece = Piece {
                        start: 0.0,
                        poly: p.poly.clone(),
                        harmonics,
                    };
                    (p.until, piece)
                })
                .collect(),
        ),
        (None, Some(rows)) => Drive::table(key, rows),
        (Some(_), Some(_)) => Err(Error::input(
            format!("{key}.table"),
            "(given with pieces)",
            "either pieces or table, not both",
        )),
        (None, None) => Err(Error::input(
            key,
            "{}",
            "pieces = [..] or table = [[t, θ], ..]",
        )),
    }
}

/// The unit-free axis of joint `j` (any vector for a kind whose rows read
/// no marker frame: a spherical joint).
fn joint_axis(key: &str, j: &JointSpec, kind: &JointKind) -> Result<Vector3<f64>> {
    Ok(match (kind, j.axis) {
        (k, _) if !k.reads_frames() => Vector3::z(),
        (_, Some(a)) => {
            let a = finite3(format!("{key}.axis"), a)?;
            if a.norm() < 1e-12 {
                return Err(Error::input(
                    format!("{key}.axis"),
                    format!("{:?}", j.axis.unwrap_or_default()),
                    "a non-zero axis vector",
                ));
            }
            a
        }
        (_, None) => {
            return Err(Error::input(
                format!("{key}.axis"),
                "(missing)",
                "an axis vector for this joint type",
            ))
        }
    })
}

/// A tied ply-angle lane `"<body>.design.<v>+<body>.design.<v>+.."`: every
/// member a design variable of a different flexible body; registered as a
/// group in [`Model::ties`].
fn tie(model: &mut Model, key: &str, name: &str) -> Result<Param> {
    let bad = || {
        Error::input(
            key,
            name,
            "design variables of different flexible bodies joined by '+' \
             (<body>.design.<variable>+<body>.design.<variable>), one ply angle",
        )
    };
    let mut group: Vec<(usize, usize)> = Vec::new();
    for part in name.split('+') {
        match parse_param(model, &[], &[], part.trim()) {
            Some(Param::Design(b, v)) if group.iter().all(|(g, _)| *g != b) => group.push((b, v)),
            _ => return Err(bad()),
        }
    }
    if group.len() < 2 {
        return Err(bad());
    }
    model.ties.push(group);
    Ok(Param::Tied(model.ties.len() - 1))
}
