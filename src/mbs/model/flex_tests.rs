//! Unit tests of the inertia invariants (`flex.rs`).

use super::*;
use crate::mbs::math::Scalar;
use num_dual::Dual64;

/// The definitions node by node (the table of the module doc), in any
/// scalar, flattened in the order of [`Invariants::from_flat`]: the
/// reference for the matrix-product sums.
fn sums<T: Scalar>(basis: &ModalBasis, x: &dyn Fn(usize) -> T) -> Vec<T> {
    let n = basis.n_modes;
    let mut mass = T::zero();
    let mut s0 = Vector3::<T>::zeros();
    let mut e0 = Matrix3::<T>::zeros();
    let mut i3 = vec![T::zero(); 3 * n];
    let mut ls = vec![T::zero(); 3 * n];
    let mut p = vec![T::zero(); 9 * n];
    let mut q = vec![T::zero(); 9 * n * n];
    let mut vv = vec![T::zero(); 3 * n * n];
    let mut j_rot = Matrix3::<T>::zeros();
    let mut c_rot = vec![T::zero(); 3 * n];
    let mut mww = vec![T::zero(); n * n];
    let mut phi = vec![Vector3::<T>::zeros(); n];
    let mut psi = vec![Vector3::<T>::zeros(); n];
    for (k, s) in basis.nodes.iter().enumerate() {
        let m = T::from_subset(&basis.node_mass[k]);
        let jk = basis.node_inertia[k].map(|v| T::from_subset(&v));
        let s = s.map(|v| T::from_subset(&v));
        for j in 0..n {
            for c in 0..3 {
                phi[j][c] = x((k * 6 + c) * n + j);
                psi[j][c] = x((k * 6 + 3 + c) * n + j);
            }
        }
        mass += m;
        s0 += s * m;
        e0 += s * s.transpose() * m;
        for c in 0..3 {
            j_rot[(c, c)] += jk[c];
        }
        for j in 0..n {
            let mp = phi[j] * m;
            let sxp = s.cross(&phi[j]) * m;
            for c in 0..3 {
                i3[c * n + j] += mp[c];
                ls[c * n + j] += sxp[c];
                c_rot[c * n + j] += jk[c] * psi[j][c];
                for r in 0..3 {
                    p[j * 9 + 3 * r + c] += mp[r] * s[c];
                }
            }
            for i in 0..n {
                let pi = phi[i] * m;
                let o = (i * n + j) * 9;
                for r in 0..3 {
                    for c in 0..3 {
                        q[o + 3 * r + c] += pi[r] * phi[j][c];
                    }
                }
                let cr = pi.cross(&phi[j]);
                for c in 0..3 {
                    vv[(i * n + j) * 3 + c] += cr[c];
                }
                mww[i * n + j] += pi.dot(&phi[j]) + psi[i].component_mul(&jk).dot(&psi[j]);
            }
        }
    }
    let mut out = Vec::with_capacity(Invariants::len_flat(n));
    out.push(mass);
    out.extend(s0.iter().copied());
    out.extend(e0.transpose().iter().copied()); // row-major
    out.extend(i3);
    out.extend(ls);
    out.extend(p);
    out.extend(q);
    out.extend(vv);
    out.extend(j_rot.transpose().iter().copied());
    out.extend(c_rot);
    out.extend(mww);
    out
}

/// Two point masses on a massless spring along x, one mode (the
/// stretching mode), with a third rotary-inertia node.
fn dumbbell() -> ModalBasis {
    let a = 0.5f64.sqrt();
    // Mode: masses 1 kg at ±1 m move ∓a along x (mass-normalized:
    // 2·a² = 1), plus a node with rotary inertia rotating 0.3 rad.
    let mut shapes = vec![0.0; 18];
    shapes[0] = -a;
    shapes[6] = a;
    shapes[12 + 5] = 0.3;
    ModalBasis {
        nodes: vec![
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::zeros(),
        ],
        node_mass: vec![1.0, 1.0, 0.0],
        node_inertia: vec![
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, 0.2),
        ],
        n_modes: 1,
        shapes,
        eigenvalues: vec![4.0],
        derivatives: vec![BasisDerivative {
            name: "b".into(),
            eigenvalues: vec![1.0],
            shapes: {
                let mut d = vec![0.0; 18];
                d[6] = 2.0;
                d
            },
            node_mass: Vec::new(),
            node_inertia: Vec::new(),
        }],
        rigid: RigidScreen::default(),
        geometric: None,
    }
}

