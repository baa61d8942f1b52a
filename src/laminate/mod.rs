//! Laminate mechanics: orthotropic plies, ABD and transverse shear stiffness,
//! and their exact first and second derivatives with respect to ply angles
//! (paper §3.2, Eqs. 20–22).
//!
//! # Method
//! A ply's reduced plane-stress stiffness `Q` (material axes 1 = fibre,
//! 2 = transverse) is rotated to the laminate axes by the ply angle θ
//! (counter-clockwise from x to the fibre). The rotated stiffness is written
//! with the Tsai–Pagano invariants U1..U5,
//!
//! ```text
//! Q̄11 = U1 + U2 cos2θ + U3 cos4θ      Q̄16 = U2/2 sin2θ + U3 sin4θ
//! Q̄22 = U1 − U2 cos2θ + U3 cos4θ      Q̄26 = U2/2 sin2θ − U3 sin4θ
//! Q̄12 = U4 − U3 cos4θ                 Q̄66 = U5 − U3 cos4θ
//! ```
//!
//! so that its first and second θ-derivatives are closed forms (the content
//! of the paper's Eq. 22, `∂Q̄/∂θ = ∂(T⁻¹ Q T⁻ᵀ)/∂θ`). Transverse shear
//! (order γxz, γyz) rotates as a second-order tensor:
//! `C̄ = [[G13 c² + G23 s², (G13−G23) c s], [.., G13 s² + G23 c²]]`.
//!
//! Through the thickness (plies listed bottom to top, z from −h/2):
//! `A = Σ Q̄ₖ (zₖ − zₖ₋₁)`, `B = ½ Σ Q̄ₖ (zₖ² − zₖ₋₁²)`,
//! `D = ⅓ Σ Q̄ₖ (zₖ³ − zₖ₋₁³)`, `S = κ Σ C̄ₖ (zₖ − zₖ₋₁)` with the shear
//! correction factor κ = 5/6 ([`SHEAR_CORRECTION`], Reissner's value for a
//! homogeneous section; first-order shear deformation theory has no better
//! universal choice, and for the thin panels of the paper (a/h ≈ 1000) the
//! shear energy is negligible anyway).
//!
//! Each ply's stiffness depends on its own angle only, so
//! `∂X/∂θₖ = Q̄ₖ'·(z-moment of ply k)` and mixed second derivatives between
//! different plies vanish. A design variable ([`DesignMap`]) ties a group of
//! plies (the paper's [θ1/θ2/θ2/θ1] ties plies 1 & 4 and 2 & 3); its
//! derivative is the sum over the group.
//!
//! # Symmetric stacks
//! When ply `k` and its mirror `n−1−k` are equal for every `k`
//! ([`Laminate::is_symmetric`]), their B contributions cancel and B = 0;
//! likewise B' when the design variable moves both plies of every mirror
//! pair it touches (the paper's θ1 on plies 1 & 4, θ2 on 2 & 3). The sum
//! over plies leaves rounding instead (about 1e-20 of |A| on the SAR
//! panels, from interface coordinates and summation order), so B and B'
//! are set to exactly zero there: the shell's membrane (u, v, θz) and
//! bending (w, θx, θy) DOFs are then uncoupled in K and K' exactly, which
//! the modal derivatives exploit (`modal::blocks`).
//!
//! # Ply thickness
//! With the mid-plane fixed at z = 0, the interfaces move with each ply's
//! thickness tₖ: `zᵢ = −h/2 + Σ_{j<i} tⱼ`, so `∂zᵢ/∂tₖ = −½` for `i ≤ k`
//! and `+½` for `i > k`. Then `∂A/∂tₖ = Q̄ₖ`, `∂S/∂tₖ = κ C̄ₖ`,
//! `∂B/∂tₖ = Σᵢ Q̄ᵢ (zᵢ₊₁ ∂zᵢ₊₁ − zᵢ ∂zᵢ)`,
//! `∂D/∂tₖ = Σᵢ Q̄ᵢ (zᵢ₊₁² ∂zᵢ₊₁ − zᵢ² ∂zᵢ)`; the mass per area moves by
//! `ρₖ` and the rotary inertia by `Σᵢ ρᵢ (zᵢ₊₁² ∂zᵢ₊₁ − zᵢ² ∂zᵢ)`
//! ([`Laminate::thickness_derivative`]). A thicker ply of a symmetric stack
//! breaks the symmetry, so `∂B/∂tₖ` is the plain sum (not zeroed).
//!
//! [`ply_stiffness_generic`] and [`stiffness_generic`] are a twin of the same
//! mechanics written generic over the scalar with the explicit `c⁴, s²c², …`
//! transformation polynomials (an independent route); tests drive them with
//! hyper-dual numbers to check the closed-form derivatives.
//!
//! Units: SI throughout (Pa, m, kg/m³, rad). A, S in N/m; B in N; D in N·m.

