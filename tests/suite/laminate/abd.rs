//! Laminate stiffness: limits, a textbook example, and exact ply-angle
//! derivatives against hyper-dual numbers.

use nalgebra::{Matrix2, Matrix3};
use num_dual::HyperDual64;
use plyscape::laminate::{
    spec::{resolve_laminate, MaterialSpec, PlySpec},
    stiffness_generic, DesignMap, Laminate, Orthotropic, Ply, Stiffness, SHEAR_CORRECTION,
};
use plyscape::Error;

fn stack(m: Orthotropic, angles_deg: &[f64], t: f64) -> Laminate {
    Laminate::new(
        angles_deg
            .iter()
            .map(|a| Ply {
                material: m,
                thickness: t,
                angle: a.to_radians(),
            })
            .collect(),
    )
    .unwrap()
}

fn close3(a: &Matrix3<f64>, b: &Matrix3<f64>, tol: f64) -> bool {
    (a - b).amax() <= tol
}

#[test]
fn isotropic_limit_is_angle_independent_and_matches_plate_formulas() {
    // Closed form derived in this test: isotropic plate, E, ν, thickness h:
    // A = E h/(1−ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, (1−ν)/2]], D = A h²/12,
    // B = 0, S = κ G h I.
    let (e, nu, h) = (70e9, 0.3, 2e-3);
    let g = e / (2.0 * (1.0 + nu));
    let m = Orthotropic {
        e1: e,
        e2: e,
        g12: g,
        g13: g,
        g23: g,
        nu12: nu,
        rho: 2700.0,
    };
    let f = e * h / (1.0 - nu * nu);
    let a_ref = Matrix3::new(
        f,
        nu * f,
        0.0,
        nu * f,
        f,
        0.0,
        0.0,
        0.0,
        f * (1.0 - nu) / 2.0,
    );
    let d_ref = a_ref * (h * h / 12.0);
    let s_ref = Matrix2::identity() * (SHEAR_CORRECTION * g * h);
    for angles in [[0.0, 0.0], [17.0, -63.0], [45.0, 90.0]] {
        let st = stack(m, &angles, h / 2.0).stiffness();
        assert!(close3(&st.a, &a_ref, 1e-12 * f), "{angles:?}");
        assert!(close3(&st.d, &d_ref, 1e-12 * f * h * h), "{angles:?}");
        assert!(st.b.amax() <= 1e-12 * f * h);
        assert!((st.s - s_ref).amax() <= 1e-12 * g * h);
    }
    let lam = stack(m, &[0.0], h);
    assert!((lam.mass_per_area() - 2700.0 * h).abs() < 1e-12);
    assert!((lam.rotary_inertia_per_area() - 2700.0 * h.powi(3) / 12.0).abs() < 1e-20);
}

#[test]
fn single_ply_limit() {
    // Closed form: one ply, A = Q̄ h, B = 0, D = Q̄ h³/12; at θ = 0 Q̄ = Q
    // (Q11 = E1/(1−ν12ν21), Q12 = ν12 E2/(1−ν12ν21), Q66 = G12), and
    // S = κ h diag(G13, G23).
    let m = Orthotropic::im6_sc1081();
    let h = 2e-3;
    let st = stack(m, &[0.0], h).stiffness();
    let nu21 = m.nu12 * m.e2 / m.e1;
    let den = 1.0 - m.nu12 * nu21;
    let q = Matrix3::new(
        m.e1 / den,
        m.nu12 * m.e2 / den,
        0.0,
        m.nu12 * m.e2 / den,
        m.e2 / den,
        0.0,
        0.0,
        0.0,
        m.g12,
    );
    assert!(close3(&st.a, &(q * h), 1e-12 * m.e1 * h));
    assert!(close3(
        &st.d,
        &(q * (h.powi(3) / 12.0)),
        1e-12 * m.e1 * h.powi(3)
    ));
    assert!(st.b.amax() == 0.0);
    let s_ref = Matrix2::new(m.g13, 0.0, 0.0, m.g23) * (SHEAR_CORRECTION * h);
    assert!((st.s - s_ref).amax() <= 1e-12 * m.g23 * h);
    // At 90°, fibre along y: Q̄11 = Q22, Q̄22 = Q11, S = κ h diag(G23, G13).
    let st = stack(m, &[90.0], h).stiffness();
    assert!((st.a[(0, 0)] - q[(1, 1)] * h).abs() < 1e-12 * m.e1 * h);
    assert!((st.a[(1, 1)] - q[(0, 0)] * h).abs() < 1e-12 * m.e1 * h);
    assert!((st.s[(0, 0)] - SHEAR_CORRECTION * m.g23 * h).abs() < 1e-12 * m.g23 * h);
}

