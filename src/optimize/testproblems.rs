//! Analytic test problems with known optima, shared by the optimizer tests,
//! the exploration tests and the benchmarks.
//!
//! Every problem is an [`Analytic`]: a plain function returning `f`, `g` and
//! their exact gradients, the variables' boxes, a standard start and the
//! published optimum with its source. Constraints follow the crate
//! convention `g_j(x) <= 0`; the Hock–Schittkowski constraints `c(x) >= 0`
//! are rewritten as `g = -c / s` with a stated normalising scale `s`, as DOT
//! expects normalised constraints (a constraint thickness CT = -0.03 then
//! means "3 % from the limit").
//!
//! Sources: W. Hock, K. Schittkowski, *Test Examples for Nonlinear
//! Programming Codes*, Lecture Notes in Economics and Mathematical Systems
//! 187, Springer 1981 (cited as "HS n"); D. M. Himmelblau, *Applied
//! Nonlinear Programming*, McGraw-Hill 1972, p. 428; H. H. Rosenbrock, The
//! Computer Journal 3 (1960) 175; L. A. Rastrigin, *Systems of Extremal
//! Control*, 1974.

use super::{Evaluation, Problem, Variable};
use crate::error::Result;

/// `f`, `g`, `∇f` (n) and `∇g` (m × n) at `x`.
pub type Kernel = fn(&[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>);

/// An analytic problem with exact gradients and a known optimum.
#[derive(Clone)]
pub struct Analytic {
    /// Name used in reports.
    pub name: String,
    /// Design variables with their boxes.
    pub variables: Vec<Variable>,
    /// Number of constraints `g_j <= 0`.
    pub n_constraints: usize,
    /// The evaluation kernel.
    pub kernel: Kernel,
    /// Standard start point.
    pub x0: Vec<f64>,
    /// Known global optima (one or several, e.g. Himmelblau's four).
    pub optima: Vec<Vec<f64>>,
    /// Known optimal objective.
    pub f_opt: f64,
}

impl Problem for Analytic {
    fn variables(&self) -> &[Variable] {
        &self.variables
    }
    fn n_constraints(&self) -> usize {
        self.n_constraints
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        let (f, g, gf, gg) = (self.kernel)(x);
        Ok(Evaluation {
            f,
            g,
            grad_f: gradients.then_some(gf),
            grad_g: gradients.then_some(gg),
        })
    }
    fn name(&self) -> &str {
        &self.name
    }
}

fn boxed(bounds: &[(f64, f64)]) -> Vec<Variable> {
    bounds
        .iter()
        .enumerate()
        .map(|(i, &(l, u))| Variable::bounded(format!("x{}", i + 1), l, u).expect("valid test box"))
        .collect()
}

/// HS 21: `f = 0.01 x1² + x2² − 100`, `10 x1 − x2 − 10 >= 0`,
/// `2 <= x1 <= 50`, `−50 <= x2 <= 50`. Optimum `x* = (2, 0)`,
/// `f* = −99.96` (HS 21); the bound `x1 >= 2` is active, the constraint is
/// not. Constraint scale s = 10.
pub fn hs21() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let f = 0.01 * x[0] * x[0] + x[1] * x[1] - 100.0;
        let g = -(10.0 * x[0] - x[1] - 10.0) / 10.0;
        (
            f,
            vec![g],
            vec![0.02 * x[0], 2.0 * x[1]],
            vec![vec![-1.0, 0.1]],
        )
    }
    Analytic {
        name: "hs21".into(),
        variables: boxed(&[(2.0, 50.0), (-50.0, 50.0)]),
        n_constraints: 1,
        kernel: k,
        x0: vec![-1.0, -1.0],
        optima: vec![vec![2.0, 0.0]],
        f_opt: -99.96,
    }
}

