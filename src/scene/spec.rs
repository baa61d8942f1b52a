//! The `[scene]` section as parsed from a study file: plain data checked
//! by serde (unknown keys refused), validated and turned into a model by
//! [`super::build`].

use crate::integrate::{Method, SensitivityForm};
use crate::mbs::responses::{Direction, ResponseKindName, Sense};
use crate::modal::ModeUpdate;
use serde::Deserialize;

/// What a scene may switch on (`[scene] effects`, written in snake case:
/// `gravity`, `actuators`, `damping`, `springs`, `loads`, `flexibility`,
/// `quadratic_velocity`, `geometric_stiffening`): what is not listed is neither built nor
/// evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
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
    /// Geometric stiffening of flexible bodies by their inertial
    /// prestress ([`crate::mbs::model::geometric`]).
    GeometricStiffening,
}

impl Effect {
    /// Every effect, in the order of the documentation.
    pub const ALL: [Effect; 8] = [
        Effect::Gravity,
        Effect::Actuators,
        Effect::Damping,
        Effect::Springs,
        Effect::Loads,
        Effect::Flexibility,
        Effect::QuadraticVelocity,
        Effect::GeometricStiffening,
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
            Effect::GeometricStiffening => "geometric_stiffening",
        }
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
                    f.derivatives = None;
                }
            }
        }
    }
}

impl SceneSpec {
    /// The ply-thickness variables (`thickness_<plies>`) that
    /// `sensitivities` differentiates on the bodies built from panel
    /// `panel` (lanes `<body>.design.thickness_<plies>`, alone or tied),
    /// in the order first met.
    pub fn thickness_variables(&self, panel: &str) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for b in &self.bodies {
            let of_panel = b
                .flexible
                .as_ref()
                .is_some_and(|f| f.kind == FlexKind::Panel && f.panel.as_deref() == Some(panel));
            if !of_panel {
                continue;
            }
            let prefix = format!("{}.design.", b.name);
            for lane in self.sensitivities.iter().flat_map(|l| l.split('+')) {
                if let Some(v) = lane.trim().strip_prefix(&prefix) {
                    if v.starts_with("thickness_") && !out.iter().any(|o| o == v) {
                        out.push(v.to_string());
                    }
                }
            }
        }
        out
    }
}

