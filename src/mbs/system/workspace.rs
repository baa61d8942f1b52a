//! The data of one right-hand-side evaluation: constraint rows, body and
//! marker kinematics, scratch storage reused across evaluations (one per
//! scalar type, [`Workspace`]), and the rank constants of the
//! constraint-space solve (`crate::mbs::constraints::solve`).

use super::invariants::InvT;
use crate::mbs::math::{Scalar, ShapePlanes, SpdScratch};
use crate::mbs::model::Param;
use nalgebra::{Matrix3, Vector3};

/// Relative pivot threshold for counting the rank of the constraint-space
/// matrix (unit-diagonal scaled): an exactly dependent row gives a pivot at
/// the regularisation level `RANK_REG` plus round-off (~1e-15); a row whose
/// pivot exceeds `RANK_REG + RANK_TOL` is counted as independent. The
/// expected counts of every test mechanism (SAR 6, Andrews 9, four-bar 3,
/// Bricard 1) are reproduced.
pub const RANK_TOL: f64 = 1e-8;

/// Tikhonov regularisation of the scaled constraint-space matrix: keeps
/// the multipliers (and so the accelerations) smooth where the rank
/// changes (singular configurations such as a parallelogram four-bar
/// passing its flat position). It perturbs the accelerations of a
/// well-conditioned mechanism by a relative `O(1e-12/σ²_min)`.
pub const RANK_REG: f64 = 1e-12;

/// Marks a row side without modal Jacobian entries.
pub const RIGID: usize = usize::MAX;

/// One constraint row: value, velocity residual, `γ`, up to two body
/// blocks `(slot, [∂/∂ṙ; ∂/∂ω'])`, the markers of the two sides, and the
/// offsets of the modal Jacobian entries `∂/∂ẇ` of flexible sides in
/// [`Workspace::mjac`] ([`RIGID`] otherwise).
#[derive(Debug, Clone, Copy)]
pub struct Row<T: Scalar> {
    /// Constraint value `Φ` (m for point and line rows, dimensionless for
    /// axis rows, rad for angle rows).
    pub phi: T,
    /// Velocity residual `Φ̇ = G v − ν` (holds `−ν` before assembly adds
    /// the Jacobian-velocity products).
    pub phidot: T,
    /// Acceleration right-hand side `γ` (with the Baumgarte terms
    /// `−2αΦ̇ − α²Φ` once assembled).
    pub gamma: T,
    /// Body blocks of the sides i and j: `(state slot, [∂/∂ṙ (3), ∂/∂ω' (3)])`
    /// (the ω part is global while a row is built, body-frame `ω'` after
    /// assembly); slot `None` for the ground or a fixed body.
    pub blocks: [(Option<usize>, [T; 6]); 2],
    /// Markers `[i, j]` of the joint: indices into
    /// [`Model::markers`](crate::mbs::Model::markers).
    pub markers: [usize; 2],
    /// Per side: offset of its n modal entries `∂/∂ẇ` in
    /// [`Workspace::mjac`], or [`RIGID`].
    pub modal: [usize; 2],
}

