//! Multi-objective test problems with known Pareto fronts, for the front
//! drivers' tests and studies.
//!
//! - ZDT1, ZDT2, ZDT3 (E. Zitzler, K. Deb, L. Thiele, "Comparison of
//!   multiobjective evolutionary algorithms: empirical results",
//!   *Evolutionary Computation* 8(2), 2000, 173–195), 30 variables in
//!   `[0, 1]`: `f1 = x1`, `g = 1 + 9/(n − 1) Σ_{i≥2} x_i`,
//!   `f2 = g·h(f1, g)` with
//!   - ZDT1: `h = 1 − √(f1/g)` (convex front `f2 = 1 − √f1`),
//!   - ZDT2: `h = 1 − (f1/g)²` (non-convex front `f2 = 1 − f1²`),
//!   - ZDT3: `h = 1 − √(f1/g) − (f1/g) sin(10π f1)` (five disconnected
//!     pieces of `f2 = 1 − √f1 − f1 sin(10π f1)`);
//!
//!   the fronts are at `g = 1` (`x2 = … = xn = 0`), `f1 ∈ [0, 1]`.
//!   For ZDT1 and ZDT3, `∂f2/∂x1 = −½√(g/x1) − …` is unbounded at
//!   `x1 = 0` (evaluated there it is `−∞`; the front's end `f1 = 0` is
//!   reached by the evolutionary side, and the gradient side's end point
//!   is its anchor at `f1 <= 1e-4`).
//! - DTLZ2 (K. Deb, L. Thiele, M. Laumanns, E. Zitzler, "Scalable
//!   multi-objective optimization test problems", *Proc. CEC 2002*,
//!   825–830), 3 objectives, 12 variables in `[0, 1]`:
//!   `g = Σ_{i=3}^{12} (x_i − ½)²`, `f1 = (1+g) cos(πx1/2) cos(πx2/2)`,
//!   `f2 = (1+g) cos(πx1/2) sin(πx2/2)`, `f3 = (1+g) sin(πx1/2)`; the
//!   front is the unit sphere's positive octant (`g = 0`).
//!
//! Every kernel returns the objectives and their exact gradients; there
//! are no constraints. [`MoAnalytic::front`] samples the analytic front
//! for IGD: 1000 points evenly spaced in `f1` for ZDT1 and ZDT2, the
//! non-dominated ones of 10 000 such points for ZDT3, and for DTLZ2 the
//! 496 directions of the simplex lattice with 30 divisions (Das & Dennis
//! 1998) scaled to unit length.

use super::multiobjective::{non_dominated, MultiEvaluation, MultiProblem};
use super::Variable;
use crate::error::{Error, Result};
use std::f64::consts::PI;

/// Objectives and their gradients (one row per objective) at `x`.
pub type MoKernel = fn(&[f64]) -> (Vec<f64>, Vec<Vec<f64>>);

/// An unconstrained multi-objective problem with exact gradients and a
/// known front.
#[derive(Clone)]
pub struct MoAnalytic {
    /// Name used in reports.
    pub name: String,
    /// Design variables with their boxes.
    pub variables: Vec<Variable>,
    /// Objective names.
    pub objectives: Vec<String>,
    /// The evaluation kernel.
    pub kernel: MoKernel,
    /// The analytic front, sampled (see the module doc).
    pub front_sample: fn() -> Vec<Vec<f64>>,
}

impl MoAnalytic {
    /// The analytic front, sampled for IGD.
    pub fn front(&self) -> Vec<Vec<f64>> {
        (self.front_sample)()
    }
}

