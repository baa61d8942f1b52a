//! The laminated flat shell triangle: 3 nodes, 6 DOF per node.
//!
//! Node DOF order: `u, v, w, θx, θy, θz` (translations \[m\], rotations about
//! the global axes \[rad\]); element DOF `6·i + c` for local node i.
//!
//! # Kinematics (Mindlin–Reissner)
//! `u(z) = u + z βx`, `v(z) = v + z βy` with `βx = θy`, `βy = −θx`.
//! Generalized strains (8, order of [`Mat8`]):
//! `ε = [u,x, v,y, u,y + v,x]`, `κ = [βx,x, βy,y, βx,y + βy,x]`,
//! `γ = [w,x + βx, w,y + βy]`, with the section law
//! `[N; M; Q] = [[A, B, 0], [B, D, 0], [0, 0, S]] [ε; κ; γ]` from
//! [`crate::laminate::Stiffness`].
//!
//! # Choice of element: stabilised DSG3
//! Membrane and bending use the linear (constant-strain) interpolation.
//! Transverse shear uses the discrete shear gap method (DSG3, Bletzinger,
//! Bischoff & Ramm 2000): the shear "gap" `Δw_j = (w_j − w_r) +
//! ∫_r^j β·dx` (trapezoidal, exact for linear β) is interpolated linearly,
//! `γ = Σ_j ∇N_j Δw_j`. It reproduces every constant shear state and gives
//! γ = 0 exactly for every Kirchhoff displacement field of the element,
//! which is what removes shear locking. DSG3 depends on the reference node r;
//! we average the three choices of r, which makes the element invariant to
//! node numbering at no cost. The shear stiffness is finally scaled by
//! `h²/(h² + α ℓ²)` (ℓ = longest edge, α = [`SHEAR_STABILISATION`];
//! Lyly, Stenberg & Vihinen 1993), which removes the residual over-stiffness
//! of DSG3 on coarse meshes of very thin plates and tends to 1 as ℓ → 0, so
//! the FSDT solution is recovered at convergence.
//!
//! Why not MITC3: Lee & Bathe (2004) and Lee, Lee & Bathe (2014, the MITC3+
//! paper) report that MITC3 is still noticeably stiff for thin plates on
//! coarse and distorted meshes, and MITC3+ needs a cubic bubble for the
//! rotations (internal DOF to condense). DSG3 plus stabilisation is a
//! constant-B element: all its operators are
//! constant, so K = A·GᵀCG exactly with one evaluation, and the ply-angle
//! derivative (paper Eq. 20) is the same product with C' (no quadrature).
//!
//! # Membrane and drilling
//! The membrane is the constant-strain triangle with a drilling rotation
//! tied to the in-plane rotation `ω = ½(v,x − u,y)` by the Hughes–Brezzi
//! penalty `½ γ_d ∫ (θz − ω)² dA` (exact integral of the linear θz). With
//! `γ_d = DRILLING_PENALTY · Ā`, `Ā = (A11 + A22 + 2A66)/4` (independent of
//! the ply angles: `Q̄11 + Q̄22 + 2Q̄66 = 2(U1 + U5)`), the term is invariant
//! under the design and contributes nothing to dK/dθ. Rigid rotations and
//! constant strain states have θz = ω, so the patch test and rigid-body
//! modes are unaffected. The CST is stiff in in-plane bending; the panel's
//! low modes are flexural and, for symmetric lay-ups (B = 0), do not
//! involve the membrane at all.
//!
//! # Mass
//! Lumped by the HRZ procedure (Hinton, Rock & Zienkiewicz 1976): the
//! diagonal of the consistent matrix of the linear triangle is m/6 per node
//! and direction, scaled so each direction carries the element mass m: m/3
//! per node for u, v, w; likewise `I A/3` for θx, θy with the rotary inertia
//! `I = Σ ρ ∫ z² dz`. The consistent drilling inertia is zero; we use the
//! polar moment of the node's tributary patch taken as a square of area A/3:
//! `J = (m/3)·(A/3)/6` (vanishes as the mesh is refined, keeps M definite).
//! Coupling inertia of unsymmetric lay-ups (`Σ ρ ∫ z dz`) is not lumped.