/// Scratch storage reused across evaluations (one per scalar type).
#[derive(Debug, Clone)]
pub struct Workspace<T: Scalar> {
    /// Constraint rows of the current evaluation, joint by joint in the
    /// order of [`Model::joints`](crate::mbs::Model::joints).
    pub rows: Vec<Row<T>>,
    /// The constraint-space matrix and then its factor (real parts: the
    /// solve is real, its tangent reuses the factor).
    pub a: Vec<f64>,
    /// The multipliers λ after a solve.
    pub rhs: Vec<T>,
    pub(crate) scale: Vec<f64>,
    /// Real scratch of the solve: right-hand side and λ, accelerations,
    /// and per lane of a dual evaluation λ' and v̇'.
    pub(crate) sol: SolveScratch,
    /// Kinematics of every moving body, indexed by state slot (see
    /// [`System::moving`](crate::mbs::System::moving)).
    pub kin: Vec<BodyKin<T>>,
    /// Kinematics of every marker at the current state.
    pub mk: Vec<MarkerKin<T>>,
    /// Per marker: its node's mode-shape rows `(Φ_k, Ψ_k)` at the current
    /// design seeds (empty for markers not on a flexible node), built once
    /// per evaluation for the kinematics, the constraint rows and the
    /// forces.
    pub(crate) shapes: Vec<NodeShapes<T>>,
    /// The design seeds each marker's `shapes` were built with (`None`
    /// for markers not on a flexible node).
    pub(crate) shape_seeds: Vec<Option<Vec<(usize, T)>>>,
    /// The same shapes as real planes ([`crate::mbs::math::planes`]), for the sums
    /// over the modes.
    pub(crate) planes: Vec<ShapePlanes>,
    /// Per marker: shapes (seeds, rows, planes) built before the current
    /// ones, most recent first, for evaluations that cycle through a few
    /// sets of design seeds.
    #[allow(clippy::type_complexity)]
    pub(crate) shape_spare: Vec<Vec<(Option<Vec<(usize, T)>>, NodeShapes<T>, ShapePlanes)>>,
    /// Per moving body: the constraint rows touching it and their
    /// products with its inverse mass ([`BodyBlock`]).
    pub(crate) blocks: Vec<BodyBlock>,
    /// Scratch for the permutation of the constraint-space solve.
    pub(crate) perm: Vec<f64>,
    /// Modal Jacobian entries of the rows' flexible sides.
    pub mjac: Vec<T>,
    /// The columns of the joint-load prestress `B` (geometric stiffening,
    /// `crate::mbs::constraints::prestress`): `(row, slot, offset)` of each
    /// row side on a joint node with point cases; its n modal entries
    /// `β = Σ_a (Aᵀ∂ṙ)_a K_{P,a} w` are at `offset` in `pvals`.
    pub(crate) pcols: Vec<(usize, usize, usize)>,
    /// The entries of the columns of `pcols`.
    pub(crate) pvals: Vec<T>,
    /// Position of each row in the fill-reducing order.
    pub(crate) inv_order: Vec<usize>,
    /// Per Gram entry of the body blocks (body by body, row by row, the
    /// lower triangle): its index in the permuted constraint-space
    /// matrix `a` (row-major `m × m`, lower triangle).
    pub(crate) scatter: Vec<usize>,
    pub(crate) spd: SpdScratch,
    /// Applied generalized forces, all bodies (velocity layout).
    pub q: Vec<T>,
    /// Per moving body: the Cholesky factor of a flexible body's mass
    /// matrix (empty for rigid bodies).
    pub(crate) mfac: Vec<Vec<T>>,
    /// Per moving body: its invariants in `T` (flexible bodies), lifted
    /// with the design seeds in `inv_seeds`.
    pub(crate) inv: Vec<Option<InvT<T>>>,
    /// The design seeds `inv[s]` was lifted with; the invariants are
    /// lifted again only when an evaluation's seeds differ (fused
    /// sensitivities seed the same unit lanes at every stage).
    pub(crate) inv_seeds: Vec<Vec<(usize, T)>>,
    /// Per moving body: lifts before the current one, most recent first,
    /// with their seeds.
    #[allow(clippy::type_complexity)]
    pub(crate) inv_spare: Vec<Vec<(Vec<(usize, T)>, InvT<T>)>>,
    /// Per moving body: the kinetic energy `½ vᵀMv` of a flexible body,
    /// from its mass matrix before the factorization (zero for rigid
    /// bodies, whose energy [`crate::mbs::dynamics::energy`] computes directly).
    pub(crate) kinetic: Vec<T>,
    /// Rank of the last factorization.
    pub rank: usize,
    /// Parameter values overriding the model's (sensitivity analysis);
    /// empty for plain evaluations.
    pub params: Vec<(Param, T)>,
    /// Frozen segment of each actuator's Eq. 32 law, by force index, while
    /// the integrator treats segment changes as events ([`crate::mbs::segments`]):
    /// the segment's line then extends past its breakpoints, so the
    /// right-hand side is smooth. Empty (or an out-of-range entry): the
    /// segment is picked by the value of θ.
    pub segments: Vec<usize>,
    /// The constraint rows left out of the solve while the integrator has
    /// chosen them anew ([`crate::mbs::watch`]): `drop[r]` for row `r`.
    /// `None`: the system's set ([`System::dropped`](crate::mbs::System::dropped)).
    pub drop: Option<Vec<bool>>,
    /// Per marker: whether its node rotation is computed
    /// ([`System::node_rotations`](crate::mbs::System::node_rotations)).
    pub(crate) rotations: Vec<bool>,
}

/// One body's share of the constraint-space matrix, in real arithmetic:
/// the rows touching the body, their entries `d_i` for its `dof`
/// velocities followed by its applied force `Q` (`b`, `(k + 1) × dof`,
/// real parts; `lanes`, their lanes in a dual evaluation, the lanes of
/// each entry together: `lanes[i · NL + l]`), `w =
/// M⁻¹ b` alike, the Gram block `g_ij = b_i · w_j` (`(k + 1)²`, lower
/// triangle), and the real inverse mass (`minv`, `dof²`; a rigid body
/// keeps `1/m` in `inv_mass` and its inertia in the model).
#[derive(Debug, Clone, Default)]
pub struct BodyBlock {
    pub(crate) rows: Vec<usize>,
    pub(crate) b: Vec<f64>,
    pub(crate) lanes: Vec<f64>,
    pub(crate) w: Vec<f64>,
    pub(crate) g: Vec<f64>,
    pub(crate) minv: Vec<f64>,
    pub(crate) inv_mass: f64,
}