/// The `[scene]` section: a multibody model with its integrator, outputs,
/// sensitivity parameters and responses (module doc of [`crate::scene`]
/// for an example of every key). Unknown keys are refused.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// The effects switched on ([`Effect`]; an unknown name is refused
    /// when the section is read, naming `scene.effects[k]`).
    pub effects: Vec<Effect>,
    /// Gravitational acceleration, global axes (m/s²; default
    /// `[0, 0, -9.81]`), applied with the `gravity` effect.
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// Baumgarte rate α of the constraint stabilisation (1/s, ≥ 0;
    /// default 10).
    #[serde(default = "default_baumgarte")]
    pub baumgarte: f64,
    /// Divergence guard: a run ends (with its outputs so far) when a
    /// flexible body's modal deflection bound exceeds this factor times
    /// the body's size (`crate::mbs::watch`; > 0, default 0.2, `inf`
    /// switches the guard off).
    #[serde(default = "default_divergence_limit")]
    pub divergence_limit: f64,
    /// Fast-rotation warning: a flexible body without the
    /// `geometric_stiffening` effect warns once when its frame turns
    /// faster than this fraction of its first modal frequency
    /// (`crate::simulate::spin`; > 0, default 0.3, `inf` switches the
    /// warning off).
    #[serde(default = "default_spin_warning_fraction")]
    pub spin_warning_fraction: f64,
    /// The bodies, `[[scene.bodies]]` (may be empty: a scene in which
    /// nothing moves is written without integrating).
    pub bodies: Vec<BodySpec>,
    /// The joints, `[[scene.joints]]` (default none).
    #[serde(default)]
    pub joints: Vec<JointSpec>,
    /// Extra named points, `[[scene.markers]]` (default none).
    #[serde(default)]
    pub markers: Vec<MarkerSpec>,
    /// Actuators, springs and loads, `[[scene.forces]]` (default none).
    #[serde(default)]
    pub forces: Vec<ForceSpec>,
    /// Time span, output interval and method, `[scene.integrator]`.
    pub integrator: IntegratorSpec,
    /// Output columns and plot, `[scene.outputs]` (default: none, only
    /// time).
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
/// "final" | "value_at" | "crossing" | "frequency"; of = [..]; scale =
/// 2.0`: a functional of `scale · Σ` the listed outputs over the run —
/// the time integral, the largest (or smallest) value located from dense
/// output, the value at the end time or at a given time, the first time
/// the sum crosses a level — or a natural frequency of a flexible body.
/// Energies (`<body>.strain_energy`, `<body>.kinetic_energy`,
/// `kinetic_energy`) are summed; any other output (`<joint>.angle`,
/// `<body>.position_z`, `<marker>.deflection_x`, ..) is one of a sum of
/// outputs with the same unit.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResponseSpec {
    /// Unique, non-empty name (the `response` of an exploration, the
    /// column of `responses.csv`).
    pub name: String,
    /// `integral` (∫ dt), `peak` (extreme over the run), `final` (at the
    /// end time), `value_at` (at `time`), `crossing` (first time the
    /// output crosses `level`, s) or `frequency` (Hz).
    pub kind: ResponseKindName,
    /// The outputs summed (at least one): energies, or scalar outputs of
    /// one unit (`<joint>.angle|rate|displacement|velocity`,
    /// `<body>.position_x|y|z`, `<marker>.deflection_x|y|z`); for
    /// `frequency` one flexible body (`["B3"]`).
    pub of: Vec<String>,
    /// Dimensionless factor of the sum (finite; default 1).
    #[serde(default = "one")]
    pub scale: f64,
    /// `peak`: `max` (default) or `min`.
    pub sense: Option<Sense>,
    /// `value_at`: the time (s), within the output times.
    pub time: Option<f64>,
    /// `crossing`: the level, in the unit of the outputs.
    pub level: Option<f64>,
    /// `crossing`: `up`, `down` or `either` (default).
    pub direction: Option<Direction>,
    /// `frequency`: the mode of the body's modal basis (1 = lowest).
    pub mode: Option<usize>,
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

fn default_divergence_limit() -> f64 {
    0.2
}

fn default_spin_warning_fraction() -> f64 {
    crate::mbs::model::SPIN_WARNING_FRACTION
}

