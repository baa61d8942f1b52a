//! Robustness of certified optima (`[robustness]`): the first-order worst
//! case from the exact gradients against the evaluated corners of the
//! tolerance box.

use crate::common::explore::{column, ctx, study, table_without};
use crate::common::temp_dir;
use plyscape::error::Result;
use plyscape::explore::multistart::robustness::{assess, COLUMNS};
use plyscape::explore::problem::problems::Hs22;
use plyscape::explore::{self, DriveFlags};
use plyscape::optimize::{Evaluation, Problem, Variable};

/// A linear problem in three variables: `f = 3x − 2y + 0.5z + 1`,
/// `g₁ = x + 0.5y − z − 1`, `g₂ = −x + 4z`.
struct Linear {
    vars: Vec<Variable>,
}

impl Problem for Linear {
    fn variables(&self) -> &[Variable] {
        &self.vars
    }
    fn n_constraints(&self) -> usize {
        2
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        Ok(Evaluation {
            f: 3.0 * x[0] - 2.0 * x[1] + 0.5 * x[2] + 1.0,
            g: vec![x[0] + 0.5 * x[1] - x[2] - 1.0, -x[0] + 4.0 * x[2]],
            grad_f: gradients.then(|| vec![3.0, -2.0, 0.5]),
            grad_g: gradients.then(|| vec![vec![1.0, 0.5, -1.0], vec![-1.0, 0.0, 4.0]]),
        })
    }
}

/// For linear functions the linearisation is exact: the first-order worst
/// case is attained at a corner, so corners and formula agree to rounding.
#[test]
fn first_order_worst_case_is_tight_for_linear_functions() {
    let p = Linear {
        vars: (0..3)
            .map(|i| Variable::bounded(format!("x{i}"), -10.0, 10.0).unwrap())
            .collect(),
    };
    let x = [0.3, -0.2, 0.1];
    let delta = [0.1, 0.25, 0.05];
    let r = assess(&p, &x, &delta, 64, 1).unwrap();
    // f = 0.9 + 0.4 + 0.05 + 1 = 2.35 (hand evaluation); spread
    // 3·0.1 + 2·0.25 + 0.5·0.05 = 0.825.
    assert!((r.f_worst - (2.35 + 0.825)).abs() < 1e-12, "{r:?}");
    assert!((r.f_worst_sampled - r.f_worst).abs() < 1e-12, "{r:?}");
    // g₁ = 0.3 − 0.1 − 0.1 − 1 = −0.9, spread 0.1 + 0.125 + 0.05 = 0.275;
    // g₂ = −0.3 + 0.4 = 0.1, spread 0.1 + 0.2 = 0.3: g₂ is the worst.
    let g = r.max_g_worst.unwrap();
    assert!((g - 0.4).abs() < 1e-12, "{r:?}");
    assert!((r.max_g_worst_sampled.unwrap() - g).abs() < 1e-12, "{r:?}");
    assert_eq!(r.evaluations, 1 + 8);
}

/// HS 22 at its optimum (1, 1) with δ = 0.01 on both variables (values by
/// hand from f = (x₁−2)² + (x₂−1)², g₂ = x₁² − x₂): first order
/// f_worst = 1 + 2δ, the worst corner (1−δ, 1±δ) gives 1 + 2δ + 2δ²;
/// g₂'s first order 3δ, its worst corner (1+δ, 1−δ) gives 3δ + δ². The
/// corners exceed the first-order estimate by O(δ²), here exactly.
#[test]
fn quadratic_problem_differs_from_the_corners_by_delta_squared() {
    let d = 0.01;
    let r = assess(&Hs22::new(), &[1.0, 1.0], &[d, d], 64, 1).unwrap();
    assert!((r.f_worst - (1.0 + 2.0 * d)).abs() < 1e-14, "{r:?}");
    assert!(
        (r.f_worst_sampled - r.f_worst - 2.0 * d * d).abs() < 1e-14,
        "{r:?}"
    );
    assert!((r.max_g_worst.unwrap() - 3.0 * d).abs() < 1e-14, "{r:?}");
    let gap = r.max_g_worst_sampled.unwrap() - r.max_g_worst.unwrap();
    assert!((gap - d * d).abs() < 1e-14, "{r:?}");
}

/// The multistart writes the columns into optima.csv for every certified
/// optimum; the HS 22 optimum carries the values above.
#[test]
fn optima_csv_carries_the_robustness_columns() {
    let tmp = temp_dir("robust-hs22");
    let dir = tmp.path().to_path_buf();
    let text = "[study]\nname = \"r\"\nseed = 7\n[problem]\nname = \"hs22\"\n\
                [multistart]\nsampler = \"sobol\"\nstarts = 6\nfeasible_only = true\n\
                points = [[0.0, 1.0]]\n[robustness]\ntolerance = [0.01, 0.01]\n";
    let s = study("r", text);
    explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    let t = table_without(&dir.join("r/optima.csv"), &[]);
    for c in COLUMNS {
        assert!(t[0].iter().any(|h| h == c), "{c} missing: {:?}", t[0]);
    }
    let f_worst: f64 = column(&t, "f_worst")[0].parse().unwrap();
    let g_worst: f64 = column(&t, "max_g_worst")[0].parse().unwrap();
    let g_sampled: f64 = column(&t, "max_g_worst_sampled")[0].parse().unwrap();
    // The certified optimum is (1, 1) to the KT tolerance.
    assert!((f_worst - 1.02).abs() < 1e-4, "{f_worst}");
    assert!((g_worst - 0.03).abs() < 1e-4, "{g_worst}");
    assert!((g_sampled - g_worst - 1e-4).abs() < 1e-5, "{g_sampled}");
    assert_eq!(column(&t, "robustness_evaluations")[0], "5");
    // A wrong number of tolerances is refused, naming the key.
    let bad = study("r", &text.replace("[0.01, 0.01]", "[0.01]"));
    let e = explore::run_multistart(&ctx(&bad, &dir, 2, DriveFlags::default()))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("robustness.tolerance") && e.contains("2 tolerances"),
        "{e}"
    );
}
