//! Panel bases shared by content within one scene build.
//!
//! Two flexible panel bodies whose bases have the same inputs get the
//! same [`ModalBasis`]: [`SharedBases`] computes it once and hands the
//! second body a copy. The inputs are everything
//! [`super::BasisBuilder::basis`] reads, compared by content, never by
//! `[[panels]]` name ([`BasisKey`]):
//! - the mesh: node coordinates, triangles, panel length and width and
//!   the centre node (length, width, `divisions` and the attachment
//!   points all act through it: an attachment point adds grid lines, so
//!   two panels with different attachment points share only if their
//!   grids come out the same);
//! - the support (with the patch size);
//! - the design map (which plies each derivative variable sets, and so
//!   the derivative names, e.g. `theta_1_4`);
//! - the laminate at this design (material, thickness and angle of each
//!   ply) and the `[[panels]]` entry's own laminate (the builder's set-up
//!   assembles it once; since `K` and `M` are both taken from the design's
//!   laminate, the basis reads only its ply count, so comparing all of it
//!   is conservative);
//! - the number of modes, the derivative approach (none, `fixed`,
//!   `updated`) and the ply-thickness variables (names, in order);
//! - with geometric stiffening, the mesh nodes at the body's joint points
//!   (the only thing the point-force cases read of them), in order;
//!   without, none.
//!
//! Every real number is compared by its bits (`f64::to_bits`): `0.0` and
//! `-0.0` differ, so a shared basis is bit for bit the one its body would
//! have computed. Not compared: the panel name (it only names errors),
//! the mesh's list of forced nodes (the basis does not read it; the scene
//! finds joint nodes by coordinates) and everything the scene does with
//! the basis afterwards per body: the rigid-mode screening
//! (`rigid_limit`), the frame placement, the damping, and which global
//! design variables the body's derivative lanes feed (each body keeps its
//! own copy and its own lanes).
//!
//! Errors are not shared: a body whose basis fails computes (and reports)
//! its own error.

use super::basis::mesh_joint_nodes;
use crate::fe::{Mesh, Panel, Support};
use crate::laminate::Laminate;
use crate::mbs::ModalBasis;
use crate::modal::ModeUpdate;
use nalgebra::Vector3;

/// The content a panel basis is computed from (module doc).
pub struct BasisKey<'a> {
    panel: &'a Panel,
    laminate: &'a Laminate,
    modes: usize,
    update: Option<ModeUpdate>,
    /// Mesh nodes at the joint points with geometric stiffening; `None`
    /// without it.
    joints: Option<Vec<usize>>,
    thickness: Vec<String>,
}

impl<'a> BasisKey<'a> {
    /// The key of the basis of `panel` laid up as `laminate` (this
    /// design), with `modes` modes, derivatives by `update`, the geometric
    /// stiffness at the panel-frame joint points `geometric` (if any) and
    /// the ply-thickness variables `thickness`.
    pub fn new(
        (panel, laminate): (&'a Panel, &'a Laminate),
        modes: usize,
        update: Option<ModeUpdate>,
        geometric: Option<&[Vector3<f64>]>,
        thickness: &[String],
    ) -> BasisKey<'a> {
        BasisKey {
            panel,
            laminate,
            modes,
            update,
            joints: geometric.map(|p| mesh_joint_nodes(&panel.mesh, p)),
            thickness: thickness.to_vec(),
        }
    }

    /// Whether `self` and `other` describe the same basis.
    pub fn same(&self, other: &BasisKey) -> bool {
        self.modes == other.modes
            && self.update == other.update
            && self.joints == other.joints
            && self.thickness == other.thickness
            && same_input((self.panel, self.laminate), (other.panel, other.laminate))
    }
}

/// Whether two panels laid up as the given laminates have the same mesh,
/// support, design map, `[[panels]]` laminate and design laminate (bits).
pub fn same_input(a: (&Panel, &Laminate), b: (&Panel, &Laminate)) -> bool {
    let (pa, pb) = (a.0, b.0);
    let same_laminate = std::ptr::eq(a.1, b.1) || same_plies(a.1, b.1);
    if std::ptr::eq(pa, pb) {
        return same_laminate;
    }
    same_laminate
        && pa.design == pb.design
        && same_support(&pa.support, &pb.support)
        && same_plies(&pa.laminate, &pb.laminate)
        && same_mesh(&pa.mesh, &pb.mesh)
}

/// Equal bits.
fn bits(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

fn same_plies(a: &Laminate, b: &Laminate) -> bool {
    let (a, b) = (a.plies(), b.plies());
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            let (m, n) = (&p.material, &q.material);
            bits(p.angle, q.angle)
                && bits(p.thickness, q.thickness)
                && [m.e1, m.e2, m.g12, m.g13, m.g23, m.nu12, m.rho]
                    .iter()
                    .zip([n.e1, n.e2, n.g12, n.g13, n.g23, n.nu12, n.rho])
                    .all(|(&x, y)| bits(x, y))
        })
}

fn same_support(a: &Support, b: &Support) -> bool {
    match (a, b) {
        (
            Support::CentralPatch { length, width },
            Support::CentralPatch {
                length: l2,
                width: w2,
            },
        ) => bits(*length, *l2) && bits(*width, *w2),
        _ => a == b,
    }
}

fn same_mesh(a: &Mesh, b: &Mesh) -> bool {
    bits(a.length, b.length)
        && bits(a.width, b.width)
        && a.centre == b.centre
        && a.nodes.len() == b.nodes.len()
        && a.triangles == b.triangles
        && a.nodes
            .iter()
            .zip(&b.nodes)
            .all(|(p, q)| bits(p[0], q[0]) && bits(p[1], q[1]))
}

/// The bases of one scene build, kept for the bodies that may ask for the
/// same content again (module doc).
pub struct SharedBases<'a> {
    /// Per `[[panels]]` entry: whether another body may ask for its
    /// content (the entry is used twice, or another used entry has the
    /// same input at this design). Only these bases are kept (a copy
    /// costs about a millisecond on the SAR panels).
    shareable: Vec<bool>,
    kept: Vec<(BasisKey<'a>, ModalBasis)>,
}

impl<'a> SharedBases<'a> {
    /// For the panels `panels` laid up as `laminates` (one each), of
    /// which entry `i` is the basis of `uses[i]` bodies.
    pub fn new(panels: &'a [Panel], laminates: &'a [Laminate], uses: &[usize]) -> SharedBases<'a> {
        let used = |i: usize| uses.get(i).copied().unwrap_or(0);
        let input = |i: usize| (&panels[i], &laminates[i]);
        let n = panels.len().min(laminates.len());
        let shareable = (0..n)
            .map(|i| {
                used(i) >= 2
                    || (used(i) == 1
                        && (0..n).any(|j| j != i && used(j) > 0 && same_input(input(i), input(j))))
            })
            .collect();
        SharedBases {
            shareable,
            kept: Vec::new(),
        }
    }

    /// Whether entry `i`'s basis may be asked for again.
    pub fn shareable(&self, i: usize) -> bool {
        self.shareable.get(i).copied().unwrap_or(false)
    }

    /// The basis kept for `key`, if one was.
    pub fn find(&self, key: &BasisKey) -> Option<&ModalBasis> {
        self.kept.iter().find(|(k, _)| k.same(key)).map(|(_, b)| b)
    }

    /// Keep a copy of `basis`, computed for `key`.
    pub fn keep(&mut self, key: BasisKey<'a>, basis: &ModalBasis) {
        self.kept.push((key, basis.clone()));
    }
}
