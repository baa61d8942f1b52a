//! A closed-form flexible body: the uniform Euler–Bernoulli cantilever
//! beam as a [`ModalBasis`], with its quasi-static deflections.
//!
//! ## Why closed form
//! The beam is the reference body for checking the floating-frame kernel
//! (paper Eqs. 5–6) on its own: its modes, eigenvalues (the Λ of Eq. 6)
//! and static deflections are known exactly, so a simulation error can be
//! told apart from a discretization error of a finite element model.
//! The modes are evaluated in closed form; the only approximation is the
//! lumped-mass quadrature of the inertia invariants, which is made
//! accurate to rounding.
//!
//! ## Model
//! The beam lies along the body x axis from the clamped root `x = 0` (the
//! body-frame origin) to the free tip `x = L`, with bending stiffnesses
//! `EI_z` (deflection `v` along y, small rotation about z = `+v'`) and
//! `EI_y` (deflection `w` along z, small rotation about y = `−w'`) and
//! mass per length `ρA`. No axial or torsion modes, no rotary inertia,
//! no shear deformation (Euler–Bernoulli).
//!
//! ## Modes (closed form)
//! `EI φ'''' = λ ρA φ` with `φ(0) = φ'(0) = 0`, `φ''(L) = φ'''(L) = 0`
//! has the eigenvalues `λ_j = ω_j² = (β_j L)⁴ EI / (ρA L⁴)`, where `β_j L`
//! are the roots of `1 + cos βL cosh βL = 0` ([`cantilever_root`]), and
//! the modes (Blevins, *Formulas for Natural Frequency and Mode Shape*,
//! Table 8-1, clamped-free)
//! `φ_j(x) = C_j [cosh βx − cos βx − σ_j (sinh βx − sin βx)]`,
//! `σ_j = (cosh βL + cos βL) / (sinh βL + sin βL)`.
//! Because `∫₀ᴸ [cosh − cos − σ(sinh − sin)]² dx = L` (same table),
//! `C_j = ±1/√(ρA L)` makes the modes mass-normalized,
//! `∫ ρA φ_i φ_j dx = δ_ij`. Sign convention: the tip displacement is
//! positive, `φ_j(L) = +2/√(ρA L)` for every mode.
//!
//! The textbook form loses all digits beyond `βL ≈ 20` (it subtracts
//! `cosh` and `σ sinh`, both `≈ e^{βx}/2`, with `1 − σ ≈ e^{−βL}`). It is
//! evaluated here as `cosh z − σ sinh z = ((1−σ)e^{z} + (1+σ)e^{−z})/2`
//! with `(1 − σ) e^{βL} = 2 (sin βL − cos βL − e^{−βL}) / D`,
//! `σ = (1 + e^{−2βL} + 2e^{−βL} cos βL) / D`,
//! `D = 1 − e^{−2βL} + 2 e^{−βL} sin βL`: only bounded exponentials
//! `e^{−βL}`, `e^{βx − βL}`, `e^{−βx}` appear, so every mode is accurate to
//! rounding relative to its amplitude.
//!
//! ## Nodes and mass lumping
//! The floating-frame kernel sees the beam through nodes with lumped
//! masses ([`ModalBasis`]). The masses sit at the points of a composite
//! Gauss–Legendre rule (`segments` equal segments × [`GAUSS_POINTS`]
//! points, exact for polynomials of degree 11 on each segment) with
//! weights `ρA w_i`, so that every invariant of
//! [`crate::mbs::Invariants`] is the Gauss quadrature of the
//! corresponding integral of the continuous modes (`mww = I`,
//! `mass = ρA L`, `∫ ρA x φ_j dx`, …) to ~1e-12 when the segments resolve
//! the highest mode ([`Beam::segments_for`]). Zero-mass nodes carry the
//! markers:
//!
//! | node | position |
//! |---|---|
//! | 0 ([`ROOT_NODE`]) | root, `x = 0` |
//! | 1 ([`TIP_NODE`]) | tip, `x = L` |
//! | 2..=10 | stations `x = kL/10`, `k = 1..9` ([`station_node`]) |
//! | 11.. | the quadrature points (masses `ρA w_i`), in increasing `x` |
//!
//! ## Quasi-static deflections
//! [`Beam::static_deflection`] gives the closed-form deflection curves of
//! the cantilever under a tip force, a uniform load and the linearly
//! varying load `p(x) = p_L x / L` (the inertial load of a spin-up about
//! the root with angular acceleration `α`: `|p_L| = ρA α L`, against the
//! sense of rotation), for checking
//! slow-loading simulations against statics.

