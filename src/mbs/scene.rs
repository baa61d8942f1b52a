//! Scenes from TOML: the `[scene]` section of a study file.
//!
//! ```toml
//! [scene]
//! effects = ["gravity", "actuators", "damping", "springs", "loads",
//!            "flexibility", "quadratic_velocity"]   # what is not listed is not built
//! gravity = [0.0, 0.0, -9.81]                       # m/s²
//! baumgarte = 10.0                                  # 1/s
//! sensitivities = ["forces[0].damping", "forces[0].segments[0].anchor", "B4.mass",
//!                  "B3.design.theta_1_4"]            # ply angle of a flexible body
//! [[scene.bodies]]
//! name = "B4"; mass = 1.5; com = [1.2, 0.0, -0.3]   # kg, m (global, initial)
//! inertia = [[..], [..], [..]]                      # kg·m², about com, global axes
//! fixed = false; velocity = [..]; angular_velocity = [..]   # m/s, rad/s (global)
//! [[scene.bodies]]                                  # floating-frame flexible body
//! name = "B3"; mass, com, inertia                   # rigid stand-in without "flexibility"
//! flexible = { kind = "panel", panel = "panel3", modes = 14, origin = [..],
//!              x_axis = [..], y_axis = [..], derivatives = "updated", damping = 0.0 }
//! # kind = "beam": length, ei_y, ei_z, rho_a, rho_ip (closed-form cantilever modes)
//! [[scene.joints]]
//! name = "R3"; type = "revolute"   # spherical | revolute | locked | driven | fixed
//! body_i = "B12"; body_j = "B8"    # "ground" allowed
//! point = [..]; axis = [..]; angle = 3.12   # global initial point, axis, θ0 (rad)
//! drive = [c0, c1, ..]             # driven: θ(t) = Σ c_k t^k
//! [[scene.markers]]  name, body, point       # extra points (springs, outputs)
//! [[scene.forces]]
//! type = "actuator"; joint = "R3"; damping = 0.5
//! segments = [{ lower, upper, value, slope, anchor }, ..]  # Eq. 32
//! type = "spring"; marker_i, marker_j, stiffness, damping, length
//! type = "load"; body, force, torque       # or table = [[t, fx, fy, fz, tx, ty, tz], ..]
//! [scene.integrator]  method = "bdf", rtol, atol, t_end, dt_out, events = true
//! [scene.outputs]  quantities = ["R3.angle", "R3.rate", "R3.reaction", "energy", "violation",
//!                                "B3.strain_energy", "B3.modal", "<marker>.deflection"]
//!                  plot = "R3.angle"; plot_file = "theta"   # theta.svg
//! ```
//! Rigid bodies start with their axes along the global axes, so `inertia`
//! is both the global and the body-frame tensor at `t = 0`. A flexible
//! body's frame is its basis frame (the beam's root, the panel's centre),
//! placed at `origin` with its x and y axes along `x_axis`, `y_axis`;
//! points on it (joints, markers) must be nodes of its basis.

use super::flex::ModalBasis;
use super::model::{
    axis_angle, frame_from_axis, Body, Drive, Force, Integral, Joint, JointKind, Load, Model,
    Param, PiecewiseLaw, Segment,
};
use super::scene_parts::{
    flexible_body, initial_distance, load_table, make_marker, parse_param, parse_quantity,
};
use crate::error::{Error, Result};
use crate::integrate::{Method, Options};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;

/// Effects a scene may list.
pub const EFFECTS: [&str; 7] = [
    "gravity",
    "actuators",
    "damping",
    "springs",
    "loads",
    "flexibility",
    "quadratic_velocity",
];

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    pub effects: Vec<String>,
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    #[serde(default = "default_baumgarte")]
    pub baumgarte: f64,
    pub bodies: Vec<BodySpec>,
    #[serde(default)]
    pub joints: Vec<JointSpec>,
    #[serde(default)]
    pub markers: Vec<MarkerSpec>,
    #[serde(default)]
    pub forces: Vec<ForceSpec>,
    pub integrator: IntegratorSpec,
    #[serde(default)]
    pub outputs: OutputSpec,
    /// Parameters for forward sensitivities of the outputs:
    /// `"<body>.mass"`, `"forces[i].stiffness"`, `"forces[i].damping"`,
    /// `"forces[i].segments[k].anchor"` (indices as in `scene.forces`).
    #[serde(default)]
    pub sensitivities: Vec<String>,
    /// Functionals of the motion over time (objective and constraints of
    /// an optimization): `[[scene.responses]]`.
    #[serde(default)]
    pub responses: Vec<ResponseSpec>,
}