use crate::error::{Error, Result};
use crate::laminate::Stiffness;
use nalgebra::{SMatrix, SVector};

/// 8×8 section stiffness `[[A, B, 0], [B, D, 0], [0, 0, S]]`.
pub type Mat8 = SMatrix<f64, 8, 8>;
/// Generalized-strain operator of an element, 8 × 18.
pub type Mat8x18 = SMatrix<f64, 8, 18>;
/// Element matrix, 18 × 18.
pub type Mat18 = SMatrix<f64, 18, 18>;
/// Element vector, 18.
pub type Vec18 = SVector<f64, 18>;

/// Element DOF of the membrane block: (u, v) of nodes 0, 1, 2.
pub const MEMBRANE_DOF: [usize; 6] = [0, 1, 6, 7, 12, 13];
/// Element DOF of the bending block: (θx, θy) of nodes 0, 1, 2.
pub const BENDING_DOF: [usize; 6] = [3, 4, 9, 10, 15, 16];
/// Element DOF of the shear block: (w, θx, θy) of nodes 0, 1, 2.
pub const SHEAR_DOF: [usize; 9] = [2, 3, 4, 8, 9, 10, 14, 15, 16];

/// The non-zero blocks of the strain operator G: membrane `gm` (3×6 on
/// [`MEMBRANE_DOF`]), bending `gb` (3×6 on [`BENDING_DOF`]), shear `gs`
/// (2×9 on [`SHEAR_DOF`]). Every other entry of G is zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompactOps {
    /// Membrane strains (εxx, εyy, γxy) from the in-plane DOFs (1/m).
    pub gm: SMatrix<f64, 3, 6>,
    /// Curvatures (κxx, κyy, κxy) from the rotation DOFs (1/m).
    pub gb: SMatrix<f64, 3, 6>,
    /// Transverse shear strains (γxz, γyz) from w and the rotations.
    pub gs: SMatrix<f64, 2, 9>,
}

/// α of the shear stabilisation `h²/(h² + α ℓ²)`: 0.1 is the value
/// recommended by Lyly, Stenberg & Vihinen (1993) and used for DSG3 by
/// Nguyen-Thoi et al. (CS-DSG3, 2012).
pub const SHEAR_STABILISATION: f64 = 0.1;

/// Drilling penalty relative to Ā ≈ 1.9 G h (isotropic): 0.05 gives about
/// G h/10. Hughes & Brezzi (1989) show any γ > 0 converges; full strength
/// (γ = G) stiffens the CST in in-plane bending, while a much smaller value
/// lowers the spurious drilling frequencies towards the flexural band.
pub const DRILLING_PENALTY: f64 = 0.05;

/// The 8×8 section matrix of a laminate stiffness (paper Eq. 20's D).
pub fn section_matrix(st: &Stiffness) -> Mat8 {
    let mut c = Mat8::zeros();
    c.fixed_view_mut::<3, 3>(0, 0).copy_from(&st.a);
    c.fixed_view_mut::<3, 3>(0, 3).copy_from(&st.b);
    c.fixed_view_mut::<3, 3>(3, 0).copy_from(&st.b);
    c.fixed_view_mut::<3, 3>(3, 3).copy_from(&st.d);
    c.fixed_view_mut::<2, 2>(6, 6).copy_from(&st.s);
    c
}

/// A flat triangle in panel coordinates with its constant operators.
#[derive(Debug, Clone, Copy)]
pub struct Triangle {
    /// Vertex coordinates \[m\], counter-clockwise.
    pub x: [[f64; 2]; 3],
    /// Area \[m²\].
    pub area: f64,
    /// Shape-function gradients ∇N_i \[1/m\].
    pub grad: [[f64; 2]; 3],
    /// Longest edge \[m\].
    pub longest_edge: f64,
}

