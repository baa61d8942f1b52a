//! Optimizer overhead and CMA-ES parallel speed-up.
//!
//! Run: `cargo bench --bench optimizer_perf [-- out.csv]`
//! (default `optimizer_perf.csv` in the current directory).
//!
//! 1. MMFD overhead per iteration for 2 and 10 variables: wall time of a
//!    whole run minus the time spent inside the (cheap, analytic) problem,
//!    divided by the iterations. Two problems each: Rosenbrock (no
//!    constraint: Fletcher–Reeves directions) and a quadratic with one
//!    active linear constraint and active bounds (direction QP, constraint
//!    following).
//! 2. CMA-ES overhead per generation for 2 and 10 variables, the same way,
//!    on one thread.
//! 3. CMA-ES generation speed-up on 2 threads vs 1 with a cost that spins
//!    for a fixed 2 ms per evaluation (10 variables, λ = 10).
//!
//! Each figure is the median of 7 repetitions.

use plyscape::optimize::testproblems as tp;
use plyscape::optimize::{cmaes, mmfd, Evaluation, NoObserver, Problem, Variable};
use plyscape::Result;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Wraps a problem, adds a fixed spin (busy) or sleep per evaluation, and
/// accumulates the time spent inside `evaluate`.
struct Timed<'a> {
    inner: &'a dyn Problem,
    spin: Duration,
    sleep: bool,
    inside: Mutex<Duration>,
    calls: Mutex<usize>,
}

impl<'a> Timed<'a> {
    fn new(inner: &'a dyn Problem, spin: Duration) -> Self {
        Timed {
            inner,
            spin,
            sleep: false,
            inside: Mutex::new(Duration::ZERO),
            calls: Mutex::new(0),
        }
    }
}

impl Problem for Timed<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        let t = Instant::now();
        if self.sleep {
            std::thread::sleep(self.spin);
        } else {
            while t.elapsed() < self.spin {
                std::hint::spin_loop();
            }
        }
        let r = self.inner.evaluate(x, gradients);
        *self.inside.lock().unwrap() += t.elapsed();
        *self.calls.lock().unwrap() += 1;
        r
    }
}