/// `[[scene.responses]] name = "psi0"; kind = "integral" | "peak";
/// of = ["B2.strain_energy", ..]; scale = 2.0`: the time integral (as an
/// extra integrated state) or the largest value over the run (located
/// from dense output) of `scale · Σ` the listed strain energies.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResponseSpec {
    pub name: String,
    pub kind: String,
    pub of: Vec<String>,
    #[serde(default = "one")]
    pub scale: f64,
}

fn one() -> f64 {
    1.0
}

/// A built response: the bodies whose strain energies it sums.
#[derive(Debug, Clone, PartialEq)]
pub enum Response {
    /// `∫ scale·ΣU dt`: index into [`Model::integrals`].
    Integral { name: String, index: usize },
    /// `max_t scale·ΣU(t)`.
    Peak {
        name: String,
        bodies: Vec<usize>,
        scale: f64,
    },
}

impl Response {
    /// The response's name.
    pub fn name(&self) -> &str {
        match self {
            Response::Integral { name, .. } | Response::Peak { name, .. } => name,
        }
    }
}

fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -9.81]
}
/// Baumgarte rate default: 10 1/s damps drift within ~0.5 s, slower than
/// the mechanisms' dynamics of interest yet far from making them stiff.
fn default_baumgarte() -> f64 {
    10.0
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    /// Rigid mass properties: required for rigid bodies, and for flexible
    /// ones when the scene does not list `flexibility` (then they are
    /// simulated rigid).
    pub mass: Option<f64>,
    pub com: Option<[f64; 3]>,
    pub inertia: Option<[[f64; 3]; 3]>,
    #[serde(default)]
    pub fixed: bool,
    #[serde(default)]
    pub velocity: [f64; 3],
    #[serde(default)]
    pub angular_velocity: [f64; 3],
    /// A floating-frame flexible body (used when `flexibility` is listed).
    pub flexible: Option<FlexSpec>,
}

/// `flexible = { kind = "beam" | "panel", modes, origin, .. }`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlexSpec {
    /// `beam` (closed-form cantilever modes) or `panel` (finite element
    /// modes of a `[[panels]]` entry).
    pub kind: String,
    /// Number of modes kept.
    pub modes: usize,
    /// Global position of the basis frame's origin at t = 0 (m): the
    /// beam's root, the panel's centre.
    pub origin: [f64; 3],
    /// Global directions of the basis frame's x and y axes at t = 0.
    #[serde(default = "unit_x")]
    pub x_axis: [f64; 3],
    #[serde(default = "unit_y")]
    pub y_axis: [f64; 3],
    /// Modal damping ratio ζ of every mode (with the `damping` effect).
    #[serde(default)]
    pub damping: f64,
    /// Beam: length (m), bending stiffnesses for deflection along y
    /// (`ei_z`) and z (`ei_y`) (N·m²), mass per length (kg/m), polar mass
    /// moment per length (kg·m, rotary inertia about the beam axis).
    pub length: Option<f64>,
    pub ei_y: Option<f64>,
    pub ei_z: Option<f64>,
    pub rho_a: Option<f64>,
    pub rho_ip: Option<f64>,
    /// Panel: the `name` of a `[[panels]]` entry of the study.
    pub panel: Option<String>,
    /// Panel: design derivatives of the modes for ply-angle sensitivities,
    /// `fixed` (Eq. 19) or `updated` (Eq. 18).
    pub derivatives: Option<String>,
}

fn unit_x() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}
fn unit_y() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// Builds the modal basis of a `kind = "panel"` body: `(panel name,
/// modes, derivatives)` → basis; errors name the study's keys.
pub type PanelBases<'a> = &'a dyn Fn(&str, usize, Option<&str>) -> Result<ModalBasis>;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub body_i: String,
    pub body_j: String,
    pub point: [f64; 3],
    pub axis: Option<[f64; 3]>,
    #[serde(default)]
    pub angle: f64,
    pub drive: Option<Vec<f64>>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerSpec {
    pub name: String,
    pub body: String,
    pub point: [f64; 3],
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentSpec {
    pub lower: f64,
    pub upper: f64,
    pub value: f64,
    #[serde(default)]
    pub slope: f64,
    #[serde(default)]
    pub anchor: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, tag = "type", rename_all = "lowercase")]
