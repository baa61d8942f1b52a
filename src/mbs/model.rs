//! The assembled description of a rigid multibody system: bodies, markers,
//! joints and force elements, with their validation.
//!
//! Conventions (SI units throughout):
//! - A body's frame sits at its centre of mass; its pose is the global
//!   position `r` (m) and Euler parameters `p`; its velocity is the global
//!   `ṙ` (m/s) and the body-frame angular velocity `ω'` (rad/s).
//! - A marker is a point `s'` (m) and an orthonormal frame (columns x, y, z)
//!   fixed in a body, or in the ground (body `None`, global coordinates).
//! - A joint connects marker `i` to marker `j`. Revolute axes are the
//!   markers' z axes; the relative angle `θ` is the rotation of `j`
//!   relative to `i` about `z_i`, `θ = atan2(z_i·(x_i × x_j), x_i·x_j)`.
//! - Prismatic and cylindrical joints slide along marker i's z axis; the
//!   displacement is `s = z_i·(x_j − x_i)` (m), zero at the start (a
//!   scene makes both markers at the joint point).

use super::energy::Energy;
use super::flex::{Invariants, ModalBasis};
use crate::error::{Error, Result};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

/// The flexible part of a floating-frame body (paper Eqs. 5–6): its modal
/// basis, the inertia invariants and their design derivatives, and the
/// modal damping.
#[derive(Debug, Clone)]
pub struct Flex {
    pub basis: Arc<ModalBasis>,
    pub inv: Invariants,
    /// `d(invariants)/d(design variable)`, one per `basis.derivatives`.
    pub dinv: Vec<Invariants>,
    /// Modal damping ratio ζ of every mode (modal force `−2ζω_j ẇ_j`);
    /// zero unless the scene lists the `damping` effect.
    pub zeta: f64,
    /// Current values of the basis's design variables (rad), for
    /// [`Param::Design`].
    pub design: Vec<f64>,
}

impl Flex {
    /// Invariants (and derivatives) of `basis`.
    pub fn new(basis: ModalBasis, zeta: f64, design: Vec<f64>) -> Flex {
        let (inv, dinv) = Invariants::with_derivatives(&basis);
        Flex {
            basis: Arc::new(basis),
            inv,
            dinv,
            zeta,
            design,
        }
    }
    /// Number of modes.
    pub fn n(&self) -> usize {
        self.basis.n_modes
    }
}

/// A rigid body (or a fixed one, which is part of the ground).
#[derive(Debug, Clone)]
pub struct Body {
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
    /// Inertia tensor about the centre of mass in body axes (kg·m²).
    pub inertia: Matrix3<f64>,
    /// Inverse of `inertia` (computed by [`Body::new`]).
    pub inv_inertia: Matrix3<f64>,
    /// Initial global position of the centre of mass (m).
    pub r0: Vector3<f64>,
    /// Initial Euler parameters (unit).
    pub p0: [f64; 4],
    /// Initial global velocity of the centre of mass (m/s).
    pub v0: Vector3<f64>,
    /// Initial angular velocity in body axes (rad/s).
    pub w0: Vector3<f64>,
    /// Fixed bodies are ground: no coordinates, markers are global.
    pub fixed: bool,
    /// Floating-frame flexibility; `None` for a rigid body. For a flexible
    /// body `r0` is the initial position of the frame origin (the basis's
    /// reference point), not of the centre of mass.
    pub flex: Option<Flex>,
}