/// HS 35 (Beale): `f = 9 − 8x1 − 6x2 − 4x3 + 2x1² + 2x2² + x3² + 2x1x2 +
/// 2x1x3`, `3 − x1 − x2 − 2x3 >= 0`, `x >= 0` (upper bounds 10 added).
/// Optimum `x* = (4/3, 7/9, 4/9)`, `f* = 1/9` (HS 35). Scale s = 3.
pub fn hs35() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let (a, b, c) = (x[0], x[1], x[2]);
        let f = 9.0 - 8.0 * a - 6.0 * b - 4.0 * c
            + 2.0 * a * a
            + 2.0 * b * b
            + c * c
            + 2.0 * a * b
            + 2.0 * a * c;
        let gf = vec![
            -8.0 + 4.0 * a + 2.0 * b + 2.0 * c,
            -6.0 + 4.0 * b + 2.0 * a,
            -4.0 + 2.0 * c + 2.0 * a,
        ];
        let g = -(3.0 - a - b - 2.0 * c) / 3.0;
        (f, vec![g], gf, vec![vec![1.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0]])
    }
    Analytic {
        name: "hs35".into(),
        variables: boxed(&[(0.0, 10.0); 3]),
        n_constraints: 1,
        kernel: k,
        x0: vec![0.5, 0.5, 0.5],
        optima: vec![vec![4.0 / 3.0, 7.0 / 9.0, 4.0 / 9.0]],
        f_opt: 1.0 / 9.0,
    }
}

/// HS 43 (Rosen–Suzuki): `f = x1² + x2² + 2x3² + x4² − 5x1 − 5x2 − 21x3 +
/// 7x4` with three convex quadratic constraints (curved), box `[−10, 10]⁴`
/// added. Optimum `x* = (0, 1, 2, −1)`, `f* = −44` (HS 43); constraints 1
/// and 3 active. Scales s = 8, 10, 5 (the constants).
pub fn hs43() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let (a, b, c, d) = (x[0], x[1], x[2], x[3]);
        let f = a * a + b * b + 2.0 * c * c + d * d - 5.0 * a - 5.0 * b - 21.0 * c + 7.0 * d;
        let gf = vec![2.0 * a - 5.0, 2.0 * b - 5.0, 4.0 * c - 21.0, 2.0 * d + 7.0];
        let c1 = 8.0 - a * a - b * b - c * c - d * d - a + b - c + d;
        let c2 = 10.0 - a * a - 2.0 * b * b - c * c - 2.0 * d * d + a + d;
        let c3 = 5.0 - 2.0 * a * a - b * b - c * c - 2.0 * a + b + d;
        let g = vec![-c1 / 8.0, -c2 / 10.0, -c3 / 5.0];
        let gg = vec![
            vec![
                (2.0 * a + 1.0) / 8.0,
                (2.0 * b - 1.0) / 8.0,
                (2.0 * c + 1.0) / 8.0,
                (2.0 * d - 1.0) / 8.0,
            ],
            vec![
                (2.0 * a - 1.0) / 10.0,
                4.0 * b / 10.0,
                2.0 * c / 10.0,
                (4.0 * d - 1.0) / 10.0,
            ],
            vec![
                (4.0 * a + 2.0) / 5.0,
                (2.0 * b - 1.0) / 5.0,
                2.0 * c / 5.0,
                -1.0 / 5.0,
            ],
        ];
        (f, g, gf, gg)
    }
    Analytic {
        name: "hs43".into(),
        variables: boxed(&[(-10.0, 10.0); 4]),
        n_constraints: 3,
        kernel: k,
        x0: vec![0.0; 4],
        optima: vec![vec![0.0, 1.0, 2.0, -1.0]],
        f_opt: -44.0,
    }
}