#[allow(clippy::large_enum_variant)]
pub enum ForceSpec {
    Actuator {
        joint: String,
        #[serde(default)]
        damping: f64,
        #[serde(default)]
        segments: Vec<SegmentSpec>,
    },
    Spring {
        marker_i: String,
        marker_j: String,
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        length: Option<f64>,
    },
    Load {
        body: String,
        #[serde(default)]
        force: [f64; 3],
        #[serde(default)]
        torque: [f64; 3],
        /// Time table `[[t, fx, fy, fz, tx, ty, tz], ..]` (s, N, N·m),
        /// linear between rows; replaces `force` and `torque`.
        table: Option<Vec<[f64; 7]>>,
    },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    #[serde(default = "default_method")]
    pub method: Method,
    #[serde(default = "default_rtol")]
    pub rtol: f64,
    #[serde(default = "default_atol")]
    pub atol: f64,
    pub t_end: f64,
    pub dt_out: f64,
    /// Segment changes of actuator laws as integration events
    /// ([`Options::events`], default `true`).
    #[serde(default = "default_events")]
    pub events: bool,
}
fn default_events() -> bool {
    true
}
fn default_method() -> Method {
    Method::Bdf
}
fn default_rtol() -> f64 {
    1e-6
}
fn default_atol() -> f64 {
    1e-8
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    #[serde(default)]
    pub quantities: Vec<String>,
    pub plot: Option<String>,
    /// File stem of the plot (default: the plotted output's name), e.g.
    /// `theta` for `theta.svg`.
    pub plot_file: Option<String>,
}

/// One output column.
#[derive(Debug, Clone, PartialEq)]
pub enum Quantity {
    Angle(usize),
    Rate(usize),
    /// Reaction force (3) and torque (3) of a joint.
    Reaction(usize),
    /// Global position of a body's centre of mass (of a flexible body:
    /// of its frame origin).
    Position(usize),
    /// Modal coordinates `w` of a flexible body (body, n: n columns).
    Modal(usize, usize),
    /// Strain energy `½ wᵀΛw` of a flexible body (J).
    Strain(usize),
    /// Elastic displacement `Φ_k w` of a marker on a flexible node, in
    /// the body's frame axes (m).
    Deflection(usize),
    Energy,
    Violation,
}

/// A built scene: the system model, integrator options and outputs.
#[derive(Debug)]
pub struct Scene {
    pub model: Model,
    pub options: Options,
    pub outputs: Vec<(String, Quantity)>,
    pub plot: Option<String>,
    /// File stem of the plot (`<plot_file>.svg`).
    pub plot_file: Option<String>,
    pub effects: Vec<String>,
    /// Sensitivity parameters with their names from the scene file.
    pub params: Vec<(String, Param)>,
    /// Response functionals.
    pub responses: Vec<Response>,
}

impl Quantity {
    /// CSV column headers with SI units.
    pub fn headers(&self, label: &str) -> Vec<String> {
        match self {
            Quantity::Angle(_) => vec![format!("{label} [rad]")],
            Quantity::Rate(_) => vec![format!("{label} [rad/s]")],
            Quantity::Reaction(_) => {
                let base = label.trim_end_matches(".reaction");
                let mut h: Vec<String> = ["x", "y", "z"]
                    .iter()
                    .map(|c| format!("{base}.force_{c} [N]"))
                    .collect();
                h.extend(
                    ["x", "y", "z"]
                        .iter()
                        .map(|c| format!("{base}.torque_{c} [N*m]")),
                );
                h
            }
            Quantity::Position(_) => ["x", "y", "z"]
                .iter()
                .map(|c| format!("{label}_{c} [m]"))
                .collect(),
            Quantity::Modal(_, n) => (1..=*n)
                .map(|j| format!("{label}_{j} [kg^0.5*m]"))
                .collect(),
            Quantity::Strain(_) => vec![format!("{label} [J]")],
            Quantity::Deflection(_) => ["x", "y", "z"]
                .iter()
                .map(|c| format!("{label}_{c} [m]"))
                .collect(),
            Quantity::Energy => vec!["energy [J]".into()],
            Quantity::Violation => vec!["violation [m|rad]".into()],
        }
    }
}

fn vec3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

