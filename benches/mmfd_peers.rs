//! MMFD against its settings on the Hock–Schittkowski problems: function
//! and gradient calls and final accuracy per problem and setting.
//!
//! Run: `cargo bench --bench mmfd_peers [-- out.csv]` (default
//! `results/mmfd_peers/peers.csv`, relative to the working directory).
//!
//! Problems: HS 21, 35, 43, 76 and 100 from their standard starts, as
//! `plyscape::optimize::testproblems` defines them (published optima and
//! sources there). Settings:
//! - `defaults`: [`MmfdOptions::default`] (DOT's defaults);
//! - `defaults+continued`: the `defaults` run, then MMFD again from its end
//!   point with tight change tolerances (DELOBJ 1e-12, DABOBJ 1e-14, CTMIN
//!   1e-8, KT tolerance 1e-8, up to 200 iterations); the calls of both
//!   runs are added. This is not a certified polish; it shows what the
//!   method itself reaches when its exits do not stop it early.
//!
//! Columns: problem, setting, n, m, iterations, function and gradient
//! calls (DOT's counting: a call with gradients counts one of each),
//! function calls per gradient call, final f, the published f*, the
//! relative error `|f − f*| / max(1, |f*|)`, the largest constraint value
//! (normalised `g_j <= 0`), and why the (last) run stopped. The counts and
//! values are deterministic: the bench times nothing.

use plyscape::optimize::mmfd::{self, MmfdOptions};
use plyscape::optimize::testproblems::{self as tp, Analytic};
use plyscape::optimize::{LocalOutcome, NoObserver, Problem};
use std::fmt::Write as _;

/// Tight continuation settings (module doc).
fn tight() -> MmfdOptions {
    MmfdOptions {
        delobj: 1e-12,
        dabobj: Some(1e-14),
        ctmin: 1e-8,
        follow_tolerance: 1e-10,
        kt_tolerance: 1e-8,
        max_iterations: 200,
        ..MmfdOptions::default()
    }
}

fn max_g(o: &LocalOutcome) -> f64 {
    o.g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

/// One CSV row of `p` after `o` with the calls `(iterations, f, g)`.
fn row(p: &Analytic, setting: &str, o: &LocalOutcome, calls: (usize, usize, usize)) -> String {
    let rel = (o.f - p.f_opt).abs() / p.f_opt.abs().max(1.0);
    format!(
        "{},{},{},{},{},{},{},{:.3},{:.12e},{:.12e},{:.3e},{:.3e},{}\n",
        p.name(),
        setting,
        p.variables().len(),
        p.n_constraints(),
        calls.0,
        calls.1,
        calls.2,
        calls.1 as f64 / calls.2.max(1) as f64,
        o.f,
        p.f_opt,
        rel,
        max_g(o),
        o.termination
    )
}

fn main() {
    let out = std::env::args()
        .skip(1)
        .find(|a| a.ends_with(".csv"))
        .unwrap_or_else(|| "results/mmfd_peers/peers.csv".into());
    let problems = [tp::hs21(), tp::hs35(), tp::hs43(), tp::hs76(), tp::hs100()];
    let mut csv = String::from(
        "problem,setting,n,m,iterations,function_calls,gradient_calls,f_per_g,f,f_star,\
         rel_error,max_g,termination\n",
    );
    let mut ratios = Vec::new();
    for p in &problems {
        let d = mmfd::minimize(p, &p.x0, &MmfdOptions::default(), &mut NoObserver)
            .expect("mmfd runs on an analytic problem");
        let cd = (d.iterations, d.function_calls, d.gradient_calls);
        ratios.push(cd.1 as f64 / cd.2 as f64);
        csv.push_str(&row(p, "defaults", &d, cd));
        let t = mmfd::minimize(p, &d.x, &tight(), &mut NoObserver)
            .expect("mmfd runs on an analytic problem");
        let ct = (
            cd.0 + t.iterations,
            cd.1 + t.function_calls,
            cd.2 + t.gradient_calls,
        );
        csv.push_str(&row(p, "defaults+continued", &t, ct));
    }
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    print!("{csv}");
    let mut summary = String::new();
    let _ = writeln!(
        summary,
        "median function calls per gradient call (defaults): {median:.3}"
    );
    print!("{summary}");
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir).expect("output directory");
    }
    std::fs::write(&out, csv).expect("write the CSV");
    println!("wrote {out}");
}