use crate::error::{require_positive, Error, Result};
use nalgebra::{Matrix2, Matrix3};
use num_dual::DualNum;

/// Shear correction factor κ applied to the transverse shear stiffness.
pub const SHEAR_CORRECTION: f64 = 5.0 / 6.0;

/// Derivatives with respect to the common thickness `s` \[m\] of a group
/// of plies ([`Laminate::thickness_group_derivative`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ThicknessDerivative {
    /// `∂(A, B, D, S)/∂s` \[per m\].
    pub first: Stiffness,
    /// `∂²(A, B, D, S)/∂s²` \[per m²\] (A and S are linear: zero).
    pub second: Stiffness,
    /// `∂(mass per area)/∂s` \[kg/m³\] (linear: no second derivative).
    pub mass: f64,
    /// `∂/∂s` and `∂²/∂s²` of the rotary inertia per area \[kg/m, kg/m²\].
    pub rotary: [f64; 2],
    /// `∂h/∂s`: the number of plies in the group.
    pub thickness: f64,
    /// `∂Ā/∂s` of [`Laminate::membrane_mean`] \[N/m²\] (linear).
    pub membrane_mean: f64,
}

/// An orthotropic ply material (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orthotropic {
    /// Fibre-direction Young's modulus E1 \[Pa\].
    pub e1: f64,
    /// Transverse Young's modulus E2 \[Pa\].
    pub e2: f64,
    /// In-plane shear modulus G12 \[Pa\].
    pub g12: f64,
    /// Transverse shear modulus G13 \[Pa\].
    pub g13: f64,
    /// Transverse shear modulus G23 \[Pa\].
    pub g23: f64,
    /// Major Poisson's ratio ν12 \[-\].
    pub nu12: f64,
    /// Density ρ \[kg/m³\].
    pub rho: f64,
}

impl Orthotropic {
    /// IM6/SC1081 carbon/epoxy, the paper's panel material (§6.2):
    /// E1 = 177 GPa, E2 = 10.8 GPa, G12 = G13 = 7.6 GPa, G23 = 8.504 GPa,
    /// ν12 = 0.27, ρ = 1600 kg/m³.
    pub fn im6_sc1081() -> Orthotropic {
        Orthotropic {
            e1: 177e9,
            e2: 10.8e9,
            g12: 7.6e9,
            g13: 7.6e9,
            g23: 8.504e9,
            nu12: 0.27,
            rho: 1600.0,
        }
    }

    /// Validate: moduli and density finite and > 0; ν12 finite with
    /// ν12² < E1/E2 (the plane-stress stiffness is positive definite only
    /// then, since ν12·ν21 = ν12²·E2/E1 must be < 1).
    pub fn validate(&self) -> Result<()> {
        require_positive("e1", self.e1)?;
        require_positive("e2", self.e2)?;
        require_positive("g12", self.g12)?;
        require_positive("g13", self.g13)?;
        require_positive("g23", self.g23)?;
        require_positive("rho", self.rho)?;
        if !self.nu12.is_finite() || self.nu12 * self.nu12 >= self.e1 / self.e2 {
            return Err(Error::input(
                "nu12",
                self.nu12,
                format!(
                    "a finite value with nu12² < e1/e2 = {:.6e} (positive definite ply)",
                    self.e1 / self.e2
                ),
            ));
        }
        Ok(())
    }

    /// Reduced plane-stress stiffness in material axes: (Q11, Q22, Q12, Q66)
    /// with `Q11 = E1/(1−ν12ν21)`, `Q22 = E2/(1−ν12ν21)`,
    /// `Q12 = ν12 E2/(1−ν12ν21)`, `Q66 = G12`, `ν21 = ν12 E2/E1`.
    pub fn reduced(&self) -> [f64; 4] {
        let nu21 = self.nu12 * self.e2 / self.e1;
        let den = 1.0 - self.nu12 * nu21;
        [
            self.e1 / den,
            self.e2 / den,
            self.nu12 * self.e2 / den,
            self.g12,
        ]
    }

    /// Tsai–Pagano invariants [U1, U2, U3, U4, U5] \[Pa\].
    pub fn invariants(&self) -> [f64; 5] {
        let [q11, q22, q12, q66] = self.reduced();
        [
            (3.0 * q11 + 3.0 * q22 + 2.0 * q12 + 4.0 * q66) / 8.0,
            (q11 - q22) / 2.0,
            (q11 + q22 - 2.0 * q12 - 4.0 * q66) / 8.0,
            (q11 + q22 + 6.0 * q12 - 4.0 * q66) / 8.0,
            (q11 + q22 - 2.0 * q12 + 4.0 * q66) / 8.0,
        ]
    }
}