impl Body {
    /// A body at rest at `r0` with orientation `p0`; checks mass > 0 and a
    /// symmetric positive definite inertia (Cholesky), with the key prefix
    /// `key` used in errors.
    pub fn new(
        key: &str,
        name: &str,
        mass: f64,
        inertia: Matrix3<f64>,
        pose: (Vector3<f64>, [f64; 4]),
    ) -> Result<Body> {
        if !(mass.is_finite() && mass > 0.0) {
            return Err(Error::input(
                format!("{key}.mass"),
                mass,
                "a finite mass > 0 (kg)",
            ));
        }
        let sym = (inertia - inertia.transpose()).norm() <= 1e-12 * inertia.norm();
        let chol = nalgebra::Cholesky::new(inertia);
        let inv = match (sym, chol) {
            (true, Some(c)) if inertia.iter().all(|v| v.is_finite()) => c.inverse(),
            _ => {
                return Err(Error::input(
                    format!("{key}.inertia"),
                    format!("{:?}", inertia.as_slice()),
                    "a symmetric positive definite 3×3 inertia tensor (kg·m²)",
                ))
            }
        };
        Ok(Body {
            name: name.to_string(),
            mass,
            inertia,
            inv_inertia: inv,
            r0: pose.0,
            p0: pose.1,
            v0: Vector3::zeros(),
            w0: Vector3::zeros(),
            fixed: false,
            flex: None,
        })
    }
}

impl Body {
    /// Initial rotation matrix `A(p0)` (body → global).
    pub fn orientation(&self) -> Matrix3<f64> {
        let p = self.p0;
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(p[0], p[1], p[2], p[3]))
            .to_rotation_matrix()
            .into_inner()
    }
}

/// A point and frame fixed in a body (or in the ground).
#[derive(Debug, Clone)]
pub struct Marker {
    pub name: String,
    /// Body index into [`Model::bodies`]; `None` = ground.
    pub body: Option<usize>,
    /// Position in body axes relative to the centre of mass (m), or the
    /// global position for ground markers.
    pub pos: Vector3<f64>,
    /// Orthonormal frame (columns x, y, z) in body axes.
    pub frame: Matrix3<f64>,
    /// Node of a flexible body's basis the marker sits on (it then moves
    /// and rotates with the modes); `None` on rigid bodies.
    pub node: Option<usize>,
}

/// A prescribed relative angle `θ(t) = Σ c_k t^k` (rad, t in s); a locked
/// revolute joint is the constant polynomial.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    pub coefficients: Vec<f64>,
}

impl Drive {
    /// `(θ, θ̇, θ̈)` at time `t`.
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let (mut f, mut d, mut dd) = (0.0, 0.0, 0.0);
        for &c in self.coefficients.iter().rev() {
            dd = dd * t + d * 2.0;
            d = d * t + f;
            f = f * t + c;
        }
        (f, d, dd)
    }
}

/// Joint types.
#[derive(Debug, Clone, PartialEq)]
pub enum JointKind {
    /// Coincident points (3 equations).
    Spherical,
    /// Coincident points and parallel z axes (5 equations).
    Revolute,
    /// Revolute with the relative angle prescribed (6 equations).
    Driven(Drive),
    /// Coincident points and frames (6 equations).
    Fixed,
    /// Translation along `z_i` only: frames parallel, point j on the line
    /// of marker i's z axis (5 equations).
    Prismatic,
    /// Translation along and rotation about `z_i`: parallel z axes, point
    /// j on the line of marker i's z axis (4 equations).
    Cylindrical,
}

impl JointKind {
    /// Number of constraint equations.
    pub fn equations(&self) -> usize {
        match self {
            JointKind::Spherical => 3,
            JointKind::Cylindrical => 4,
            JointKind::Revolute | JointKind::Prismatic => 5,
            JointKind::Driven(_) | JointKind::Fixed => 6,
        }
    }
    /// Names of the constraint equations, in the order
    /// `super::rows::joint_rows` assembles them: `x`, `y`, `z` the
    /// global components of `x_i − x_j` (coincident points); `xi.zj`,
    /// `yi.zj`, `xi.yj` the dot products of marker axes (parallel axes,
    /// no twist); `angle` the prescribed `θ − f(t)`; `xi.d`, `yi.d` the
    /// offsets `x_i·(x_j − x_i)`, `y_i·(x_j − x_i)` of point j from marker
    /// i's z line. As many names as [`JointKind::equations`].
    pub fn row_names(&self) -> &'static [&'static str] {
        match self {
            JointKind::Spherical => &["x", "y", "z"],
            JointKind::Revolute => &["x", "y", "z", "xi.zj", "yi.zj"],
            JointKind::Driven(_) => &["x", "y", "z", "xi.zj", "yi.zj", "angle"],
            JointKind::Fixed => &["x", "y", "z", "xi.zj", "yi.zj", "xi.yj"],
            JointKind::Cylindrical => &["xi.d", "yi.d", "xi.zj", "yi.zj"],
            JointKind::Prismatic => &["xi.d", "yi.d", "xi.zj", "yi.zj", "xi.yj"],
        }
    }
    /// Whether the joint has a relative rotation angle about z.
    pub fn has_angle(&self) -> bool {
        matches!(
            self,
            JointKind::Revolute | JointKind::Driven(_) | JointKind::Cylindrical
        )
    }
    /// Whether the joint has a displacement along z (prismatic,
    /// cylindrical).
    pub fn has_slide(&self) -> bool {
        matches!(self, JointKind::Prismatic | JointKind::Cylindrical)
    }
}

