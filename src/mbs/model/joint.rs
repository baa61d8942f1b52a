//! Joints as data, and the one table of joint kinds.
//!
//! A joint connects marker `i` to marker `j`. Revolute axes are the
//! markers' z axes; the relative angle `θ` is the rotation of `j`
//! relative to `i` about `z_i`, `θ = atan2(z_i·(x_i × x_j), x_i·x_j)`.
//! Prismatic and cylindrical joints slide along marker i's z axis; the
//! displacement is `s = z_i·(x_j − x_i)` (m), zero at the start (a scene
//! makes both markers at the joint point).
//!
//! Every kind is a list of row blocks ([`JointKind::blocks`], the only
//! match over the kinds): its equation count, row names and flags
//! ([`JointKind::has_angle`], [`JointKind::has_slide`],
//! [`JointKind::reads_frames`]) follow from that list, and the constraint
//! layer turns each block into its rows (`crate::mbs::constraints::rows`).
//!
//! | kind | blocks | rows |
//! |---|---|---|
//! | spherical | point | `x_i − x_j = 0` (3) |
//! | revolute | point, parallel | + `x_i·z_j = 0`, `y_i·z_j = 0` (5) |
//! | driven | point, parallel, angle | + `θ − f(t) = 0` (6), `f` a [`Drive`] |
//! | fixed | point, parallel, twist | revolute + `x_i·y_j = 0` (6) |
//! | cylindrical | line, parallel | `x_i·d = 0`, `y_i·d = 0` with `d = x_j − x_i`, + `x_i·z_j = 0`, `y_i·z_j = 0` (4) |
//! | prismatic | line, parallel, twist | cylindrical + `x_i·y_j = 0` (5) |

use super::drive::Drive;

/// A block of constraint rows between two markers: the unit joint kinds
/// are made of. The rows of a block are named (for labels of reactions
/// and redundant rows) by [`RowBlock::names`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowBlock {
    /// Coincident points `x_i − x_j = 0`, global components `x`, `y`, `z`.
    Point,
    /// Point j on the line of marker i's z axis: `x_i·d = 0`, `y_i·d = 0`
    /// with `d = x_j − x_i` (`xi.d`, `yi.d`).
    Line,
    /// Parallel z axes: `x_i·z_j = 0`, `y_i·z_j = 0` (`xi.zj`, `yi.zj`).
    Parallel,
    /// No twist about the z axes: `x_i·y_j = 0` (`xi.yj`).
    Twist,
    /// The relative angle prescribed by the joint's [`Drive`]:
    /// `θ − f(t) = 0` (`angle`).
    Angle,
}

impl RowBlock {
    /// Names of the block's rows, in the order they are assembled.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            RowBlock::Point => &["x", "y", "z"],
            RowBlock::Line => &["xi.d", "yi.d"],
            RowBlock::Parallel => &["xi.zj", "yi.zj"],
            RowBlock::Twist => &["xi.yj"],
            RowBlock::Angle => &["angle"],
        }
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
    /// The row blocks of this kind, in the order they are assembled: the
    /// table every other property of a kind follows from (the module
    /// docs show it).
    pub fn blocks(&self) -> &'static [RowBlock] {
        use RowBlock::{Angle, Line, Parallel, Point, Twist};
        match self {
            JointKind::Spherical => &[Point],
            JointKind::Revolute => &[Point, Parallel],
            JointKind::Driven(_) => &[Point, Parallel, Angle],
            JointKind::Fixed => &[Point, Parallel, Twist],
            JointKind::Cylindrical => &[Line, Parallel],
            JointKind::Prismatic => &[Line, Parallel, Twist],
        }
    }
    /// The prescribed angle of a kind with an [`RowBlock::Angle`] block.
    pub fn drive(&self) -> Option<&Drive> {
        match self {
            JointKind::Driven(d) => Some(d),
            _ => None,
        }
    }
    /// Number of constraint equations (rows of all blocks).
    pub fn equations(&self) -> usize {
        self.blocks().iter().map(|b| b.names().len()).sum()
    }
    /// Names of the constraint equations, in assembly order: the
    /// [`RowBlock::names`] of every block. As many names as
    /// [`JointKind::equations`].
    pub fn row_names(&self) -> impl Iterator<Item = &'static str> {
        self.blocks().iter().flat_map(|b| b.names().iter().copied())
    }
    /// Whether the joint has a relative rotation angle about z: its z
    /// axes are kept parallel ([`RowBlock::Parallel`]) and no twist row
    /// locks the rotation about them (a driven angle is still an angle).
    pub fn has_angle(&self) -> bool {
        let b = self.blocks();
        b.contains(&RowBlock::Parallel) && !b.contains(&RowBlock::Twist)
    }
    /// Whether the joint has a displacement along z: point j is kept on
    /// marker i's z line ([`RowBlock::Line`]) rather than at its point.
    pub fn has_slide(&self) -> bool {
        self.blocks().contains(&RowBlock::Line)
    }
    /// Whether the joint's rows read the marker frames (every block but
    /// [`RowBlock::Point`]): the joint then needs an axis, and a marker
    /// on a flexible node needs its node rotation.
    pub fn reads_frames(&self) -> bool {
        self.blocks().iter().any(|b| *b != RowBlock::Point)
    }
}

#[derive(Debug, Clone)]
/// A joint connecting marker `i` to marker `j` (see the module doc for
/// the kinds, their rows, `θ` and `s`).
pub struct Joint {
    /// Name, as looked up by [`Model::joint`](crate::mbs::Model::joint) and used in row labels.
    pub name: String,
    /// Kind of joint ([`JointKind::blocks`] gives its rows).
    pub kind: JointKind,
    /// Marker i (the reference side: axis `z_i`): index into
    /// [`Model::markers`](crate::mbs::Model::markers).
    pub i: usize,
    /// Marker j: index into [`Model::markers`](crate::mbs::Model::markers).
    pub j: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_follow_from_the_blocks() {
        let driven = JointKind::Driven(Drive::Polynomial(vec![0.0]));
        let angle = [true, true, false, true, false, false];
        let slide = [false, false, false, true, true, false];
        let kinds = [
            JointKind::Revolute,
            driven,
            JointKind::Fixed,
            JointKind::Cylindrical,
            JointKind::Prismatic,
            JointKind::Spherical,
        ];
        for (k, kind) in kinds.iter().enumerate() {
            assert_eq!(kind.has_angle(), angle[k], "{kind:?}");
            assert_eq!(kind.has_slide(), slide[k], "{kind:?}");
            assert_eq!(kind.reads_frames(), k < 5, "{kind:?}");
        }
    }
}
