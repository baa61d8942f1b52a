//! Several objectives at once: the least a Pareto front needs.
//!
//! A [`MultiProblem`] returns, for a design `x`, the objectives `f_i`
//! (all minimized), the constraints `g_j(x) <= 0` and, when asked, all
//! their exact gradients in one call, like [`Problem`] does for one
//! objective. Objectives a study maximizes are negated by [`Oriented`],
//! which also picks the study's objectives by name, so that every algorithm
//! minimizes.
//!
//! Dominance (minimization): `a` dominates `b` when `a_i <= b_i` for every
//! objective and `a_i < b_i` for at least one ([`dominates`]).
//!
//! The gradient side of a front solves single-objective problems made from
//! a [`MultiProblem`] (scalarizations, each a [`Problem`]):
//! - [`EpsilonConstraint`]: minimize `Σ_i w_i f_i` subject to
//!   `(f_j − ε_j)/s_j <= 0` for the capped objectives (and the problem's own
//!   constraints): the single-objective optima and their lexicographic
//!   refinement.
//! - [`Tchebycheff`]: the reference-point (Pascoletti–Serafini) form of the
//!   augmented weighted Tchebycheff problem in normalized objectives
//!   `u_i = (f_i − z_i)/s_i` (`z` the ideal point, `s` the ideal-to-nadir
//!   range): minimize `t + ρ Σ_i u_i` over `(x, t)` subject to
//!   `u_i(x) − r_i − t <= 0` for a reference point `r`. Its solution is the
//!   point of the front where the ray `r + t·(1, …, 1)` meets it (or the
//!   front's nearest point in the max-norm when it misses), Pareto optimal
//!   for `ρ > 0` (Miettinen, *Nonlinear Multiobjective Optimization*,
//!   Kluwer 1999, Thm 3.4.6); reference points spread evenly over a simplex
//!   give points spread along the front, convex or not.
//!
//! **Objectives that are maxima.** An objective may be the largest of a
//! few smooth pieces, `f_i = max_k p_ik` (a peak over time: the response
//! at each of its critical time points, [`MultiProblem::objective_pieces`]);
//! where two pieces are equal `f_i` has a kink and its gradient jumps, so
//! a scalarization that uses `f_i` as one smooth function stalls there.
//! The scalarizations take such an objective piece by piece, as the
//! epigraph of the maximum: [`Tchebycheff`]'s constraint becomes one
//! `(p_ik − z_i)/s_i − r_i − t <= 0` per piece, and a cap one
//! `(p_ik − ε_i)/s_i <= 0` per piece; minimizing such an objective alone
//! is the Tchebycheff problem of that objective alone
//! ([`Tchebycheff::only`]: minimize `t` with every piece at most `t`).

use super::{Evaluation, Problem, Variable};
use crate::error::{Error, Result};

/// What one evaluation of a [`MultiProblem`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct MultiEvaluation {
    /// Objective values (minimized).
    pub f: Vec<f64>,
    /// Constraint values, feasible when `g[j] <= 0`.
    pub g: Vec<f64>,
    /// Gradient of each objective (k rows of length n) when asked for.
    pub grad_f: Option<Vec<Vec<f64>>>,
    /// Gradients of each `g[j]` (m rows of length n) when asked for.
    pub grad_g: Option<Vec<Vec<f64>>>,
    /// The further pieces of the objectives that are maxima
    /// ([`MultiProblem::objective_pieces`] `K_i > 1`): for each such
    /// objective in order, its pieces 2 to `K_i` (the largest is `f_i`
    /// itself); empty when every objective is smooth.
    pub pieces: Vec<f64>,
    /// Their gradients (rows of length n), with the objectives'.
    pub grad_pieces: Option<Vec<Vec<f64>>>,
}

impl MultiEvaluation {
    /// An evaluation whose objectives are all smooth (no pieces).
    pub fn smooth(
        (f, g): (Vec<f64>, Vec<f64>),
        grad_f: Option<Vec<Vec<f64>>>,
        grad_g: Option<Vec<Vec<f64>>>,
    ) -> MultiEvaluation {
        MultiEvaluation {
            f,
            g,
            grad_f,
            grad_g,
            pieces: vec![],
            grad_pieces: None,
        }
    }

