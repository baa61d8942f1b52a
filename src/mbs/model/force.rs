//! Force elements as data: gravity, the paper's Eq. 32
//! spring-damper-actuator with its piecewise-linear law, linear
//! spring-dampers between markers or along a sliding joint, torsion
//! spring-dampers on revolute joints, and constant
//! or time-tabulated loads (SI units). They are applied by
//! `crate::mbs::forces`.

use crate::error::{Error, Result};
use nalgebra::Vector3;

/// One segment of a piecewise-linear law, written as in the paper's Eq. 32:
/// on `lower < θ ≤ upper` the value is `value + slope·(anchor − θ)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Lower bound of `θ` (rad), excluded.
    pub lower: f64,
    /// Upper bound of `θ` (rad), included.
    pub upper: f64,
    /// Value of the law at `θ = anchor` (N·m).
    pub value: f64,
    /// Slope `k` of the line `value + k·(anchor − θ)` (N·m/rad).
    pub slope: f64,
    /// Angle at which the line takes `value` (rad).
    pub anchor: f64,
}

/// Piecewise-linear law `M(θ)` (Eq. 32 without the damping term): the
/// segments tile an interval of `θ`; outside it the nearest boundary
/// segment extends its line.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLaw {
    /// Segments sorted by `lower`.
    pub segments: Vec<Segment>,
}

impl PiecewiseLaw {
    /// Validates (non-empty, `lower < upper`, finite; sorted by `lower`,
    /// each segment's `upper` is the next one's `lower`: no gap, no
    /// overlap) and sorts. `key` (e.g. `forces[0].segments`) names the
    /// offending segment in errors, with the bounds of both neighbours.
    pub fn new(key: &str, segments: Vec<Segment>) -> Result<PiecewiseLaw> {
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
        // Sorted by lower bound, remembering the written index of each.
        let mut order: Vec<usize> = (0..segments.len()).collect();
        order.sort_by(|&a, &b| segments[a].lower.total_cmp(&segments[b].lower));
        for w in order.windows(2) {
            let (a, b) = (&segments[w[0]], &segments[w[1]]);
            if a.upper != b.lower {
                let what = if a.upper < b.lower {
                    "a gap"
                } else {
                    "an overlap"
                };
                return Err(Error::input(
                    format!("{key}[{}]", w[1]),
                    format!("({}, {}]", b.lower, b.upper),
                    format!(
                        "lower = {} (the upper bound of {key}[{}], ({}, {}]): the segments \
                         must tile the angle range without gaps or overlaps; here {what} \
                         between the two",
                        a.upper, w[0], a.lower, a.upper
                    ),
                ));
            }
        }
        let segments = order.into_iter().map(|k| segments[k].clone()).collect();
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

/// Force elements. Only those the scene's `effects` list asks for exist.
#[derive(Debug, Clone)]
pub enum Force {
    /// Uniform gravity `g` (m/s²) on every moving body.
    Gravity {
        /// Acceleration of gravity, global axes (m/s²).
        g: Vector3<f64>,
    },
    /// Rotational spring-damper-actuator on a revolute joint (paper Eq. 32):
    /// torque on marker j about `z_i`: `τ = −(c·θ̇ + law(θ))` (N·m), the
    /// reaction on marker i. `damping` = c (N·m·s), `law` may be absent.
    Rotational {
        /// Index of the revolute joint into [`Model::joints`](crate::mbs::Model::joints).
        joint: usize,
        /// Piecewise-linear law `law(θ)` (N·m, θ in rad); `None` = none.
        law: Option<PiecewiseLaw>,
        /// Damping coefficient `c` (N·m·s/rad).
        damping: f64,
    },
    /// Linear spring-damper between markers i and j: tension
    /// `F = k(l − l0) + c·l̇` (N), pulling the points together when > 0.
    SpringDamper {
        /// Marker i: index into [`Model::markers`](crate::mbs::Model::markers).
        i: usize,
        /// Marker j: index into [`Model::markers`](crate::mbs::Model::markers).
        j: usize,
        /// Stiffness `k` (N/m).
        stiffness: f64,
        /// Damping coefficient `c` (N·s/m).
        damping: f64,
        /// Free length `l0` (m).
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
        /// Index of the prismatic or cylindrical joint into
        /// [`Model::joints`](crate::mbs::Model::joints).
        joint: usize,
        /// Stiffness `k` (N/m).
        stiffness: f64,
        /// Damping coefficient `c` (N·s/m).
        damping: f64,
        /// Free displacement `s0` (m).
        length: f64,
        /// Constant actuator force `f` (N), pushing the markers apart along `z_i`.
        force: f64,
    },
    /// Torsion spring-damper on a revolute joint: torque on marker j about
    /// `z_i`, `τ = −k·(θ − θ0) − c·θ̇ + τ0` (N·m), the reaction on marker
    /// i, with `θ − θ0` taken in (−π, π] (the joint angle is measured
    /// there: the spring holds within half a turn of `θ0`). Positive `τ`
    /// turns body j in the positive sense about the axis: the natural sign
    /// of a spring of potential `½k(θ − θ0)²`.
    TorsionSpring {
        /// Index of the revolute joint into
        /// [`Model::joints`](crate::mbs::Model::joints).
        joint: usize,
        /// Stiffness `k` (N·m/rad).
        stiffness: f64,
        /// Damping coefficient `c` (N·m·s/rad).
        damping: f64,
        /// Free angle `θ0` (rad).
        angle: f64,
        /// Constant preload torque `τ0` (N·m), turning body j positively.
        torque: f64,
    },
    /// Force (N) at the centre of mass and torque (N·m) on a body,
    /// constant or tabulated in time, with components in global or body
    /// axes (`frame`). On a flexible body the force is distributed in
    /// proportion to mass (as a uniform acceleration field `f/m`, so it
    /// also loads the modes through `i3ᵀ`); the torque acts on the frame.
    BodyLoad {
        /// Index of the body into [`Model::bodies`](crate::mbs::Model::bodies).
        body: usize,
        /// Force and torque, constant or tabulated in time.
        load: Load,
        /// Axes of the load's components.
        frame: LoadFrame,
    },
    /// Force (N) at the point of a marker and torque (N·m) on its body,
    /// constant or tabulated in time, with components in global or body
    /// axes: on the body, the force `f` and the moment `s × f` of the
    /// marker's lever arm `s`, plus the torque; on a flexible node, also
    /// the modal forces `Φ_kᵀAᵀf` and `Ψ_kᵀ(…)τ` of the node.
    MarkerLoad {
        /// Index of the marker into [`Model::markers`](crate::mbs::Model::markers).
        marker: usize,
        /// Force and torque, constant or tabulated in time.
        load: Load,
        /// Axes of the load's components.
        frame: LoadFrame,
    },
}

/// The axes a load's components are given in (a study's `frame`:
/// `global` or `body`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
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
    /// A constant force and torque.
    Constant {
        /// Force (N).
        force: Vector3<f64>,
        /// Torque (N·m).
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