/// A joint between markers `i` and `j`.
#[derive(Debug, Clone)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    pub i: usize,
    pub j: usize,
}

/// One segment of a piecewise-linear law, written as in the paper's Eq. 32:
/// on `lower < θ ≤ upper` the value is `value + slope·(anchor − θ)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    pub lower: f64,
    pub upper: f64,
    pub value: f64,
    pub slope: f64,
    pub anchor: f64,
}

/// Piecewise-linear law `M(θ)` (Eq. 32 without the damping term). Outside
/// the union of the segments the nearest boundary segment extends its line.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLaw {
    /// Segments sorted by `lower`.
    pub segments: Vec<Segment>,
}

impl PiecewiseLaw {
    /// Validates (non-empty, `lower < upper`, finite) and sorts.
    pub fn new(key: &str, mut segments: Vec<Segment>) -> Result<PiecewiseLaw> {
        if segments.is_empty() {
            return Err(Error::input(key, "[]", "at least one segment"));
        }
        for (k, s) in segments.iter().enumerate() {
            let finite = [s.value, s.slope, s.anchor].iter().all(|v| v.is_finite());
            if s.lower.partial_cmp(&s.upper) != Some(std::cmp::Ordering::Less) || !finite {
                return Err(Error::input(
                    format!("{key}[{k}]"),
                    format!("{s:?}"),
                    "lower < upper and finite value, slope, anchor",
                ));
            }
        }
        segments.sort_by(|a, b| a.lower.total_cmp(&b.lower));
        Ok(PiecewiseLaw { segments })
    }

    /// The segment that applies at `θ` (real value).
    pub fn segment(&self, theta: f64) -> &Segment {
        &self.segments[self.segment_index(theta)]
    }

    /// Index of the segment that applies at `θ`.
    pub fn segment_index(&self, theta: f64) -> usize {
        let segs = &self.segments;
        if let Some(k) = segs
            .iter()
            .position(|s| theta > s.lower && theta <= s.upper)
        {
            return k;
        }
        if theta <= segs[0].lower {
            return 0;
        }
        if theta > segs[segs.len() - 1].upper {
            return segs.len() - 1;
        }
        // A gap between segments: the nearest one below.
        segs.iter().rposition(|s| s.upper < theta).unwrap_or(0)
    }
}

/// A model value that can be a sensitivity parameter. In the right-hand
/// side it is read through [`crate::mbs::Workspace::params`], so that a
/// dual-number value gives the exact parameter derivative `∂f/∂p`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Param {
    /// Stiffness `k` of the spring-damper `forces[i]` (N/m), between
    /// markers or along a joint.
    Stiffness(usize),
    /// Damping of `forces[i]`: `c` of a spring-damper (N·s/m) or of a
    /// rotational actuator (N·m·s).
    Damping(usize),
    /// Mass of `bodies[i]` (kg): translational inertia and weight (the
    /// inertia tensor is a separate datum).
    Mass(usize),
    /// Anchor (breakpoint) of segment `k` of the law of the actuator
    /// `forces[i]`: the `3.12` in `0.10 + 9.00(3.12 − θ)` (rad).
    Anchor(usize, usize),
    /// Design variable `k` (a ply angle, rad) of the modal basis of the
    /// flexible body `bodies[i]`: its exact effect on Λ and the mode
    /// shapes comes from the basis's derivatives (`dΛ/dθ`, `dX/dθ`).
    Design(usize, usize),
    /// One ply angle shared by several flexible bodies (rad): the design
    /// variables `Model::ties[g]` (`(body, variable)` pairs) move
    /// together, so one sensitivity lane gives the derivative with respect
    /// to the shared angle (the sum of the members' lanes).
    Tied(usize),
}

