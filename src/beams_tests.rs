//! Unit tests of [`crate::beams`] (a file of their own to keep
//! `beams.rs` short).

use super::*;
use crate::mbs::Invariants;

/// A beam with unequal stiffnesses so that the two planes interleave
/// (ω_Z/ω_Y = √2.5).
fn beam() -> Beam {
    Beam {
        length: 2.0,
        ei_y: 7.5e3,
        ei_z: 3.0e3,
        rho_a: 1.7,
    }
}

/// Columns of `plane` in basis order.
fn columns(b: &Beam, m: usize, plane: Plane) -> Vec<usize> {
    b.mode_order(m)
        .iter()
        .enumerate()
        .filter(|(_, o)| o.0 == plane)
        .map(|(c, _)| c)
        .collect()
}

#[test]
fn roots_match_blevins() {
    // Blevins, Formulas for Natural Frequency and Mode Shape (1979),
    // Table 8-1, clamped-free beam, λ_i = β_i L, i = 1..5.
    let blevins = [1.87510407, 4.69409113, 7.85475744, 10.99554073, 14.13716839];
    for (j, r) in blevins.iter().enumerate() {
        let b = cantilever_root(j);
        assert!((b - r).abs() < 6e-9, "root {j}: {b} vs {r}");
    }
    // Residual of the frequency equation and the asymptote (j + ½)π
    // (same table, i > 5) for high roots.
    for j in [5, 10, 40, 300] {
        let b = cantilever_root(j);
        assert!((b.cos() + 1.0 / b.cosh()).abs() < 1e-14 * b, "root {j}");
        assert!((b - (j as f64 + 0.5) * PI).abs() < 1e-6, "root {j}: {b}");
    }
}

#[test]
fn gauss_legendre_is_exact_to_degree_eleven() {
    // ∫₋₁¹ x^k dx = 2/(k+1) for even k, 0 for odd k (closed form).
    let (x, w) = gauss_legendre(GAUSS_POINTS);
    for k in 0..=11 {
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k)).sum();
        let exact = if k % 2 == 0 {
            2.0 / (k + 1) as f64
        } else {
            0.0
        };
        assert!((q - exact).abs() < 1e-15, "degree {k}: {q} vs {exact}");
    }
    assert!(x.windows(2).all(|p| p[0] < p[1]));
}

#[test]
fn stable_form_matches_textbook_form_and_boundary_conditions() {
    let b = beam();
    let l = b.length;
    // Low modes: the textbook cosh/sinh form (Blevins Table 8-1) is
    // accurate there; compare at the stations.
    for j in 0..4 {
        let bl = cantilever_root(j);
        let sigma = (bl.cosh() + bl.cos()) / (bl.sinh() + bl.sin());
        let raw = |x: f64| {
            let z = bl * x / l;
            z.cosh() - z.cos() - sigma * (z.sinh() - z.sin())
        };
        let sign = raw(l).signum();
        let c = sign / (b.rho_a * l).sqrt();
        for k in 0..=10 {
            let x = k as f64 * l / 10.0;
            let (phi, _) = b.mode(j, x);
            assert!(
                (phi - c * raw(x)).abs() < 1e-10 * c.abs(),
                "mode {j} at {x}"
            );
        }
    }
    // All modes (up to βL ≈ 95, where the textbook form has no digit
    // left): φ(0) = φ'(0) = 0, φ''(L) = φ'''(L) = 0 relative to the
    // amplitude β^k/√(ρA L), and the tip value +2/√(ρA L).
    for j in 0..30 {
        let f = ModeFn::new(j, l, b.rho_a);
        let amp = 1.0 / (b.rho_a * l).sqrt();
        let (d0, dl) = (f.eval(0.0), f.eval(l));
        for (k, v) in [(0, d0[0]), (1, d0[1]), (2, dl[2]), (3, dl[3])] {
            let rel = v.abs() / (amp * f.beta.powi(k));
            assert!(rel < 1e-11, "mode {j}, derivative {k}: {rel:e}");
        }
        assert!((dl[0] - 2.0 * amp).abs() < 1e-11 * amp, "mode {j} tip");
    }
}