#[test]
fn dumbbell_invariants_by_hand() {
    // Closed forms derived in this test from the definitions.
    let b = dumbbell();
    b.validate("b").unwrap();
    let inv = Invariants::new(&b);
    let a = 0.5f64.sqrt();
    assert_eq!(inv.mass, 2.0);
    assert!(inv.s0.norm() < 1e-15);
    assert!((inv.e0[(0, 0)] - 2.0).abs() < 1e-15);
    // i3 = Σ m Φ = −a + a = 0; ls = Σ m s × Φ = 0 (s ∥ Φ).
    assert!(inv.i3.iter().all(|v| v.abs() < 1e-15));
    assert!(inv.ls.iter().all(|v| v.abs() < 1e-15));
    // p = Σ m Φ sᵀ: (−a)(−1) + a·1 = 2a in entry (x, x).
    assert!((inv.p[0] - 2.0 * a).abs() < 1e-15);
    // q = Σ m Φ Φᵀ: 2a² = 1 in (x, x); v = 0.
    assert!((inv.q[0] - 1.0).abs() < 1e-15);
    // Rotary: c_rot z = 0.2·0.3, mww = 1 + 0.3²·0.2.
    assert!((inv.c_rot[2] - 0.06).abs() < 1e-15);
    assert!((inv.mww[0] - (1.0 + 0.018)).abs() < 1e-15);
    assert!((inv.j_rot[(2, 2)] - 0.2).abs() < 1e-15);
}

/// A basis of 7 nodes and 3 modes with deterministic pseudo-random
/// positions, masses, inertias, shapes and shape derivatives.
fn scrambled() -> ModalBasis {
    let r = |k: usize| ((k as f64 * 0.618_034 + 0.1).fract() - 0.5) * 2.0;
    let (nn, n) = (7, 3);
    ModalBasis {
        nodes: (0..nn)
            .map(|k| Vector3::new(r(3 * k), r(3 * k + 1), r(3 * k + 2)))
            .collect(),
        node_mass: (0..nn).map(|k| 1.0 + r(50 + k).abs()).collect(),
        node_inertia: (0..nn)
            .map(|k| Vector3::new(r(60 + k).abs(), r(70 + k).abs(), r(80 + k).abs()))
            .collect(),
        n_modes: n,
        shapes: (0..6 * nn * n).map(|i| r(100 + i)).collect(),
        eigenvalues: vec![1.0, 2.0, 3.0],
        derivatives: vec![BasisDerivative {
            name: "b".into(),
            eigenvalues: vec![0.1, 0.2, 0.3],
            shapes: (0..6 * nn * n).map(|i| r(400 + i)).collect(),
            node_mass: Vec::new(),
            node_inertia: Vec::new(),
        }],
        rigid: RigidScreen::default(),
        geometric: None,
    }
}

#[test]
fn matrix_product_sums_equal_the_node_by_node_definitions() {
    // Values from f64 sums, derivatives from dual-number sums of the
    // definitions, both node by node; the products agree to round-off.
    let b = scrambled();
    let (inv, d) = Invariants::with_derivatives(&b);
    let n = b.n_modes;
    let want = Invariants::from_flat(n, &sums::<f64>(&b, &|i| b.shapes[i]), b.eigenvalues.clone());
    let dual = sums::<Dual64>(&b, &|i| {
        Dual64::new(b.shapes[i], b.derivatives[0].shapes[i])
    });
    let eps: Vec<f64> = dual.iter().map(|x| x.eps).collect();
    let dwant = Invariants::from_flat(n, &eps, vec![0.1, 0.2, 0.3]);
    let close = |a: &Invariants, b: &Invariants, what: &str| {
        for (name, x, y) in [
            ("i3", &a.i3, &b.i3),
            ("ls", &a.ls, &b.ls),
            ("p", &a.p, &b.p),
            ("q", &a.q, &b.q),
            ("v", &a.v, &b.v),
            ("c_rot", &a.c_rot, &b.c_rot),
            ("mww", &a.mww, &b.mww),
        ] {
            for (u, v) in x.iter().zip(y) {
                assert!((u - v).abs() < 1e-13, "{what} {name}: {u} vs {v}");
            }
        }
        assert!((a.e0 - b.e0).norm() < 1e-13 && (a.s0 - b.s0).norm() < 1e-13);
        assert!((a.j_rot - b.j_rot).norm() < 1e-13 && (a.mass - b.mass).abs() < 1e-13);
    };
    close(&inv, &want, "value");
    close(&d[0], &dwant, "derivative");
    assert_eq!(d[0].mass, 0.0);
}