impl Param {
    /// The model's current value of this parameter, if it exists.
    pub fn value(&self, model: &Model) -> Option<f64> {
        match *self {
            Param::Mass(b) => model.bodies.get(b).map(|b| b.mass),
            Param::Stiffness(f) => match model.forces.get(f) {
                Some(Force::SpringDamper { stiffness, .. })
                | Some(Force::JointSpring { stiffness, .. }) => Some(*stiffness),
                _ => None,
            },
            Param::Damping(f) => match model.forces.get(f) {
                Some(Force::SpringDamper { damping, .. })
                | Some(Force::JointSpring { damping, .. })
                | Some(Force::Rotational { damping, .. }) => Some(*damping),
                _ => None,
            },
            Param::Anchor(f, k) => match model.forces.get(f) {
                Some(Force::Rotational { law: Some(l), .. }) => l.segments.get(k).map(|s| s.anchor),
                _ => None,
            },
            Param::Design(b, k) => model
                .bodies
                .get(b)
                .and_then(|b| b.flex.as_ref())
                .and_then(|f| f.design.get(k).copied()),
            Param::Tied(g) => {
                let &(b, k) = model.ties.get(g)?.first()?;
                Param::Design(b, k).value(model)
            }
        }
    }

    /// The design variable of flexible body `body` that this parameter
    /// seeds, if any ([`Param::Design`] of that body, or a member of a
    /// [`Param::Tied`] group).
    pub fn design_of(&self, model: &Model, body: usize) -> Option<usize> {
        match *self {
            Param::Design(b, k) if b == body => Some(k),
            Param::Tied(g) => model
                .ties
                .get(g)?
                .iter()
                .find(|(b, _)| *b == body)
                .map(|(_, k)| *k),
            _ => None,
        }
    }

    /// Whether this is a ply-angle parameter (design or tied design).
    pub fn is_design(&self) -> bool {
        matches!(self, Param::Design(..) | Param::Tied(_))
    }

    /// Set this parameter to `v` in `model` (for finite differences and
    /// studies). A [`Param::Design`] variable only records `v`: the modal
    /// basis must be rebuilt for the new design (its derivatives describe
    /// the old one).
    pub fn set(&self, model: &mut Model, v: f64) {
        match *self {
            Param::Mass(b) => model.bodies[b].mass = v,
            Param::Stiffness(f) => match &mut model.forces[f] {
                Force::SpringDamper { stiffness, .. } | Force::JointSpring { stiffness, .. } => {
                    *stiffness = v
                }
                _ => {}
            },
            Param::Damping(f) => match &mut model.forces[f] {
                Force::SpringDamper { damping, .. }
                | Force::JointSpring { damping, .. }
                | Force::Rotational { damping, .. } => *damping = v,
                _ => {}
            },
            Param::Anchor(f, k) => {
                if let Force::Rotational { law: Some(l), .. } = &mut model.forces[f] {
                    l.segments[k].anchor = v;
                }
            }
            Param::Design(b, k) => {
                if let Some(f) = model.bodies[b].flex.as_mut() {
                    f.design[k] = v;
                }
            }
            Param::Tied(g) => {
                for (b, k) in model.ties[g].clone() {
                    Param::Design(b, k).set(model, v);
                }
            }
        }
    }
}