/// One `[[scene.bodies]]` entry: a rigid body, or a flexible one with a
/// `flexible` table. Rigid bodies start with their axes along the global
/// axes.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique body name (`ground` is reserved for the fixed frame).
    pub name: String,
    /// Rigid mass properties: required for rigid bodies, and for flexible
    /// ones when the scene does not list `flexibility` (then they are
    /// simulated rigid).
    /// Mass (kg, > 0).
    pub mass: Option<f64>,
    /// Initial global position of the centre of mass (m).
    pub com: Option<[f64; 3]>,
    /// Inertia tensor about the centre of mass, global (= body) axes at
    /// `t = 0` (kg·m², symmetric positive definite).
    pub inertia: Option<[[f64; 3]; 3]>,
    /// Fixed to ground (default `false`).
    #[serde(default)]
    pub fixed: bool,
    /// Initial velocity of the centre of mass, global axes (m/s; default
    /// 0).
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Initial angular velocity, global axes (rad/s; default 0).
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
    pub kind: FlexKind,
    /// Number of modes kept.
    pub modes: usize,
    /// Global position of the basis frame's origin at t = 0 (m): the
    /// beam's root, the panel's centre.
    pub origin: [f64; 3],
    /// Global direction of the basis frame's x axis at t = 0 (default
    /// `[1, 0, 0]`).
    #[serde(default = "unit_x")]
    pub x_axis: [f64; 3],
    /// Global direction of the basis frame's y axis at t = 0 (default
    /// `[0, 1, 0]`; made orthogonal to `x_axis`).
    #[serde(default = "unit_y")]
    pub y_axis: [f64; 3],
    /// Modal damping ratio ζ of every mode (with the `damping` effect).
    #[serde(default)]
    pub damping: f64,
    /// Beam: length along the frame's x axis (m).
    pub length: Option<f64>,
    /// Beam: bending stiffness for deflection along z (N·m²).
    pub ei_y: Option<f64>,
    /// Beam: bending stiffness for deflection along y (N·m²).
    pub ei_z: Option<f64>,
    /// Beam: mass per length (kg/m).
    pub rho_a: Option<f64>,
    /// Beam: polar mass moment per length (kg·m, rotary inertia about the
    /// beam axis).
    pub rho_ip: Option<f64>,
    /// Panel: the `name` of a `[[panels]]` entry of the study.
    pub panel: Option<String>,
    /// Panel: design derivatives of the modes for ply-angle sensitivities,
    /// `fixed` (Eq. 19) or `updated` (Eq. 18); none when absent.
    pub derivatives: Option<ModeUpdate>,
    /// Panel: drop the modes whose rigid-body content exceeds this share
    /// (in (0, 1]; default [`crate::panels::basis::RIGID_CONTENT_LIMIT`]
    /// = 0.9; 1 keeps every mode), see [`crate::panels::basis`].
    pub rigid_limit: Option<f64>,
}

/// Where a flexible body's modes come from (`flexible.kind`: `beam` or
/// `panel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FlexKind {
    /// Closed-form Euler–Bernoulli cantilever modes ([`crate::beams`]).
    Beam,
    /// Finite element modes of a `[[panels]]` entry ([`crate::panels`]).
    Panel,
}

fn unit_x() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}
fn unit_y() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// One `[[scene.joints]]` entry. Each joint also makes the markers
/// `<joint>.i` and `<joint>.j` at its point on either body.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    /// Unique joint name.
    pub name: String,
    /// `type`: the kind of joint ([`JointType`]).
    #[serde(rename = "type")]
    pub kind: JointType,
    /// First body (`ground` allowed).
    pub body_i: String,
    /// Second body (`ground` allowed).
    pub body_j: String,
    /// Global initial position of the joint (m).
    pub point: [f64; 3],
    /// Global axis (revolute, locked, driven, prismatic, cylindrical;
    /// normalised).
    pub axis: Option<[f64; 3]>,
    /// Initial relative angle θ0 (rad, default 0; 0 for prismatic); the
    /// held angle of a `locked` joint.
    #[serde(default)]
    pub angle: f64,
    /// `driven`: the prescribed angle θ(t) ([`DriveSpec`]): polynomial
    /// coefficients `[c0, c1, ..]` of `θ(t) = Σ c_k t^k` (rad, rad/s, ..),
    /// a piecewise law `{ pieces = [..] }` or a table `{ table = [..] }`.
    pub drive: Option<DriveSpec>,
}

/// A driven joint's `drive` as written: an array (polynomial
/// coefficients) or a table with `pieces` or `table`
/// ([`crate::mbs::model::drive`] for the laws and their derivatives).
#[derive(Debug, Clone, PartialEq)]
pub enum DriveSpec {
    /// `drive = [c0, c1, ..]`: `θ(t) = Σ c_k t^k`.
    Polynomial(Vec<f64>),
    /// `drive = { pieces = [..] }` or `drive = { table = [..] }`.
    Law(DriveLawSpec),
}

impl<'de> Deserialize<'de> for DriveSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::value::{MapAccessDeserializer, SeqAccessDeserializer};
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = DriveSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "polynomial coefficients [c0, c1, ..], { pieces = [..] } or \
                     { table = [[t, θ], ..] }",
                )
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, a: A) -> Result<DriveSpec, A::Error> {
                Vec::<f64>::deserialize(SeqAccessDeserializer::new(a)).map(DriveSpec::Polynomial)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, a: A) -> Result<DriveSpec, A::Error> {
                DriveLawSpec::deserialize(MapAccessDeserializer::new(a)).map(DriveSpec::Law)
            }
        }
        d.deserialize_any(V)
    }
}