use crate::error::{Error, Result};
use crate::mbs::model::geometric::Geometric;
use crate::mbs::ModalBasis;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Gauss–Legendre points per segment of the mass-lumping rule (exact for
/// polynomials of degree `2·6 − 1 = 11` on each segment).
pub const GAUSS_POINTS: usize = 6;
/// Node index of the root (`x = 0`, zero mass).
pub const ROOT_NODE: usize = 0;
/// Node index of the tip (`x = L`, zero mass).
pub const TIP_NODE: usize = 1;
/// Number of zero-mass station nodes (root, tip and the nine interior
/// tenths) before the quadrature nodes.
pub const STATION_NODES: usize = 11;

/// The node at the station `x = k L / 10` (`k = 0..=10`): 0 is the root,
/// 10 the tip; `None` for `k > 10`.
pub fn station_node(k: usize) -> Option<usize> {
    match k {
        0 => Some(ROOT_NODE),
        10 => Some(TIP_NODE),
        1..=9 => Some(k + 1),
        _ => None,
    }
}

/// Bending plane of a mode or a load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    /// Deflection `v` along body y, rotation about z (`+v'`); stiffness `EI_z`.
    Y,
    /// Deflection `w` along body z, rotation about y (`−w'`); stiffness `EI_y`.
    Z,
}

/// A static load on the cantilever (in one bending plane).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StaticLoad {
    /// Force `F` (N) at the tip.
    Tip(f64),
    /// Uniform distributed load `q` (N/m).
    Uniform(f64),
    /// Linearly varying load `p(x) = p_L x / L` with tip value `p_L` (N/m).
    Linear(f64),
}

/// A uniform Euler–Bernoulli cantilever beam along body x (see the module
/// doc for axes and conventions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// Length `L` (m).
    pub length: f64,
    /// Bending stiffness for deflection along body z, rotation about y
    /// (N·m²).
    pub ei_y: f64,
    /// Bending stiffness for deflection along body y, rotation about z
    /// (N·m²).
    pub ei_z: f64,
    /// Mass per unit length `ρA` (kg/m).
    pub rho_a: f64,
}

/// `key.name`, or `name` alone when `key` is empty.
fn sub(key: &str, name: &str) -> String {
    if key.is_empty() {
        name.to_string()
    } else {
        format!("{key}.{name}")
    }
}