/// One ply: material, thickness \[m\] and angle \[rad\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ply {
    /// Material of the ply.
    pub material: Orthotropic,
    /// Thickness \[m\].
    pub thickness: f64,
    /// Angle from the laminate x axis to the fibre, counter-clockwise \[rad\].
    pub angle: f64,
}

/// Rotated ply stiffness and its θ-derivatives of order 0, 1 or 2:
/// in-plane Q̄ (3×3, Voigt order xx, yy, xy with engineering shear) and
/// transverse shear C̄ (2×2, order γxz, γyz), unscaled by κ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlyStiffness {
    /// In-plane Q̄ (or its derivative) \[Pa per rad^order\].
    pub q: Matrix3<f64>,
    /// Transverse shear C̄ (or its derivative) \[Pa per rad^order\].
    pub g: Matrix2<f64>,
}

impl Ply {
    /// `order`-th derivative (0, 1 or 2) of the rotated stiffness with
    /// respect to the ply angle, from the invariant form (module doc).
    pub fn stiffness_derivative(&self, order: u8) -> PlyStiffness {
        let [u1, u2, u3, u4, u5] = self.material.invariants();
        let t = self.angle;
        let (s2, c2) = (2.0 * t).sin_cos();
        let (s4, c4) = (4.0 * t).sin_cos();
        let (s1, c1) = t.sin_cos();
        let (g13, g23) = (self.material.g13, self.material.g23);
        // f(θ) and its derivatives: cos2θ, sin2θ, cos4θ, sin4θ, c², s², cs.
        // d/dθ cos2θ = −2 sin2θ etc.; c² = (1+cos2θ)/2, s² = (1−cos2θ)/2,
        // cs = sin2θ/2.
        let (cc2, ss2, cc4, ss4, u0) = match order {
            0 => (c2, s2, c4, s4, 1.0),
            1 => (-2.0 * s2, 2.0 * c2, -4.0 * s4, 4.0 * c4, 0.0),
            _ => (-4.0 * c2, -4.0 * s2, -16.0 * c4, -16.0 * s4, 0.0),
        };
        let q11 = u0 * u1 + u2 * cc2 + u3 * cc4;
        let q22 = u0 * u1 - u2 * cc2 + u3 * cc4;
        let q12 = u0 * u4 - u3 * cc4;
        let q66 = u0 * u5 - u3 * cc4;
        let q16 = 0.5 * u2 * ss2 + u3 * ss4;
        let q26 = 0.5 * u2 * ss2 - u3 * ss4;
        let q = Matrix3::new(q11, q12, q16, q12, q22, q26, q16, q26, q66);
        let (cc, ss, cs) = if order == 0 {
            (c1 * c1, s1 * s1, c1 * s1)
        } else {
            (0.5 * cc2, -0.5 * cc2, 0.5 * ss2)
        };
        let g = Matrix2::new(
            g13 * cc + g23 * ss,
            (g13 - g23) * cs,
            (g13 - g23) * cs,
            g13 * ss + g23 * cc,
        );
        PlyStiffness { q, g }
    }
}

/// Laminate stiffness: membrane A, coupling B, bending D, transverse shear S
/// (S includes κ). Generalized stress–strain law
/// `[N; M] = [[A, B], [B, D]] [ε; κ]`, `Q = S γ`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stiffness {
    /// Membrane stiffness A \[N/m\].
    pub a: Matrix3<f64>,
    /// Membrane–bending coupling B \[N\].
    pub b: Matrix3<f64>,
    /// Bending stiffness D \[N·m\].
    pub d: Matrix3<f64>,
    /// Transverse shear stiffness S = κ Σ C̄ₖ tₖ \[N/m\], order (γxz, γyz).
    pub s: Matrix2<f64>,
}

impl Stiffness {
    fn add_ply(&mut self, p: &PlyStiffness, z0: f64, z1: f64) {
        self.a += p.q * (z1 - z0);
        self.b += p.q * (0.5 * (z1 * z1 - z0 * z0));
        self.d += p.q * ((z1 * z1 * z1 - z0 * z0 * z0) / 3.0);
        self.s += p.g * (SHEAR_CORRECTION * (z1 - z0));
    }
}

/// A stack of plies, listed bottom (z = −h/2) to top.
#[derive(Debug, Clone, PartialEq)]
pub struct Laminate {
    plies: Vec<Ply>,
}