/// Force elements. Only those the scene's `effects` list asks for exist.
#[derive(Debug, Clone)]
pub enum Force {
    /// Uniform gravity `g` (m/s²) on every moving body.
    Gravity { g: Vector3<f64> },
    /// Rotational spring-damper-actuator on a revolute joint (paper Eq. 32):
    /// torque on marker j about `z_i`: `τ = −(c·θ̇ + law(θ))` (N·m), the
    /// reaction on marker i. `damping` = c (N·m·s), `law` may be absent.
    Rotational {
        joint: usize,
        law: Option<PiecewiseLaw>,
        damping: f64,
    },
    /// Linear spring-damper between markers i and j: tension
    /// `F = k(l − l0) + c·l̇` (N), pulling the points together when > 0.
    SpringDamper {
        i: usize,
        j: usize,
        stiffness: f64,
        damping: f64,
        length: f64,
    },
    /// Translational spring-damper-actuator along the axis `z_i` of the
    /// prismatic or cylindrical joint `joint`: tension
    /// `T = k(s − s0) − f + c·ṡ` (N) with `s` the joint displacement, `s0`
    /// = `length` and `f` = `force` a constant actuator force pushing the
    /// markers apart along `z_i`; `−T z_i` on marker j, `+T z_i` on marker
    /// i and the torque `−T z_i×(x_j − x_i)` on marker i, which makes the
    /// spring the exact gradient of `½k(s − s0)²` also off the axis.
    JointSpring {
        joint: usize,
        stiffness: f64,
        damping: f64,
        length: f64,
        force: f64,
    },
    /// Force (N) at the centre of mass and torque (N·m) on a body,
    /// constant or tabulated in time, with components in global or body
    /// axes (`frame`). On a flexible body the force is distributed in
    /// proportion to mass (as a uniform acceleration field `f/m`, so it
    /// also loads the modes through `i3ᵀ`); the torque acts on the frame.
    BodyLoad {
        body: usize,
        load: Load,
        frame: LoadFrame,
    },
    /// Force (N) at the point of a marker and torque (N·m) on its body,
    /// constant or tabulated in time, with components in global or body
    /// axes: on the body, the force `f` and the moment `s × f` of the
    /// marker's lever arm `s`, plus the torque; on a flexible node, also
    /// the modal forces `Φ_kᵀAᵀf` and `Ψ_kᵀ(…)τ` of the node.
    MarkerLoad {
        marker: usize,
        load: Load,
        frame: LoadFrame,
    },
}

/// The axes a load's components are given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadFrame {
    /// Global axes: the load keeps its direction in space.
    Global,
    /// The body's frame axes (`A` of the rigid body or of the flexible
    /// body's floating frame): a follower load turning with the body.
    Body,
}

/// A force and torque, constant or piecewise linear in time.
#[derive(Debug, Clone, PartialEq)]
pub enum Load {
    Constant {
        force: Vector3<f64>,
        torque: Vector3<f64>,
    },
    /// Rows `(t, [fx, fy, fz, tx, ty, tz])` with increasing `t`; linear
    /// between rows, held at the first and last row outside them.
    Table(Vec<(f64, [f64; 6])>),
}

impl Load {
    /// Force and torque at time `t` (s).
    pub fn eval(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let split = |v: &[f64; 6]| {
            (
                Vector3::new(v[0], v[1], v[2]),
                Vector3::new(v[3], v[4], v[5]),
            )
        };
        match self {
            Load::Constant { force, torque } => (*force, *torque),
            Load::Table(rows) => {
                let k = rows.partition_point(|(tk, _)| *tk <= t);
                if k == 0 {
                    return split(&rows[0].1);
                }
                if k == rows.len() {
                    return split(&rows[k - 1].1);
                }
                let ((t0, a), (t1, b)) = (&rows[k - 1], &rows[k]);
                let f = (t - t0) / (t1 - t0);
                let mut v = [0.0; 6];
                for c in 0..6 {
                    v[c] = a[c] + f * (b[c] - a[c]);
                }
                split(&v)
            }
        }
    }
}

/// The whole rigid model.
#[derive(Debug, Clone, Default)]
pub struct Model {
    pub bodies: Vec<Body>,
    pub markers: Vec<Marker>,
    pub joints: Vec<Joint>,
    pub forces: Vec<Force>,
    /// Baumgarte rate α (1/s): the constraint acceleration equation is
    /// `Φ̈ + 2αΦ̇ + α²Φ = 0` (critically damped drift).
    pub baumgarte: f64,
    /// Quadratic-velocity inertia terms (gyroscopic `ω×Jω` of rigid
    /// bodies; centrifugal and Coriolis couplings of flexible ones): the
    /// scene's `quadratic_velocity` effect.
    pub quadratic_velocity: bool,
    /// Time integrals carried as extra states (after the velocities), so
    /// that their sensitivities come with the integration
    /// (docs/numerics.md, "Responses and optimization").
    pub integrals: Vec<Integral>,
    /// Groups of `(body, design variable)` that [`Param::Tied`] lanes move
    /// together.
    pub ties: Vec<Vec<(usize, usize)>>,
}

