//! Bodies and markers as data. A body's frame sits at its centre of mass
//! (rigid) or at its basis's reference point (flexible); its pose is the
//! global position `r` (m) and Euler parameters `p`; its velocity the
//! global `ṙ` (m/s) and the body-frame angular velocity `ω'` (rad/s). A
//! marker is a point `s'` (m) and an orthonormal frame (columns x, y, z)
//! fixed in a body, or in the ground (body `None`, global coordinates).

use super::flex::{Invariants, ModalBasis};
use crate::error::{Error, Result};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

/// The flexible part of a floating-frame body (paper Eqs. 5–6): its modal
/// basis, the inertia invariants and their design derivatives, and the
/// modal damping.
#[derive(Debug, Clone)]
pub struct Flex {
    /// The modal basis (nodes, masses, mode shapes, eigenvalues and their
    /// design derivatives), shared by the clones of the body.
    pub basis: Arc<ModalBasis>,
    /// Inertia invariants of `basis` at the current design.
    pub inv: Invariants,
    /// `d(invariants)/d(design variable)`, one per `basis.derivatives`.
    pub dinv: Vec<Invariants>,
    /// Modal damping ratio ζ of every mode (modal force `−2ζω_j ẇ_j`);
    /// zero unless the scene lists the `damping` effect.
    pub zeta: f64,
    /// Current values of the basis's design variables (rad), for
    /// [`Param::Design`](crate::mbs::Param::Design).
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
    /// Name, as looked up by [`Model::body`](crate::mbs::Model::body).
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
    /// Name, as looked up by [`Model::marker`](crate::mbs::Model::marker).
    pub name: String,
    /// Body index into [`Model::bodies`](crate::mbs::Model::bodies); `None` = ground.
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
