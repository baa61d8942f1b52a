//! Active against plain CMA-ES on Rosenbrock 10-D: function evaluations
//! to reach f <= 1e-10 (f* = 0 at (1, …, 1), Rosenbrock 1960), per seed and
//! the median over seeds 0..10.
//!
//! Run: `cargo bench --bench cmaes_active [-- out.csv]` (default
//! `results/cmaes_active/rosenbrock10.csv`). IPOP-CMA-ES with the default
//! options (σ0 = 0.3 of the range [−5, 5], λ = 10, random mean in the
//! box), `target = 1e-10`, budget 100 000; `active = true` adds the
//! negative weights (module doc of `plyscape::optimize::cmaes`). Counts
//! are deterministic per seed: the bench times nothing.

use plyscape::optimize::cmaes::{self, CmaesOptions};
use plyscape::optimize::testproblems as tp;
use plyscape::optimize::{NoObserver, Termination};

fn main() {
    let out = std::env::args()
        .skip(1)
        .find(|a| a.ends_with(".csv"))
        .unwrap_or_else(|| "results/cmaes_active/rosenbrock10.csv".into());
    let p = tp::rosenbrock(10);
    let mut csv = String::from("update,seed,evaluations,f,reached\n");
    for active in [false, true] {
        let name = if active { "active" } else { "plain" };
        let mut evals = Vec::new();
        for seed in 0..10 {
            let options = CmaesOptions {
                seed,
                max_evaluations: 100_000,
                target: Some(1e-10),
                active,
                ..CmaesOptions::default()
            };
            let o = cmaes::minimize(&p, &options, &mut NoObserver).expect("cmaes runs");
            let reached = o.termination == Termination::TargetReached;
            csv.push_str(&format!(
                "{name},{seed},{},{:.3e},{reached}\n",
                o.function_calls, o.f
            ));
            // A run that misses the target counts as the whole budget.
            evals.push(if reached { o.function_calls } else { 100_000 });
        }
        evals.sort_unstable();
        let median = (evals[4] + evals[5]) / 2;
        csv.push_str(&format!("{name},median,{median},,\n"));
    }
    print!("{csv}");
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir).expect("output directory");
    }
    std::fs::write(&out, csv).expect("write the CSV");
    println!("wrote {out}");
}
