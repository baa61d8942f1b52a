//! Geometric (dynamic) stiffening of floating-frame bodies: the modal
//! geometric stiffness of the inertial and joint-load prestress, as unit
//! load cases.
//!
//! ## Why
//! The linear floating-frame model (paper Eqs. 5–6) keeps the elastic
//! deformation linear in the modal coordinates `w`, so the stress a body's
//! own rotation puts into it (the axial tension of a spinning beam, the
//! membrane stress of a spinning panel) does not stiffen it: a beam spun
//! up past its first bending frequency diverges (Kane, Ryan & Banerjee,
//! *J. Guidance* 10(2), 1987). The standard remedy keeps the geometric
//! stiffness of that prestress (Wallrapp & Wiedemann, *Nonlinear Dynamics*
//! 2002; Shabana, *Dynamics of Multibody Systems*, 3rd ed., ch. 5 on
//! geometric stiffening; Sharf's second-order modal terms, *J. Guidance*
//! 1996, give the same terms for beams).
//!
//! ## Unit load cases
//! The inertial body force per unit mass at the undeformed point `s`
//! (frame axes) of a frame turning with `ω` (frame axes), accelerating
//! with `ω̇` and with the frame origin accelerating with `a`, under gravity
//! `g`, is `b = −ω×(ω×s) − ω̇×s + Aᵀ(g − a)`. It is linear in the
//! coefficients
//!
//! | case `k` | coefficient `c_k` | body force per unit mass `b_k(s)` | unit of `K_k` |
//! |---|---|---|---|
//! | 0, 1, 2 | `ω_x², ω_y², ω_z²` | `s − e_a s_a` | 1 (1/s² per (rad/s)²) |
//! | 3, 4, 5 | `ω_xω_y, ω_yω_z, ω_zω_x` | `−(e_a s_b + e_b s_a)` | 1 |
//! | 6, 7, 8 | `ω̇_x, ω̇_y, ω̇_z` | `s × e_c` | 1 (1/s² per rad/s²) |
//! | 9, 10, 11 | `(Aᵀ(g − a))_x, _y, _z` | `e_a` | 1/m (1/s² per m/s²) |
//!
//! (`−ω×(ω×s) = |ω|²s − ω(ω·s) = Σ_ab ω_aω_b (δ_ab s − e_a s_b)`.) For
//! each case the basis's source solves the static stress field of the
//! body force `ρ b_k` (held at the body's supports: the clamped root of a
//! beam) and projects the geometric stiffness `K_G,k` of that stress
//! field on the mass-normalized modes: `K_k = Φᵀ K_G,k Φ` (n × n,
//! symmetric). For the cantilever beam of [`crate::beams`] the stress is
//! the axial force `N_k(x) = ∫ₓᴸ ρA b_k,x dξ` and
//! `K_k,ij = ∫₀ᴸ N_k φ_i' φ_j' dx` (both bending planes).
//!
//! ## The modal stiffness at run time
//! `K_geo(ω, ω̇, a) = Σ_k c_k K_k` (1/s²) adds to `Λ` in the modal
//! equations (paper Eq. 6): the elastic force becomes `−(Λ + K_geo) w`.
//! Only the six `ω_aω_b` cases and gravity are forces; the `ω̇` and `a`
//! cases multiply an acceleration, so they enter the mass matrix, in its
//! symmetric places (`M[w_j, ω_c] = (K_{6+c} w)_j`,
//! `M[w_j, ṙ_c] = −Σ_a A_ca (K_{9+a} w)_j`), which is what the
//! foreshortening of the second-order shapes gives in the kinetic energy
//! to first order in `w`. The higher-order terms of the frame equations
//! (the change of the rotational inertia by the foreshortening, order
//! `w²`) are left out, so the total energy is conserved to `O(w²)` only.
//!
//! ## Joint-load prestress
//! The joints load a body at its marker nodes, and that load stresses it
//! too (a beam pulled at its tip by a joint is taut). For every node `P`
//! of the body that carries a joint marker (only when the scene asks for
//! the effect) three more cases follow the twelve above: a unit point
//! force along frame axis `a = x, y, z` at `P`, held as the inertial cases
//! are (the clamped root of a beam; inertia relief on a free–free panel),
//! with `K_{P,a} = Φᵀ K_G(stress of the unit force a at P) Φ` (1/(N·s²)
//! per mass-normalized coordinate, i.e. 1/s² per N). Joint moments are
//! not loaded (forces only): the moment a revolute or locked joint passes
//! does not stress a beam axially nor a plate in its plane to first
//! order. At run time the force of the joints on the body at `P`, in
//! frame axes, is linear in the multipliers, `f_P = Aᵀ Σ_r (∂ṙ-block of
//! row r at P) λ_r`, and the modal equations get `−Σ_a f_P,a K_{P,a} w =
//! −B(w) λ` ([`crate::mbs::constraints`] solves `M v̇ = Q + (Gᵀ − B) λ`).
//! The point cases do not depend on the frame origin.
//!
//! ## Moving the frame origin
//! The cases 0–8 are linear in `s`, so moving the frame origin to `o`
//! (`s → s − o`) changes case `k` by the uniform body force `−b_k(o)`:
//! `K_k → K_k − Σ_a b_k(o)_a K_{9+a}` ([`Geometric::shifted`]).