impl Beam {
    /// Check that length, stiffnesses and mass per length are finite and
    /// positive; `key` prefixes the error keys (empty: none).
    pub fn validate(&self, key: &str) -> Result<()> {
        for (name, v, unit) in [
            ("length", self.length, "m"),
            ("ei_y", self.ei_y, "N·m²"),
            ("ei_z", self.ei_z, "N·m²"),
            ("rho_a", self.rho_a, "kg/m"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::input(
                    sub(key, name),
                    v,
                    format!("a finite value > 0 ({unit})"),
                ));
            }
        }
        Ok(())
    }

    /// Bending stiffness of `plane` (N·m²).
    pub fn stiffness(&self, plane: Plane) -> f64 {
        match plane {
            Plane::Y => self.ei_z,
            Plane::Z => self.ei_y,
        }
    }

    /// Eigenvalue `λ_j = (β_j L)⁴ EI / (ρA L⁴)` (1/s²) of mode `j`
    /// (0-based) in `plane`.
    pub fn eigenvalue(&self, plane: Plane, j: usize) -> f64 {
        let b = cantilever_root(j) / self.length;
        b.powi(4) * self.stiffness(plane) / self.rho_a
    }

    /// Natural circular frequency `ω_j = (β_j L)² √(EI / (ρA L⁴))`
    /// (rad/s) of mode `j` (0-based) in `plane`.
    pub fn frequency(&self, plane: Plane, j: usize) -> f64 {
        let b = cantilever_root(j) / self.length;
        b * b * (self.stiffness(plane) / self.rho_a).sqrt()
    }

    /// Mass-normalized mode `j` (0-based) at `x ∈ [0, L]`: `(φ_j(x),
    /// φ_j'(x))` in 1/√kg and 1/(m·√kg). The shape is the same in both
    /// planes (uniform section); `φ_j(L) > 0`.
    pub fn mode(&self, j: usize, x: f64) -> (f64, f64) {
        let d = ModeFn::new(j, self.length, self.rho_a).eval(x);
        (d[0], d[1])
    }

    /// The basis columns in order: `(plane, j)` of each mode, both planes
    /// merged by increasing frequency, ties with plane Y first.
    pub fn mode_order(&self, modes_per_plane: usize) -> Vec<(Plane, usize)> {
        let mut order: Vec<(Plane, usize)> = [Plane::Y, Plane::Z]
            .iter()
            .flat_map(|&p| (0..modes_per_plane).map(move |j| (p, j)))
            .collect();
        // `sort_by` is stable and plane Y comes first in the list, so equal
        // frequencies keep plane Y first.
        order.sort_by(|a, b| {
            self.eigenvalue(a.0, a.1)
                .total_cmp(&self.eigenvalue(b.0, b.1))
        });
        order
    }

    /// A segment count for which the quadrature of the invariants of the
    /// first `modes_per_plane` modes per plane is accurate to 1e-12 or
    /// better (measured: `|mww − I| < 1e-14` for 4, 8 and 20 modes): the
    /// highest product `φ_i φ_j` oscillates with wavenumber `≤ 2β_n`, and
    /// the 6-point rule's error on one segment of length `h` scales like
    /// `(2β_n h)^{12} / 5·10¹⁵` (Abramowitz & Stegun 25.4.29), so
    /// `2β_n h ≤ 2` suffices: `segments ≥ β_n L`.
    pub fn segments_for(modes_per_plane: usize) -> usize {
        let n = modes_per_plane.max(1);
        (cantilever_root(n - 1).ceil() as usize).max(4)
    }

    /// The modal basis with `modes_per_plane` bending modes in each plane
    /// (`n = 2·modes_per_plane` columns in the order of
    /// [`Beam::mode_order`]), masses lumped at the points of `segments`
    /// equal segments × [`GAUSS_POINTS`] Gauss–Legendre points (see the
    /// module doc for the node list; [`Beam::segments_for`] gives a count
    /// that resolves the modes). Shape components: plane Y modes
    /// `u_y = φ`, `r_z = φ'`; plane Z modes `u_z = φ`, `r_y = −φ'`.
    pub fn basis(&self, modes_per_plane: usize, segments: usize) -> Result<ModalBasis> {
        self.validate("")?;
        if modes_per_plane == 0 {
            return Err(Error::input(
                "modes_per_plane",
                modes_per_plane,
                "at least one bending mode per plane",
            ));
        }
        if segments == 0 {
            return Err(Error::input(
                "segments",
                segments,
                "at least one quadrature segment",
            ));
        }
        let l = self.length;
        let mut xs = vec![0.0, l];
        xs.extend((1..10).map(|k| k as f64 * l / 10.0));
        let mut node_mass = vec![0.0; STATION_NODES];
        let (gx, gw) = gauss_legendre(GAUSS_POINTS);
        let h = l / segments as f64;
        for s in 0..segments {
            for (xi, wi) in gx.iter().zip(&gw) {
                xs.push((s as f64 + 0.5 * (1.0 + xi)) * h);
                node_mass.push(self.rho_a * 0.5 * h * wi);
            }
        }
        let fns: Vec<ModeFn> = (0..modes_per_plane)
            .map(|j| ModeFn::new(j, l, self.rho_a))
            .collect();
        let order = self.mode_order(modes_per_plane);
        let (nn, n) = (xs.len(), order.len());
        let mut shapes = vec![0.0; 6 * nn * n];
        for (k, &x) in xs.iter().enumerate() {
            let vals: Vec<[f64; 4]> = fns.iter().map(|f| f.eval(x)).collect();
            for (c, &(plane, j)) in order.iter().enumerate() {
                let [phi, dphi, ..] = vals[j];
                match plane {
                    Plane::Y => {
                        shapes[(k * 6 + 1) * n + c] = phi;
                        shapes[(k * 6 + 5) * n + c] = dphi;
                    }
                    Plane::Z => {
                        shapes[(k * 6 + 2) * n + c] = phi;
                        shapes[(k * 6 + 4) * n + c] = -dphi;
                    }
                }
            }
        }
        let eigenvalues: Vec<f64> = order.iter().map(|&(p, j)| self.eigenvalue(p, j)).collect();
        if let Some(j) = eigenvalues
            .iter()
            .position(|l| !(l.is_finite() && *l > 0.0))
        {
            return Err(Error::numerical(
                "beams::basis",
                format!(
                    "eigenvalue {j} = {} out of range (L = {l} m, EI_y = {}, EI_z = {} N·m², ρA = {} kg/m)",
                    eigenvalues[j], self.ei_y, self.ei_z, self.rho_a
                ),
            ));
        }
        if let Some(i) = shapes.iter().position(|v| !v.is_finite()) {
            return Err(Error::numerical(
                "beams::basis",
                format!(
                    "mode shape entry {i} = {} (L = {l} m, ρA = {} kg/m)",
                    shapes[i], self.rho_a
                ),
            ));
        }
        Ok(ModalBasis {
            nodes: xs.iter().map(|&x| Vector3::new(x, 0.0, 0.0)).collect(),
            node_mass,
            node_inertia: vec![Vector3::zeros(); nn],
            n_modes: n,
            shapes,
            eigenvalues,
            derivatives: Vec::new(),
            rigid: crate::mbs::RigidScreen::default(),
            geometric: Some(self.geometric(&order, segments)),
        })
    }

    /// The modal geometric stiffness of the unit load cases
    /// ([`crate::mbs::model::geometric`]) for the basis columns `order`:
    /// the body force of case `k` on the beam axis has the axial part
    /// `b_k,x(ξ) = α_k + β_k ξ`, held at the clamped root by the axial
    /// force `N_k(x) = ρA [α_k (L − x) + β_k (L² − x²)/2]` (tension
    /// positive), and `K_k,ij = ∫₀ᴸ N_k φ_i' φ_j' dx` for two modes of the
    /// same plane (zero across planes: `v'` and `w'` are orthogonal
    /// slopes), by the Gauss rule of the mass lumping (`segments` ×
    /// [`GAUSS_POINTS`] points). Only the cases `ω_y²`, `ω_z²` (β = 1)
    /// and the axial body force `b_x` (α = 1) are non-zero for the
    /// clamped root at the frame origin.
    pub fn geometric(&self, order: &[(Plane, usize)], segments: usize) -> Geometric {
        use crate::mbs::model::geometric::{case_load, CASES};
        let (l, n) = (self.length, order.len());
        let fns: Vec<ModeFn> = (0..order.iter().map(|o| o.1 + 1).max().unwrap_or(0))
            .map(|j| ModeFn::new(j, l, self.rho_a))
            .collect();
        let (gx, gw) = gauss_legendre(GAUSS_POINTS);
        let h = l / segments.max(1) as f64;
        // ∫ N_α φ_i'φ_j' and ∫ N_β φ_i'φ_j' with N_α = ρA (L − x) and
        // N_β = ρA (L² − x²)/2.
        let (mut ka, mut kb) = (vec![0.0; n * n], vec![0.0; n * n]);
        for s in 0..segments.max(1) {
            for (xi, wi) in gx.iter().zip(&gw) {
                let x = (s as f64 + 0.5 * (1.0 + xi)) * h;
                let w = 0.5 * h * wi * self.rho_a;
                let d: Vec<f64> = order.iter().map(|&(_, j)| fns[j].eval(x)[1]).collect();
                for (i, oi) in order.iter().enumerate() {
                    for (j, oj) in order.iter().enumerate() {
                        if oi.0 == oj.0 {
                            ka[i * n + j] += w * (l - x) * d[i] * d[j];
                            kb[i * n + j] += w * 0.5 * (l * l - x * x) * d[i] * d[j];
                        }
                    }
                }
            }
        }
        let mut cases = Vec::with_capacity(CASES * n * n);
        for k in 0..CASES {
            let alpha = case_load(k, &Vector3::zeros()).x;
            let beta = case_load(k, &Vector3::x()).x - alpha;
            cases.extend((0..n * n).map(|e| alpha * ka[e] + beta * kb[e]));
        }
        Geometric {
            n,
            cases,
            derivatives: Vec::new(),
            point_nodes: Vec::new(),
        }
    }

    /// The three point-force cases ([`crate::mbs::model::geometric`],
    /// joint-load prestress) of a unit force at the axis point `x = x_p`
    /// for the basis columns `order`: held at the clamped root, a unit
    /// force along body x puts the axial force `N = 1` (tension) into
    /// `[0, x_p]` and none beyond, so `K_{P,x,ij} = ∫₀^{x_p} φ_i' φ_j' dx`
    /// (same plane, by `segments` × [`GAUSS_POINTS`] Gauss points on
    /// `[0, x_p]`); a transverse unit force bends the beam without axial
    /// force, so `K_{P,y} = K_{P,z} = 0`. Three n × n blocks, row-major
    /// (1/s² per N).
    pub fn point_cases(&self, order: &[(Plane, usize)], segments: usize, x_p: f64) -> Vec<f64> {
        let n = order.len();
        let fns: Vec<ModeFn> = (0..order.iter().map(|o| o.1 + 1).max().unwrap_or(0))
            .map(|j| ModeFn::new(j, self.length, self.rho_a))
            .collect();
        let (gx, gw) = gauss_legendre(GAUSS_POINTS);
        let x_p = x_p.clamp(0.0, self.length);
        let h = x_p / segments.max(1) as f64;
        let mut out = vec![0.0; 3 * n * n];
        for s in 0..segments.max(1) {
            for (xi, wi) in gx.iter().zip(&gw) {
                let x = (s as f64 + 0.5 * (1.0 + xi)) * h;
                let w = 0.5 * h * wi;
                let d: Vec<f64> = order.iter().map(|&(_, j)| fns[j].eval(x)[1]).collect();
                for (i, oi) in order.iter().enumerate() {
                    for (j, oj) in order.iter().enumerate() {
                        if oi.0 == oj.0 {
                            out[i * n + j] += w * d[i] * d[j];
                        }
                    }
                }
            }
        }
        out
    }

    /// Static deflection `(v(x), v'(x))` (m, rad) in `plane` of the
    /// clamped-free beam under `load`, with `EI` of that plane (rotation
    /// about z is `+v'` in plane Y, about y is `−v'` in plane Z).
    /// Solutions of `EI v'''' = p` with `v(0) = v'(0) = 0`,
    /// `v''(L) = 0`, `EI v'''(L) = −F`, derived by integrating the beam
    /// equation; the tip values are those of Gere & Timoshenko,
    /// *Mechanics of Materials*, App. G, Table G-1 (cantilever beams):
    /// - tip force `F`: `v = F x² (3L − x) / (6 EI)`, tip `F L³ / (3 EI)`;
    /// - uniform `q`: `v = q x² (6L² − 4Lx + x²) / (24 EI)`, tip
    ///   `q L⁴ / (8 EI)`;
    /// - linear `p_L x / L`: `v = p_L x² (20L³ − 10L²x + x³) / (120 L EI)`,
    ///   tip `11 p_L L⁴ / (120 EI)`. Derivation: `v = p_L x⁵/(120 L EI)
    ///   + c₃x³ + c₂x²`; `v'''(L) = 0` gives `c₃ = −p_L L/(12 EI)`,
    ///   `v''(L) = 0` gives `c₂ = p_L L²/(6 EI)`. Check by superposition
    ///   with Table G-1: uniform `p_L` minus the load decreasing linearly
    ///   from `p_L` at the root to 0 at the tip, `(1/8 − 1/30) p_L L⁴/EI`.
    pub fn static_deflection(&self, plane: Plane, load: StaticLoad, x: f64) -> (f64, f64) {
        let (l, ei) = (self.length, self.stiffness(plane));
        match load {
            StaticLoad::Tip(f) => (
                f * x * x * (3.0 * l - x) / (6.0 * ei),
                f * x * (2.0 * l - x) / (2.0 * ei),
            ),
            StaticLoad::Uniform(q) => (
                q * x * x * (6.0 * l * l - 4.0 * l * x + x * x) / (24.0 * ei),
                q * x * (3.0 * l * l - 3.0 * l * x + x * x) / (6.0 * ei),
            ),
            StaticLoad::Linear(p) => (
                p * x * x * (20.0 * l.powi(3) - 10.0 * l * l * x + x.powi(3)) / (120.0 * l * ei),
                p * x * (8.0 * l.powi(3) - 6.0 * l * l * x + x.powi(3)) / (24.0 * l * ei),
            ),
        }
    }

    /// Tip deflection under a tip force `F` (N): `F L³ / (3 EI)` (m).
    pub fn tip_deflection_tip_load(&self, plane: Plane, force: f64) -> f64 {
        self.static_deflection(plane, StaticLoad::Tip(force), self.length)
            .0
    }

    /// Tip deflection under a uniform load `q` (N/m): `q L⁴ / (8 EI)` (m).
    pub fn tip_deflection_uniform_load(&self, plane: Plane, q: f64) -> f64 {
        self.static_deflection(plane, StaticLoad::Uniform(q), self.length)
            .0
    }

    /// Tip deflection under `p(x) = p_L x / L` (N/m):
    /// `11 p_L L⁴ / (120 EI)` (m). A spin-up about the root's z axis with
    /// angular acceleration `α` loads the beam (in the body frame) with
    /// `p_L = −ρA α L` along y.
    pub fn tip_deflection_linear_load(&self, plane: Plane, p_l: f64) -> f64 {
        self.static_deflection(plane, StaticLoad::Linear(p_l), self.length)
            .0
    }
}

