//! The coefficients of the explicit pairs checked against the order
//! conditions of Butcher's rooted trees (Hairer, Nørsett & Wanner,
//! *Solving Ordinary Differential Equations I*, §II.2, Theorem 2.13): a
//! method of weights `w` is of order `p` iff `Σᵢ wᵢ Φᵢ(t) = 1/γ(t)` for
//! every tree `t` with at most `p` nodes, with `Φᵢ(τ) = 1`,
//! `Φᵢ([t₁..tₘ]) = Πₖ (A Φ(tₖ))ᵢ` and `γ([t₁..tₘ]) = |t| Πₖ γ(tₖ)`; a
//! continuous extension is of order `p` at `θ` iff
//! `Σᵢ wᵢ(θ) Φᵢ(t) = θ^|t|/γ(t)` (ibid. §II.6). And the observed order of
//! one step on the circular Kepler orbit, whose solution is `(cos t, sin t)`.

use super::pair::Pair;

/// A rooted tree: its node count, `γ`, and its children (indices of
/// earlier trees).
struct Tree {
    nodes: usize,
    gamma: f64,
    children: Vec<usize>,
}

/// Every rooted tree with at most `p` nodes, each once (children as
/// non-increasing index lists).
fn trees(p: usize) -> Vec<Tree> {
    let mut all = vec![Tree {
        nodes: 1,
        gamma: 1.0,
        children: vec![],
    }];
    for n in 2..=p {
        let mut new = Vec::new();
        forests(&all, n - 1, all.len(), &mut vec![], &mut new);
        for children in new {
            let gamma = n as f64 * children.iter().map(|&c| all[c].gamma).product::<f64>();
            all.push(Tree {
                nodes: n,
                gamma,
                children,
            });
        }
    }
    all
}

/// The multisets of trees (indices below `below`, non-increasing) with
/// `left` nodes in all, appended to `prefix`, into `out`.
fn forests(
    all: &[Tree],
    left: usize,
    below: usize,
    prefix: &mut Vec<usize>,
    out: &mut Vec<Vec<usize>>,
) {
    if left == 0 {
        out.push(prefix.clone());
        return;
    }
    for k in (0..below).rev() {
        if all[k].nodes <= left {
            prefix.push(k);
            forests(all, left - all[k].nodes, k + 1, prefix, out);
            prefix.pop();
        }
    }
}

/// `Φ(t)` over all stages of `pair`, for every tree of `trees`; with
/// `abs`, of `|A|` (the size that bounds the rounding of `Φ`).
fn phis(pair: &Pair, trees: &[Tree], abs: bool) -> Vec<Vec<f64>> {
    let s = pair.stages();
    let mut phi: Vec<Vec<f64>> = Vec::new();
    for t in trees {
        let mut v = vec![1.0; s];
        for &ch in &t.children {
            for (i, vi) in v.iter_mut().enumerate() {
                let a_phi: f64 = pair.a[i]
                    .iter()
                    .zip(&phi[ch])
                    .map(|(a, p)| if abs { a.abs() * p } else { a * p })
                    .sum();
                *vi *= a_phi;
            }
        }
        phi.push(v);
    }
    phi
}

