//! The `[scene]` section as parsed from a study file: plain data checked
//! by serde (unknown keys refused), validated and turned into a model by
//! [`super::build`].

use crate::error::{Error, Result};
use crate::integrate::{Method, SensitivityForm};
use crate::modal::ModeUpdate;
use serde::Deserialize;

/// Effects a scene may list.
/// What a scene may switch on (`[scene] effects`): what is not listed is
/// neither built nor evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    /// Uniform gravity on every moving body.
    Gravity,
    /// The Eq. 32 laws of actuators.
    Actuators,
    /// Actuator, spring and modal damping.
    Damping,
    /// Spring-dampers between markers.
    Springs,
    /// Constant or tabulated loads.
    Loads,
    /// Flexible bodies with their `flexible` table (else rigid stand-ins).
    Flexibility,
    /// Quadratic-velocity (gyroscopic and centrifugal) terms.
    QuadraticVelocity,
}

impl Effect {
    /// Every effect, in the order of the documentation.
    pub const ALL: [Effect; 7] = [
        Effect::Gravity,
        Effect::Actuators,
        Effect::Damping,
        Effect::Springs,
        Effect::Loads,
        Effect::Flexibility,
        Effect::QuadraticVelocity,
    ];

    /// The name written in study files.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Gravity => "gravity",
            Effect::Actuators => "actuators",
            Effect::Damping => "damping",
            Effect::Springs => "springs",
            Effect::Loads => "loads",
            Effect::Flexibility => "flexibility",
            Effect::QuadraticVelocity => "quadratic_velocity",
        }
    }

    /// The effect named `name`, if any.
    pub fn parse(name: &str) -> Option<Effect> {
        Effect::ALL.into_iter().find(|e| e.name() == name)
    }
}

impl SceneSpec {
    /// Drop the mode derivatives of flexible bodies that no sensitivity
    /// parameter differentiates (no `<body>.design.<variable>` in
    /// `sensitivities`, alone or in a tied lane `a+b`): what a study does
    /// not ask for is not computed.
    /// The modes, and so every output, are the same either way.
    pub fn prune_derivatives(&mut self) {
        let lanes = &self.sensitivities;
        for b in &mut self.bodies {
            let prefix = format!("{}.design.", b.name);
            if !lanes
                .iter()
                .flat_map(|l| l.split('+'))
                .any(|l| l.trim().starts_with(&prefix))
            {
                if let Some(f) = &mut b.flexible {
                    f.derivatives_name = None;
                }
            }
        }
    }

    /// The listed effects; an unknown name is an input error on
    /// `effects[k]` listing the known ones.
    pub fn effect_list(&self) -> Result<Vec<Effect>> {
        self.effects
            .iter()
            .enumerate()
            .map(|(k, e)| {
                Effect::parse(e).ok_or_else(|| {
                    let names: Vec<&str> = Effect::ALL.iter().map(|e| e.name()).collect();
                    Error::input(
                        format!("effects[{k}]"),
                        e,
                        format!("one of {}", names.join(", ")),
                    )
                })
            })
            .collect()
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Effect names as written ([`SceneSpec::effect_list`] checks them).
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
    /// `"<body>.mass"`, `"<force>.stiffness"`, `"<force>.damping"` (a
    /// named force), `"forces[i].stiffness"`, `"forces[i].damping"`,
    /// `"forces[i].segments[k].anchor"` (indices as in `scene.forces`).
    #[serde(default)]
    pub sensitivities: Vec<String>,
    /// Functionals of the motion over time (objective and constraints of
    /// an optimization): `[[scene.responses]]`.
    #[serde(default)]
    pub responses: Vec<ResponseSpec>,
}

/// `[[scene.responses]] name = "psi0"; kind = "integral" | "peak" |
/// "final"; of = ["B2.strain_energy", "crank.kinetic_energy",
/// "kinetic_energy", ..]; scale = 2.0`: the time integral (as an extra
/// integrated state), the largest value over the run (located from dense
/// output) or the value at the end time of `scale · Σ` the listed
/// energies (strain energies of flexible bodies, kinetic energies of a
/// body or of all bodies).
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
    /// modes of a `[[panels]]` entry), as written; [`FlexSpec::kind`]
    /// gives the [`FlexKind`].
    #[serde(rename = "kind")]
    pub kind_name: String,
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
    /// `fixed` (Eq. 19) or `updated` (Eq. 18), as written;
    /// [`FlexSpec::derivatives`] gives the [`ModeUpdate`].
    #[serde(rename = "derivatives")]
    pub derivatives_name: Option<String>,
    /// Panel: drop the modes whose rigid-body content exceeds this share
    /// (in (0, 1]; default [`crate::panels::basis::RIGID_CONTENT_LIMIT`]
    /// = 0.9; 1 keeps every mode), see [`crate::panels::basis`].
    pub rigid_limit: Option<f64>,
}