/// min Σ (x_i − 2)² s.t. Σ x_i <= n/2, 0 <= x_i <= 10 with the first
/// variable bounded above by 0.1 (active bound and active constraint).
fn constrained(n: usize) -> tp::Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let n = x.len() as f64;
        let f = x.iter().map(|v| (v - 2.0).powi(2)).sum();
        let gf = x.iter().map(|v| 2.0 * (v - 2.0)).collect();
        let g = (x.iter().sum::<f64>() - 0.5 * n) / n;
        (f, vec![g], gf, vec![vec![1.0 / n; x.len()]])
    }
    let mut variables = vec![Variable::bounded("x1", 0.0, 0.1).unwrap()];
    for i in 1..n {
        variables.push(Variable::bounded(format!("x{}", i + 1), 0.0, 10.0).unwrap());
    }
    tp::Analytic {
        name: format!("constrained{n}"),
        variables,
        n_constraints: 1,
        kernel: k,
        x0: vec![0.05; n],
        optima: vec![],
        f_opt: f64::NAN,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<()> {
    // `cargo bench` adds `--bench` to the arguments.
    let out = std::env::args()
        .skip(1)
        .find(|a| a != "--bench")
        .unwrap_or_else(|| "optimizer_perf.csv".into());
    let mut rows: Vec<(String, usize, f64, String)> = Vec::new();
    let reps = 7;

    // 1. MMFD overhead per iteration.
    for n in [2usize, 10] {
        for p in [tp::rosenbrock(n), constrained(n)] {
            let opts = mmfd::MmfdOptions {
                delobj: 1e-9,
                dabobj: Some(1e-12),
                ..Default::default()
            };
            let mut per_iter = Vec::new();
            let mut iters = 0;
            for _ in 0..reps {
                let timed = Timed::new(&p, Duration::ZERO);
                let t = Instant::now();
                let o = mmfd::minimize(&timed, &p.x0, &opts, &mut NoObserver)?;
                let total = t.elapsed();
                let inside = *timed.inside.lock().unwrap();
                iters = o.iterations.max(1);
                per_iter.push((total - inside).as_secs_f64() * 1e6 / iters as f64);
            }
            let m = median(per_iter);
            println!(
                "MMFD {:>14} n = {n:2}: {m:8.2} µs/iteration ({iters} iterations)",
                p.name
            );
            rows.push((
                format!("mmfd_overhead_us_per_iteration_{}", p.name),
                n,
                m,
                format!("{iters} iterations"),
            ));
        }
    }

    // 2. CMA-ES overhead per generation (1 thread).
    let pool1 = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let pool2 = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for n in [2usize, 10] {
        let p = tp::rosenbrock(n);
        let opts = cmaes::CmaesOptions {
            seed: 5,
            max_evaluations: 4000,
            max_restarts: 0,
            ..Default::default()
        };
        let mut per_gen = Vec::new();
        let mut gens = 0;
        for _ in 0..reps {
            let timed = Timed::new(&p, Duration::ZERO);
            let t = Instant::now();
            let o = pool1.install(|| cmaes::minimize(&timed, &opts, &mut NoObserver))?;
            let total = t.elapsed();
            let inside = *timed.inside.lock().unwrap();
            gens = o.generations.max(1);
            per_gen.push((total - inside).as_secs_f64() * 1e6 / gens as f64);
        }
        let m = median(per_gen);
        println!("CMA-ES rosenbrock n = {n:2}: {m:8.2} µs/generation ({gens} generations)");
        rows.push((
            "cmaes_overhead_us_per_generation".into(),
            n,
            m,
            format!("{gens} generations, 1 thread"),
        ));
    }

    // 3. Speed-up with a fixed-cost evaluation.
    let p = tp::rastrigin(10);
    let spin = Duration::from_millis(2);
    let gens = 5;
    let opts = cmaes::CmaesOptions {
        seed: 9,
        max_evaluations: 10 * gens,
        popsize: Some(10),
        ..Default::default()
    };
    for sleep in [false, true] {
        let kind = if sleep { "sleep" } else { "spin" };
        let mut t1 = Vec::new();
        let mut t2 = Vec::new();
        for _ in 0..reps {
            for (pool, times) in [(&pool1, &mut t1), (&pool2, &mut t2)] {
                let mut timed = Timed::new(&p, spin);
                timed.sleep = sleep;
                let t = Instant::now();
                let o = pool.install(|| cmaes::minimize(&timed, &opts, &mut NoObserver))?;
                times.push(t.elapsed().as_secs_f64() * 1e3 / o.generations as f64);
            }
        }
        let (m1, m2) = (median(t1), median(t2));
        println!(
            "CMA-ES generation (λ = 10, 2 ms {kind}/eval): 1 thread {m1:.2} ms, 2 threads {m2:.2} ms, speed-up {:.3}",
            m1 / m2
        );
        let note = format!("lambda 10, 2 ms {kind} per evaluation");
        rows.push((
            format!("cmaes_generation_ms_1_thread_{kind}"),
            10,
            m1,
            note.clone(),
        ));
        rows.push((
            format!("cmaes_generation_ms_2_threads_{kind}"),
            10,
            m2,
            note.clone(),
        ));
        rows.push((format!("cmaes_speedup_2_vs_1_{kind}"), 10, m1 / m2, note));
    }

    let mut w = csv::Writer::from_path(&out).map_err(|e| plyscape::Error::csv(&out, e))?;
    w.write_record(["metric", "n_variables", "value", "note"])
        .map_err(|e| plyscape::Error::csv(&out, e))?;
    for (m, n, v, note) in rows {
        w.write_record([m, n.to_string(), format!("{v:.6}"), note])
            .map_err(|e| plyscape::Error::csv(&out, e))?;
    }
    w.flush().map_err(|e| plyscape::Error::io(&out, e))?;
    println!("wrote {out}");
    Ok(())
}