/// `β_j L`, the `j`-th (0-based) positive root of
/// `1 + cos βL cosh βL = 0` (cantilever frequency equation; 1.8751,
/// 4.6941, 7.8548, …; tends to `(j + ½)π`). Solved as
/// `cos b + 1/cosh b = 0` (same roots, bounded terms) by Newton's method
/// safeguarded with bisection in the bracket `[jπ, (j+1)π]`, which holds
/// exactly one root; converges to rounding for every `j`.
pub fn cantilever_root(j: usize) -> f64 {
    let f = |b: f64| {
        let sech = 1.0 / b.cosh();
        (b.cos() + sech, -b.sin() - sech * b.tanh())
    };
    let (mut lo, mut hi) = (j as f64 * PI, (j + 1) as f64 * PI);
    let lo_positive = f(lo).0 > 0.0;
    let mut b = if j == 0 { 1.875 } else { (j as f64 + 0.5) * PI };
    for _ in 0..200 {
        let (fb, db) = f(b);
        if fb == 0.0 {
            return b;
        }
        if (fb > 0.0) == lo_positive {
            lo = b;
        } else {
            hi = b;
        }
        let mut next = b - fb / db;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - b).abs() <= 2.0 * f64::EPSILON * b {
            return next;
        }
        b = next;
    }
    b
}