impl Laminate {
    /// Build and validate: at least one ply, every material valid, every
    /// thickness finite and > 0, every angle finite. Keys of errors are
    /// `plies[k].…` (0-based).
    pub fn new(plies: Vec<Ply>) -> Result<Laminate> {
        if plies.is_empty() {
            return Err(Error::input("plies", "[]", "at least one ply"));
        }
        for (k, p) in plies.iter().enumerate() {
            let at = |e: Error| e.in_file("", &format!("plies[{k}]"));
            p.material
                .validate()
                .map_err(|e| e.in_file("", &format!("plies[{k}].material")))?;
            require_positive("thickness", p.thickness).map_err(at)?;
            crate::error::require_finite("angle", p.angle).map_err(at)?;
        }
        Ok(Laminate { plies })
    }

    /// The plies, bottom to top.
    pub fn plies(&self) -> &[Ply] {
        &self.plies
    }

    /// Total thickness h \[m\].
    pub fn thickness(&self) -> f64 {
        self.plies.iter().map(|p| p.thickness).sum()
    }

    /// Mass per unit area `Σ ρₖ tₖ` \[kg/m²\].
    pub fn mass_per_area(&self) -> f64 {
        self.plies
            .iter()
            .map(|p| p.material.rho * p.thickness)
            .sum()
    }

    /// Rotary inertia per unit area about the mid-surface `Σ ρₖ ∫ z² dz`
    /// \[kg\].
    pub fn rotary_inertia_per_area(&self) -> f64 {
        let mut z0 = -0.5 * self.thickness();
        let mut r = 0.0;
        for p in &self.plies {
            let z1 = z0 + p.thickness;
            r += p.material.rho * (z1 * z1 * z1 - z0 * z0 * z0) / 3.0;
            z0 = z1;
        }
        r
    }

    /// Angle-independent mean membrane stiffness
    /// `Ā = (A11 + A22 + 2A66)/4 = Σ tₖ (U1 + U5)ₖ / 2` \[N/m\] (the sum
    /// `Q̄11 + Q̄22 + 2Q̄66 = 2(U1 + U5)` is a rotation invariant). Used to
    /// scale the shell's drilling penalty so that it does not depend on the
    /// design.
    pub fn membrane_mean(&self) -> f64 {
        self.plies
            .iter()
            .map(|p| {
                let u = p.material.invariants();
                p.thickness * (u[0] + u[4]) / 2.0
            })
            .sum()
    }

    /// Ply angles \[rad\].
    pub fn angles(&self) -> Vec<f64> {
        self.plies.iter().map(|p| p.angle).collect()
    }

    /// The same stack with new angles (one per ply, \[rad\]).
    pub fn with_angles(&self, angles: &[f64]) -> Result<Laminate> {
        if angles.len() != self.plies.len() {
            return Err(Error::input(
                "angles",
                angles.len(),
                format!("one angle per ply ({})", self.plies.len()),
            ));
        }
        let mut plies = self.plies.clone();
        for (k, (p, &a)) in plies.iter_mut().zip(angles).enumerate() {
            crate::error::require_finite(&format!("angles[{k}]"), a)?;
            p.angle = a;
        }
        Ok(Laminate { plies })
    }

    /// The same stack with new ply thicknesses (one per ply, \[m\], each
    /// finite and > 0).
    pub fn with_thicknesses(&self, thicknesses: &[f64]) -> Result<Laminate> {
        if thicknesses.len() != self.plies.len() {
            return Err(Error::input(
                "thicknesses",
                thicknesses.len(),
                format!("one thickness per ply ({})", self.plies.len()),
            ));
        }
        let mut plies = self.plies.clone();
        for (p, &t) in plies.iter_mut().zip(thicknesses) {
            p.thickness = t;
        }
        Laminate::new(plies)
    }

    /// Exact first derivatives with respect to the thickness of ply `k`
    /// (module doc, "Ply thickness"): A, B, D, S per metre of ply
    /// thickness, and (mass per area \[kg/m² per m\], rotary inertia per
    /// area \[kg per m\]). Zero for `k` out of range.
    pub fn thickness_derivative(&self, k: usize) -> (Stiffness, [f64; 2]) {
        let mut st = Stiffness::default();
        let mut inertia = [0.0, 0.0];
        if k >= self.plies.len() {
            return (st, inertia);
        }
        let z = self.interfaces();
        let dz = |i: usize| if i > k { 0.5 } else { -0.5 };
        for (i, p) in self.plies.iter().enumerate() {
            let q = p.stiffness_derivative(0);
            let (z0, z1, d0, d1) = (z[i], z[i + 1], dz(i), dz(i + 1));
            st.a += q.q * (d1 - d0);
            st.b += q.q * (z1 * d1 - z0 * d0);
            st.d += q.q * (z1 * z1 * d1 - z0 * z0 * d0);
            st.s += q.g * (SHEAR_CORRECTION * (d1 - d0));
            inertia[1] += p.material.rho * (z1 * z1 * d1 - z0 * z0 * d0);
        }
        inertia[0] = self.plies[k].material.rho;
        (st, inertia)
    }

