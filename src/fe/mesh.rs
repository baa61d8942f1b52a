//! Structured triangle mesh of a rectangular panel with nodes forced at given
//! points (attachment points, the centre, corners of a clamped patch).
//!
//! Panel coordinates: origin at the panel centre, x along the length
//! (e1, `length`), y along the width (e2, `width`), in metres.
//!
//! Grid lines are placed at both edges, at x = 0 / y = 0 and at every forced
//! coordinate; each interval between consecutive lines is then divided into
//! `round(Δ/h)` (at least 1) equal cells, where `h = length / divisions`.
//! Every node of the grid is a mesh node, so every forced point is a node.
//! Each cell is split into two triangles along alternating diagonals
//! (checkerboard "union-jack" pattern), which removes the directional bias of
//! a single diagonal direction. Cell aspect ratios stay within a factor of
//! about two of square unless two forced coordinates lie closer than h/2;
//! [`Mesh::worst_aspect`] reports it.

use crate::error::{require_positive, Error, Result};

/// Input of [`Mesh::structured`].
#[derive(Debug, Clone, PartialEq)]
pub struct MeshParams {
    /// Panel length along x \[m\].
    pub length: f64,
    /// Panel width along y \[m\].
    pub width: f64,
    /// Target number of cells along the length (sets h = length/divisions).
    pub divisions: usize,
    /// Points that must be nodes (panel coordinates, \[m\]).
    pub points: Vec<[f64; 2]>,
}

/// A triangle mesh in panel coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Node coordinates (x, y) \[m\].
    pub nodes: Vec<[f64; 2]>,
    /// Triangles, node indices counter-clockwise.
    pub triangles: Vec<[usize; 3]>,
    /// Panel length \[m\].
    pub length: f64,
    /// Panel width \[m\].
    pub width: f64,
    /// Node of each forced point (same order as `MeshParams::points`).
    pub forced: Vec<usize>,
    /// The node at the panel centre.
    pub centre: usize,
}

/// Largest number of divisions accepted (bounds memory: ~10⁶ nodes).
pub const MAX_DIVISIONS: usize = 1000;

impl Mesh {
    /// Build the structured mesh (module doc). Errors: non-positive or
    /// non-finite sizes (`length`, `width`), `divisions` outside
    /// 1..=[`MAX_DIVISIONS`], a forced point outside the panel
    /// (`attachment_points[k]`).
    pub fn structured(p: &MeshParams) -> Result<Mesh> {
        require_positive("length", p.length)?;
        require_positive("width", p.width)?;
        if p.divisions == 0 || p.divisions > MAX_DIVISIONS {
            return Err(Error::input(
                "divisions",
                p.divisions,
                format!("an integer in 1..={MAX_DIVISIONS}"),
            ));
        }
        let (hx, hy) = (0.5 * p.length, 0.5 * p.width);
        let tol = 1e-9 * p.length.max(p.width);
        for (k, q) in p.points.iter().enumerate() {
            let inside = q[0].is_finite()
                && q[1].is_finite()
                && q[0].abs() <= hx + tol
                && q[1].abs() <= hy + tol;
            if !inside {
                return Err(Error::input(
                    format!("attachment_points[{k}]"),
                    format!("[{}, {}]", q[0], q[1]),
                    format!(
                        "a point inside the panel, |x| <= {hx} and |y| <= {hy} (origin at the centre)"
                    ),
                ));
            }
        }
        let h = p.length / p.divisions as f64;
        let xs = grid_lines(hx, p.points.iter().map(|q| q[0]), h, tol);
        let ys = grid_lines(hy, p.points.iter().map(|q| q[1]), h, tol);
        let (nx, ny) = (xs.len(), ys.len());
        use crate::study::memory;
        memory::require_fits(
            "divisions",
            p.divisions,
            &format!("the panel analysis of {nx} x {ny} nodes (12 KB per DOF, measured)"),
            memory::PANEL_BYTES_PER_DOF * (6 * nx * ny) as f64,
            memory::available_bytes(),
        )?;
        let mut nodes = Vec::with_capacity(nx * ny);
        for &y in &ys {
            for &x in &xs {
                nodes.push([x, y]);
            }
        }
        let id = |i: usize, j: usize| j * nx + i;
        let mut triangles = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let (p00, p10, p11, p01) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if (i + j) % 2 == 0 {
                    triangles.push([p00, p10, p11]);
                    triangles.push([p00, p11, p01]);
                } else {
                    triangles.push([p00, p10, p01]);
                    triangles.push([p10, p11, p01]);
                }
            }
        }
        let locate = |x: f64, v: &[f64]| {
            v.iter()
                .enumerate()
                .min_by(|a, b| (a.1 - x).abs().total_cmp(&(b.1 - x).abs()))
                .map(|(i, _)| i)
                .unwrap_or(0)
        };
        let node_of = |q: [f64; 2]| id(locate(q[0], &xs), locate(q[1], &ys));
        let forced = p.points.iter().map(|&q| node_of(q)).collect();
        let centre = node_of([0.0, 0.0]);
        Ok(Mesh {
            nodes,
            triangles,
            length: p.length,
            width: p.width,
            forced,
            centre,
        })
    }

    /// The node within `1e-9·max(length, width)` of (x, y), if any.
    pub fn node_at(&self, x: f64, y: f64) -> Option<usize> {
        let tol = 1e-9 * self.length.max(self.width);
        self.nodes
            .iter()
            .position(|q| (q[0] - x).abs() <= tol && (q[1] - y).abs() <= tol)
    }

    /// Largest ratio (longest edge) / (altitude onto it) over the triangles
    /// (2.0 for a right isosceles triangle; grows for slivers).
    pub fn worst_aspect(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| self.nodes[i]);
                let e = |a: [f64; 2], b: [f64; 2]| {
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
                };
                let lmax = e(p[0], p[1]).max(e(p[1], p[2])).max(e(p[2], p[0]));
                let area2 = ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                    - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]))
                    .abs();
                lmax * lmax / area2
            })
            .fold(0.0, f64::max)
    }
}

/// Sorted grid coordinates on [−half, half]: the edges, 0, the forced
/// coordinates, and equal subdivisions of each interval with cells close to h.
fn grid_lines(half: f64, forced: impl Iterator<Item = f64>, h: f64, tol: f64) -> Vec<f64> {
    let mut key: Vec<f64> = vec![-half, 0.0, half];
    key.extend(forced.map(|x| x.clamp(-half, half)));
    key.sort_by(f64::total_cmp);
    key.dedup_by(|a, b| (*a - *b).abs() <= tol);
    key[0] = -half;
    let last = key.len() - 1;
    key[last] = half;
    let mut out = vec![key[0]];
    for w in key.windows(2) {
        let n = ((w[1] - w[0]) / h).round().max(1.0) as usize;
        for k in 1..=n {
            out.push(if k == n {
                w[1]
            } else {
                w[0] + (w[1] - w[0]) * k as f64 / n as f64
            });
        }
    }
    out
}
