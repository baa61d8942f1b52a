//! Study-file specs for a material and a ply stack. Angles are written in
//! DEGREES in the file and converted to radians once, in `resolve`.

use super::{Laminate, Orthotropic, Ply};
use crate::error::{Error, Result};
use serde::Deserialize;

/// `material = { e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9,
/// g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }` (SI units: Pa, kg/m³).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Young's modulus along the fibre (Pa).
    pub e1: f64,
    /// Young's modulus across the fibre (Pa).
    pub e2: f64,
    /// In-plane shear modulus (Pa).
    pub g12: f64,
    /// Transverse shear modulus in the 1-3 plane (Pa).
    pub g13: f64,
    /// Transverse shear modulus in the 2-3 plane (Pa).
    pub g23: f64,
    /// Major Poisson's ratio ν12 (-).
    pub nu12: f64,
    /// Density (kg/m³).
    pub rho: f64,
}

impl MaterialSpec {
    /// Validate (key prefix `material`).
    pub fn resolve(&self) -> Result<Orthotropic> {
        let m = Orthotropic {
            e1: self.e1,
            e2: self.e2,
            g12: self.g12,
            g13: self.g13,
            g23: self.g23,
            nu12: self.nu12,
            rho: self.rho,
        };
        m.validate().map_err(|e| e.in_file("", "material"))?;
        Ok(m)
    }
}

/// `{ angle = 90.0, thickness = 0.5e-3 }`: angle in degrees, thickness in m.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PlySpec {
    /// Ply angle \[deg\].
    pub angle: f64,
    /// Ply thickness \[m\].
    pub thickness: f64,
}

/// Build a laminate of one material from ply specs (bottom to top),
/// converting degrees to radians. Error keys: `material.…`, `plies[k].…`.
pub fn resolve_laminate(material: &MaterialSpec, plies: &[PlySpec]) -> Result<Laminate> {
    let m = material.resolve()?;
    if plies.is_empty() {
        return Err(Error::input("plies", "[]", "at least one ply"));
    }
    Laminate::new(
        plies
            .iter()
            .map(|p| Ply {
                material: m,
                thickness: p.thickness,
                angle: p.angle.to_radians(),
            })
            .collect(),
    )
}