    /// Exact first and second derivatives with respect to the common
    /// thickness `s` of the plies of `group` (every ply of the group has
    /// thickness `s`; module doc, "Ply thickness"). The interfaces move by
    /// `∂zᵢ/∂s = Σ_{k∈group} ±½` (constant), so A, S, the mass per area
    /// and the mean membrane stiffness are linear in `s`,
    /// `B'' = Σᵢ Q̄ᵢ (∂zᵢ₊₁² − ∂zᵢ²)`, `D'' = Σᵢ Q̄ᵢ 2(zᵢ₊₁∂zᵢ₊₁² − zᵢ∂zᵢ²)`
    /// and alike for the rotary inertia. As for the ply angles, B' and B''
    /// are exactly zero on a symmetric stack whose group is closed under
    /// the mid-plane mirror (they vanish up to rounding).
    pub fn thickness_group_derivative(&self, group: &[usize]) -> ThicknessDerivative {
        let z = self.interfaces();
        let n = self.plies.len();
        // ∂zᵢ/∂s: −½ per group ply at or above interface i, +½ per one below.
        let dz: Vec<f64> = (0..=n)
            .map(|i| {
                group
                    .iter()
                    .filter(|&&k| k < n)
                    .map(|&k| if i > k { 0.5 } else { -0.5 })
                    .sum()
            })
            .collect();
        let mut out = ThicknessDerivative::default();
        for (i, p) in self.plies.iter().enumerate() {
            let q = p.stiffness_derivative(0);
            let (z0, z1, d0, d1) = (z[i], z[i + 1], dz[i], dz[i + 1]);
            out.first.a += q.q * (d1 - d0);
            out.first.b += q.q * (z1 * d1 - z0 * d0);
            out.first.d += q.q * (z1 * z1 * d1 - z0 * z0 * d0);
            out.first.s += q.g * (SHEAR_CORRECTION * (d1 - d0));
            out.second.b += q.q * (d1 * d1 - d0 * d0);
            out.second.d += q.q * (2.0 * (z1 * d1 * d1 - z0 * d0 * d0));
            let rho = p.material.rho;
            out.rotary[0] += rho * (z1 * z1 * d1 - z0 * z0 * d0);
            out.rotary[1] += rho * 2.0 * (z1 * d1 * d1 - z0 * d0 * d0);
        }
        for &k in group.iter().filter(|&&k| k < n) {
            let p = &self.plies[k];
            out.mass += p.material.rho;
            let u = p.material.invariants();
            out.membrane_mean += (u[0] + u[4]) / 2.0;
            out.thickness += 1.0;
        }
        if self.is_symmetric() && self.mirror_closed(group) {
            out.first.b = Matrix3::zeros();
            out.second.b = Matrix3::zeros();
        }
        out
    }

    /// Ply interface coordinates z₀ = −h/2 < z₁ < … < z_n = h/2.
    fn interfaces(&self) -> Vec<f64> {
        let mut z = Vec::with_capacity(self.plies.len() + 1);
        let mut acc = -0.5 * self.thickness();
        z.push(acc);
        for p in &self.plies {
            acc += p.thickness;
            z.push(acc);
        }
        z
    }

    /// Is the stack symmetric about its mid-plane: ply `k` and ply
    /// `n−1−k` equal (material, thickness, angle) for every `k`?
    pub fn is_symmetric(&self) -> bool {
        let n = self.plies.len();
        (0..n / 2).all(|k| self.plies[k] == self.plies[n - 1 - k])
    }

    /// Is `group` closed under the mid-plane mirror (ply `k` in it ⇒ ply
    /// `n−1−k` in it)?
    fn mirror_closed(&self, group: &[usize]) -> bool {
        let n = self.plies.len();
        group.iter().all(|&k| group.contains(&(n - 1 - k)))
    }

    /// A, B, D, S (module doc). For a mid-plane symmetric stack B is
    /// exactly zero (module doc, "Symmetric stacks").
    pub fn stiffness(&self) -> Stiffness {
        let all: Vec<usize> = (0..self.plies.len()).collect();
        self.group_derivative(&all, 0)
    }

    /// `order`-th derivative (1 or 2) of A, B, D, S with respect to the
    /// angle of ply `k` alone (paper Eq. 21 with Eq. 22). Order 0 gives ply
    /// k's contribution.
    pub fn ply_derivative(&self, k: usize, order: u8) -> Stiffness {
        let z = self.interfaces();
        let mut st = Stiffness::default();
        if let Some(p) = self.plies.get(k) {
            st.add_ply(&p.stiffness_derivative(order), z[k], z[k + 1]);
        }
        st
    }