#[test]
fn basis_is_orthonormal_with_the_lumped_masses() {
    // ∫ ρA φ_i φ_j dx = δ_ij (module doc), by the lumped quadrature;
    // both planes, cross-plane products are zero by construction.
    let b = beam();
    for m in [8, 20] {
        let basis = b.basis(m, Beam::segments_for(m)).unwrap();
        basis.validate("beam").unwrap();
        let inv = Invariants::new(&basis);
        let n = basis.n_modes;
        let mut worst = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let d = if i == j { 1.0 } else { 0.0 };
                worst = worst.max((inv.mww[i * n + j] - d).abs());
            }
        }
        println!("{m} modes/plane: |mww − I| = {worst:.2e}");
        assert!(worst < 1e-10, "{m} modes/plane: |mww − I| = {worst:e}");
        // Sorted by frequency, both planes present.
        assert!(basis.eigenvalues.windows(2).all(|p| p[0] <= p[1]));
        assert_eq!(columns(&b, m, Plane::Y).len(), m);
    }
    // Equal stiffnesses: ties in the order Y, Z.
    let mut round = b;
    round.ei_y = round.ei_z;
    let order = round.mode_order(3);
    assert_eq!(order[0], (Plane::Y, 0));
    assert_eq!(order[1], (Plane::Z, 0));
    assert_eq!(order[5], (Plane::Z, 2));
}

#[test]
fn invariants_match_closed_forms() {
    let b = beam();
    let (l, ra) = (b.length, b.rho_a);
    let m = 6;
    let basis = b.basis(m, Beam::segments_for(m)).unwrap();
    let inv = Invariants::new(&basis);
    let n = inv.n;
    // Rigid-body integrals (closed forms): ρA L, ρA L²/2 x̂, ρA L³/3.
    assert!((inv.mass - ra * l).abs() < 1e-12 * ra * l);
    assert!((inv.s0.x - ra * l * l / 2.0).abs() < 1e-12 * ra * l * l);
    assert!(inv.s0.y == 0.0 && inv.s0.z == 0.0);
    assert!((inv.e0[(0, 0)] - ra * l.powi(3) / 3.0).abs() < 1e-12 * ra * l.powi(3));
    assert!(inv.e0.iter().skip(1).all(|v| *v == 0.0));
    // Modal integrals, derived in this test from φ'''' = β⁴φ and the
    // boundary conditions: ∫φ dx = −φ'''(0)/β⁴, ∫xφ dx = φ''(0)/β⁴.
    // i3 = Σ m Φ, ls = Σ m s × Φ with s × (0, φ, 0) = (0, 0, xφ) and
    // s × (0, 0, φ) = (0, −xφ, 0).
    for (c, &(plane, j)) in b.mode_order(m).iter().enumerate() {
        let f = ModeFn::new(j, l, ra);
        let d0 = f.eval(0.0);
        let int_phi = -ra * d0[3] / f.beta.powi(4);
        let int_x_phi = ra * d0[2] / f.beta.powi(4);
        let scale = (ra * l).sqrt().recip() * l;
        let (ci, cl, sl) = match plane {
            Plane::Y => (1, 2, 1.0),
            Plane::Z => (2, 1, -1.0),
        };
        assert!((inv.i3[ci * n + c] - int_phi).abs() < 1e-12 * ra * scale);
        assert!((inv.ls[cl * n + c] - sl * int_x_phi).abs() < 1e-12 * ra * scale * l);
        // No axial motion: no x component of i3 and no torsion in ls.
        assert!(inv.i3[c] == 0.0 && inv.ls[c] == 0.0);
    }
}

/// Static response `Σ_c X_(node, comp),c f_c / λ_c` over the columns
/// `cols` with modal forces `f`.
fn modal_static(basis: &ModalBasis, node: usize, comp: usize, cols: &[usize], f: &[f64]) -> f64 {
    cols.iter()
        .zip(f)
        .map(|(&c, fc)| basis.shape(node, comp, c) * fc / basis.eigenvalues[c])
        .sum()
}