    /// Largest constraint value (`-inf` without constraints).
    pub fn max_g(&self) -> f64 {
        self.g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The pieces of objective `i` with their gradients (when evaluated
    /// with them), `f_i` first, for the piece counts `counts`
    /// ([`MultiProblem::objective_pieces`] of every objective).
    pub fn pieces_of(&self, counts: &[usize], i: usize) -> Vec<(f64, Option<&[f64]>)> {
        let from: usize = counts[..i].iter().map(|k| k - 1).sum();
        let mut out = vec![(self.f[i], self.grad_f.as_ref().map(|g| g[i].as_slice()))];
        for k in from..from + counts[i] - 1 {
            let grad = self.grad_pieces.as_ref().map(|g| g[k].as_slice());
            out.push((self.pieces[k], grad));
        }
        out
    }
}

/// Every objective's piece count (`K_i >= 1`) of `problem`.
pub fn piece_counts(problem: &dyn MultiProblem) -> Vec<usize> {
    (0..problem.objective_names().len())
        .map(|i| problem.objective_pieces(i).max(1))
        .collect()
}

/// A problem with several objectives, all minimized, subject to
/// `g(x) <= 0` and the variables' bounds. Deterministic and thread-safe,
/// like [`Problem`].
pub trait MultiProblem: Sync {
    /// The design variables.
    fn variables(&self) -> &[Variable];
    /// The objectives' names (`f1`, `f2`, …), in evaluation order.
    fn objective_names(&self) -> Vec<String>;
    /// Number of inequality constraints `g_j <= 0`.
    fn n_constraints(&self) -> usize;
    /// Evaluate at `x`; with `gradients` also every objective's and
    /// constraint's gradient.
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<MultiEvaluation>;
    /// The smooth pieces objective `i` is the largest of (module doc;
    /// default 1: a smooth objective); the evaluation carries pieces 2 to
    /// `K_i` in [`MultiEvaluation::pieces`].
    fn objective_pieces(&self, _i: usize) -> usize {
        1
    }
    /// Short name for reports.
    fn name(&self) -> &str;
    /// Objective `i` with its unit, for plot axes (default: its name, a
    /// dimensionless test objective).
    fn objective_label(&self, i: usize) -> String {
        format!("{} [-]", self.objective_names()[i])
    }
    /// The unit of objective `i` as the study writes it (in its
    /// [`objective_scale`](MultiProblem::objective_scale) multiple),
    /// e.g. `J*s`, for table headers (default: none, a dimensionless test
    /// objective).
    fn objective_unit(&self, _i: usize) -> Option<String> {
        None
    }
    /// The factor from objective `i` as evaluated to its value in its unit
    /// (default 1; a normalised objective `f = R/|R(x_n)|` has `|R(x_n)|`).
    fn objective_scale(&self, _i: usize) -> f64 {
        1.0
    }
    /// Variable `i` with its unit, for plot axes (default: its name).
    fn variable_label(&self, i: usize) -> String {
        self.variables()[i].name.clone()
    }
    /// The simulations run so far, for a problem that caches evaluations
    /// by design (default: none counted, every call evaluates).
    fn simulations(&self) -> Option<usize> {
        None
    }
    /// The analytic front, sampled (objectives in evaluation order), when
    /// the problem has a known one (default: none).
    fn known_front(&self) -> Option<Vec<Vec<f64>>> {
        None
    }
    /// The start design of the gradient side: the centre of the box.
    fn start(&self) -> Vec<f64> {
        self.variables()
            .iter()
            .map(|v| 0.5 * (v.lower + v.upper))
            .collect()
    }
}

/// Does `a` dominate `b` (minimization)?
pub fn dominates(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| x <= y) && a.iter().zip(b).any(|(x, y)| x < y)
}

/// Indices of the non-dominated points of `points` (minimization), in
/// their order; of equal points only the first is kept.
pub fn non_dominated(points: &[Vec<f64>]) -> Vec<usize> {
    (0..points.len())
        .filter(|&i| {
            !points.iter().enumerate().any(|(j, q)| {
                dominates(q, &points[i]) || (j < i && q.as_slice() == points[i].as_slice())
            })
        })
        .collect()
}

/// The non-dominated `(design, objectives)` pairs of `points`, in their
/// order ([`non_dominated`] on the objectives).
pub fn non_dominated_pairs(points: &[(Vec<f64>, Vec<f64>)]) -> Vec<(Vec<f64>, Vec<f64>)> {
    let f: Vec<Vec<f64>> = points.iter().map(|p| p.1.clone()).collect();
    non_dominated(&f)
        .into_iter()
        .map(|i| points[i].clone())
        .collect()
}

/// One objective of a study: which of the problem's, and its direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Pick {
    /// Index among the problem's objectives.
    pub index: usize,
    /// Maximized (negated inside, so that every algorithm minimizes).
    pub maximize: bool,
}