/// Real scratch of the constraint-space solve ([`crate::mbs::constraints::solve`]).
#[derive(Debug, Clone, Default)]
pub struct SolveScratch {
    pub(crate) rhs: Vec<f64>,
    pub(crate) lam: Vec<f64>,
    pub(crate) acc: Vec<f64>,
    pub(crate) tmp: Vec<f64>,
    /// λ' and v̇' of every lane (lane-interleaved, `m × lanes` and
    /// `nvel × lanes`).
    pub(crate) dlam: Vec<f64>,
    pub(crate) dacc: Vec<f64>,
    /// One body's `r₁` of every lane (lane-interleaved, `dof × lanes`).
    pub(crate) r1: Vec<f64>,
    /// One body's `w_iᵀ M' w_i` per row and lane (lane-interleaved).
    pub(crate) quad: Vec<f64>,
    /// Every lane's right-hand side for λ', `D'` diagonal and λ'
    /// (lane-interleaved, `m × lanes` each), and a flexible body's `M'v̇`
    /// (`dof × lanes`).
    pub(crate) lane_rhs: Vec<f64>,
    pub(crate) dd: Vec<f64>,
    pub(crate) lane_lam: Vec<f64>,
    pub(crate) mp: Vec<f64>,
    /// Per row: whether it is left out of the solve (the workspace's set
    /// or the system's), for the tangent.
    pub(crate) dropped: Vec<bool>,
    /// The joint-load prestress force `B λ` (velocity layout, modal
    /// entries only; in a dual evaluation's tangent, every lane's `B'λ`,
    /// lane-major), the iteration's λ and right-hand side.
    pub(crate) bz: Vec<f64>,
    pub(crate) plam: Vec<f64>,
    pub(crate) prhs: Vec<f64>,
}

/// Translational and rotational mode-shape rows of a node (n columns each).
pub type NodeShapes<T> = (Vec<Vector3<T>>, Vec<Vector3<T>>);

/// Kinematics of one body at the current state.
#[derive(Debug, Clone)]
pub struct BodyKin<T: Scalar> {
    /// Global position of the frame origin `r` (m).
    pub r: Vector3<T>,
    /// Rotation matrix `A(p)` (body axes → global).
    pub a: Matrix3<T>,
    /// Global velocity of the frame origin `ṙ` (m/s).
    pub v: Vector3<T>,
    /// Global angular velocity.
    pub w: Vector3<T>,
    /// Body-frame angular velocity.
    pub wb: Vector3<T>,
    /// Modal coordinates and rates (empty for rigid bodies).
    pub q: Vec<T>,
    /// Modal rates `ẇ` (length n; empty for rigid bodies).
    pub qd: Vec<T>,
    /// Design seeds `(variable, δ)` of a flexible body's basis (dual
    /// parts of [`Param::Design`] values; empty in plain evaluations).
    pub design: Vec<(usize, T)>,
}

/// Global kinematics of a marker. On a flexible node whose rotation
/// nothing in the model reads ([`System::node_rotations`](crate::mbs::System::node_rotations):
/// only point-row joints use the marker), [`System::markers_kin`]
/// leaves the node's rotation out: `frame`, `w`, `alpha` and `tangent`
/// are then those of the body frame.
///
/// [`System::markers_kin`]: crate::mbs::System::markers_kin
#[derive(Debug, Clone, Copy)]
pub struct MarkerKin<T: Scalar> {
    /// State slot of the marker's body (index into [`Workspace::kin`]);
    /// `None` for the ground or a fixed body.
    pub slot: Option<usize>,
    /// Global position.
    pub x: Vector3<T>,
    /// Global velocity.
    pub v: Vector3<T>,
    /// Lever arm from the body frame origin (global).
    pub s: Vector3<T>,
    /// Global frame columns.
    pub frame: Matrix3<T>,
    /// Global angular velocity of the marker.
    pub w: Vector3<T>,
    /// Velocity-dependent part of the point's acceleration:
    /// `ω×(ω×s) + 2ω×(AΦẇ)`.
    pub acc: Vector3<T>,
    /// Velocity-dependent part of the marker's angular acceleration:
    /// `ω×(AΨẇ)` (zero on rigid bodies).
    pub alpha: Vector3<T>,
    /// `(body, node)` of a marker on a flexible node.
    pub node: Option<(usize, usize)>,
    /// Tangent operator `T(Ψ_k w)` of the node rotation (identity on
    /// rigid bodies): the marker's angular velocity is `ω + A T Ψ_k ẇ`.
    pub tangent: Matrix3<T>,
}

impl<T: Scalar> Workspace<T> {
    /// An empty workspace (buffers grow on first use).
    pub fn empty() -> Self {
        Workspace {
            rows: Vec::new(),
            a: Vec::new(),
            rhs: Vec::new(),
            scale: Vec::new(),
            sol: Default::default(),
            kin: Vec::new(),
            mk: Vec::new(),
            shapes: Vec::new(),
            shape_seeds: Vec::new(),
            planes: Vec::new(),
            shape_spare: Vec::new(),
            blocks: Vec::new(),
            perm: Vec::new(),
            mjac: Vec::new(),
            mfac: Vec::new(),
            inv: Vec::new(),
            inv_seeds: Vec::new(),
            inv_spare: Vec::new(),
            kinetic: Vec::new(),
            inv_order: Vec::new(),
            scatter: Vec::new(),
            spd: Default::default(),
            q: Vec::new(),
            rank: 0,
            params: Vec::new(),
            segments: Vec::new(),
            drop: None,
            rotations: Vec::new(),
            pcols: Vec::new(),
            pvals: Vec::new(),
        }
    }
}