impl MultiProblem for MoAnalytic {
    fn variables(&self) -> &[Variable] {
        &self.variables
    }
    fn objective_names(&self) -> Vec<String> {
        self.objectives.clone()
    }
    fn n_constraints(&self) -> usize {
        0
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<MultiEvaluation> {
        if x.len() != self.variables.len() {
            return Err(Error::input(
                format!("{}.x", self.name),
                format!("a vector of length {}", x.len()),
                format!("length {}", self.variables.len()),
            ));
        }
        let (f, gf) = (self.kernel)(x);
        Ok(MultiEvaluation::smooth(
            (f, vec![]),
            gradients.then_some(gf),
            gradients.then(Vec::new),
        ))
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn known_front(&self) -> Option<Vec<Vec<f64>>> {
        Some(self.front())
    }
}

fn unit_box(n: usize) -> Vec<Variable> {
    (1..=n)
        .map(|i| Variable::bounded(format!("x{i}"), 0.0, 1.0).expect("valid unit box"))
        .collect()
}

fn names(k: usize) -> Vec<String> {
    (1..=k).map(|i| format!("f{i}")).collect()
}

/// `g = 1 + 9/(n − 1) Σ_{i≥2} x_i` of the ZDT problems and `∂g/∂x_i`.
fn zdt_g(x: &[f64]) -> (f64, f64) {
    let dg = 9.0 / (x.len() - 1) as f64;
    (1.0 + dg * x[1..].iter().sum::<f64>(), dg)
}

/// The ZDT objectives from `f2 = g·h`: `(f2, ∂f2/∂x1, ∂f2/∂g)` given.
fn zdt(x: &[f64], f2: fn(f64, f64) -> (f64, f64, f64)) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = x.len();
    let (g, dg) = zdt_g(x);
    let (v, d1, dgv) = f2(x[0], g);
    let mut g1 = vec![0.0; n];
    g1[0] = 1.0;
    let mut g2 = vec![dgv * dg; n];
    g2[0] = d1;
    (vec![x[0], v], vec![g1, g2])
}

fn zdt1_kernel(x: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    zdt(x, |f1, g| {
        let r = (f1 * g).sqrt();
        (g - r, -0.5 * (g / f1).sqrt(), 1.0 - 0.5 * (f1 / g).sqrt())
    })
}

fn zdt2_kernel(x: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    zdt(x, |f1, g| {
        (g - f1 * f1 / g, -2.0 * f1 / g, 1.0 + f1 * f1 / (g * g))
    })
}

fn zdt3_kernel(x: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    zdt(x, |f1, g| {
        let (s, c) = (10.0 * PI * f1).sin_cos();
        (
            g - (f1 * g).sqrt() - f1 * s,
            -0.5 * (g / f1).sqrt() - s - 10.0 * PI * f1 * c,
            1.0 - 0.5 * (f1 / g).sqrt(),
        )
    })
}

/// `n` points of `f2 = h(f1)` evenly spaced in `f1 ∈ [0, 1]`.
fn zdt_front(n: usize, h: fn(f64) -> f64) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| {
            let f1 = i as f64 / (n - 1) as f64;
            vec![f1, h(f1)]
        })
        .collect()
}

/// ZDT1 (30 variables).
pub fn zdt1() -> MoAnalytic {
    MoAnalytic {
        name: "zdt1".into(),
        variables: unit_box(30),
        objectives: names(2),
        kernel: zdt1_kernel,
        front_sample: || zdt_front(1000, |f1| 1.0 - f1.sqrt()),
    }
}

/// ZDT2 (30 variables).
pub fn zdt2() -> MoAnalytic {
    MoAnalytic {
        name: "zdt2".into(),
        variables: unit_box(30),
        objectives: names(2),
        kernel: zdt2_kernel,
        front_sample: || zdt_front(1000, |f1| 1.0 - f1 * f1),
    }
}

/// ZDT3 (30 variables).
pub fn zdt3() -> MoAnalytic {
    MoAnalytic {
        name: "zdt3".into(),
        variables: unit_box(30),
        objectives: names(2),
        kernel: zdt3_kernel,
        front_sample: || {
            let all = zdt_front(10_000, |f1| 1.0 - f1.sqrt() - f1 * (10.0 * PI * f1).sin());
            non_dominated(&all)
                .into_iter()
                .map(|i| all[i].clone())
                .collect()
        },
    }
}

fn dtlz2_kernel(x: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = x.len();
    let h = 0.5 * PI;
    let g: f64 = x[2..].iter().map(|v| (v - 0.5).powi(2)).sum();
    let (s1, c1) = (h * x[0]).sin_cos();
    let (s2, c2) = (h * x[1]).sin_cos();
    let a = 1.0 + g;
    let f = vec![a * c1 * c2, a * c1 * s2, a * s1];
    let mut grads = Vec::with_capacity(3);
    // ∂f/∂x1, ∂f/∂x2 of the angular factors, times (1 + g); ∂f/∂x_i for
    // i >= 3 is (angular factor)·2(x_i − ½).
    let angular = [
        (c1 * c2, -h * s1 * c2, -h * c1 * s2),
        (c1 * s2, -h * s1 * s2, h * c1 * c2),
        (s1, h * c1, 0.0),
    ];
    for (p, d1, d2) in angular {
        let mut row = vec![0.0; n];
        row[0] = a * d1;
        row[1] = a * d2;
        for i in 2..n {
            row[i] = p * 2.0 * (x[i] - 0.5);
        }
        grads.push(row);
    }
    (f, grads)
}