/// `∫ scale · Σ terms dt` over energy terms (strain and kinetic energies
/// of bodies, [`Energy`]): the paper's objective Ψ₀ = ∫ 2U dt (Eq. 33) is
/// the strain energies of the flexible bodies with `scale = 2`; the
/// IDAS slider-crank's `G = ∫ T dt` the kinetic energies with 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Integral {
    pub terms: Vec<Energy>,
    pub scale: f64,
}

impl Model {
    /// Index of a marker by name.
    pub fn marker(&self, name: &str) -> Option<usize> {
        self.markers.iter().position(|m| m.name == name)
    }
    /// Index of a body by name.
    pub fn body(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }
    /// Index of a joint by name.
    pub fn joint(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }
    /// Total number of constraint equations.
    pub fn equations(&self) -> usize {
        self.joints.iter().map(|j| j.kind.equations()).sum()
    }
    /// Label of constraint row `r` (rows are assembled joint by joint in
    /// the order of [`Model::joints`]): `<joint>.<equation>` with the
    /// equation named by [`JointKind::row_names`], e.g. `S3.z`; `None`
    /// past the last row.
    pub fn row_label(&self, r: usize) -> Option<String> {
        let mut first = 0;
        for j in &self.joints {
            let names = j.kind.row_names();
            if r < first + names.len() {
                return Some(format!("{}.{}", j.name, names[r - first]));
            }
            first += names.len();
        }
        None
    }
}

/// An orthonormal frame whose z axis is the unit `axis` (x chosen
/// perpendicular to it, deterministic). `axis` must be non-zero.
pub fn frame_from_axis(axis: &Vector3<f64>) -> Matrix3<f64> {
    let z = axis.normalize();
    let trial = if z.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let x = (trial - z * z.dot(&trial)).normalize();
    let y = z.cross(&x);
    Matrix3::from_columns(&[x, y, z])
}

/// Rotation by `angle` about the unit vector `axis` (Rodrigues).
pub fn axis_angle(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(*axis), angle).into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drive_polynomial_derivatives() {
        // θ = 1 + 2t + 3t²: closed form derived in this test.
        let d = Drive {
            coefficients: vec![1.0, 2.0, 3.0],
        };
        let (f, df, ddf) = d.eval(0.5);
        assert!((f - 2.75).abs() < 1e-15);
        assert!((df - 5.0).abs() < 1e-15);
        assert!((ddf - 6.0).abs() < 1e-15);
    }

    #[test]
    fn row_names_match_the_equation_counts_and_label_rows_in_joint_order() {
        let kinds = [
            JointKind::Spherical,
            JointKind::Revolute,
            JointKind::Driven(Drive {
                coefficients: vec![0.0],
            }),
            JointKind::Fixed,
            JointKind::Cylindrical,
            JointKind::Prismatic,
        ];
        for k in &kinds {
            assert_eq!(k.row_names().len(), k.equations(), "{k:?}");
        }
        let joint = |name: &str, kind: JointKind| Joint {
            name: name.into(),
            kind,
            i: 0,
            j: 0,
        };
        let model = Model {
            joints: vec![
                joint("R", JointKind::Revolute),
                joint("S", JointKind::Spherical),
            ],
            ..Model::default()
        };
        let labels: Vec<Option<String>> = (0..9).map(|r| model.row_label(r)).collect();
        assert_eq!(labels[0].as_deref(), Some("R.x"));
        assert_eq!(labels[4].as_deref(), Some("R.yi.zj"));
        assert_eq!(labels[5].as_deref(), Some("S.x"));
        assert_eq!(labels[7].as_deref(), Some("S.z"));
        assert_eq!(labels[8], None);
    }
}