/// A problem's objectives chosen and oriented: objective `k` is the
/// problem's `picks[k].index`, negated when maximized.
pub struct Oriented<'a> {
    inner: &'a dyn MultiProblem,
    picks: Vec<Pick>,
    names: Vec<String>,
}

impl<'a> Oriented<'a> {
    /// The objectives named `names` (`maximize[k]` for each) of `inner`;
    /// an unknown name is an input error at `objectives[k].name`.
    pub fn new(inner: &'a dyn MultiProblem, names: &[(String, bool)]) -> Result<Self> {
        let all = inner.objective_names();
        let mut picks = Vec::new();
        for (k, (name, maximize)) in names.iter().enumerate() {
            let index = all.iter().position(|n| n == name).ok_or_else(|| {
                Error::input(
                    format!("objectives[{k}].name"),
                    format!("\"{name}\""),
                    format!("an objective of {}: {}", inner.name(), all.join(", ")),
                )
            })?;
            picks.push(Pick {
                index,
                maximize: *maximize,
            });
        }
        Ok(Oriented {
            inner,
            picks,
            names: names.iter().map(|(n, _)| n.clone()).collect(),
        })
    }

    /// The sign that turns a study's value into the minimized one and back
    /// (`-1` for maximized objectives).
    pub fn sign(&self, k: usize) -> f64 {
        if self.picks[k].maximize {
            -1.0
        } else {
            1.0
        }
    }
}

impl MultiProblem for Oriented<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn objective_names(&self) -> Vec<String> {
        self.names.clone()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<MultiEvaluation> {
        let e = self.inner.evaluate(x, gradients)?;
        let s: Vec<f64> = (0..self.picks.len()).map(|k| self.sign(k)).collect();
        // The further pieces of the minimized picks, in the picks' order.
        let counts = piece_counts(self.inner);
        let (mut pieces, mut grad_pieces) = (vec![], e.grad_f.as_ref().map(|_| vec![]));
        for (k, p) in self.picks.iter().enumerate() {
            if self.objective_pieces(k) > 1 {
                for (v, g) in e.pieces_of(&counts, p.index).into_iter().skip(1) {
                    pieces.push(v);
                    if let (Some(rows), Some(g)) = (grad_pieces.as_mut(), g) {
                        rows.push(g.to_vec());
                    }
                }
            }
        }
        Ok(MultiEvaluation {
            f: self
                .picks
                .iter()
                .zip(&s)
                .map(|(p, s)| s * e.f[p.index])
                .collect(),
            grad_f: e.grad_f.map(|gf| {
                self.picks
                    .iter()
                    .zip(&s)
                    .map(|(p, s)| gf[p.index].iter().map(|v| s * v).collect())
                    .collect()
            }),
            g: e.g,
            grad_g: e.grad_g,
            pieces,
            grad_pieces,
        })
    }
    /// The inner objective's pieces when it is minimized (a maximized
    /// maximum is no epigraph: its pieces are dropped).
    fn objective_pieces(&self, k: usize) -> usize {
        match &self.picks[k] {
            p if p.maximize => 1,
            p => self.inner.objective_pieces(p.index),
        }
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn objective_label(&self, k: usize) -> String {
        self.inner.objective_label(self.picks[k].index)
    }
    fn objective_unit(&self, k: usize) -> Option<String> {
        self.inner.objective_unit(self.picks[k].index)
    }
    fn objective_scale(&self, k: usize) -> f64 {
        self.inner.objective_scale(self.picks[k].index)
    }
    fn variable_label(&self, i: usize) -> String {
        self.inner.variable_label(i)
    }
    fn simulations(&self) -> Option<usize> {
        self.inner.simulations()
    }
    /// The inner problem's front in the picked order, when every objective
    /// is picked and minimized (a front of some of the objectives, or with
    /// one maximized, is another front).
    fn known_front(&self) -> Option<Vec<Vec<f64>>> {
        let all = self.inner.objective_names().len();
        if self.picks.len() != all || self.picks.iter().any(|p| p.maximize) {
            return None;
        }
        let front = self.inner.known_front()?;
        Some(
            front
                .iter()
                .map(|f| {
                    (0..self.picks.len())
                        .map(|k| self.sign(k) * f[self.picks[k].index])
                        .collect()
                })
                .collect(),
        )
    }
    fn start(&self) -> Vec<f64> {
        self.inner.start()
    }
}

/// Minimize `Σ_i w_i f_i` subject to `(f_j − ε_j)/s_j <= 0` for every
/// capped objective `j` (one per piece of an objective that is a maximum,
/// module doc) and the problem's own constraints (first). Only
/// the objectives with `w_i != 0` or a cap enter, so an objective whose
/// gradient is unbounded somewhere (ZDT's `f2` at `x1 = 0`) does not
/// spoil a problem that does not use it.
pub struct EpsilonConstraint<'a> {
    inner: &'a dyn MultiProblem,
    weights: Vec<f64>,
    caps: Vec<(usize, f64, f64)>,
    counts: Vec<usize>,
    name: String,
}