/// HS 76: `f = x1² + 0.5x2² + x3² + 0.5x4² − x1x3 + x3x4 − x1 − 3x2 + x3 −
/// x4`, three linear constraints, `x >= 0` (upper bounds 10 added).
/// Optimum `x* = (3/11, 23/11, 0, 6/11)`, `f* = −103/22 = −4.6818181…`
/// (HS 76; exact fractions from the KKT system, which the test re-derives);
/// the bound `x3 >= 0` and the first two constraints are active.
/// Scales s = 5, 4, 1.5.
pub fn hs76() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let (a, b, c, d) = (x[0], x[1], x[2], x[3]);
        let f = a * a + 0.5 * b * b + c * c + 0.5 * d * d - a * c + c * d - a - 3.0 * b + c - d;
        let gf = vec![
            2.0 * a - c - 1.0,
            b - 3.0,
            2.0 * c - a + d + 1.0,
            d + c - 1.0,
        ];
        let g = vec![
            -(5.0 - a - 2.0 * b - c - d) / 5.0,
            -(4.0 - 3.0 * a - b - 2.0 * c + d) / 4.0,
            -(b + 4.0 * c - 1.5) / 1.5,
        ];
        let gg = vec![
            vec![0.2, 0.4, 0.2, 0.2],
            vec![0.75, 0.25, 0.5, -0.25],
            vec![0.0, -1.0 / 1.5, -4.0 / 1.5, 0.0],
        ];
        (f, g, gf, gg)
    }
    Analytic {
        name: "hs76".into(),
        variables: boxed(&[(0.0, 10.0); 4]),
        n_constraints: 3,
        kernel: k,
        x0: vec![0.5; 4],
        optima: vec![vec![3.0 / 11.0, 23.0 / 11.0, 0.0, 6.0 / 11.0]],
        f_opt: -103.0 / 22.0,
    }
}

/// HS 100: 7 variables, 4 nonlinear constraints (box `[−10, 10]⁷` added).
/// Optimum `f* = 680.6300573` at `x* ≈ (2.330499, 1.951372, −0.4775414,
/// 4.365726, −0.6244870, 1.038131, 1.594227)` (HS 100); constraints 1 and
/// 4 active. Scales s = 127, 282, 196, 10.
pub fn hs100() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let [x1, x2, x3, x4, x5, x6, x7] = [x[0], x[1], x[2], x[3], x[4], x[5], x[6]];
        let f = (x1 - 10.0).powi(2)
            + 5.0 * (x2 - 12.0).powi(2)
            + x3.powi(4)
            + 3.0 * (x4 - 11.0).powi(2)
            + 10.0 * x5.powi(6)
            + 7.0 * x6 * x6
            + x7.powi(4)
            - 4.0 * x6 * x7
            - 10.0 * x6
            - 8.0 * x7;
        let gf = vec![
            2.0 * (x1 - 10.0),
            10.0 * (x2 - 12.0),
            4.0 * x3.powi(3),
            6.0 * (x4 - 11.0),
            60.0 * x5.powi(5),
            14.0 * x6 - 4.0 * x7 - 10.0,
            4.0 * x7.powi(3) - 4.0 * x6 - 8.0,
        ];
        let c1 = 127.0 - 2.0 * x1 * x1 - 3.0 * x2.powi(4) - x3 - 4.0 * x4 * x4 - 5.0 * x5;
        let c2 = 282.0 - 7.0 * x1 - 3.0 * x2 - 10.0 * x3 * x3 - x4 + x5;
        let c3 = 196.0 - 23.0 * x1 - x2 * x2 - 6.0 * x6 * x6 + 8.0 * x7;
        let c4 = -4.0 * x1 * x1 - x2 * x2 + 3.0 * x1 * x2 - 2.0 * x3 * x3 - 5.0 * x6 + 11.0 * x7;
        let g = vec![-c1 / 127.0, -c2 / 282.0, -c3 / 196.0, -c4 / 10.0];
        let gg = vec![
            vec![
                4.0 * x1 / 127.0,
                12.0 * x2.powi(3) / 127.0,
                1.0 / 127.0,
                8.0 * x4 / 127.0,
                5.0 / 127.0,
                0.0,
                0.0,
            ],
            vec![
                7.0 / 282.0,
                3.0 / 282.0,
                20.0 * x3 / 282.0,
                1.0 / 282.0,
                -1.0 / 282.0,
                0.0,
                0.0,
            ],
            vec![
                23.0 / 196.0,
                2.0 * x2 / 196.0,
                0.0,
                0.0,
                0.0,
                12.0 * x6 / 196.0,
                -8.0 / 196.0,
            ],
            vec![
                (8.0 * x1 - 3.0 * x2) / 10.0,
                (2.0 * x2 - 3.0 * x1) / 10.0,
                4.0 * x3 / 10.0,
                0.0,
                0.0,
                0.5,
                -1.1,
            ],
        ];
        (f, g, gf, gg)
    }
    Analytic {
        name: "hs100".into(),
        variables: boxed(&[(-10.0, 10.0); 7]),
        n_constraints: 4,
        kernel: k,
        x0: vec![1.0, 2.0, 0.0, 4.0, 0.0, 1.0, 1.0],
        optima: vec![vec![
            2.330499, 1.951372, -0.4775414, 4.365726, -0.6244870, 1.038131, 1.594227,
        ]],
        f_opt: 680.6300573,
    }
}