/// `drive = { pieces = [..] }` (a piecewise law) or `drive = { table =
/// [[t, θ], ..] }` (a cubic spline through the rows): exactly one of the
/// two.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveLawSpec {
    /// The pieces in time order; each one's time τ starts at 0 where
    /// the piece starts (the first at t = 0).
    pub pieces: Option<Vec<PieceSpec>>,
    /// Rows `[t, θ]` (s, rad), `t` strictly increasing, at least 4: the
    /// not-a-knot C² cubic spline through them, continued linearly
    /// outside.
    pub table: Option<Vec<[f64; 2]>>,
}

/// One piece of a piecewise drive: `θ = Σ c_k τ^k + Σ a sin(ωτ + φ)` with
/// `τ` the time since the piece's start.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PieceSpec {
    /// End time of the piece (s, absolute): required on every piece but
    /// the last, refused on the last.
    pub until: Option<f64>,
    /// Polynomial coefficients `[c0, c1, ..]` in powers of τ (rad, rad/s,
    /// ..; default none).
    #[serde(default)]
    pub poly: Vec<f64>,
    /// Harmonic terms (default none).
    #[serde(default)]
    pub harmonics: Vec<HarmonicSpec>,
}

/// A harmonic term `amplitude · sin(omega·τ + phase)` of a piece.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HarmonicSpec {
    /// Amplitude (rad).
    pub amplitude: f64,
    /// Angular frequency (rad/s).
    pub omega: f64,
    /// Phase at the piece's start (rad, default 0).
    #[serde(default)]
    pub phase: f64,
}

/// A joint's `type` in a study file. Each maps to one
/// [`crate::mbs::JointKind`] (`locked` and `driven` to a driven revolute).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointType {
    /// A common point (3 equations).
    Spherical,
    /// A common point and a common axis: one rotation left (5 equations).
    Revolute,
    /// A revolute joint held at its initial `angle` (6 equations).
    Locked,
    /// A revolute joint whose angle follows the `drive` law θ(t)
    /// (polynomial, pieces or table; 6 equations).
    Driven,
    /// No relative motion (6 equations).
    Fixed,
    /// A sliding joint along `axis`: one translation left (5 equations).
    Prismatic,
    /// A sliding and turning joint about `axis` (4 equations).
    Cylindrical,
}

/// One `[[scene.markers]]` entry: a named point fixed on a body (for
/// springs, loads and outputs).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerSpec {
    /// Unique marker name.
    pub name: String,
    /// The body it is fixed on (`ground` allowed).
    pub body: String,
    /// Global initial position (m); on a flexible body a node of its
    /// basis.
    pub point: [f64; 3],
}

/// One segment of an actuator's law (paper Eq. 32): on `lower < θ ≤
/// upper` the torque is `value + slope·(anchor − θ)`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentSpec {
    /// Lower end of the segment's joint-angle range (rad).
    pub lower: f64,
    /// Upper end of the range (rad, > `lower`).
    pub upper: f64,
    /// Torque at `θ = anchor` (N·m).
    pub value: f64,
    /// Torque decrease per angle (N·m/rad, default 0).
    #[serde(default)]
    pub slope: f64,
    /// Angle where the torque is `value` (rad, default 0).
    #[serde(default)]
    pub anchor: f64,
}