#[test]
fn tip_load_modal_superposition_converges_to_closed_form() {
    // Closed forms (Gere & Timoshenko, Mechanics of Materials, App. G, Table G-1,
    // cantilever with a tip load): tip deflection
    // F L³/(3 EI), tip slope F L²/(2 EI). Modal force of a tip load:
    // f_j = F φ_j(L).
    let b = beam();
    let m = 8;
    let basis = b.basis(m, Beam::segments_for(m)).unwrap();
    let force = 40.0;
    for (plane, comp, rot, rsign) in [(Plane::Y, 1, 5, 1.0), (Plane::Z, 2, 4, -1.0)] {
        let cols = columns(&b, m, plane);
        let f: Vec<f64> = cols
            .iter()
            .map(|&c| force * basis.shape(TIP_NODE, comp, c))
            .collect();
        let (exact, slope) = b.static_deflection(plane, StaticLoad::Tip(force), b.length);
        assert!((exact - b.tip_deflection_tip_load(plane, force)).abs() < 1e-15 * exact);
        let mut last = f64::INFINITY;
        for k in 1..=m {
            let err =
                (modal_static(&basis, TIP_NODE, comp, &cols[..k], &f[..k]) - exact).abs() / exact;
            println!("{plane:?} tip load, {k} modes: rel. error {err:.3e}");
            assert!(
                err < last,
                "{plane:?}: error {err:e} with {k} modes after {last:e}"
            );
            last = err;
        }
        assert!(
            last < 1e-3,
            "{plane:?}: tip deflection error {last:e} with {m} modes"
        );
        let rot_err =
            (rsign * modal_static(&basis, TIP_NODE, rot, &cols, &f) - slope).abs() / slope;
        println!("{plane:?} tip load, tip rotation rel. error {rot_err:.3e}");
        assert!(rot_err < 3e-3, "{plane:?}: tip rotation error {rot_err:e}");
    }
}

#[test]
fn spin_up_load_modal_superposition_converges_to_closed_form() {
    // A spin-up with angular acceleration α about z loads the beam with
    // p(x) = ρA α x = p_L x/L, p_L = ρA α L. Modal forces
    // ∫ p φ_j dx = α Σ m x φ_j = α ls_z,j (plane Y) and, for the same
    // load along z, −α ls_y,j (plane Z). Closed form 11 p_L L⁴/(120 EI)
    // and the deflection curve of `static_deflection` (derived there,
    // tip value checked against Gere & Timoshenko Table G-1 by
    // superposition).
    let b = beam();
    let m = 8;
    let basis = b.basis(m, Beam::segments_for(m)).unwrap();
    let inv = Invariants::new(&basis);
    let n = inv.n;
    let alpha = 3.0;
    let p_l = b.rho_a * alpha * b.length;
    for (plane, comp, ls_row, sign) in [(Plane::Y, 1, 2, 1.0), (Plane::Z, 2, 1, -1.0)] {
        let cols = columns(&b, m, plane);
        let f: Vec<f64> = cols
            .iter()
            .map(|&c| sign * alpha * inv.ls[ls_row * n + c])
            .collect();
        let exact = b.tip_deflection_linear_load(plane, p_l);
        let ei = b.stiffness(plane);
        assert!((exact - 11.0 * p_l * b.length.powi(4) / (120.0 * ei)).abs() < 1e-15 * exact);
        let mut last = f64::INFINITY;
        for k in 1..=m {
            let err =
                (modal_static(&basis, TIP_NODE, comp, &cols[..k], &f[..k]) - exact).abs() / exact;
            println!("{plane:?} linear load, {k} modes: rel. error {err:.3e}");
            assert!(
                err < last,
                "{plane:?}: error {err:e} with {k} modes after {last:e}"
            );
            last = err;
        }
        assert!(
            last < 1e-4,
            "{plane:?}: tip deflection error {last:e} with {m} modes"
        );
        // The whole deflection curve at the stations.
        for s in 1..=10 {
            let x = s as f64 * b.length / 10.0;
            let node = station_node(s).unwrap();
            assert!((basis.nodes[node].x - x).abs() < 1e-15);
            let v = modal_static(&basis, node, comp, &cols, &f);
            let (ve, _) = b.static_deflection(plane, StaticLoad::Linear(p_l), x);
            assert!(
                (v - ve).abs() < 1e-4 * exact,
                "{plane:?} at x = {x}: {v} vs {ve}"
            );
        }
    }
}