use crate::error::{Error, Result};
use nalgebra::Vector3;

/// Number of unit load cases (module doc table).
pub const CASES: usize = 12;

/// The names of the unit load cases, in order (module doc table).
pub const CASE_NAMES: [&str; CASES] = [
    "wx2", "wy2", "wz2", "wxwy", "wywz", "wzwx", "dwx", "dwy", "dwz", "bx", "by", "bz",
];

/// The body force per unit mass of unit load case `k` (module doc table)
/// at the frame point `s` (m/s² per unit coefficient).
pub fn case_load(k: usize, s: &Vector3<f64>) -> Vector3<f64> {
    let e = |a: usize| Vector3::ith(a, 1.0);
    match k {
        0..=2 => s - e(k) * s[k],
        3..=5 => {
            let (a, b) = (k - 3, (k - 2) % 3);
            -(e(a) * s[b] + e(b) * s[a])
        }
        6..=8 => s.cross(&e(k - 6)),
        9..=11 => e(k - 9),
        _ => Vector3::zeros(),
    }
}

/// The modal geometric stiffness of the unit load cases of a basis (and
/// its design derivatives): `K_k = Φᵀ K_G,k Φ`, see the module doc.
#[derive(Debug, Clone, PartialEq)]
pub struct Geometric {
    /// Number of modes `n`.
    pub n: usize,
    /// The [`CASES`] matrices `K_k`, n × n each, row-major:
    /// `[(k·n + i)·n + j]` (units in the module doc table).
    pub cases: Vec<f64>,
    /// `dK_k/db` in the layout of `cases`, one per design variable of the
    /// basis, in the order of its `derivatives`.
    pub derivatives: Vec<Vec<f64>>,
    /// The joint nodes `P` with point-force cases (module doc): node
    /// `point_nodes[p]` has its three cases `K_{P,x}, K_{P,y}, K_{P,z}`
    /// as blocks `CASES + 3p + a` of `cases` (and of each derivative),
    /// after the inertial ones.
    pub point_nodes: Vec<usize>,
}

impl Geometric {
    /// Entry `(i, j)` of case `k`.
    #[inline]
    pub fn get(&self, k: usize, i: usize, j: usize) -> f64 {
        self.cases[(k * self.n + i) * self.n + j]
    }

    /// Number of blocks: the inertial cases and three per joint node.
    pub fn blocks(&self) -> usize {
        CASES + 3 * self.point_nodes.len()
    }

    /// Block index of the point case along frame axis `a` at node
    /// `node`, if the node has point cases.
    pub fn point_block(&self, node: usize, a: usize) -> Option<usize> {
        let p = self.point_nodes.iter().position(|&k| k == node)?;
        Some(CASES + 3 * p + a)
    }

    /// Add the point cases of `nodes` (`3 · nodes.len()` blocks of n × n,
    /// row-major, and per design variable the same), after the existing
    /// ones.
    pub fn add_points(&mut self, nodes: &[usize], cases: &[f64], derivatives: &[Vec<f64>]) {
        self.point_nodes.extend_from_slice(nodes);
        self.cases.extend_from_slice(cases);
        for (d, dd) in self.derivatives.iter_mut().zip(derivatives) {
            d.extend_from_slice(dd);
        }
    }