/// Linear objective on a disc: `f = x + y`, `x² + y² − 1 <= 0`, box
/// `[−2, 2]²`. Optimum `x* = (−1/√2, −1/√2)`, `f* = −√2` (closed form: the
/// gradient (1, 1) is antiparallel to the outward normal there). The
/// projected direction is tangent to the circle, so every step leaves the
/// disc and must be pulled back (constraint following).
pub fn disc() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        (
            x[0] + x[1],
            vec![x[0] * x[0] + x[1] * x[1] - 1.0],
            vec![1.0, 1.0],
            vec![vec![2.0 * x[0], 2.0 * x[1]]],
        )
    }
    let s = -std::f64::consts::FRAC_1_SQRT_2;
    Analytic {
        name: "disc".into(),
        variables: boxed(&[(-2.0, 2.0); 2]),
        n_constraints: 1,
        kernel: k,
        x0: vec![0.9, 0.0],
        optima: vec![vec![s, s]],
        f_opt: -std::f64::consts::SQRT_2,
    }
}

/// A landscape of the violation with many local minima, as the SAR
/// problem's peak-strain constraint has: on the torus `[−π, π)²`,
/// `f = 2 − cos(a − 0.1) − cos(b − 0.1)` subject to
/// `g = 1.2 − cos a cos b − 0.3 cos 5a cos 5b <= 0`. The feasible set is two
/// small islands, around `(0, 0)` and `(π, π)` (where `cos a cos b = 1`;
/// elsewhere `cos a cos b < 0.9` leaves `g > 0`), and the ripple of the
/// second term gives the violation a local minimum in most cells of a
/// 5 × 5 pattern. The unconstrained minimum `(0.1, 0.1)` lies inside the
/// first island (`g = −0.021`), so `f* = 0` (closed form).
pub fn ripple() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let (a, b) = (x[0], x[1]);
        let f = 2.0 - (a - 0.1).cos() - (b - 0.1).cos();
        let g = 1.2 - a.cos() * b.cos() - 0.3 * (5.0 * a).cos() * (5.0 * b).cos();
        let dg = vec![
            a.sin() * b.cos() + 1.5 * (5.0 * a).sin() * (5.0 * b).cos(),
            a.cos() * b.sin() + 1.5 * (5.0 * a).cos() * (5.0 * b).sin(),
        ];
        (f, vec![g], vec![(a - 0.1).sin(), (b - 0.1).sin()], vec![dg])
    }
    let pi = std::f64::consts::PI;
    let angle = |name: &str| Variable::periodic(name, -pi, 2.0 * pi).expect("valid period");
    Analytic {
        name: "ripple".into(),
        variables: vec![angle("a"), angle("b")],
        n_constraints: 1,
        kernel: k,
        x0: vec![2.0, 1.5],
        optima: vec![vec![0.1, 0.1]],
        f_opt: 0.0,
    }
}