pub(super) fn finite3(key: String, a: [f64; 3]) -> Result<Vector3<f64>> {
    if a.iter().all(|v| v.is_finite()) {
        Ok(vec3(a))
    } else {
        Err(Error::input(key, format!("{a:?}"), "finite components"))
    }
}

impl SceneSpec {
    /// Build the model of a scene without panel bodies. Errors name the
    /// key below `scene` (e.g. `joints[2].body_i`); callers attach the
    /// file with `Error::in_file`.
    pub fn build(&self) -> Result<Scene> {
        self.build_with(&|name, _, _| {
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
        for (k, e) in self.effects.iter().enumerate() {
            if !EFFECTS.contains(&e.as_str()) {
                return Err(Error::input(
                    format!("effects[{k}]"),
                    e,
                    format!("one of {}", EFFECTS.join(", ")),
                ));
            }
        }
        let has = |e: &str| self.effects.iter().any(|x| x == e);
        if !(self.baumgarte >= 0.0 && self.baumgarte.is_finite()) {
            return Err(Error::input(
                "baumgarte",
                self.baumgarte,
                "a finite rate ≥ 0 (1/s)",
            ));
        }
        let mut model = Model {
            baumgarte: self.baumgarte,
            quadratic_velocity: has("quadratic_velocity"),
            ..Model::default()
        };
        for (k, b) in self.bodies.iter().enumerate() {
            let key = format!("bodies[{k}]");
            if model.body(&b.name).is_some() || b.name == "ground" {
                return Err(Error::input(
                    format!("{key}.name"),
                    &b.name,
                    "a unique body name other than 'ground'",
                ));
            }
            let mut body = match (&b.flexible, has("flexibility")) {
                (Some(f), true) => {
                    if b.fixed {
                        return Err(Error::input(
                            format!("{key}.fixed"),
                            "true",
                            "a moving body (a fixed body cannot be flexible)",
                        ));
                    }
                    flexible_body(&key, &b.name, f, has("damping"), panels)?
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
            body.fixed = b.fixed;
            body.v0 = finite3(format!("{key}.velocity"), b.velocity)?;
            body.w0 = body.orientation().transpose()
                * finite3(format!("{key}.angular_velocity"), b.angular_velocity)?;
            model.bodies.push(body);
        }
        let find_body = |key: String, name: &str, model: &Model| -> Result<Option<usize>> {
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
        };
        for (k, m) in self.markers.iter().enumerate() {
            let key = format!("markers[{k}]");
            let body = find_body(format!("{key}.body"), &m.body, &model)?;
            let p = finite3(format!("{key}.point"), m.point)?;
            let mk = make_marker(
                &model,
                &format!("{key}.point"),
                (&m.name, body),
                p,
                Matrix3::identity(),
            )?;
            model.markers.push(mk);
        }
        for (k, j) in self.joints.iter().enumerate() {
            let key = format!("joints[{k}]");
            let bi = find_body(format!("{key}.body_i"), &j.body_i, &model)?;
            let bj = find_body(format!("{key}.body_j"), &j.body_j, &model)?;
            if bi == bj {
                return Err(Error::input(
                    format!("{key}.body_j"),
                    &j.body_j,
                    "a body other than body_i",
                ));
            }
            let point = finite3(format!("{key}.point"), j.point)?;
            let kind = match j.kind.as_str() {
                "spherical" => JointKind::Spherical,
                "revolute" => JointKind::Revolute,
                "fixed" => JointKind::Fixed,
                "locked" => JointKind::Driven(Drive {
                    coefficients: vec![j.angle],
                }),
                "driven" => match &j.drive {
                    Some(c) if !c.is_empty() && c.iter().all(|v| v.is_finite()) => {
                        JointKind::Driven(Drive {
                            coefficients: c.clone(),
                        })
                    }
                    other => {
                        return Err(Error::input(
                            format!("{key}.drive"),
                            format!("{other:?}"),
                            "polynomial coefficients [c0, c1, ..] of θ(t) (rad, s)",
                        ))
                    }
                },
                other => {
                    return Err(Error::input(
                        format!("{key}.type"),
                        other,
                        "spherical, revolute, locked, driven or fixed",
                    ))
                }
            };
            let axis = match (&kind, j.axis) {
                (JointKind::Spherical, _) => Vector3::z(),
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
            };
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
            let mi = make_marker(&model, &pk, (&format!("{}.i", j.name), bi), point, fi)?;
            let mj = make_marker(&model, &pk, (&format!("{}.j", j.name), bj), point, fj)?;
            model.markers.push(mi);
            model.markers.push(mj);
            if model.joint(&j.name).is_some() {
                return Err(Error::input(
                    format!("{key}.name"),
                    &j.name,
                    "a unique joint name",
                ));
            }
            model.joints.push(Joint {
                name: j.name.clone(),
                kind,
                i: n,
                j: n + 1,
            });
        }
        if has("gravity") {
            model.forces.push(Force::Gravity {
                g: finite3("gravity".into(), self.gravity)?,
            });
        }
        // Model index of each scene force (None: not built).
        let mut force_index: Vec<Option<usize>> = vec![None; self.forces.len()];
        for (k, f) in self.forces.iter().enumerate() {
            let key = format!("forces[{k}]");
            match f {
                ForceSpec::Actuator {
                    joint,
                    damping,
                    segments,
                } => {
                    let jt = model.joint(joint).ok_or_else(|| {
                        Error::input(
                            format!("{key}.joint"),
                            joint,
                            "the name of a joint in scene.joints",
                        )
                    })?;
                    if !model.joints[jt].kind.has_angle()
                        || matches!(model.joints[jt].kind, JointKind::Driven(_))
                    {
                        return Err(Error::input(
                            format!("{key}.joint"),
                            joint,
                            "a free revolute joint",
                        ));
                    }
                    if !(damping.is_finite() && *damping >= 0.0) {
                        return Err(Error::input(
                            format!("{key}.damping"),
                            damping,
                            "a finite damping ≥ 0 (N·m·s)",
                        ));
                    }
                    let law = if has("actuators") && !segments.is_empty() {
                        let segs = segments
                            .iter()
                            .map(|s| Segment {
                                lower: s.lower,
                                upper: s.upper,
                                value: s.value,
                                slope: s.slope,
                                anchor: s.anchor,
                            })
                            .collect();
                        Some(PiecewiseLaw::new(&format!("{key}.segments"), segs)?)
                    } else {
                        None
                    };
                    let c = if has("damping") { *damping } else { 0.0 };
                    if law.is_some() || c != 0.0 {
                        force_index[k] = Some(model.forces.len());
                        model.forces.push(Force::Rotational {
                            joint: jt,
                            law,
                            damping: c,
                        });
                    }
                }
                ForceSpec::Spring {
                    marker_i,
                    marker_j,
                    stiffness,
                    damping,
                    length,
                } => {
                    let find = |key: String, name: &str| {
                        model.marker(name).ok_or_else(|| {
                            Error::input(key, name, "the name of a marker in scene.markers")
                        })
                    };
                    let i = find(format!("{key}.marker_i"), marker_i)?;
                    let j = find(format!("{key}.marker_j"), marker_j)?;
                    let l0 = initial_distance(&model, i, j);
                    let length = length.unwrap_or(l0);
                    for (name, v) in [
                        ("stiffness", *stiffness),
                        ("damping", *damping),
                        ("length", length),
                    ] {
                        if !(v.is_finite() && v >= 0.0) {
                            return Err(Error::input(
                                format!("{key}.{name}"),
                                v,
                                "a finite value ≥ 0",
                            ));
                        }
                    }
                    if l0 < 1e-9 {
                        return Err(Error::input(
                            format!("{key}.marker_j"),
                            marker_j,
                            "a point distinct from marker_i",
                        ));
                    }
                    if !has("springs") {
                        continue;
                    }
                    let c = if has("damping") { *damping } else { 0.0 };
                    force_index[k] = Some(model.forces.len());
                    model.forces.push(Force::SpringDamper {
                        i,
                        j,
                        stiffness: *stiffness,
                        damping: c,
                        length,
                    });
                }
                ForceSpec::Load {
                    body,
                    force,
                    torque,
                    table,
                } => {
                    let b = find_body(format!("{key}.body"), body, &model)?.ok_or_else(|| {
                        Error::input(format!("{key}.body"), body, "a body (not ground)")
                    })?;
                    let force = finite3(format!("{key}.force"), *force)?;
                    let torque = finite3(format!("{key}.torque"), *torque)?;
                    let load = match table {
                        None => Load::Constant { force, torque },
                        Some(rows) => Load::Table(load_table(&format!("{key}.table"), rows)?),
                    };
                    if !has("loads") {
                        continue;
                    }
                    force_index[k] = Some(model.forces.len());
                    model.forces.push(Force::BodyLoad { body: b, load });
                }
            }
        }
        let it = &self.integrator;
        if !(it.dt_out > 0.0 && it.dt_out.is_finite()) {
            return Err(Error::input(
                "integrator.dt_out",
                it.dt_out,
                "an output interval > 0 (s)",
            ));
        }
        if !(it.t_end > 0.0 && it.t_end.is_finite()) || it.t_end / it.dt_out > 1e7 {
            return Err(Error::input(
                "integrator.t_end",
                it.t_end,
                "an end time > 0 (s) with at most 1e7 output intervals",
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
        };
        options.validate()?;
        let flex_names: Vec<&str> = self
            .bodies
            .iter()
            .filter(|b| b.flexible.is_some())
            .map(|b| b.name.as_str())
            .collect();
        let mut outputs = Vec::new();
        for (k, q) in self.outputs.quantities.iter().enumerate() {
            outputs.push((
                q.clone(),
                parse_quantity(&model, &flex_names, &format!("outputs.quantities[{k}]"), q)?,
            ));
        }
        if let Some(p) = &self.outputs.plot {
            match parse_quantity(&model, &flex_names, "outputs.plot", p)? {
                Quantity::Angle(_) | Quantity::Rate(_) | Quantity::Energy | Quantity::Violation => {
                }
                _ => {
                    return Err(Error::input(
                        "outputs.plot",
                        p,
                        "a scalar output (angle, rate, energy, violation)",
                    ))
                }
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
        let responses = self.responses(&mut model, &flex_names)?;
        let mut params = Vec::new();
        for (k, name) in self.sensitivities.iter().enumerate() {
            let key = format!("sensitivities[{k}]");
            let p = parse_param(&model, &self.forces, &force_index, name).ok_or_else(|| {
                Error::input(
                    &key,
                    name,
                    "<body>.mass (rigid body), <body>.design.<variable> (flexible body), \
                     forces[i].stiffness, forces[i].damping or \
                     forces[i].segments[k].anchor of a force the effects list builds",
                )
            })?;
            if params.iter().any(|(_, q)| *q == p) {
                return Err(Error::input(key, name, "each parameter once"));
            }
            params.push((name.clone(), p));
        }
        Ok(Scene {
            model,
            options,
            outputs,
            plot: self.outputs.plot.clone(),
            plot_file: self.outputs.plot_file.clone(),
            effects: self.effects.clone(),
            params,
            responses,
        })
    }

    /// Build `[[scene.responses]]` (integrals become model states).
    fn responses(&self, model: &mut Model, flex_names: &[&str]) -> Result<Vec<Response>> {
        let mut out: Vec<Response> = Vec::new();
        for (k, r) in self.responses.iter().enumerate() {
            let key = format!("responses[{k}]");
            if r.name.is_empty() || out.iter().any(|o| o.name() == r.name) {
                return Err(Error::input(
                    format!("{key}.name"),
                    &r.name,
                    "a unique, non-empty name",
                ));
            }
            if !r.scale.is_finite() {
                return Err(Error::input(
                    format!("{key}.scale"),
                    r.scale,
                    "a finite factor",
                ));
            }
            let mut bodies = Vec::new();
            for (i, q) in r.of.iter().enumerate() {
                let body = q
                    .strip_suffix(".strain_energy")
                    .filter(|b| flex_names.contains(b))
                    .and_then(|b| model.body(b))
                    .ok_or_else(|| {
                        Error::input(
                            format!("{key}.of[{i}]"),
                            q,
                            "<body>.strain_energy of a body with a `flexible` table",
                        )
                    })?;
                bodies.push(body);
            }
            if bodies.is_empty() {
                return Err(Error::input(
                    format!("{key}.of"),
                    "[]",
                    "at least one strain energy",
                ));
            }
            out.push(match r.kind.as_str() {
                "integral" => {
                    model.integrals.push(Integral {
                        bodies,
                        scale: r.scale,
                    });
                    Response::Integral {
                        name: r.name.clone(),
                        index: model.integrals.len() - 1,
                    }
                }
                "peak" => Response::Peak {
                    name: r.name.clone(),
                    bodies,
                    scale: r.scale,
                },
                other => {
                    return Err(Error::input(
                        format!("{key}.kind"),
                        other,
                        "integral or peak",
                    ));
                }
            });
        }
        Ok(out)
    }
}