impl<'a> EpsilonConstraint<'a> {
    /// Weights `weights` (one per objective) and caps `(j, ε_j, s_j)` with
    /// `s_j > 0`.
    pub fn new(
        inner: &'a dyn MultiProblem,
        weights: Vec<f64>,
        caps: Vec<(usize, f64, f64)>,
    ) -> Self {
        let name = format!("{}-epsilon", inner.name());
        EpsilonConstraint {
            inner,
            weights,
            caps,
            counts: piece_counts(inner),
            name,
        }
    }
}

impl Problem for EpsilonConstraint<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        let capped: usize = self.caps.iter().map(|c| self.counts[c.0]).sum();
        self.inner.n_constraints() + capped
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        let mut e = self.inner.evaluate(x, gradients)?;
        let gg_in = e.grad_g.take();
        let n = x.len();
        let used = |i: usize| self.weights[i] != 0.0;
        let f = (0..e.f.len())
            .filter(|&i| used(i))
            .map(|i| self.weights[i] * e.f[i])
            .sum();
        let mut g = e.g.clone();
        let mut dcap = Vec::new();
        for &(j, eps, s) in &self.caps {
            for (p, dp) in e.pieces_of(&self.counts, j) {
                g.push((p - eps) / s);
                dcap.extend(dp.map(|d| d.iter().map(|v| v / s).collect::<Vec<f64>>()));
            }
        }
        let (grad_f, grad_g) = match (&e.grad_f, gg_in) {
            (Some(gf), Some(gg)) => {
                let mut df = vec![0.0; n];
                for (i, row) in gf.iter().enumerate().filter(|(i, _)| used(*i)) {
                    for (d, v) in df.iter_mut().zip(row) {
                        *d += self.weights[i] * v;
                    }
                }
                let mut dg = gg;
                dg.extend(dcap);
                (Some(df), Some(dg))
            }
            _ => (None, None),
        };
        Ok(Evaluation {
            f,
            g,
            grad_f,
            grad_g,
        })
    }
    fn name(&self) -> &str {
        &self.name
    }
}

/// The augmented reference-point Tchebycheff problem of the module doc
/// over `(x, t)`: the problem's constraints first, then one
/// `u_i − r_i − t <= 0` per objective (per piece of an objective that is
/// a maximum), then the caps ([`Tchebycheff::capped`]).
pub struct Tchebycheff<'a> {
    inner: &'a dyn MultiProblem,
    ideal: Vec<f64>,
    scale: Vec<f64>,
    reference: Vec<f64>,
    rho: f64,
    vars: Vec<Variable>,
    /// The objectives in the maximum (all unless [`Tchebycheff::only`]).
    used: Vec<usize>,
    /// `(j, ε_j, s_j)`: `(p_jk − ε_j)/s_j <= 0` for every piece of `f_j`.
    caps: Vec<(usize, f64, f64)>,
    counts: Vec<usize>,
    name: String,
}

impl<'a> Tchebycheff<'a> {
    /// The problem for reference point `reference` (normalized), with the
    /// ideal point `ideal`, ranges `scale` (> 0), augmentation `rho`, and
    /// `t` bounded by `[t_lower, t_upper]`.
    pub fn new(
        inner: &'a dyn MultiProblem,
        (ideal, scale): (Vec<f64>, Vec<f64>),
        reference: Vec<f64>,
        rho: f64,
        (t_lower, t_upper): (f64, f64),
    ) -> Result<Self> {
        let mut vars = inner.variables().to_vec();
        vars.push(Variable::bounded("t", t_lower, t_upper)?);
        let name = format!("{}-tchebycheff", inner.name());
        let counts = piece_counts(inner);
        Ok(Tchebycheff {
            inner,
            used: (0..counts.len()).collect(),
            ideal,
            scale,
            reference,
            rho,
            vars,
            caps: vec![],
            counts,
            name,
        })
    }

    /// Only objective `i` in the maximum: with ideal 0, range 1 and
    /// reference 0, minimizing `t + ρ f_i` with every piece of `f_i` at
    /// most `t` is minimizing `f_i` (the epigraph of a maximum, module
    /// doc).
    pub fn only(mut self, i: usize) -> Self {
        self.used = vec![i];
        self
    }