/// Two ply-like angles in degrees, periodic on `[−90, 90)`:
/// `f = 1 − cos 2(θ1 − 88°) + 1 − cos 2(θ2 + 85°) + 0.2 (1 − cos 2(θ1 − θ2 −
/// 173°))`. Every term is >= 0 and vanishes only at `θ* = (88°, −85°)`
/// (mod 180°), so `f* = 0` (closed form). From the start `(−80°, 80°)` the
/// optimum lies 12° and 15° away across the ±90° seam, 168° and 165° away
/// inside the box: a solver that stops at the bound fails.
pub fn seam() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let r = std::f64::consts::PI / 180.0;
        let a = 2.0 * r * (x[0] - 88.0);
        let b = 2.0 * r * (x[1] + 85.0);
        let c = 2.0 * r * (x[0] - x[1] - 173.0);
        let f = 2.0 - a.cos() - b.cos() + 0.2 * (1.0 - c.cos());
        let gf = vec![
            2.0 * r * (a.sin() + 0.2 * c.sin()),
            2.0 * r * (b.sin() - 0.2 * c.sin()),
        ];
        (f, vec![], gf, vec![])
    }
    Analytic {
        name: "seam".into(),
        variables: vec![
            Variable::periodic("theta1_deg", -90.0, 180.0).expect("valid"),
            Variable::periodic("theta2_deg", -90.0, 180.0).expect("valid"),
        ],
        n_constraints: 0,
        kernel: k,
        x0: vec![-80.0, 80.0],
        optima: vec![vec![88.0, -85.0]],
        f_opt: 0.0,
    }
}

/// Himmelblau's function `f = (x² + y − 11)² + (x + y² − 7)²` on
/// `[−5, 5]²`, unconstrained; four global minima with `f* = 0` at (3, 2),
/// (−2.805118, 3.131312), (−3.779310, −3.283186), (3.584428, −1.848126)
/// (Himmelblau 1972, p. 428).
pub fn himmelblau() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let a = x[0] * x[0] + x[1] - 11.0;
        let b = x[0] + x[1] * x[1] - 7.0;
        (
            a * a + b * b,
            vec![],
            vec![4.0 * a * x[0] + 2.0 * b, 2.0 * a + 4.0 * b * x[1]],
            vec![],
        )
    }
    Analytic {
        name: "himmelblau".into(),
        variables: boxed(&[(-5.0, 5.0); 2]),
        n_constraints: 0,
        kernel: k,
        x0: vec![0.0, 0.0],
        optima: vec![
            vec![3.0, 2.0],
            vec![-2.805118, 3.131312],
            vec![-3.779310, -3.283186],
            vec![3.584428, -1.848126],
        ],
        f_opt: 0.0,
    }
}

fn rosenbrock_kernel(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let n = x.len();
    let mut f = 0.0;
    let mut gf = vec![0.0; n];
    for i in 0..n - 1 {
        let t = x[i + 1] - x[i] * x[i];
        let u = 1.0 - x[i];
        f += 100.0 * t * t + u * u;
        gf[i] += -400.0 * t * x[i] - 2.0 * u;
        gf[i + 1] += 200.0 * t;
    }
    (f, vec![], gf, vec![])
}

/// The n-dimensional Rosenbrock function `Σ 100 (x_{i+1} − x_i²)² + (1 −
/// x_i)²` on `[−5, 5]ⁿ`; minimum `f* = 0` at `(1, …, 1)` (Rosenbrock 1960).
pub fn rosenbrock(n: usize) -> Analytic {
    let n = n.max(2);
    Analytic {
        name: format!("rosenbrock{n}"),
        variables: boxed(&vec![(-5.0, 5.0); n]),
        n_constraints: 0,
        kernel: rosenbrock_kernel,
        x0: vec![-1.2; n],
        optima: vec![vec![1.0; n]],
        f_opt: 0.0,
    }
}