impl Triangle {
    /// Geometry of a triangle; fails (numerical) if it is degenerate or
    /// clockwise.
    pub fn new(x: [[f64; 2]; 3]) -> Result<Triangle> {
        let area2 =
            (x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]);
        let scale = (0..3)
            .map(|i| {
                let j = (i + 1) % 3;
                ((x[j][0] - x[i][0]).powi(2) + (x[j][1] - x[i][1]).powi(2)).sqrt()
            })
            .fold(0.0, f64::max);
        if area2.is_nan() || area2 <= 1e-12 * scale * scale {
            return Err(Error::numerical(
                "fe::element::Triangle",
                format!("degenerate or clockwise triangle {x:?} (2·area = {area2:e})"),
            ));
        }
        let mut grad = [[0.0; 2]; 3];
        for (i, g) in grad.iter_mut().enumerate() {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            *g = [(x[j][1] - x[k][1]) / area2, (x[k][0] - x[j][0]) / area2];
        }
        Ok(Triangle {
            x,
            area: 0.5 * area2,
            grad,
            longest_edge: scale,
        })
    }

    /// Generalized-strain operator G (8 × 18): `[ε; κ; γ] = G q_e` with the
    /// DSG3 shear rows averaged over the three reference nodes (module doc).
    pub fn strain_operator(&self) -> Mat8x18 {
        let mut g = Mat8x18::zeros();
        for i in 0..3 {
            let [nx, ny] = self.grad[i];
            let c = 6 * i;
            // membrane
            g[(0, c)] = nx;
            g[(1, c + 1)] = ny;
            g[(2, c)] = ny;
            g[(2, c + 1)] = nx;
            // bending: βx = θy, βy = −θx
            g[(3, c + 4)] = nx;
            g[(4, c + 3)] = -ny;
            g[(5, c + 4)] = ny;
            g[(5, c + 3)] = -nx;
        }
        // DSG3 shear, averaged over the reference node r.
        let third = 1.0 / 3.0;
        for r in 0..3 {
            for j in 0..3 {
                if j == r {
                    continue;
                }
                let dx = self.x[j][0] - self.x[r][0];
                let dy = self.x[j][1] - self.x[r][1];
                // Δw_j = w_j − w_r + ½(β_r + β_j)·(dx, dy),
                // β·d = θy dx − θx dy.
                for (row, gcomp) in [(6, self.grad[j][0]), (7, self.grad[j][1])] {
                    let f = gcomp * third;
                    g[(row, 6 * j + 2)] += f;
                    g[(row, 6 * r + 2)] -= f;
                    for n in [r, j] {
                        g[(row, 6 * n + 4)] += 0.5 * f * dx;
                        g[(row, 6 * n + 3)] -= 0.5 * f * dy;
                    }
                }
            }
        }
        g
    }

    /// Shear stabilisation factor `h²/(h² + α ℓ²)` for thickness h \[m\].
    pub fn shear_factor(&self, h: f64) -> f64 {
        h * h / (h * h + SHEAR_STABILISATION * self.longest_edge * self.longest_edge)
    }

    /// The shear stabilisation factor `f(h) = h²/(h² + c)`, `c = α ℓ²`,
    /// and its first two derivatives with respect to h:
    /// `f' = 2hc/(h² + c)²`, `f'' = 2c(c − 3h²)/(h² + c)³`.
    pub fn shear_factor_derivatives(&self, h: f64) -> [f64; 3] {
        let c = SHEAR_STABILISATION * self.longest_edge * self.longest_edge;
        let q = h * h + c;
        [
            self.shear_factor(h),
            2.0 * h * c / (q * q),
            2.0 * c * (c - 3.0 * h * h) / (q * q * q),
        ]
    }

    /// `A · Gᵀ C_e G` with C_e = C whose shear block is scaled by the
    /// stabilisation factor for thickness h, by dense 8×18 products. Used
    /// both for K (C = section matrix) and its ply-angle derivatives
    /// (C = C', C'': paper Eq. 20). Reference for [`Triangle::section_stiffness`].
    pub fn section_stiffness_dense(&self, g: &Mat8x18, c: &Mat8, h: f64) -> Mat18 {
        let mut ce = *c;
        let f = self.shear_factor(h);
        for i in 6..8 {
            for j in 6..8 {
                ce[(i, j)] *= f;
            }
        }
        let cg = ce * g;
        g.transpose() * cg * self.area
    }

    /// The same product as [`Triangle::section_stiffness_dense`] from the
    /// compact blocks of G (about 10× fewer operations): membrane rows act
    /// on (u, v), bending rows on (θx, θy), shear rows on (w, θx, θy), and C
    /// has the block form `[[A, B, 0], [B, D, 0], [0, 0, S]]` (entries
    /// outside these blocks are ignored).
    pub fn section_stiffness(&self, g: &CompactOps, c: &Mat8, h: f64) -> Mat18 {
        let mut k = Mat18::zeros();
        self.section_stiffness_into(g, c, h, &mut k);
        k
    }

    /// [`Triangle::section_stiffness`] written into `k` (overwritten), for
    /// assembly loops that reuse one buffer.
    pub fn section_stiffness_into(&self, g: &CompactOps, c: &Mat8, h: f64, k: &mut Mat18) {
        let ar = self.area;
        let a = c.fixed_view::<3, 3>(0, 0) * ar;
        let b = c.fixed_view::<3, 3>(0, 3) * ar;
        let d = c.fixed_view::<3, 3>(3, 3) * ar;
        let s = c.fixed_view::<2, 2>(6, 6) * (self.shear_factor(h) * ar);
        let kmm = g.gm.transpose() * (a * g.gm);
        let kmb = g.gm.transpose() * (b * g.gb);
        let kbb = g.gb.transpose() * (d * g.gb);
        let kss = g.gs.transpose() * (s * g.gs);
        k.fill(0.0);
        for i in 0..6 {
            for j in 0..6 {
                k[(MEMBRANE_DOF[i], MEMBRANE_DOF[j])] = kmm[(i, j)];
                k[(MEMBRANE_DOF[i], BENDING_DOF[j])] = kmb[(i, j)];
                k[(BENDING_DOF[j], MEMBRANE_DOF[i])] = kmb[(i, j)];
                k[(BENDING_DOF[i], BENDING_DOF[j])] = kbb[(i, j)];
            }
        }
        for i in 0..9 {
            for j in 0..9 {
                k[(SHEAR_DOF[i], SHEAR_DOF[j])] += kss[(i, j)];
            }
        }
    }

    /// Compact blocks of the strain operator (see [`CompactOps`]).
    pub fn compact_operator(&self) -> CompactOps {
        let g = self.strain_operator();
        CompactOps {
            gm: SMatrix::from_fn(|r, j| g[(r, MEMBRANE_DOF[j])]),
            gb: SMatrix::from_fn(|r, j| g[(3 + r, BENDING_DOF[j])]),
            gs: SMatrix::from_fn(|r, j| g[(6 + r, SHEAR_DOF[j])]),
        }
    }

    /// Drilling penalty matrix `γ_d ∫ (Nθz − Ω q)ᵀ (Nθz − Ω q) dA`, with
    /// `∫ N_i N_j dA = A (1 + δ_ij)/12` and `Ω q = ω = ½(v,x − u,y)`.
    /// `gamma` in N/m (N·m per radian² per m²).
    pub fn drilling_stiffness(&self, gamma: f64) -> Mat18 {
        let mut k = Mat18::zeros();
        self.add_drilling(gamma, &mut k);
        k
    }

    /// Add [`Triangle::drilling_stiffness`] to `k` (touches only the u, v
    /// and θz rows and columns).
    pub fn add_drilling(&self, gamma: f64, k: &mut Mat18) {
        // Ω on (u_i, v_i) in MEMBRANE_DOF order: ω = Σ ½(N_i,x v_i − N_i,y u_i).
        let om: [f64; 6] = std::array::from_fn(|j| {
            let g = self.grad[j / 2];
            if j % 2 == 0 {
                -0.5 * g[1]
            } else {
                0.5 * g[0]
            }
        });
        let ga = gamma * self.area;
        for p in 0..6 {
            for q in 0..6 {
                k[(MEMBRANE_DOF[p], MEMBRANE_DOF[q])] += ga * om[p] * om[q];
            }
        }
        for i in 0..3 {
            let ti = 6 * i + 5;
            for j in 0..3 {
                k[(ti, 6 * j + 5)] += ga * if i == j { 2.0 } else { 1.0 } / 12.0;
            }
            // cross terms −γ ∫ N_i dA Ω = −γ (A/3) Ω
            for q in 0..6 {
                let v = -ga / 3.0 * om[q];
                k[(ti, MEMBRANE_DOF[q])] += v;
                k[(MEMBRANE_DOF[q], ti)] += v;
            }
        }
    }

    /// Membrane resultants `N = A ε + B κ` = (N_xx, N_yy, N_xy) \[N/m\]
    /// of the element displacement `q` (element DOF order) with the
    /// laminate's `a`, `b` (constant over the element: CST membrane,
    /// constant curvature).
    pub fn membrane_resultants(
        &self,
        g: &CompactOps,
        a: &nalgebra::Matrix3<f64>,
        b: &nalgebra::Matrix3<f64>,
        q: &Vec18,
    ) -> [f64; 3] {
        let um = SVector::<f64, 6>::from_fn(|j, _| q[MEMBRANE_DOF[j]]);
        let ub = SVector::<f64, 6>::from_fn(|j, _| q[BENDING_DOF[j]]);
        let n = a * (g.gm * um) + b * (g.gb * ub);
        [n[0], n[1], n[2]]
    }

    /// Slope `(w,x, w,y)` of the linear deflection with node values `w`.
    pub fn slope(&self, w: [f64; 3]) -> [f64; 2] {
        let mut s = [0.0; 2];
        for (g, wi) in self.grad.iter().zip(w) {
            s[0] += g[0] * wi;
            s[1] += g[1] * wi;
        }
        s
    }

    /// Geometric (initial-stress) stiffness of the membrane prestress
    /// `n` = (N_xx, N_yy, N_xy) \[N/m\]: `K_G = ∫ [w,x w,y]ᵀ N [w,x w,y] dA`
    /// with `N = [[N_xx, N_xy], [N_xy, N_yy]]`, on the w DOFs only (the
    /// von Kármán plate term; the in-plane terms `u,α N u,β` are left
    /// out, as for the axial term of a beam). Exact for the linear `w`:
    /// `K_G,ij = A ∇N_iᵀ N ∇N_j`.
    pub fn geometric_stiffness(&self, n: [f64; 3]) -> Mat18 {
        let mut k = Mat18::zeros();
        for i in 0..3 {
            let [ax, ay] = self.grad[i];
            let (nx, ny) = (n[0] * ax + n[2] * ay, n[2] * ax + n[1] * ay);
            for j in 0..3 {
                let [bx, by] = self.grad[j];
                k[(6 * i + 2, 6 * j + 2)] = self.area * (nx * bx + ny * by);
            }
        }
        k
    }

    /// HRZ lumped mass (module doc): `mass_area` = Σρt \[kg/m²\],
    /// `rotary_area` = Σρ∫z² \[kg\]. Diagonal, element DOF order.
    pub fn lumped_mass(&self, mass_area: f64, rotary_area: f64) -> [f64; 18] {
        let mt = mass_area * self.area / 3.0;
        let mr = rotary_area * self.area / 3.0;
        let md = mt * (self.area / 3.0) / 6.0;
        let mut m = [0.0; 18];
        for i in 0..3 {
            m[6 * i..6 * i + 6].copy_from_slice(&[mt, mt, mt, mr, mr, md]);
        }
        m
    }
}