/// The simplex lattice of `m` weights summing to 1 in steps of `1/h`
/// (Das & Dennis 1998), in lexicographic order.
pub fn simplex_lattice(m: usize, h: usize) -> Vec<Vec<f64>> {
    fn rec(m: usize, left: usize, h: usize, cur: &mut Vec<usize>, out: &mut Vec<Vec<f64>>) {
        if cur.len() == m - 1 {
            cur.push(left);
            out.push(cur.iter().map(|&k| k as f64 / h as f64).collect());
            cur.pop();
            return;
        }
        for k in 0..=left {
            cur.push(k);
            rec(m, left - k, h, cur, out);
            cur.pop();
        }
    }
    let mut out = Vec::new();
    if m >= 1 && h >= 1 {
        rec(m, h, h, &mut Vec::new(), &mut out);
    }
    out
}

/// DTLZ2 with 3 objectives and 12 variables.
pub fn dtlz2() -> MoAnalytic {
    MoAnalytic {
        name: "dtlz2".into(),
        variables: unit_box(12),
        objectives: names(3),
        kernel: dtlz2_kernel,
        front_sample: || {
            simplex_lattice(3, 30)
                .into_iter()
                .map(|w| {
                    let r = w.iter().map(|v| v * v).sum::<f64>().sqrt();
                    w.iter().map(|v| v / r).collect()
                })
                .collect()
        },
    }
}