    /// First derivative of A, B, D, S with respect to design variable `v`
    /// of `map` (sum over its plies).
    pub fn design_derivative(&self, map: &DesignMap, v: usize) -> Stiffness {
        self.group_derivative(&map.groups[v], 1)
    }

    /// Second derivative ∂²/∂θ_v∂θ_w. Zero unless v == w (groups are
    /// disjoint and each ply depends on its own angle only); then the sum of
    /// the group's plies' second derivatives.
    pub fn design_second_derivative(&self, map: &DesignMap, v: usize, w: usize) -> Stiffness {
        if v != w {
            return Stiffness::default();
        }
        self.group_derivative(&map.groups[v], 2)
    }

    /// `order`-th derivative with respect to the common angle of `group`
    /// (order 0 over all plies: the stiffness itself); B' is exactly zero
    /// when the stack is symmetric and the group mirror-closed (module doc,
    /// "Symmetric stacks").
    fn group_derivative(&self, group: &[usize], order: u8) -> Stiffness {
        let z = self.interfaces();
        let mut st = Stiffness::default();
        for &k in group {
            st.add_ply(&self.plies[k].stiffness_derivative(order), z[k], z[k + 1]);
        }
        if self.is_symmetric() && self.mirror_closed(group) {
            st.b = Matrix3::zeros();
        }
        st
    }

    /// Apply design-variable values (radians) through `map`: each variable
    /// sets the angle of every ply in its group; other plies keep theirs.
    pub fn with_design(&self, map: &DesignMap, values: &[f64]) -> Result<Laminate> {
        if values.len() != map.len() {
            return Err(Error::input(
                "design",
                values.len(),
                format!("one value per design variable ({})", map.len()),
            ));
        }
        let mut angles = self.angles();
        for (g, &v) in map.groups.iter().zip(values) {
            for &k in g {
                angles[k] = v;
            }
        }
        self.with_angles(&angles)
    }
}

/// Design variables: variable v sets the angle of every ply in `groups[v]`
/// (0-based ply indices). Groups are non-empty and disjoint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DesignMap {
    groups: Vec<Vec<usize>>,
}

impl DesignMap {
    /// Validate against a laminate of `n_plies` plies.
    pub fn new(groups: Vec<Vec<usize>>, n_plies: usize) -> Result<DesignMap> {
        let mut seen = vec![false; n_plies];
        for (v, g) in groups.iter().enumerate() {
            if g.is_empty() {
                return Err(Error::input(
                    format!("design[{v}]"),
                    "[]",
                    "a non-empty list of plies",
                ));
            }
            for &k in g {
                if k >= n_plies || seen[k] {
                    return Err(Error::input(
                        format!("design[{v}]"),
                        k + 1,
                        format!("a ply number in 1..={n_plies} used by one variable only"),
                    ));
                }
                seen[k] = true;
            }
        }
        Ok(DesignMap { groups })
    }

    /// One variable per ply.
    pub fn per_ply(n_plies: usize) -> DesignMap {
        DesignMap {
            groups: (0..n_plies).map(|k| vec![k]).collect(),
        }
    }

    /// Symmetric tying: ply k and ply n−1−k share a variable
    /// (the paper's [θ1/θ2/θ2/θ1] for n = 4).
    pub fn symmetric(n_plies: usize) -> DesignMap {
        DesignMap {
            groups: (0..n_plies.div_ceil(2))
                .map(|k| {
                    let j = n_plies - 1 - k;
                    if j == k {
                        vec![k]
                    } else {
                        vec![k, j]
                    }
                })
                .collect(),
        }
    }

    /// Number of design variables.
    pub fn len(&self) -> usize {
        self.groups.len()
    }

    /// No design variables?
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// The ply groups (0-based).
    pub fn groups(&self) -> &[Vec<usize>] {
        &self.groups
    }
}