/// Where a flexible body's modes come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlexKind {
    /// Closed-form Euler–Bernoulli cantilever modes ([`crate::beams`]).
    Beam,
    /// Finite element modes of a `[[panels]]` entry ([`crate::panels`]).
    Panel,
}

impl FlexSpec {
    /// The kind; an unknown name is an input error on `<key>.kind`.
    pub fn kind(&self, key: &str) -> Result<FlexKind> {
        match self.kind_name.as_str() {
            "beam" => Ok(FlexKind::Beam),
            "panel" => Ok(FlexKind::Panel),
            other => Err(Error::input(format!("{key}.kind"), other, "beam or panel")),
        }
    }

    /// The derivative approach of a panel body (None: no derivatives); an
    /// unknown name is an input error on `<key>.derivatives`.
    pub fn derivatives(&self, key: &str) -> Result<Option<ModeUpdate>> {
        match self.derivatives_name.as_deref() {
            None => Ok(None),
            Some(d) => ModeUpdate::parse(d).map(Some).ok_or_else(|| {
                Error::input(
                    format!("{key}.derivatives"),
                    d,
                    "fixed (Eq. 19) or updated (Eq. 18)",
                )
            }),
        }
    }
}

fn unit_x() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}
fn unit_y() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

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
        /// Name for sensitivity parameters (`<name>.damping`).
        name: Option<String>,
        joint: String,
        #[serde(default)]
        damping: f64,
        #[serde(default)]
        segments: Vec<SegmentSpec>,
    },
    /// A spring-damper between two markers (`marker_i`, `marker_j`; rest
    /// `length` default: the initial distance) or along a prismatic or
    /// cylindrical `joint` (rest displacement `length`, default 0, and a
    /// constant actuator `force` along the axis, default 0).
    Spring {
        /// Name for sensitivity parameters (`<name>.stiffness`,
        /// `<name>.damping`).
        name: Option<String>,
        marker_i: Option<String>,
        marker_j: Option<String>,
        joint: Option<String>,
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        length: Option<f64>,
        force: Option<f64>,
    },
    /// A force and torque at a body's centre of mass (`body`) or at a
    /// marker (`marker`), in global or body axes (`frame`).
    Load {
        body: Option<String>,
        marker: Option<String>,
        /// `global` (default) or `body`, as written.
        frame: Option<String>,
        #[serde(default)]
        force: [f64; 3],
        #[serde(default)]
        torque: [f64; 3],
        /// Time table `[[t, fx, fy, fz, tx, ty, tz], ..]` (s, N, N·m),
        /// linear between rows; replaces `force` and `torque`.
        table: Option<Vec<[f64; 7]>>,
    },
}

impl ForceSpec {
    /// The force's name, if it has one (loads have none).
    pub fn name(&self) -> Option<&str> {
        match self {
            ForceSpec::Actuator { name, .. } | ForceSpec::Spring { name, .. } => name.as_deref(),
            ForceSpec::Load { .. } => None,
        }
    }
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
    /// ([`crate::integrate::Options::events`], default `true`).
    #[serde(default = "default_events")]
    pub events: bool,
    /// Form of the forward sensitivities: `fused` (the default: the lanes
    /// ride in the state, one directional derivative per lane and stage or
    /// Newton iterate) or `staggered` (diffsol's sensitivity equations, two
    /// per lane and stage). Both control the error of the states alone;
    /// with tsit45 they agree to about 1e-11 (tests/suite/explore/scene.rs), with
    /// the implicit methods to the lanes' integration error.
    pub sensitivity_form: Option<SensitivityForm>,
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