/// The problems of this module by name (`zdt1`, `zdt2`, `zdt3`, `dtlz2`).
pub fn by_name(name: &str) -> Option<MoAnalytic> {
    match name {
        "zdt1" => Some(zdt1()),
        "zdt2" => Some(zdt2()),
        "zdt3" => Some(zdt3()),
        "dtlz2" => Some(dtlz2()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::multiobjective::{EpsilonConstraint, Oriented, Tchebycheff};
    use crate::optimize::Problem;

    fn check_gradients(p: &MoAnalytic, x: &[f64]) {
        let e = p.evaluate(x, true).unwrap();
        let gf = e.grad_f.unwrap();
        for i in 0..x.len() {
            let h = 1e-6;
            let (mut a, mut b) = (x.to_vec(), x.to_vec());
            a[i] += h;
            b[i] -= h;
            let (fa, fb) = (
                p.evaluate(&a, false).unwrap().f,
                p.evaluate(&b, false).unwrap().f,
            );
            for k in 0..fa.len() {
                let fd = (fa[k] - fb[k]) / (2.0 * h);
                assert!(
                    (fd - gf[k][i]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "{} df{}/dx{} {fd} {}",
                    p.name,
                    k + 1,
                    i + 1,
                    gf[k][i]
                );
            }
        }
    }

    #[test]
    fn gradients_match_central_differences() {
        let x30: Vec<f64> = (0..30).map(|i| 0.05 + 0.03 * i as f64).collect();
        for p in [zdt1(), zdt2(), zdt3()] {
            check_gradients(&p, &x30);
        }
        let x12: Vec<f64> = (0..12).map(|i| 0.1 + 0.07 * i as f64).collect();
        check_gradients(&dtlz2(), &x12);
    }

    #[test]
    fn designs_on_the_front_give_the_analytic_front() {
        // ZDT (Zitzler, Deb & Thiele 2000): x2..xn = 0 gives g = 1 and
        // f2 = h(f1, 1). x1 = 0.25: ZDT1 f2 = 1 − 0.5, ZDT2 f2 = 1 − 1/16,
        // ZDT3 f2 = 1 − 0.5 − 0.25 sin(2.5π) = 0.25.
        let mut x = vec![0.0; 30];
        x[0] = 0.25;
        let f = |p: MoAnalytic| p.evaluate(&x, false).unwrap().f;
        assert_eq!(f(zdt1()), vec![0.25, 0.5]);
        assert_eq!(f(zdt2()), vec![0.25, 0.9375]);
        assert!((f(zdt3())[1] - 0.25).abs() < 1e-15);
        // DTLZ2 (Deb et al. 2002): x3.. = 1/2 gives g = 0, |f| = 1;
        // x1 = x2 = 1/2 gives f = (1/2, 1/2, 1/√2).
        let mut x = vec![0.5; 12];
        let e = dtlz2().evaluate(&x, false).unwrap().f;
        assert!((e[0] - 0.5).abs() < 1e-15 && (e[2] - 0.5f64.sqrt()).abs() < 1e-15);
        x[4] = 0.9; // g = 0.16: the point moves out to radius 1.16
        let e = dtlz2().evaluate(&x, false).unwrap().f;
        assert!((e.iter().map(|v| v * v).sum::<f64>().sqrt() - 1.16).abs() < 1e-14);
    }

    #[test]
    fn the_sampled_fronts() {
        assert_eq!(zdt1().front().len(), 1000);
        assert_eq!(simplex_lattice(3, 30).len(), 496); // C(32, 2)
        for p in dtlz2().front() {
            assert!((p.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-12);
        }
        // ZDT3's front: five pieces, the first from f1 = 0 to 0.0830
        // (Zitzler, Deb & Thiele 2000, Fig. 1(c); the piece ends at
        // f1 ≈ 0.0830015 in the literature's tabulations).
        let z = zdt3().front();
        let gaps = z.windows(2).filter(|w| w[1][0] - w[0][0] > 0.01).count();
        assert_eq!(gaps, 4);
        let end = z.windows(2).find(|w| w[1][0] - w[0][0] > 0.01).unwrap()[0][0];
        assert!((end - 0.0830).abs() < 2e-4, "{end}");
    }

    // The scalarizations of `multiobjective` on these problems.

    /// Central differences of every objective and constraint of a
    /// scalarization against its exact gradients.
    fn check_scalarization(p: &dyn Problem, x: &[f64]) {
        let e = p.evaluate(x, true).unwrap();
        let (gf, gg) = (e.grad_f.unwrap(), e.grad_g.unwrap());
        for i in 0..x.len() {
            let h = 1e-6;
            let (mut a, mut b) = (x.to_vec(), x.to_vec());
            a[i] += h;
            b[i] -= h;
            let (ea, eb) = (
                p.evaluate(&a, false).unwrap(),
                p.evaluate(&b, false).unwrap(),
            );
            let fd = (ea.f - eb.f) / (2.0 * h);
            assert!((fd - gf[i]).abs() < 1e-6 * (1.0 + fd.abs()), "df/dx{i}");
            for (j, row) in gg.iter().enumerate() {
                let fd = (ea.g[j] - eb.g[j]) / (2.0 * h);
                assert!((fd - row[i]).abs() < 1e-6 * (1.0 + fd.abs()), "dg{j}/dx{i}");
            }
        }
    }

    #[test]
    fn scalarizations_have_exact_gradients() {
        let z = zdt1();
        let x: Vec<f64> = (0..30).map(|i| 0.1 + 0.025 * i as f64).collect();
        check_scalarization(
            &EpsilonConstraint::new(&z, vec![1.0, 0.0], vec![(1, 0.4, 2.0)]),
            &x,
        );
        let t = Tchebycheff::new(
            &z,
            (vec![0.0, 0.0], vec![1.0, 2.0]),
            vec![0.3, 0.7],
            1e-3,
            (-2.0, 20.0),
        )
        .unwrap();
        let mut xt = x.clone();
        xt.push(0.2);
        check_scalarization(&t, &xt);
        // Maximizing −f2 is minimizing f2: same values, same gradients.
        let d = dtlz2();
        let o = Oriented::new(&d, &[("f3".into(), false), ("f1".into(), true)]).unwrap();
        let x: Vec<f64> = (0..12).map(|i| 0.2 + 0.05 * i as f64).collect();
        let (eo, ed) = (o.evaluate(&x, true).unwrap(), d.evaluate(&x, true).unwrap());
        assert_eq!(eo.f, vec![ed.f[2], -ed.f[0]]);
        assert_eq!(eo.grad_f.unwrap()[1][3], -ed.grad_f.unwrap()[0][3]);
        let e = Oriented::new(&d, &[("f4".into(), false)]).err().unwrap();
        assert!(e.to_string().contains("objectives[0].name"), "{e}");
    }

    #[test]
    fn the_tchebycheff_start_satisfies_its_constraints() {
        let z = zdt1();
        let t = Tchebycheff::new(
            &z,
            (vec![0.0, 0.0], vec![1.0, 1.0]),
            vec![0.5, 0.5],
            1e-4,
            (-2.0, 20.0),
        )
        .unwrap();
        let x0 = vec![0.5; 30];
        let e = t.evaluate(&t.start(&x0).unwrap(), false).unwrap();
        assert!(e.max_g().abs() < 1e-12, "{:?}", e.g);
    }
}