#[test]
fn invariant_derivatives_match_finite_differences() {
    // Central finite differences of the invariants along dX.
    let b = dumbbell();
    let (_, d) = Invariants::with_derivatives(&b);
    let h = 1e-6;
    let at = |t: f64| {
        let mut x = b.clone();
        for (s, ds) in x.shapes.iter_mut().zip(&b.derivatives[0].shapes) {
            *s += t * ds;
        }
        Invariants::new(&x)
    };
    let (ip, im) = (at(h), at(-h));
    let fd = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
    };
    for (an, num) in [
        (&d[0].p, fd(&ip.p, &im.p)),
        (&d[0].q, fd(&ip.q, &im.q)),
        (&d[0].mww, fd(&ip.mww, &im.mww)),
        (&d[0].i3, fd(&ip.i3, &im.i3)),
    ] {
        for (x, y) in an.iter().zip(&num) {
            assert!((x - y).abs() < 1e-8, "{x} vs {y}");
        }
    }
    assert_eq!(d[0].lambda, vec![1.0]);
    assert_eq!(d[0].mass, 0.0);
}

/// Every invariant of the flat layout plus Λ, for comparisons.
fn flat(i: &Invariants) -> Vec<f64> {
    let mut v = vec![i.mass];
    v.extend(i.s0.iter());
    v.extend(i.e0.iter());
    for x in [&i.i3, &i.ls, &i.p, &i.q, &i.v, &i.c_rot, &i.mww, &i.lambda] {
        v.extend(x.iter());
    }
    v.extend(i.j_rot.iter());
    v
}

#[test]
fn invariant_derivatives_with_mass_derivatives_match_finite_differences() {
    // A variable that moves the node masses and inertias as well as the
    // shapes (a ply thickness): every invariant, the constant ones
    // included, against central differences along (m', J', X', Λ'). The
    // sums are cubic in the step, so the truncation is ~h² times the third
    // derivative / 6 ≈ 1e-10 at h = 1e-5 and rounding ~1e-16/h ≈ 1e-11.
    let mut b = scrambled();
    let nn = b.nodes.len();
    let r = |k: usize| ((k as f64 * 0.414_214 + 0.3).fract() - 0.5) * 2.0;
    b.derivatives[0].node_mass = (0..nn).map(r).collect();
    b.derivatives[0].node_inertia = (0..nn)
        .map(|k| Vector3::new(r(20 + k), r(40 + k), r(60 + k)))
        .collect();
    b.validate("b").unwrap();
    let (_, d) = Invariants::with_derivatives(&b);
    let h = 1e-5;
    let at = |t: f64| {
        let mut x = b.clone();
        let dv = &b.derivatives[0];
        x.shapes
            .iter_mut()
            .zip(&dv.shapes)
            .for_each(|(s, ds)| *s += t * ds);
        x.node_mass
            .iter_mut()
            .zip(&dv.node_mass)
            .for_each(|(s, ds)| *s += t * ds);
        x.node_inertia
            .iter_mut()
            .zip(&dv.node_inertia)
            .for_each(|(s, ds)| *s += ds * t);
        x.eigenvalues
            .iter_mut()
            .zip(&dv.eigenvalues)
            .for_each(|(s, ds)| *s += t * ds);
        flat(&Invariants::new(&x))
    };
    let (p, m) = (at(h), at(-h));
    let an = flat(&d[0]);
    for (k, (a, (x, y))) in an.iter().zip(p.iter().zip(&m)).enumerate() {
        let fd = (x - y) / (2.0 * h);
        assert!(
            (a - fd).abs() < 1e-9 * (1.0 + fd.abs()),
            "entry {k}: {a} vs {fd}"
        );
    }
    assert!(d[0].mass != 0.0 && d[0].j_rot.norm() > 0.0);
}

#[test]
fn truncation_and_bad_input() {
    let mut b = dumbbell();
    b.n_modes = 1;
    assert_eq!(b.truncated(5).n_modes, 1);
    b.eigenvalues[0] = -1.0;
    let e = b.validate("scene.bodies[0].modal").unwrap_err().to_string();
    assert!(e.contains("eigenvalues[0]"), "{e}");
}