/// Rotated ply stiffness, generic over the scalar (twin of
/// [`Ply::stiffness_derivative`] by the explicit transformation
/// polynomials). Returns (Q̄ as rows, C̄ as rows).
pub fn ply_stiffness_generic<T: DualNum<Primitive = f64> + Copy>(
    m: &Orthotropic,
    theta: T,
) -> ([[T; 3]; 3], [[T; 2]; 2]) {
    let [q11, q22, q12, q66] = m.reduced();
    let (s, c) = theta.sin_cos();
    let (c2, s2) = (c * c, s * s);
    let (c4, s4, s2c2) = (c2 * c2, s2 * s2, s2 * c2);
    let b11 = c4 * q11 + s2c2 * (2.0 * (q12 + 2.0 * q66)) + s4 * q22;
    let b22 = s4 * q11 + s2c2 * (2.0 * (q12 + 2.0 * q66)) + c4 * q22;
    let b12 = s2c2 * (q11 + q22 - 4.0 * q66) + (s4 + c4) * q12;
    let b66 = s2c2 * (q11 + q22 - 2.0 * q12 - 2.0 * q66) + (s4 + c4) * q66;
    let b16 = s * c2 * c * (q11 - q12 - 2.0 * q66) + s2 * s * c * (q12 - q22 + 2.0 * q66);
    let b26 = s2 * s * c * (q11 - q12 - 2.0 * q66) + s * c2 * c * (q12 - q22 + 2.0 * q66);
    let g11 = c2 * m.g13 + s2 * m.g23;
    let g22 = s2 * m.g13 + c2 * m.g23;
    let g12 = s * c * (m.g13 - m.g23);
    (
        [[b11, b12, b16], [b12, b22, b26], [b16, b26, b66]],
        [[g11, g12], [g12, g22]],
    )
}

/// Generic laminate stiffness (A, B, D, S as row arrays) for plies of the
/// given materials and thicknesses at angles `angles` (same order).
pub type GenericAbd<T> = ([[T; 3]; 3], [[T; 3]; 3], [[T; 3]; 3], [[T; 2]; 2]);

/// A, B, D, S generic over the scalar (twin of [`Laminate::stiffness`]).
pub fn stiffness_generic<T: DualNum<Primitive = f64> + Copy>(
    lam: &Laminate,
    angles: &[T],
) -> GenericAbd<T> {
    let zero = T::from(0.0);
    let mut a = [[zero; 3]; 3];
    let mut b = [[zero; 3]; 3];
    let mut d = [[zero; 3]; 3];
    let mut s = [[zero; 2]; 2];
    let z = lam.interfaces();
    for (k, p) in lam.plies.iter().enumerate() {
        let (q, g) = ply_stiffness_generic(&p.material, angles[k]);
        let (z0, z1) = (z[k], z[k + 1]);
        let (m1, m2, m3) = (
            z1 - z0,
            0.5 * (z1 * z1 - z0 * z0),
            (z1 * z1 * z1 - z0 * z0 * z0) / 3.0,
        );
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += q[i][j] * m1;
                b[i][j] += q[i][j] * m2;
                d[i][j] += q[i][j] * m3;
            }
        }
        for i in 0..2 {
            for j in 0..2 {
                s[i][j] += g[i][j] * (SHEAR_CORRECTION * m1);
            }
        }
    }
    (a, b, d, s)
}

