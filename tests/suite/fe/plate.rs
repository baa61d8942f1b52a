//! No shear locking: simply supported square plate under uniform pressure,
//! thin (a/h = 1000, Kirchhoff series) and moderately thick (a/h = 10,
//! FSDT Navier series), solved with faer's sparse Cholesky.

use faer::prelude::*;
use faer::Side;
use plyscape::fe::{Derivatives, Mesh, MeshParams, PanelModel, Support};
use plyscape::laminate::{DesignMap, Laminate, Orthotropic, Ply, SHEAR_CORRECTION};

const E: f64 = 70e9;
const NU: f64 = 0.3;

fn isotropic(h: f64) -> Laminate {
    let g = E / (2.0 * (1.0 + NU));
    let m = Orthotropic {
        e1: E,
        e2: E,
        g12: g,
        g13: g,
        g23: g,
        nu12: NU,
        rho: 2700.0,
    };
    Laminate::new(vec![Ply {
        material: m,
        thickness: h,
        angle: 0.0,
    }])
    .unwrap()
}

/// Centre deflection of the FE model of an a×a simply supported plate.
fn fe_centre_deflection(a: f64, h: f64, divisions: usize, q: f64) -> f64 {
    let mesh = Mesh::structured(&MeshParams {
        length: a,
        width: a,
        divisions,
        points: vec![],
    })
    .unwrap();
    let model = PanelModel::new(mesh, Support::SimplySupported).unwrap();
    let lam = isotropic(h);
    let sys = model
        .assemble(&lam, &DesignMap::per_ply(1), Derivatives::None)
        .unwrap();
    let f = model.uniform_pressure_load(q);
    let llt = sys.k.sp_cholesky(Side::Lower).expect("K positive definite");
    let rhs = Col::<f64>::from_fn(f.len(), |i| f[i]);
    let x = llt.solve(&rhs);
    let c = model.mesh().centre;
    x[model.free_dof(c, 2).unwrap()]
}

/// Kirchhoff plate, Navier double series (Timoshenko & Woinowsky-Krieger,
/// Theory of Plates and Shells, §30, Eq. 137 at the centre):
/// `w = 16 q/(π⁶ D) Σ_{m,n odd} (−1)^((m+n)/2−1) / (m n (m²/a² + n²/b²)²)`.
fn kirchhoff_series(a: f64, q: f64, d: f64) -> f64 {
    let mut s = 0.0;
    for m in (1..400).step_by(2) {
        for n in (1..400).step_by(2) {
            let (mf, nf) = (m as f64, n as f64);
            let sign = if ((m + n) / 2 - 1) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            s += sign / (mf * nf * (mf * mf / (a * a) + nf * nf / (a * a)).powi(2));
        }
    }
    16.0 * q / (std::f64::consts::PI.powi(6) * d) * s
}

/// FSDT plate (hard simple support SS-1), Navier series (Reddy, Theory and
/// Analysis of Elastic Plates and Shells, 2nd ed., §6.3, Eq. 6.3.13 family):
/// per (m, n) solve
/// `[[s11, s12, s13], [s12, s22, s23], [s13, s23, s33]] {W, X, Y} = {Q, 0, 0}`
/// with `s11 = K(α²+β²)`, `s12 = Kα`, `s13 = Kβ`, `s22 = D11α² + D66β² + K`,
/// `s23 = (D12 + D66)αβ`, `s33 = D66α² + D22β² + K`, `K = κGh`,
/// `Q = 16q/(π² m n)`, α = mπ/a, β = nπ/a (derived in this test from the
/// FSDT equilibrium equations with w = W sin αx sin βy, φx = X cos αx sin βy,
/// φy = Y sin αx cos βy).
fn fsdt_series(a: f64, h: f64, q: f64) -> f64 {
    let d11 = E * h.powi(3) / (12.0 * (1.0 - NU * NU));
    let (d12, d66) = (NU * d11, 0.5 * (1.0 - NU) * d11);
    let k = SHEAR_CORRECTION * E / (2.0 * (1.0 + NU)) * h;
    let pi = std::f64::consts::PI;
    let mut w = 0.0;
    for m in (1..400).step_by(2) {
        for n in (1..400).step_by(2) {
            let (al, be) = (m as f64 * pi / a, n as f64 * pi / a);
            let s = nalgebra::Matrix3::new(
                k * (al * al + be * be),
                k * al,
                k * be,
                k * al,
                d11 * al * al + d66 * be * be + k,
                (d12 + d66) * al * be,
                k * be,
                (d12 + d66) * al * be,
                d66 * al * al + d11 * be * be + k,
            );
            let qmn = 16.0 * q / (pi * pi * (m * n) as f64);
            let x = s
                .lu()
                .solve(&nalgebra::Vector3::new(qmn, 0.0, 0.0))
                .unwrap();
            let sign = if ((m + n) / 2 - 1) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            w += sign * x[0];
        }
    }
    w
}

#[test]
fn thin_plate_a_over_h_1000_matches_kirchhoff_series() {
    let (a, h, q): (f64, f64, f64) = (1.0, 1e-3, 1.0);
    let d = E * h.powi(3) / (12.0 * (1.0 - NU * NU));
    let w_ref = kirchhoff_series(a, q, d);
    // Timoshenko & Woinowsky-Krieger, Table 8 (ν = 0.3): w_max = 0.00406 q a⁴/D.
    assert!((w_ref * d / (q * a.powi(4)) - 0.00406).abs() < 5e-6);
    let mut errs = Vec::new();
    for n in [16, 32] {
        let w = fe_centre_deflection(a, h, n, q);
        errs.push((w - w_ref).abs() / w_ref);
        eprintln!(
            "a/h=1000 n={n}: w = {w:.6e}, ref {w_ref:.6e}, rel err {:.3e}",
            errs.last().unwrap()
        );
    }
    // Measured: 9.5e-3 (n = 16), 2.4e-3 (n = 32): second-order convergence,
    // no locking at a/h = 1000.
    assert!(errs[1] < 4e-3, "{errs:?}");
    assert!(
        errs[1] < 0.35 * errs[0],
        "converges at second order: {errs:?}"
    );
}

#[test]
fn thick_plate_a_over_h_10_matches_fsdt_navier_series() {
    let (a, h, q): (f64, f64, f64) = (1.0, 0.1, 1.0);
    let w_ref = fsdt_series(a, h, q);
    let d = E * h.powi(3) / (12.0 * (1.0 - NU * NU));
    // Reddy (2nd ed.), Table 10.1.2 style check: FSDT / CPT centre deflection
    // ratio for a/h = 10, ν = 0.3, κ = 5/6 is 0.4273/0.4062.
    let ratio = w_ref / kirchhoff_series(a, q, d);
    assert!((ratio - 0.4273 / 0.4062).abs() < 1e-3, "ratio {ratio}");
    let mut errs = Vec::new();
    for n in [16, 32] {
        let w = fe_centre_deflection(a, h, n, q);
        errs.push((w - w_ref).abs() / w_ref);
        eprintln!(
            "a/h=10 n={n}: w = {w:.6e}, ref {w_ref:.6e}, rel err {:.3e}",
            errs.last().unwrap()
        );
    }
    // Measured: 7.7e-3 (n = 16), 1.9e-3 (n = 32).
    assert!(errs[1] < 3e-3, "{errs:?}");
    assert!(
        errs[1] < 0.35 * errs[0],
        "converges at second order: {errs:?}"
    );
}