    /// With caps `(j, ε_j, s_j)`, `s_j > 0`, as [`EpsilonConstraint`]'s.
    pub fn capped(mut self, caps: Vec<(usize, f64, f64)>) -> Self {
        self.caps = caps;
        self
    }

    /// Normalized objectives `u_i = (f_i − z_i)/s_i`.
    pub fn normalized(&self, f: &[f64]) -> Vec<f64> {
        f.iter()
            .zip(self.ideal.iter().zip(&self.scale))
            .map(|(f, (z, s))| (f - z) / s)
            .collect()
    }

    /// The start `(x0, t0)` with `t0 = max_i (u_i(x0) − r_i)` over the
    /// objectives in the maximum (every added constraint satisfied, the
    /// largest active), clamped to `t`'s bounds.
    pub fn start(&self, x0: &[f64]) -> Result<Vec<f64>> {
        let e = self.inner.evaluate(x0, false)?;
        let u = self.normalized(&e.f);
        let t0 = (self.used.iter())
            .map(|&i| u[i] - self.reference[i])
            .fold(f64::NEG_INFINITY, f64::max);
        let mut x = x0.to_vec();
        x.push(self.vars[x0.len()].wrap(t0));
        Ok(x)
    }
}

impl Problem for Tchebycheff<'_> {
    fn variables(&self) -> &[Variable] {
        &self.vars
    }
    fn n_constraints(&self) -> usize {
        let pieces: usize = self.used.iter().map(|&i| self.counts[i]).sum();
        let capped: usize = self.caps.iter().map(|c| self.counts[c.0]).sum();
        self.inner.n_constraints() + pieces + capped
    }
    fn evaluate(&self, xt: &[f64], gradients: bool) -> Result<Evaluation> {
        let n = self.vars.len() - 1;
        if xt.len() != n + 1 {
            return Err(Error::input(
                "tchebycheff.x",
                format!("a vector of length {}", xt.len()),
                format!("length {}", n + 1),
            ));
        }
        let (x, t) = (&xt[..n], xt[n]);
        let mut e = self.inner.evaluate(x, gradients)?;
        let gg_in = e.grad_g.take();
        let u = self.normalized(&e.f);
        let f = t + self.rho * self.used.iter().map(|&i| u[i]).sum::<f64>();
        let mut g = e.g.clone();
        // The added rows: (value, gradient in x, coefficient of t).
        let mut rows: Vec<(f64, Option<&[f64]>, f64, f64)> = Vec::new();
        for &i in &self.used {
            let (z, s, r) = (self.ideal[i], self.scale[i], self.reference[i]);
            for (p, dp) in e.pieces_of(&self.counts, i) {
                rows.push(((p - z) / s - r - t, dp, s, -1.0));
            }
        }
        for &(j, eps, s) in &self.caps {
            for (p, dp) in e.pieces_of(&self.counts, j) {
                rows.push(((p - eps) / s, dp, s, 0.0));
            }
        }
        g.extend(rows.iter().map(|r| r.0));
        let (grad_f, grad_g) = match (&e.grad_f, gg_in) {
            (Some(gf), Some(gg)) => {
                let mut df = vec![0.0; n + 1];
                df[n] = 1.0;
                for &i in &self.used {
                    for (d, v) in df.iter_mut().zip(&gf[i]) {
                        *d += self.rho * v / self.scale[i];
                    }
                }
                let mut dg: Vec<Vec<f64>> = gg
                    .into_iter()
                    .map(|mut row| {
                        row.push(0.0);
                        row
                    })
                    .collect();
                for (_, dp, s, dt) in &rows {
                    let mut du: Vec<f64> = dp.unwrap_or_default().iter().map(|v| v / s).collect();
                    du.push(*dt);
                    dg.push(du);
                }
                (Some(df), Some(dg))
            }
            _ => (None, None),
        };
        Ok(Evaluation {
            f,
            g,
            grad_f,
            grad_g,
        })
    }
    fn name(&self) -> &str {
        &self.name
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dominance_and_the_non_dominated_filter() {
        assert!(dominates(&[1.0, 2.0], &[1.0, 3.0]));
        assert!(!dominates(&[1.0, 2.0], &[1.0, 2.0]));
        assert!(!dominates(&[0.0, 3.0], &[1.0, 2.0]));
        let p = vec![
            vec![1.0, 2.0],
            vec![2.0, 1.0],
            vec![2.0, 2.0],
            vec![1.0, 2.0],
            vec![0.5, 3.0],
        ];
        assert_eq!(non_dominated(&p), vec![0, 1, 4]);
    }
}