pub mod spec;

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    #[test]
    fn invariant_and_polynomial_forms_agree() {
        // Two independent routes to Q̄(θ) (module doc): must agree to rounding.
        let m = Orthotropic::im6_sc1081();
        for &t in &[0.0, 0.3, 1.1, -2.0, 3.0] {
            let p = Ply {
                material: m,
                thickness: 1e-3,
                angle: t,
            };
            let a = p.stiffness_derivative(0);
            let (q, g) = ply_stiffness_generic(&m, t);
            for i in 0..3 {
                for j in 0..3 {
                    assert!((a.q[(i, j)] - q[i][j]).abs() < 1e-12 * m.e1, "{i}{j}");
                }
            }
            for i in 0..2 {
                for j in 0..2 {
                    assert!((a.g[(i, j)] - g[i][j]).abs() < 1e-12 * m.g23);
                }
            }
        }
    }

    #[test]
    fn thickness_derivatives_match_central_differences() {
        // A, B, D and the inertias are polynomials of degree ≤ 3 in each
        // thickness, so central differences (step 1e-8 m on 0.13-0.5 mm
        // plies) carry truncation ~(h/t)² ≈ 1e-9 and rounding ~1e-10 of
        // the largest entry; the exact derivatives must agree to 1e-7.
        let m = Orthotropic::im6_sc1081();
        let ply = |deg: f64, t: f64| Ply {
            material: m,
            thickness: t,
            angle: f64::to_radians(deg),
        };
        let stacks = [
            // Unsymmetric (B ≠ 0) with unequal plies.
            vec![
                ply(30.0, 0.5e-3),
                ply(-45.0, 0.13e-3),
                ply(60.0, 0.3e-3),
                ply(10.0, 0.2e-3),
            ],
            // Symmetric (B = 0 exactly): one thicker ply makes B ≠ 0.
            vec![
                ply(55.0, 0.5e-3),
                ply(-55.0, 0.5e-3),
                ply(-55.0, 0.5e-3),
                ply(55.0, 0.5e-3),
            ],
        ];
        let h = 1e-8;
        for plies in stacks {
            let lam = Laminate::new(plies).unwrap();
            let t = lam.plies().iter().map(|p| p.thickness).collect::<Vec<_>>();
            for k in 0..t.len() {
                let (d, [dm, dr]) = lam.thickness_derivative(k);
                let at = |s: f64| {
                    let mut tt = t.clone();
                    tt[k] += s;
                    lam.with_thicknesses(&tt).unwrap()
                };
                let (lp, lm) = (at(h), at(-h));
                let (sp, sm) = (lp.stiffness(), lm.stiffness());
                // Each quantity's scale: its largest reference entry or
                // `floor` (B' may vanish: on [55/-55/-55/55] thickening
                // ply 2 or 3 moves no B, and the differences leave rounding).
                let close = |an: &[f64], fd: &[f64], what: &str, floor: f64| {
                    let scale = fd.iter().fold(floor, |a, v| a.max(v.abs()));
                    for (a, b) in an.iter().zip(fd) {
                        assert!((a - b).abs() <= 1e-7 * scale, "ply {k} {what}: {a} vs {b}");
                    }
                };
                let (qa, ht) = (d.a.abs().max(), lam.thickness());
                let fd3 =
                    |p: &Matrix3<f64>, q: &Matrix3<f64>| ((p - q) / (2.0 * h)).as_slice().to_vec();
                close(d.a.as_slice(), &fd3(&sp.a, &sm.a), "A", 0.0);
                close(d.b.as_slice(), &fd3(&sp.b, &sm.b), "B", qa * ht);
                close(d.d.as_slice(), &fd3(&sp.d, &sm.d), "D", qa * ht * ht);
                close(
                    d.s.as_slice(),
                    ((sp.s - sm.s) / (2.0 * h)).as_slice(),
                    "S",
                    0.0,
                );
                let fm = (lp.mass_per_area() - lm.mass_per_area()) / (2.0 * h);
                close(&[dm], &[fm], "mass", 0.0);
                let fr = (lp.rotary_inertia_per_area() - lm.rotary_inertia_per_area()) / (2.0 * h);
                close(&[dr], &[fr], "rotary inertia", 0.0);
            }
            // The unsymmetric stack's outer ply moves B.
            if !lam.is_symmetric() {
                assert!(lam.thickness_derivative(0).0.b.abs().max() > 1.0);
            }
        }
    }

    #[test]
    fn symmetric_stacks_have_exactly_zero_coupling() {
        // B = ½ Σ Q̄ₖ (zₖ² − zₖ₋₁²) cancels pairwise for mirror-equal plies;
        // with 0.13 mm plies the interface coordinates are not exact binary
        // mirrors, so the plain sum leaves rounding that must not remain.
        let m = Orthotropic::im6_sc1081();
        let ply = |deg: f64| Ply {
            material: m,
            thickness: 0.13e-3,
            angle: deg.to_radians(),
        };
        let sym = Laminate::new(vec![ply(55.0), ply(-55.0), ply(-55.0), ply(55.0)]).unwrap();
        assert!(sym.is_symmetric());
        assert_eq!(sym.stiffness().b, Matrix3::zeros());
        let paper = DesignMap::new(vec![vec![0, 3], vec![1, 2]], 4).unwrap();
        for v in 0..2 {
            assert_eq!(sym.design_derivative(&paper, v).b, Matrix3::zeros());
            assert_eq!(
                sym.design_second_derivative(&paper, v, v).b,
                Matrix3::zeros()
            );
        }
        // A variable on one ply of a pair breaks the symmetry: B' ≠ 0, and it
        // equals the twin's value (hyper-dual derivative of the plain sum).
        let per_ply = DesignMap::per_ply(4);
        let b1 = sym.design_derivative(&per_ply, 0).b;
        let angles: Vec<num_dual::Dual64> = sym
            .angles()
            .iter()
            .enumerate()
            .map(|(k, &t)| num_dual::Dual64::new(t, if k == 0 { 1.0 } else { 0.0 }))
            .collect();
        let (_, bg, _, _) = stiffness_generic(&sym, &angles);
        let scale = b1.abs().max();
        assert!(scale > 1e-3, "{scale}");
        for i in 0..3 {
            for j in 0..3 {
                assert!((b1[(i, j)] - bg[i][j].eps).abs() < 1e-9 * scale, "{i}{j}");
            }
        }
        // An unsymmetric stack keeps its B from the sum.
        let uns = Laminate::new(vec![ply(55.0), ply(-55.0), ply(-55.0), ply(40.0)]).unwrap();
        assert!(!uns.is_symmetric());
        let b = uns.stiffness().b;
        let (_, bg, _, _) = stiffness_generic(&uns, &uns.angles());
        assert!(b.abs().max() > 1e-3);
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (b[(i, j)] - bg[i][j]).abs() < 1e-9 * b.abs().max(),
                    "{i}{j}"
                );
            }
        }
    }
}
