//! Timing of the modal kernel on ~10k-DOF test matrices, one core.
//!
//! Cases:
//! - `laplace5`: 100 × 100 grid, 5-point Dirichlet Laplacian (10,000 DOFs),
//!   varied spring stiffnesses and masses;
//! - `block9x3`: 58 × 58 nodes × 3 DOFs (10,092 DOFs), 9-point stencil with
//!   dense 3 × 3 blocks: a fill pattern closer to a shell model.
//!
//! Each case has two design variables (two families of elements scaled by
//! `1 + a·sin θ₀` and `1 + b·cos 2θ₁`). Timed: pattern + AMD + symbolic
//! factorization, 14 modes (numeric Cholesky + Lanczos), eigenvalue
//! derivatives only (fixed-mode) and eigenvalue + eigenvector derivatives
//! (updated-mode, Nelson). Median CPU time of 7 runs (thread `schedstat`,
//! which on this VM ticks in 4 ms steps) and the fastest wall time of the 7
//! (best estimate for an unloaded core). Overrides for experiments:
//! `BENCH_BLOCK`, `BENCH_TOL`, `BENCH_BASIS`. Writes
//! `results/modal_bench/modal_bench.csv`.
//!
//! Run: `cargo bench --bench modal_bench`

use std::time::Instant;

use faer::sparse::{SparseColMat, Triplet};
use plyscape::modal::{DerivativeOptions, DesignDerivative, ModalOptions, ModalSolver, ModeUpdate};

/// Element: DOF blocks of two nodes (or one node to ground), a 3×3 SPD block
/// (or 1×1), and its design family (0 or 1).
struct Elem {
    a: usize,
    b: Option<usize>,
    block: Vec<f64>,
    dofs: usize,
    family: usize,
}

struct Case {
    name: &'static str,
    n: usize,
    elems: Vec<Elem>,
    mass: Vec<f64>,
}

fn laplace5(nx: usize) -> Case {
    let id = |i: usize, j: usize| i + nx * j;
    let mut elems = Vec::new();
    let mut e = 0usize;
    for j in 0..nx {
        for i in 0..nx {
            let w = |e: usize| 1.0e4 * (1.0 + 0.5 * ((e as f64) * 0.73).sin());
            if i + 1 < nx {
                elems.push(Elem {
                    a: id(i, j),
                    b: Some(id(i + 1, j)),
                    block: vec![w(e)],
                    dofs: 1,
                    family: 0,
                });
                e += 1;
            }
            if j + 1 < nx {
                elems.push(Elem {
                    a: id(i, j),
                    b: Some(id(i, j + 1)),
                    block: vec![w(e)],
                    dofs: 1,
                    family: 1,
                });
                e += 1;
            }
            if i == 0 || j == 0 || i + 1 == nx || j + 1 == nx {
                elems.push(Elem {
                    a: id(i, j),
                    b: None,
                    block: vec![w(e)],
                    dofs: 1,
                    family: 0,
                });
                e += 1;
            }
        }
    }
    let n = nx * nx;
    Case {
        name: "laplace5",
        n,
        elems,
        mass: (0..n)
            .map(|i| 1.0 + 0.3 * ((i as f64) * 1.37).cos())
            .collect(),
    }
}

fn block9x3(nx: usize) -> Case {
    let id = |i: usize, j: usize| i + nx * j;
    let mut elems = Vec::new();
    let mut e = 0usize;
    let block = |e: usize| {
        // SPD 3×3: diagonally dominant with varied entries.
        let s = |k: f64| ((e as f64) * 0.37 + k).sin();
        let (d0, d1, d2) = (3.0 + s(0.1), 3.0 + s(0.7), 3.0 + s(1.3));
        let (o01, o02, o12) = (0.5 * s(2.1), 0.4 * s(2.9), 0.3 * s(3.7));
        vec![d0, o01, o02, o01, d1, o12, o02, o12, d2]
            .into_iter()
            .map(|v| 1.0e4 * v)
            .collect::<Vec<f64>>()
    };
    for j in 0..nx {
        for i in 0..nx {
            let nbrs = [(1i64, 0i64), (0, 1), (1, 1), (1, -1)];
            for (f, (di, dj)) in nbrs.iter().enumerate() {
                let (ii, jj) = (i as i64 + di, j as i64 + dj);
                if ii >= 0 && jj >= 0 && (ii as usize) < nx && (jj as usize) < nx {
                    elems.push(Elem {
                        a: id(i, j),
                        b: Some(id(ii as usize, jj as usize)),
                        block: block(e),
                        dofs: 3,
                        family: f % 2,
                    });
                    e += 1;
                }
            }
            if i == 0 || j == 0 || i + 1 == nx || j + 1 == nx {
                elems.push(Elem {
                    a: id(i, j),
                    b: None,
                    block: block(e),
                    dofs: 3,
                    family: 0,
                });
                e += 1;
            }
        }
    }
    let n = 3 * nx * nx;
    Case {
        name: "block9x3",
        n,
        elems,
        mass: (0..n)
            .map(|i| if i % 3 == 2 { 0.05 } else { 1.0 } * (1.0 + 0.2 * ((i as f64) * 0.91).sin()))
            .collect(),
    }
}