#[test]
fn symmetric_layups_have_no_coupling_and_cross_ply_has_closed_form_b() {
    let m = Orthotropic::im6_sc1081();
    let t = 0.5e-3;
    for angles in [
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 90.0, 90.0, 0.0],
        [30.0, -45.0, -45.0, 30.0],
    ] {
        let st = stack(m, &angles, t).stiffness();
        assert!(
            st.b.amax() <= 1e-12 * st.a.amax() * 4.0 * t,
            "{angles:?}: B = {}",
            st.b
        );
    }
    // Closed form derived in this test: [0/90] with plies of t, h = 2t:
    // B11 = ½ Q11 (0 − t²) + ½ Q22 (t² − 0) = (Q22 − Q11) t²/2, B22 = −B11,
    // other entries 0.
    let st = stack(m, &[0.0, 90.0], t).stiffness();
    let [q11, q22, _, _] = m.reduced();
    let b11 = (q22 - q11) * t * t / 2.0;
    let b_ref = Matrix3::new(b11, 0.0, 0.0, 0.0, -b11, 0.0, 0.0, 0.0, 0.0);
    assert!(close3(&st.b, &b_ref, 1e-12 * q11 * t * t));
}

#[test]
fn barbero_example_5_7_single_45_degree_ply() {
    // Barbero, Introduction to Composite Materials Design (2nd ed.),
    // Example 5.7: E1 = 67192, E2 = 12139, G12 = 7638 MPa, ν12 = 0.365, one
    // 45° ply of unit thickness: A11 = A22 = 30229.87, A12 = 14953.87,
    // A16 = A26 = 14102.68, A66 = 18051.87 (MPa·m). The book prints 2
    // decimals: tolerance 0.01 (MPa-based units kept here).
    let m = Orthotropic {
        e1: 67192.0,
        e2: 12139.0,
        g12: 7638.0,
        g13: 7638.0,
        g23: 4000.0,
        nu12: 0.365,
        rho: 1.0,
    };
    let a = stack(m, &[45.0], 1.0).stiffness().a;
    let want = [
        (0, 0, 30229.87),
        (1, 1, 30229.87),
        (0, 1, 14953.87),
        (0, 2, 14102.68),
        (1, 2, 14102.68),
        (2, 2, 18051.87),
    ];
    for (i, j, v) in want {
        assert!(
            (a[(i, j)] - v).abs() < 0.01,
            "A{}{} = {} vs {v}",
            i + 1,
            j + 1,
            a[(i, j)]
        );
    }
}

#[allow(clippy::needless_range_loop)]
/// Max-entry difference between an analytic `Stiffness` and the given
/// hyper-dual part of the generic twin, relative to `scale`.
fn rel_err(
    st: &Stiffness,
    g: &plyscape::laminate::GenericAbd<HyperDual64>,
    part: fn(&HyperDual64) -> f64,
    scale: &Stiffness,
) -> f64 {
    let (a, b, d, s) = g;
    let mut err: f64 = 0.0;
    let h_scale = scale.a.amax();
    let bscale = scale.b.amax().max(1e-3 * h_scale * 1e-3);
    for i in 0..3 {
        for j in 0..3 {
            err = err.max((st.a[(i, j)] - part(&a[i][j])).abs() / scale.a.amax());
            err = err.max((st.b[(i, j)] - part(&b[i][j])).abs() / bscale);
            err = err.max((st.d[(i, j)] - part(&d[i][j])).abs() / scale.d.amax());
        }
    }
    for i in 0..2 {
        for j in 0..2 {
            err = err.max((st.s[(i, j)] - part(&s[i][j])).abs() / scale.s.amax());
        }
    }
    err
}