fn rastrigin_kernel(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let tau = 2.0 * std::f64::consts::PI;
    let mut f = 10.0 * x.len() as f64;
    let mut gf = Vec::with_capacity(x.len());
    for &xi in x {
        f += xi * xi - 10.0 * (tau * xi).cos();
        gf.push(2.0 * xi + 10.0 * tau * (tau * xi).sin());
    }
    (f, vec![], gf, vec![])
}

/// `min x` on `[−3, 3]` subject to `g = 0.5 + x² − x⁴/4 <= 0` (closed
/// form, derived here): feasible for `x² >= 2 + √6` (`|x| >= 2.10938`), so
/// a local optimum on the constraint at `x* = +2.10938` (multiplier
/// `λ = 1/|g'(x*)| = 0.19354`, `g' = 2x − x³`) and the global one on the
/// bound −3; the violation has a local minimum `g = 0.5 > 0` at `x = 0`,
/// which no descent on the violation leaves. A test of infeasible ends.
pub fn islands() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let x = x[0];
        let g = 0.5 + x * x - 0.25 * x.powi(4);
        (x, vec![g], vec![1.0], vec![vec![2.0 * x - x.powi(3)]])
    }
    Analytic {
        name: "islands".into(),
        variables: boxed(&[(-3.0, 3.0)]),
        n_constraints: 1,
        kernel: k,
        x0: vec![0.3],
        optima: vec![vec![-3.0]],
        f_opt: -3.0,
    }
}

/// The n-dimensional Rastrigin function `10 n + Σ x_i² − 10 cos 2πx_i` on
/// `[−5.12, 5.12]ⁿ`; global minimum `f* = 0` at the origin among ~11ⁿ local
/// minima (Rastrigin 1974).
pub fn rastrigin(n: usize) -> Analytic {
    let n = n.max(1);
    Analytic {
        name: format!("rastrigin{n}"),
        variables: boxed(&vec![(-5.12, 5.12); n]),
        n_constraints: 0,
        kernel: rastrigin_kernel,
        x0: vec![3.0; n],
        optima: vec![vec![0.0; n]],
        f_opt: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every analytic gradient against central finite differences.
    #[test]
    fn gradients_match_central_differences() {
        let problems = [
            hs21(),
            hs35(),
            hs43(),
            hs76(),
            hs100(),
            disc(),
            seam(),
            himmelblau(),
            rosenbrock(4),
            rastrigin(3),
        ];
        for p in problems {
            let n = p.variables.len();
            let x: Vec<f64> = (0..n).map(|i| 0.3 + 0.17 * i as f64).collect();
            let (_, _, gf, gg) = (p.kernel)(&x);
            let h = 1e-6;
            for i in 0..n {
                let mut xp = x.clone();
                let mut xm = x.clone();
                xp[i] += h;
                xm[i] -= h;
                let (fp, gp, _, _) = (p.kernel)(&xp);
                let (fm, gm, _, _) = (p.kernel)(&xm);
                let d = (fp - fm) / (2.0 * h);
                assert!(
                    (d - gf[i]).abs() < 1e-6 * (1.0 + d.abs()),
                    "{} df/dx{i}",
                    p.name
                );
                for j in 0..p.n_constraints {
                    let d = (gp[j] - gm[j]) / (2.0 * h);
                    assert!(
                        (d - gg[j][i]).abs() < 1e-6 * (1.0 + d.abs()),
                        "{} dg{j}/dx{i}",
                        p.name
                    );
                }
            }
        }
    }

    /// The stated optima are feasible and give the stated f.
    #[test]
    fn optima_are_consistent() {
        for p in [hs21(), hs35(), hs43(), hs76(), hs100(), disc(), seam()] {
            let (f, g, _, _) = (p.kernel)(&p.optima[0]);
            assert!(
                (f - p.f_opt).abs() < 1e-5 * (1.0 + p.f_opt.abs()),
                "{}",
                p.name
            );
            assert!(g.iter().all(|&gj| gj < 1e-6), "{} g = {g:?}", p.name);
        }
    }
}