/// Σ_e w(e) K_e in full symmetric storage.
fn assemble(c: &Case, w: impl Fn(&Elem) -> f64) -> SparseColMat<usize, f64> {
    let mut t = Vec::new();
    for el in &c.elems {
        let s = w(el);
        let d = el.dofs;
        for r in 0..d {
            for q in 0..d {
                let v = s * el.block[r * d + q];
                let (ar, aq) = (el.a * d + r, el.a * d + q);
                t.push(Triplet::new(ar, aq, v));
                if let Some(b) = el.b {
                    let (br, bq) = (b * d + r, b * d + q);
                    t.push(Triplet::new(br, bq, v));
                    t.push(Triplet::new(ar, bq, -v));
                    t.push(Triplet::new(br, aq, -v));
                }
            }
        }
    }
    SparseColMat::try_new_from_triplets(c.n, c.n, &t).unwrap()
}

/// CPU time of this thread [ms] (Linux `schedstat`, ns resolution): the
/// machine is shared, so wall time overstates the kernel's cost.
fn cpu_ms() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| {
            s.split_whitespace()
                .next()
                .and_then(|v| v.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |ns| ns * 1e-6)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> plyscape::Result<()> {
    let theta = [0.3f64, 0.4f64];
    let (a, b) = (0.4, 0.3);
    let out_dir = std::path::Path::new("results/modal_bench");
    std::fs::create_dir_all(out_dir).map_err(|e| plyscape::Error::io(out_dir, e))?;
    let path = out_dir.join("modal_bench.csv");
    let mut w = csv::Writer::from_path(&path).map_err(|e| plyscape::Error::csv(&path, e))?;
    w.write_record([
        "case",
        "n",
        "nnz_k",
        "nnz_factor",
        "n_modes",
        "n_vars",
        "t_symbolic_ms",
        "t_modes_ms",
        "t_dlambda_ms",
        "t_dmodes_ms",
        "t_modes_plus_derivs_ms",
        "solves",
        "restarts",
        "basis",
        "max_residual",
        "lambda_1",
        "lambda_14",
        "wall_factor_ms",
        "wall_lanczos_ms",
        "min_wall_symbolic_ms",
        "min_wall_modes_ms",
        "min_wall_dmodes_ms",
    ])
    .map_err(|e| plyscape::Error::csv(&path, e))?;
    for case in [laplace5(100), block9x3(58)] {
        let wgt = |el: &Elem| {
            if el.family == 0 {
                1.0 + a * theta[0].sin()
            } else {
                1.0 + b * (2.0 * theta[1]).cos()
            }
        };
        let k = assemble(&case, wgt);
        let dk0 = assemble(&case, |el| {
            if el.family == 0 {
                a * theta[0].cos()
            } else {
                0.0
            }
        });
        let d2k0 = assemble(&case, |el| {
            if el.family == 0 {
                -a * theta[0].sin()
            } else {
                0.0
            }
        });
        let dk1 = assemble(&case, |el| {
            if el.family == 1 {
                -2.0 * b * (2.0 * theta[1]).sin()
            } else {
                0.0
            }
        });
        let d2k1 = assemble(&case, |el| {
            if el.family == 1 {
                -4.0 * b * (2.0 * theta[1]).cos()
            } else {
                0.0
            }
        });
        let vars = [
            DesignDerivative {
                dk: &dk0,
                d2k: Some(&d2k0),
                mass: None,
            },
            DesignDerivative {
                dk: &dk1,
                d2k: Some(&d2k1),
                mass: None,
            },
        ];
        let mut opts = ModalOptions::new(14);
        if let Ok(v) = std::env::var("BENCH_BLOCK") {
            opts.block_size = v.parse().unwrap();
        }
        if let Ok(v) = std::env::var("BENCH_TOL") {
            opts.tol = v.parse().unwrap();
        }
        if let Ok(v) = std::env::var("BENCH_BASIS") {
            opts.max_basis = Some(v.parse().unwrap());
        }
        let fixed = DerivativeOptions {
            update: ModeUpdate::Fixed,
            ..Default::default()
        };
        let upd = DerivativeOptions::default();
        let (mut ts, mut tm, mut tl, mut td) = (vec![], vec![], vec![], vec![]);
        // Fastest wall time of the 7 runs: the best estimate of the cost on
        // an unloaded core.
        let mut wall_min = [f64::INFINITY; 3];
        let mut last = None;
        for _ in 0..7 {
            let w0 = Instant::now();
            let t0 = cpu_ms();
            let mut solver = ModalSolver::new(&k, &case.mass)?;
            let t1 = cpu_ms();
            let w1 = Instant::now();
            let modes = solver.solve(&opts)?;
            let t2 = cpu_ms();
            let w2 = Instant::now();
            let _dl = solver.derivatives(&modes, &vars, &fixed)?;
            let t3 = cpu_ms();
            let w3 = Instant::now();
            let _dx = solver.derivatives(&modes, &vars, &upd)?;
            let t4 = cpu_ms();
            let w4 = Instant::now();
            ts.push(t1 - t0);
            tm.push(t2 - t1);
            tl.push(t3 - t2);
            td.push(t4 - t3);
            for (m, d) in wall_min.iter_mut().zip([w1 - w0, w2 - w1, w4 - w3]) {
                *m = m.min(d.as_secs_f64() * 1e3);
            }
            last = Some(modes);
        }
        let modes = last.unwrap();
        let (ts, tm, tl, td) = (median(ts), median(tm), median(tl), median(td));
        let maxres = modes.residuals.iter().cloned().fold(0.0, f64::max);
        println!(
            "{:9} n={:6} nnz(K)={:7} nnz(L)={:8} symbolic {:7.2} ms | 14 modes {:7.2} ms ({} solves, {} restarts, basis {}) | dλ {:6.2} ms | dλ+dX {:7.2} ms | modes+derivs {:7.2} ms | max res {:.1e} | last run wall: Cholesky {:.2} ms, Lanczos {:.2} ms | min wall: symbolic {:.2}, modes {:.2}, dλ+dX {:.2} ms",
            case.name, case.n, k.compute_nnz(), modes.stats.factor_nnz, ts, tm, modes.stats.solves,
            modes.stats.restarts, modes.stats.basis, tl, td, tm + td, maxres,
            modes.stats.factor_seconds * 1e3, modes.stats.lanczos_seconds * 1e3,
            wall_min[0], wall_min[1], wall_min[2]
        );
        w.write_record([
            case.name.to_string(),
            case.n.to_string(),
            k.compute_nnz().to_string(),
            modes.stats.factor_nnz.to_string(),
            "14".into(),
            "2".into(),
            format!("{ts:.3}"),
            format!("{tm:.3}"),
            format!("{tl:.3}"),
            format!("{td:.3}"),
            format!("{:.3}", tm + td),
            modes.stats.solves.to_string(),
            modes.stats.restarts.to_string(),
            modes.stats.basis.to_string(),
            format!("{maxres:e}"),
            format!("{:e}", modes.lambda[0]),
            format!("{:e}", modes.lambda[13]),
            format!("{:.3}", modes.stats.factor_seconds * 1e3),
            format!("{:.3}", modes.stats.lanczos_seconds * 1e3),
            format!("{:.3}", wall_min[0]),
            format!("{:.3}", wall_min[1]),
            format!("{:.3}", wall_min[2]),
        ])
        .map_err(|e| plyscape::Error::csv(&path, e))?;
    }
    w.flush().map_err(|e| plyscape::Error::io(&path, e))?;
    println!("wrote {}", path.display());
    Ok(())
}