#[test]
fn ply_angle_derivatives_match_hyper_dual_numbers() {
    // Reference: forward-mode AD with hyper-dual numbers (num-dual 0.15) of
    // the generic twin `stiffness_generic` (explicit transformation
    // polynomials, an independent route from the invariant closed forms).
    let m = Orthotropic::im6_sc1081();
    let lam = stack(m, &[12.0, -37.0, 71.0, 155.0], 0.5e-3);
    let scale = lam.stiffness();
    let n = lam.plies().len();
    for k in 0..n {
        for l in 0..n {
            let angles: Vec<HyperDual64> = lam
                .angles()
                .iter()
                .enumerate()
                .map(|(i, &t)| {
                    HyperDual64::new(
                        t,
                        if i == k { 1.0 } else { 0.0 },
                        if i == l { 1.0 } else { 0.0 },
                        0.0,
                    )
                })
                .collect();
            let g = stiffness_generic(&lam, &angles);
            // value
            assert!(rel_err(&scale, &g, |x| x.re, &scale) < 1e-12);
            // first derivative w.r.t. ply k
            let d1 = lam.ply_derivative(k, 1);
            let e1 = rel_err(&d1, &g, |x| x.eps1, &scale);
            assert!(e1 < 1e-10, "d/dθ{k}: {e1:e}");
            // second derivative (mixed ones vanish)
            let d2 = if k == l {
                lam.ply_derivative(k, 2)
            } else {
                Stiffness::default()
            };
            let e2 = rel_err(&d2, &g, |x| x.eps1eps2, &scale);
            assert!(e2 < 1e-10, "d²/dθ{k}dθ{l}: {e2:e}");
        }
    }
}

#[test]
fn design_variable_derivatives_sum_over_tied_plies() {
    // [θ1/θ2/θ2/θ1] (paper §6): variable 0 ties plies 1&4, variable 1 ties
    // 2&3. Reference: hyper-dual numbers seeded on every ply of a group.
    let m = Orthotropic::im6_sc1081();
    let lam = stack(m, &[25.0, -60.0, -60.0, 25.0], 0.5e-3);
    let map = DesignMap::new(vec![vec![0, 3], vec![1, 2]], 4).unwrap();
    assert_eq!(map, DesignMap::symmetric(4));
    let scale = lam.stiffness();
    for v in 0..2 {
        for w in 0..2 {
            let angles: Vec<HyperDual64> = lam
                .angles()
                .iter()
                .enumerate()
                .map(|(i, &t)| {
                    let inv = map.groups()[v].contains(&i);
                    let inw = map.groups()[w].contains(&i);
                    HyperDual64::new(t, inv as u8 as f64, inw as u8 as f64, 0.0)
                })
                .collect();
            let g = stiffness_generic(&lam, &angles);
            let e1 = rel_err(&lam.design_derivative(&map, v), &g, |x| x.eps1, &scale);
            assert!(e1 < 1e-10, "v={v}: {e1:e}");
            let d2 = lam.design_second_derivative(&map, v, w);
            let e2 = rel_err(&d2, &g, |x| x.eps1eps2, &scale);
            assert!(e2 < 1e-10, "v={v} w={w}: {e2:e}");
        }
    }
    let moved = lam.with_design(&map, &[0.1, 0.2]).unwrap();
    assert_eq!(moved.angles(), vec![0.1, 0.2, 0.2, 0.1]);
}

fn input_key(e: Error) -> String {
    match e {
        Error::Input { key, .. } => key,
        other => panic!("expected an input error, got {other}"),
    }
}

#[test]
fn bad_input_is_reported_with_key() {
    let good = MaterialSpec {
        e1: 177e9,
        e2: 10.8e9,
        g12: 7.6e9,
        g13: 7.6e9,
        g23: 8.504e9,
        nu12: 0.27,
        rho: 1600.0,
    };
    let plies = vec![
        PlySpec {
            angle: 0.0,
            thickness: 0.5e-3,
        };
        4
    ];
    assert!(resolve_laminate(&good, &plies).is_ok());
    let mut m = good;
    m.e2 = -1.0;
    assert_eq!(
        input_key(resolve_laminate(&m, &plies).unwrap_err()),
        "material.e2"
    );
    let mut m = good;
    m.g23 = 0.0;
    assert_eq!(
        input_key(resolve_laminate(&m, &plies).unwrap_err()),
        "material.g23"
    );
    // ν12² ≥ E1/E2: with E1/E2 = 1, ν12 = 1 makes Q singular.
    let mut m = good;
    m.e1 = m.e2;
    m.nu12 = 1.0;
    let e = resolve_laminate(&m, &plies).unwrap_err();
    assert!(e.to_string().contains("nu12"), "{e}");
    assert_eq!(
        input_key(resolve_laminate(&good, &[]).unwrap_err()),
        "plies"
    );
    let mut p = plies.clone();
    p[2].thickness = 0.0;
    assert_eq!(
        input_key(resolve_laminate(&good, &p).unwrap_err()),
        "plies[2].thickness"
    );
    assert!(DesignMap::new(vec![vec![0, 3], vec![3]], 4).is_err());
    assert!(DesignMap::new(vec![vec![4]], 4).is_err());
    assert!(DesignMap::new(vec![vec![]], 4).is_err());
}