/// The largest residual `|Σ wᵢ Φᵢ(t) − θ^|t|/γ(t)|` over the trees of
/// `order` nodes, relative to the size of the sum (`Σ |wᵢ| Φᵢ(t)` of
/// `|A|`, `phi.1`, with `|wᵢ|` from the absolute values of the weights'
/// own terms, `w.1`): the coefficients are written to double precision, so
/// a satisfied condition leaves a residual of a few rounding units of
/// that size (up to 1e-10 absolute for the extension's weights of 10⁴),
/// a violated one a residual of order one.
fn residual(
    w: (&[f64], &[f64]),
    theta: f64,
    order: usize,
    trees: &[Tree],
    phi: (&[Vec<f64>], &[Vec<f64>]),
) -> f64 {
    trees
        .iter()
        .zip(phi.0.iter().zip(phi.1))
        .filter(|(t, _)| t.nodes == order)
        .map(|(t, (p, pa))| {
            let sum: f64 = w.0.iter().zip(p).map(|(w, p)| w * p).sum();
            let size: f64 = w.1.iter().zip(pa).map(|(w, p)| w.abs() * p).sum();
            (sum - theta.powi(t.nodes as i32) / t.gamma).abs() / (f64::EPSILON * size)
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_trees_are_counted_right() {
    // 1, 1, 2, 4, 9, 20, 48 rooted trees of 1..7 nodes (OEIS A000081).
    let t = trees(7);
    let counts: Vec<usize> = (1..=7)
        .map(|n| t.iter().filter(|t| t.nodes == n).count())
        .collect();
    assert_eq!(counts, [1, 1, 2, 4, 9, 20, 48]);
    // γ of the bushy tree of 4 nodes is 4, of the tall one 24.
    let g4: Vec<f64> = t.iter().filter(|t| t.nodes == 4).map(|t| t.gamma).collect();
    assert!(g4.contains(&4.0) && g4.contains(&24.0), "{g4:?}");
}

#[test]
fn vern65_satisfies_its_order_conditions() {
    let pair = Pair::vern65();
    let trees = trees(7);
    let (phi, phi_abs) = (phis(&pair, &trees, false), phis(&pair, &trees, true));
    let phi = (&phi[..], &phi_abs[..]);
    for (i, (row, c)) in pair.a.iter().zip(&pair.c).enumerate() {
        // To the rounding of the sum (terms up to 208 in size).
        let sum: f64 = row.iter().sum();
        let size: f64 = row.iter().map(|a| a.abs()).sum();
        assert!(
            (sum - c).abs() <= 4.0 * f64::EPSILON * size,
            "row {i}: Σa = {sum}, c = {c}"
        );
    }
    let pad = |w: &[f64]| {
        let mut w = w.to_vec();
        w.resize(pair.stages(), 0.0);
        w
    };
    let b = pad(&pair.b);
    let b_hat: Vec<f64> = pad(&pair
        .b
        .iter()
        .zip(&pair.e)
        .map(|(b, e)| b - e)
        .collect::<Vec<_>>());
    // Of order `exact` and not one more, to rounding (the exact residual
    // is 0; one order more leaves a residual of the method's own size).
    let exactly = |w: &[f64], exact: usize, what: &str| {
        for order in 1..=exact {
            let r = residual((w, w), 1.0, order, &trees, phi);
            assert!(
                r < 16.0,
                "{what}, order {order}: residual {r:.1} rounding units"
            );
        }
        assert!(
            residual((w, w), 1.0, exact + 1, &trees, phi) > 1e6,
            "{what}"
        );
    };
    // The solution is of order 6, the embedded one of order 5 (so the
    // error estimate is O(h⁶)).
    exactly(&b, 6, "solution");
    exactly(&b_hat, 5, "embedded");
    // FSAL: the last stage is the solution at the step's end.
    assert_eq!(pair.a[pair.s - 1], pair.b[..pair.s - 1]);
    assert_eq!(pair.c[pair.s - 1], 1.0);
    let mut size = pair.clone();
    size.dense = (pair.dense.iter())
        .map(|row| row.iter().map(|p| p.abs()).collect())
        .collect();
    for theta in [0.1, 0.25, 0.5, 0.8, 1.0] {
        let w = (pair.weights(theta), size.weights(theta));
        for order in 1..=5 {
            let r = residual((&w.0, &w.1), theta, order, &trees, phi);
            assert!(
                r < 16.0,
                "extension at θ = {theta}, order {order}: {r:.1} rounding units"
            );
        }
    }
    // At θ = 1 the extension is the step's solution.
    for (w, b) in pair.weights(1.0).iter().zip(&b) {
        assert!((w - b).abs() < 1e-11, "{w} against {b}");
    }
}

#[test]
fn tsit45_of_diffsol_satisfies_its_order_conditions() {
    // The reading of diffsol's tableau (used to check the driver against
    // diffsol's stepping): order 5, embedded 4, extension 4.
    let pair = Pair::of_tableau(&diffsol::Tableau::tsit45());
    let trees = trees(5);
    let (phi, phi_abs) = (phis(&pair, &trees, false), phis(&pair, &trees, true));
    let phi = (&phi[..], &phi_abs[..]);
    for order in 1..=5 {
        let r = residual((&pair.b, &pair.b), 1.0, order, &trees, phi);
        assert!(r < 16.0, "order {order}: {r:.1} rounding units");
    }
    let w = pair.weights(0.4);
    for order in 1..=4 {
        let r = residual((&w, &w), 0.4, order, &trees, phi);
        assert!(r < 16.0, "extension, order {order}: {r:.1} rounding units");
    }
}

/// One step of length `h` of `pair` on the circular Kepler orbit
/// `q̈ = −q/|q|³` from `q = (1, 0)`, `q̇ = (0, 1)`, whose solution is
/// `q = (cos t, sin t)`: the errors of `q₁` of the solution, of the
/// embedded solution and of the extension at `θ`.
fn one_step(pair: &Pair, h: f64, theta: f64) -> (f64, f64, f64) {
    let f = |z: [f64; 4]| {
        let r3 = (z[0] * z[0] + z[1] * z[1]).powf(1.5);
        [z[2], z[3], -z[0] / r3, -z[1] / r3]
    };
    let z0 = [1.0, 0.0, 0.0, 1.0];
    let combine = |w: &[f64], k: &[[f64; 4]]| {
        let mut z = z0;
        for (wj, kj) in w.iter().zip(k) {
            for (zi, ki) in z.iter_mut().zip(kj) {
                *zi += h * wj * ki;
            }
        }
        z
    };
    let mut k: Vec<[f64; 4]> = Vec::new();
    for row in &pair.a {
        let z = combine(row, &k);
        k.push(f(z));
    }
    let b_hat: Vec<f64> = pair.b.iter().zip(&pair.e).map(|(b, e)| b - e).collect();
    (
        (combine(&pair.b, &k)[0] - h.cos()).abs(),
        (combine(&b_hat, &k)[0] - h.cos()).abs(),
        (combine(&pair.weights(theta), &k)[0] - (theta * h).cos()).abs(),
    )
}

#[test]
fn vern65_local_errors_converge_at_their_orders() {
    // Local error of a method of order p: O(h^(p+1)); halving h divides
    // it by 2^(p+1): at least 2⁷ for the solution (measured 2^7.9 and
    // 2^8.0 here: its error is smaller on this orbit than the order
    // asks), 2⁶ for the embedded solution (2^5.5, 2^5.9, 2^6.0) and for
    // the order-5 extension at θ = 0.3 (2^5.4, 2^5.5); steps small
    // enough to be asymptotic, large enough to stay above rounding.
    let pair = Pair::vern65();
    let errors: Vec<(f64, f64, f64)> = [0.4, 0.2, 0.1, 0.05]
        .iter()
        .map(|h| one_step(&pair, *h, 0.3))
        .collect();
    let rate = |a: f64, b: f64| (a / b).log2();
    for (k, w) in errors.windows(2).enumerate() {
        let (p, q, r) = (
            rate(w[0].0, w[1].0),
            rate(w[0].1, w[1].1),
            rate(w[0].2, w[1].2),
        );
        if k < 2 {
            assert!((6.6..8.5).contains(&p), "solution: {p:.2} {errors:?}");
        }
        assert!((5.3..6.5).contains(&q), "embedded: {q:.2} {errors:?}");
        if k > 0 {
            assert!((5.2..6.5).contains(&r), "extension: {r:.2} {errors:?}");
        }
    }
}