    /// The cases restricted to the modes `keep` (in that order), with
    /// their derivatives.
    pub fn picked(&self, keep: &[usize]) -> Geometric {
        let n = self.n;
        let blocks = self.blocks();
        let pick = |v: &[f64]| -> Vec<f64> {
            (0..blocks)
                .flat_map(|k| {
                    keep.iter()
                        .flat_map(move |&i| keep.iter().map(move |&j| v[(k * n + i) * n + j]))
                })
                .collect()
        };
        Geometric {
            n: keep.len(),
            cases: pick(&self.cases),
            derivatives: self.derivatives.iter().map(|d| pick(d)).collect(),
            point_nodes: self.point_nodes.clone(),
        }
    }

    /// The cases after moving the frame origin to the frame point `o`
    /// (module doc: `K_k → K_k − Σ_a b_k(o)_a K_{9+a}`).
    pub fn shifted(&self, o: &Vector3<f64>) -> Geometric {
        let nn = self.n * self.n;
        let shift = |v: &[f64]| -> Vec<f64> {
            let mut out = v.to_vec();
            for k in 0..9 {
                let b = case_load(k, o);
                for a in 0..3 {
                    if b[a] != 0.0 {
                        for e in 0..nn {
                            out[k * nn + e] -= b[a] * v[(9 + a) * nn + e];
                        }
                    }
                }
            }
            out
        };
        Geometric {
            n: self.n,
            cases: shift(&self.cases),
            derivatives: self.derivatives.iter().map(|d| shift(d)).collect(),
            point_nodes: self.point_nodes.clone(),
        }
    }

    /// Check sizes (`n` modes, `n_derivatives` design variables) and
    /// values; `key` names the basis in errors.
    pub fn validate(&self, key: &str, n: usize, n_derivatives: usize) -> Result<()> {
        let want = self.blocks() * n * n;
        if self.n != n
            || self.cases.len() != want
            || self.derivatives.iter().any(|d| d.len() != want)
            || self.derivatives.len() != n_derivatives
        {
            return Err(Error::input(
                format!("{key}.geometric"),
                format!(
                    "{} modes, {} entries, {} derivatives",
                    self.n,
                    self.cases.len(),
                    self.derivatives.len()
                ),
                format!(
                    "{} blocks of {n} × {n} = {want} entries and {n_derivatives} derivatives",
                    self.blocks()
                ),
            ));
        }
        if let Some(i) = self.cases.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(
                format!("{key}.geometric.cases[{i}]"),
                self.cases[i],
                "finite geometric stiffness entries",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn case_loads_sum_to_the_inertial_body_force() {
        // −ω×(ω×s) − ω̇×s + b: the definition of the module doc.
        let (w, dw, b) = (
            Vector3::new(0.3, -1.2, 2.0),
            Vector3::new(-0.7, 0.4, 1.1),
            Vector3::new(0.5, 9.0, -2.0),
        );
        let s = Vector3::new(1.5, -0.25, 0.8);
        let c = [
            w.x * w.x,
            w.y * w.y,
            w.z * w.z,
            w.x * w.y,
            w.y * w.z,
            w.z * w.x,
            dw.x,
            dw.y,
            dw.z,
            b.x,
            b.y,
            b.z,
        ];
        let sum = (0..CASES).fold(Vector3::zeros(), |acc, k| acc + case_load(k, &s) * c[k]);
        let want = -w.cross(&w.cross(&s)) - dw.cross(&s) + b;
        assert!((sum - want).norm() < 1e-13, "{sum} vs {want}");
    }

    #[test]
    fn shift_moves_linear_cases_by_uniform_ones() {
        // Two modes; uniform cases 9..12 set to distinct constants, the
        // others zero: after the shift case k holds −Σ_a b_k(o)_a K_{9+a}.
        let n = 2;
        let mut cases = vec![0.0; CASES * n * n];
        for a in 0..3 {
            for e in 0..n * n {
                cases[(9 + a) * n * n + e] = (a + 1) as f64 * (e + 1) as f64;
            }
        }
        let g = Geometric {
            n,
            cases,
            derivatives: vec![],
            point_nodes: vec![],
        };
        let o = Vector3::new(0.5, 2.0, -1.0);
        let s = g.shifted(&o);
        for k in 0..9 {
            let b = case_load(k, &o);
            for e in 0..n * n {
                let want = -(0..3).map(|a| b[a] * (a + 1) as f64).sum::<f64>() * (e + 1) as f64;
                assert!((s.cases[k * n * n + e] - want).abs() < 1e-14);
            }
        }
        let p = s.picked(&[1]);
        assert_eq!(p.n, 1);
        assert_eq!(p.get(10, 0, 0), s.get(10, 1, 1));
    }
}