/// Nodes `ξ_i` (increasing) and weights `w_i` of the `n`-point
/// Gauss–Legendre rule on `[−1, 1]`: roots of `P_n` by Newton's method
/// from Tricomi's estimate `cos(π(i + ¾)/(n + ½))`, `w_i = 2 / ((1 − ξ²)
/// P_n'(ξ)²)` (Abramowitz & Stegun 25.4.29).
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut xs = vec![0.0; n];
    let mut ws = vec![0.0; n];
    let legendre = |x: f64| {
        // (P_n(x), P_n'(x)) by the three-term recurrence.
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
            p0 = p1;
            p1 = p2;
        }
        let pn = if n == 0 { 1.0 } else { p1 };
        (pn, n as f64 * (x * pn - p0) / (x * x - 1.0))
    };
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(x);
            let dx = p / dp;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        let (_, dp) = legendre(x);
        xs[n - 1 - i] = x;
        ws[n - 1 - i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
    (xs, ws)
}

/// One mass-normalized cantilever mode in the stable form of the module
/// doc.
struct ModeFn {
    /// `β` (1/m).
    beta: f64,
    /// `βL`.
    bl: f64,
    /// `σ`.
    sigma: f64,
    /// `(1 − σ) e^{βL}`.
    ep: f64,
    /// `±1/√(ρA L)` (sign: positive tip displacement).
    scale: f64,
}