#[test]
fn uniform_load_modal_superposition_converges_to_closed_form() {
    // Uniform load q: modal forces q ∫φ_j dx = q i3_y,j / ρA; closed
    // form q L⁴/(8 EI) (Gere & Timoshenko, App. G,
    // Table G-1, cantilever with a uniform load).
    let b = beam();
    let m = 8;
    let basis = b.basis(m, Beam::segments_for(m)).unwrap();
    let inv = Invariants::new(&basis);
    let q = 25.0;
    let cols = columns(&b, m, Plane::Y);
    let f: Vec<f64> = cols
        .iter()
        .map(|&c| q * inv.i3[inv.n + c] / b.rho_a)
        .collect();
    let exact = b.tip_deflection_uniform_load(Plane::Y, q);
    assert!((exact - q * b.length.powi(4) / (8.0 * b.ei_z)).abs() < 1e-15 * exact);
    let err = (modal_static(&basis, TIP_NODE, 1, &cols, &f) - exact).abs() / exact;
    println!("uniform load, {m} modes: rel. error {err:.3e}");
    assert!(err < 3e-6, "uniform load: tip deflection error {err:e}");
}

#[test]
fn static_curves_satisfy_the_beam_equation() {
    // Central finite differences (step h) of v against v', and of
    // EI v'''' against the load p(x); v(0) = v'(0) = 0.
    let b = beam();
    let (l, ei) = (b.length, b.ei_z);
    let h = 1e-2;
    let x = 0.7 * l;
    for (load, p) in [
        (StaticLoad::Tip(7.0), 0.0),
        (StaticLoad::Uniform(5.0), 5.0),
        (StaticLoad::Linear(4.0), 4.0 * x / l),
    ] {
        let v = |x: f64| b.static_deflection(Plane::Y, load, x);
        assert_eq!(v(0.0), (0.0, 0.0));
        let d1 = (v(x + h).0 - v(x - h).0) / (2.0 * h);
        assert!((d1 - v(x).1).abs() < 1e-5 * v(l).1.abs(), "{load:?}: slope");
        let d4 = (v(x + 2.0 * h).0 - 4.0 * v(x + h).0 + 6.0 * v(x).0 - 4.0 * v(x - h).0
            + v(x - 2.0 * h).0)
            / h.powi(4);
        assert!(
            (ei * d4 - p).abs() < 1e-4 * (1.0 + p),
            "{load:?}: EI v'''' = {}",
            ei * d4
        );
        // Free end: the bending moment EI v''(L) vanishes.
        let d2 = (v(l).0 - 2.0 * v(l - h).0 + v(l - 2.0 * h).0) / (h * h);
        let d2_next = (v(l - h).0 - 2.0 * v(l - 2.0 * h).0 + v(l - 3.0 * h).0) / (h * h);
        // Linear extrapolation of the backward second difference to x = L.
        let at_l = 2.0 * d2 - d2_next;
        assert!(
            at_l.abs() < 1e-3 * v(l).1.abs() / l,
            "{load:?}: v''(L) = {at_l}"
        );
    }
}

#[test]
fn bad_input_names_the_key() {
    let ok = beam();
    for (beam, key) in [
        (Beam { length: 0.0, ..ok }, "bodies[1].beam.length"),
        (Beam { ei_y: -1.0, ..ok }, "bodies[1].beam.ei_y"),
        (
            Beam {
                ei_z: f64::NAN,
                ..ok
            },
            "bodies[1].beam.ei_z",
        ),
        (
            Beam {
                rho_a: f64::INFINITY,
                ..ok
            },
            "bodies[1].beam.rho_a",
        ),
    ] {
        match beam.validate("bodies[1].beam") {
            Err(Error::Input { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{key}: {other:?}"),
        }
        assert!(matches!(beam.basis(2, 4), Err(Error::Input { .. })));
    }
    // Valid but absurd values whose eigenvalues overflow: a numerical
    // error, no infinity in the basis.
    let tiny = Beam {
        length: 1e-100,
        ..ok
    };
    assert!(matches!(tiny.basis(2, 4), Err(Error::Numerical { .. })));
    for (m, s, key) in [(0, 4, "modes_per_plane"), (2, 0, "segments")] {
        match ok.basis(m, s) {
            Err(Error::Input { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{key}: {other:?}"),
        }
    }
}
