//! Where a scene's right-hand side spends its time, and how stiff it is.
//!
//! `cargo bench --bench scene_profile -- studies/sar_phase1_flexible.toml`
//! (that study when none is named, so a plain `cargo bench` runs it too).
//!
//! Prints, at the consistent initial state of the study's scene:
//! - the natural frequencies of each flexible body's modal basis (Hz);
//! - the cost of the pieces of one right-hand side in `f64`, in
//!   `Dual64` (one Jacobian-vector product) and in `DualN<8>` (the eight
//!   lanes of a fused 8-variable sensitivity evaluation), from
//!   [`plyscape::sections::kernel_bench::rhs_pieces`] (fastest of 7 batches, µs);
//! - the cost of one dense Jacobian by `n` dual evaluations (what an
//!   implicit method pays per Jacobian without column compression);
//! - the eigenvalues of that Jacobian with the largest modulus and the
//!   states that dominate the fastest one (power iteration on `J²`): the
//!   stiffness an integrator meets.
use nalgebra::{DMatrix, DVector};
use num_dual::Dual64;
use plyscape::mbs::math::DualN;
use plyscape::mbs::{System, Workspace};
use plyscape::scene::load_scene;
use plyscape::sections::kernel_bench::{rhs_pieces, PIECES};
use plyscape::study::Study;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // `cargo bench` adds `--bench` to the arguments.
    let path = std::env::args()
        .skip(1)
        .find(|a| a != "--bench")
        .unwrap_or_else(|| "studies/sar_phase1_flexible.toml".into());
    let study = Study::load(std::path::Path::new(&path))?;
    let scene = load_scene(&study)?;
    for b in &scene.model.bodies {
        if let Some(f) = &b.flex {
            let hz: Vec<String> = f
                .inv
                .lambda
                .iter()
                .map(|l| format!("{:.3}", l.sqrt() / (2.0 * std::f64::consts::PI)))
                .collect();
            println!("{} modes [Hz]: {}", b.name, hz.join(" "));
        }
    }
    let sys = System::new(scene.model.clone());
    let mut y = sys.initial_state();
    let p = sys.project(0.0, &mut y)?;
    let n = y.len();
    println!(
        "{n} states, {} equations, rank {} ({} redundant)",
        p.equations,
        p.rank,
        p.equations - p.rank
    );
    let plain = rhs_pieces(&sys, 0.0, &y);
    let scale = 1.0 / (n as f64).sqrt();
    let yd: Vec<Dual64> = y.iter().map(|&v| Dual64::new(v, scale)).collect();
    let dual = rhs_pieces(&sys, 0.0, &yd);
    // Eight lanes, as a fused 8-variable sensitivity evaluation carries
    // (state lanes only: the design lanes of the invariants cost the same
    // arithmetic).
    let y8: Vec<DualN<8>> = y
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            DualN::new(
                v,
                std::array::from_fn(|l| scale * (1.0 + ((k * 7 + l * 3) % 5) as f64)),
            )
        })
        .collect();
    let dual8 = rhs_pieces(&sys, 0.0, &y8);
    println!(
        "{:<46} {:>10} {:>10} {:>10}",
        "piece", "f64 [us]", "dual [us]", "8 lanes [us]"
    );
    for (k, name) in PIECES.iter().enumerate() {
        println!(
            "{name:<46} {:>10.1} {:>10.1} {:>10.1}",
            plain[k], dual[k], dual8[k]
        );
    }
    // Dense Jacobian by n dual evaluations.
    let mut ws = Workspace::<Dual64>::empty();
    let mut dy = vec![Dual64::from(0.0); n];
    let mut j = DMatrix::<f64>::zeros(n, n);
    let start = Instant::now();
    for c in 0..n {
        let yd: Vec<Dual64> = y
            .iter()
            .enumerate()
            .map(|(k, &v)| Dual64::new(v, if k == c { 1.0 } else { 0.0 }))
            .collect();
        sys.rhs(0.0, &yd, &mut dy, &mut ws);
        for r in 0..n {
            j[(r, c)] = dy[r].eps;
        }
    }
    println!(
        "dense Jacobian ({n} dual rhs): {:.2} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    let start = Instant::now();
    let lu = j.clone().lu();
    println!(
        "dense LU of J ({n}x{n}, nalgebra): {:.3} ms (det sign {})",
        start.elapsed().as_secs_f64() * 1e3,
        lu.determinant().signum()
    );
    let mut ev: Vec<_> = j.complex_eigenvalues().iter().cloned().collect();
    ev.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    println!("largest eigenvalues of J [1/s]:");
    for e in ev.iter().take(8) {
        println!("  {:+.4e} {:+.4e}i", e.re, e.im);
    }
    // States of the fastest mode: power iteration on J² (its eigenvalue
    // -ω² dominates when one oscillation is much faster than the rest).
    let mut v = DVector::<f64>::from_fn(n, |k, _| 1.0 + (k % 7) as f64);
    for _ in 0..40 {
        v = &j * (&j * &v);
        v /= v.norm();
    }
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|a, b| v[*b].abs().total_cmp(&v[*a].abs()));
    let layout = |k: usize| -> String {
        for s in 0..sys.nb() {
            let (p, o, d) = (sys.pos_off(s), sys.vel_off(s), sys.dof(s));
            let name = &sys.model.bodies[sys.moving[s]].name;
            if (p..p + d + 1).contains(&k) {
                return match k - p {
                    0..=2 => format!("{name} r[{}]", k - p),
                    3..=6 => format!("{name} p[{}]", k - p - 3),
                    m => format!("{name} w[{}]", m - 7),
                };
            }
            if (o..o + d).contains(&k) {
                return match k - o {
                    0..=2 => format!("{name} v[{}]", k - o),
                    3..=5 => format!("{name} omega'[{}]", k - o - 3),
                    m => format!("{name} wdot[{}]", m - 6),
                };
            }
        }
        format!("state {k}")
    };
    println!("fastest mode, largest components:");
    for &k in idx.iter().take(6) {
        println!("  {:<22} {:+.4e}", layout(k), v[k]);
    }
    Ok(())
}