impl ModeFn {
    fn new(j: usize, length: f64, rho_a: f64) -> ModeFn {
        let bl = cantilever_root(j);
        let e = (-bl).exp();
        let (s, c) = bl.sin_cos();
        let d = 1.0 - e * e + 2.0 * e * s;
        let sigma = (1.0 + e * e + 2.0 * e * c) / d;
        let ep = 2.0 * (s - c - e) / d;
        // Unscaled tip value: φ''(L) = 0 gives φ(L) = 2(σ sin βL − cos βL) = ±2.
        let tip = sigma * s - c;
        let scale = tip.signum() / (rho_a * length).sqrt();
        ModeFn {
            beta: bl / length,
            bl,
            sigma,
            ep,
            scale,
        }
    }

    /// `[φ, φ', φ'', φ''']` at `x` (per √kg, per m^k).
    fn eval(&self, x: f64) -> [f64; 4] {
        let z = self.beta * x;
        let (s, c) = z.sin_cos();
        let e_plus = self.ep * (z - self.bl).exp();
        let e_minus = (1.0 + self.sigma) * (-z).exp();
        let even = 0.5 * (e_plus + e_minus);
        let odd = 0.5 * (e_plus - e_minus);
        let (b, k) = (self.beta, self.scale);
        [
            k * (even - c + self.sigma * s),
            k * b * (odd + s + self.sigma * c),
            k * b * b * (even + c - self.sigma * s),
            k * b * b * b * (odd - s - self.sigma * c),
        ]
    }
}

#[cfg(test)]
#[path = "beams_tests.rs"]
mod tests;