/// One `[[scene.forces]]` entry, chosen by `type`: `actuator`, `spring`
/// or `load`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, tag = "type", rename_all = "lowercase")]
#[allow(clippy::large_enum_variant)]
pub enum ForceSpec {
    /// A rotational actuator on a revolute joint: the torque law of its
    /// `segments` (Eq. 32, with the `actuators` effect) and a viscous
    /// damping (with the `damping` effect).
    Actuator {
        /// Name for sensitivity parameters (`<name>.damping`).
        name: Option<String>,
        /// The revolute joint it acts on.
        joint: String,
        /// Viscous damping (N·m·s/rad, default 0).
        #[serde(default)]
        damping: f64,
        /// The torque law's segments (default none: no torque).
        #[serde(default)]
        segments: Vec<SegmentSpec>,
    },
    /// A spring-damper between two markers (`marker_i`, `marker_j`; rest
    /// `length` default: the initial distance), along a prismatic or
    /// cylindrical `joint` (rest displacement `length`, default 0, and a
    /// constant actuator `force` along the axis, default 0), or about a
    /// revolute `joint` (a torsion spring: free `angle`, default 0, and a
    /// constant preload `torque`, default 0).
    Spring {
        /// Name for sensitivity parameters (`<name>.stiffness`,
        /// `<name>.damping`).
        name: Option<String>,
        /// First marker (with `marker_j`; not with `joint`).
        marker_i: Option<String>,
        /// Second marker.
        marker_j: Option<String>,
        /// A prismatic or cylindrical joint to act along, or a revolute
        /// joint to act about (instead of the markers).
        joint: Option<String>,
        /// Stiffness (N/m; N·m/rad about a revolute joint).
        stiffness: f64,
        /// Viscous damping (N·s/m; N·m·s/rad about a revolute joint;
        /// default 0).
        #[serde(default)]
        damping: f64,
        /// Rest length (m; default: the initial distance of the markers, or
        /// 0 along a joint).
        length: Option<f64>,
        /// Constant force along a joint's axis (N, default 0).
        force: Option<f64>,
        /// Free angle θ0 of a torsion spring (rad, default 0): τ = −k(θ −
        /// θ0) − cθ̇ + torque.
        angle: Option<f64>,
        /// Constant preload torque of a torsion spring (N·m, default 0),
        /// turning body j positively about the axis.
        torque: Option<f64>,
    },
    /// A force and torque at a body's centre of mass (`body`) or at a
    /// marker (`marker`), in global or body axes (`frame`).
    Load {
        /// The body loaded at its centre of mass (or `marker`).
        body: Option<String>,
        /// The marker loaded (or `body`).
        marker: Option<String>,
        /// Axes of the components: `global` (default) or `body` (turning
        /// with the body).
        frame: Option<crate::mbs::LoadFrame>,
        /// Constant force (N, default 0).
        #[serde(default)]
        force: [f64; 3],
        /// Constant torque (N·m, default 0).
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

/// `[scene.integrator]`: method, tolerances, time span and output times.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    /// Integration method ([`Method`]): `bdf` (default), `tsit45`, `esdirk34`
    /// or `vern65`.
    #[serde(default = "default_method")]
    pub method: Method,
    /// Relative tolerance of the error control (default 1e-6).
    #[serde(default = "default_rtol")]
    pub rtol: f64,
    /// Absolute tolerance (state units; default 1e-8).
    #[serde(default = "default_atol")]
    pub atol: f64,
    /// End time (s, > 0; the run starts at 0).
    pub t_end: f64,
    /// Output interval (s, > 0): rows of `history.csv` at 0, dt_out, ...
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

/// `[scene.outputs]`: the columns of `history.csv` and the plotted one.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Output names, one column group each in this order (default none):
    /// `energy`, `violation`, `kinetic_energy`, `<joint>.angle|rate|reaction`,
    /// `<joint>.displacement|velocity`, `<body>.position|kinetic_energy`,
    /// `<flexible body>.modal|strain_energy`, `<marker>.deflection`
    /// ([`crate::scene::QuantityKind`]).
    #[serde(default)]
    pub quantities: Vec<String>,
    /// A one-column output to plot as an SVG (default: no plot).
    pub plot: Option<String>,
    /// File stem of the plot (default: the plotted output's name), e.g.
    /// `theta` for `theta.svg`.
    pub plot_file: Option<String>,
}
