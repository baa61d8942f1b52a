//! [`Erk`]: an explicit Runge–Kutta pair ([`Pair`]) stepped here, on a
//! diffsol problem, for pairs with more stages than diffsol's explicit
//! solver holds (module doc of `super::pair`).
//!
//! Everything but the tableau is diffsol's explicit solver's, so that a
//! comparison of pairs compares the pairs: the same first step (the
//! starting-step algorithm of Hairer, Nørsett & Wanner, *Solving Ordinary
//! Differential Equations I*, §II.4), the same weighted RMS error norm
//! (diffsol's `squared_norm`: the mean of `(eᵢ/(atol_i + rtol |y₀ᵢ|))²`
//! against 1), the same step-size controller (factor
//! `0.9 · err^(−kI/(q+1))`, with the previous error's `kP` term, clamped
//! to the problem's shrink and growth bounds; `q` the embedded order), the
//! same approach to the stop time and the same root finding on the dense
//! output of each accepted step. The test `of_tableau_steps_as_diffsol`
//! checks this: with tsit45's tableau the driver takes diffsol's steps.
//!
//! The stages only the continuous extension needs are computed when the
//! dense output of a step is first asked for.

use super::options::Stats;
use super::pair::Pair;
use super::stepper::Stepper;
use diffsol::nonlinear_solver::root::RootFinder;
use diffsol::{
    ConstantOp, FaerContext, FaerVec, NonLinearOp, OdeEquations, OdeSolverProblem,
    OdeSolverStopReason, Op, Vector,
};
use std::cell::{Cell, RefCell};

/// An explicit pair stepping one leg of `problem` from its `t0` and its
/// initial condition.
pub(super) struct Erk<'a, Eqn: OdeEquations<T = f64, V = FaerVec<f64>, C = FaerContext>> {
    problem: &'a OdeSolverProblem<Eqn>,
    pair: Pair,
    /// Time and state reached, and the derivative there (FSAL).
    t: f64,
    y: FaerVec<f64>,
    f: FaerVec<f64>,
    /// The next step's length.
    h: f64,
    /// The last accepted step: its start, its start state and its length.
    last: (f64, FaerVec<f64>, f64),
    /// `h kᵢ` of the stages of the last accepted step (all stages; the
    /// extension's once `extended`).
    k: RefCell<Vec<FaerVec<f64>>>,
    extended: Cell<bool>,
    /// Stages of the step being tried, and its solution.
    trial: Vec<FaerVec<f64>>,
    y1: FaerVec<f64>,
    tstop: Option<f64>,
    prev_error: Option<f64>,
    roots: Option<RootFinder<FaerVec<f64>>>,
    steps: usize,
    failures: usize,
}

/// diffsol's explicit-solver defaults (`ExplicitRkConfig`) where the
/// problem's options leave them open: growth at most 2, shrink at least
/// 0.5, no dead zone.
fn bounds(o: &diffsol::OdeSolverOptions<f64>) -> (f64, f64, f64, f64) {
    (
        o.min_timestep_shrink.unwrap_or(0.5),
        o.max_timestep_shrink.unwrap_or(1.0),
        o.min_timestep_growth.unwrap_or(1.0),
        o.max_timestep_growth.unwrap_or(2.0),
    )
}

impl<'a, Eqn: OdeEquations<T = f64, V = FaerVec<f64>, C = FaerContext>> Erk<'a, Eqn> {
    /// A solver at the problem's start with its first step chosen.
    pub(super) fn new(problem: &'a OdeSolverProblem<Eqn>, pair: Pair) -> Result<Self, String> {
        if pair.s < 2 || pair.a.len() != pair.stages() || pair.dense.len() != pair.stages() {
            return Err("inconsistent explicit pair".into());
        }
        let ctx = *problem.context();
        let n = problem.eqn.rhs().nstates();
        let mut y = FaerVec::zeros(n, ctx);
        problem.eqn.init().call_inplace(problem.t0, &mut y);
        let mut f = FaerVec::zeros(n, ctx);
        problem.eqn.rhs().call_inplace(&y, problem.t0, &mut f);
        let roots = problem.eqn.root().map(|g| {
            let finder = RootFinder::new(g.nout(), n, ctx);
            finder.init(&g, &y, problem.t0);
            finder
        });
        let stages = (0..pair.stages())
            .map(|_| FaerVec::zeros(n, ctx))
            .collect::<Vec<_>>();
        let mut erk = Erk {
            problem,
            t: problem.t0,
            h: 0.0,
            last: (problem.t0, y.clone(), 0.0),
            k: RefCell::new(stages.clone()),
            extended: Cell::new(false),
            trial: stages,
            y1: y.clone(),
            y,
            f,
            pair,
            tstop: None,
            prev_error: None,
            roots,
            steps: 0,
            failures: 0,
        };
        erk.h = erk.first_step();
        Ok(erk)
    }

    /// The first step (Hairer, Nørsett & Wanner I, §II.4, as diffsol's
    /// explicit solver chooses it): from the norms of `y₀`, `f₀` and a
    /// difference quotient of `f` over a trial Euler step.
    fn first_step(&self) -> f64 {
        let p = self.problem;
        let norm = |v: &FaerVec<f64>| v.squared_norm(&self.y, &p.atol, p.rtol).sqrt();
        let (d0, d1) = (norm(&self.y), norm(&self.f));
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let mut y1 = self.y.clone();
        y1.axpy(h0, &self.f, 1.0);
        let mut f1 = self.f.clone();
        p.eqn.rhs().call_inplace(&y1, self.t + h0, &mut f1);
        f1.axpy(-1.0, &self.f, 1.0);
        let d2 = norm(&f1) / h0;
        let max_d = d1.max(d2);
        let h1 = if max_d < 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / max_d).powf(1.0 / (1.0 + self.pair.order as f64))
        };
        (100.0 * h0).min(h1)
    }

    /// Stages `1..s` of a step of length `h` from `(t, y)` (stage 0 is
    /// `h f`), into `trial`, and the solution into `y1`.
    fn attempt(&mut self, h: f64) {
        let p = self.problem;
        let s = self.pair.s;
        self.trial[0].axpy(h, &self.f, 0.0);
        for i in 1..s {
            stage_into(&mut self.y1, &self.y, &self.pair.a[i], &self.trial[..i]);
            let ki = &mut self.trial[i];
            p.eqn
                .rhs()
                .call_inplace(&self.y1, self.t + self.pair.c[i] * h, ki);
            *ki *= diffsol::scale(h);
        }
        stage_into(&mut self.y1, &self.y, &self.pair.b, &self.trial[..s]);
    }

    /// The squared error norm of the step just tried (diffsol's measure).
    fn error(&self) -> f64 {
        let p = self.problem;
        let mut err = self.y.clone();
        err.fill(0.0);
        for (e, k) in self.pair.e.iter().zip(&self.trial) {
            if *e != 0.0 {
                err.axpy(*e, k, 1.0);
            }
        }
        err.squared_norm(&self.y, &p.atol, p.rtol)
    }

    /// The step-size factor for the squared error norm `err` (diffsol's
    /// controller).
    fn factor(&self, err: f64) -> f64 {
        let o = &self.problem.ode_options;
        let q = (self.pair.order + 1) as f64;
        let ki = o.pi_control_integral / q;
        let raw = match self.prev_error {
            Some(prev) if o.pi_control_proportional != 0.0 => {
                let kp = o.pi_control_proportional / q;
                err.powf(-(ki + kp)) * prev.powf(kp)
            }
            _ => err.powf(-ki),
        };
        let (min_shrink, max_shrink, min_growth, max_growth) = bounds(o);
        let mut factor = 0.9 * raw;
        if factor > max_shrink && factor < min_growth {
            factor = 1.0;
        }
        factor.clamp(min_shrink, max_growth)
    }

    /// Take the step just tried: the new state, its derivative (the last
    /// stage of an FSAL pair), and its stages for the dense output.
    fn accept(&mut self, h: f64) {
        let s = self.pair.s;
        std::mem::swap(&mut self.last.1, &mut self.y);
        self.last.0 = self.t;
        self.last.2 = h;
        std::mem::swap(&mut self.y, &mut self.y1);
        self.t += h;
        if self.pair.fsal {
            self.f.axpy(1.0 / h, &self.trial[s - 1], 0.0);
        } else {
            self.problem
                .eqn
                .rhs()
                .call_inplace(&self.y, self.t, &mut self.f);
        }
        let mut k = self.k.borrow_mut();
        for (ki, ti) in k.iter_mut().zip(&self.trial[..s]) {
            ki.copy_from(ti);
        }
        self.extended.set(s == self.pair.stages());
        self.steps += 1;
    }

    /// The extension's stages of the last accepted step, once.
    fn extend(&self) {
        if self.extended.get() {
            return;
        }
        let (t0, y0, h) = (self.last.0, &self.last.1, self.last.2);
        let mut k = self.k.borrow_mut();
        let mut ys = y0.clone();
        for i in self.pair.s..self.pair.stages() {
            stage_into(&mut ys, y0, &self.pair.a[i], &k[..i]);
            let ki = &mut k[i];
            self.problem
                .eqn
                .rhs()
                .call_inplace(&ys, t0 + self.pair.c[i] * h, ki);
            *ki *= diffsol::scale(h);
        }
        self.extended.set(true);
    }

    /// The dense output at `t` of the last accepted step into `out`.
    fn dense_into(&self, t: f64, out: &mut FaerVec<f64>) {
        self.extend();
        let (t0, y0, h) = (self.last.0, &self.last.1, self.last.2);
        let theta = if h == 0.0 { 1.0 } else { (t - t0) / h };
        let w = self.pair.weights(theta);
        stage_into(out, y0, &w, &self.k.borrow());
    }

    /// At the stop time (within rounding): whether the integration ends
    /// here; otherwise shorten the next step to end at it.
    fn approach_stop(&mut self) -> Result<bool, String> {
        let Some(tstop) = self.tstop else {
            return Ok(false);
        };
        let roundoff = 100.0 * f64::EPSILON * (self.t.abs() + self.h.abs());
        if (self.t - tstop).abs() <= roundoff {
            return Ok(true);
        }
        if tstop < self.t - roundoff {
            return Err(format!(
                "stop time {tstop} s is before the current time {} s",
                self.t
            ));
        }
        if self.t + self.h > tstop + roundoff {
            self.h = tstop - self.t;
        }
        Ok(false)
    }
}

/// `out = y + Σⱼ wⱼ kⱼ` (the terms with `wⱼ = 0` skipped).
fn stage_into(out: &mut FaerVec<f64>, y: &FaerVec<f64>, w: &[f64], k: &[FaerVec<f64>]) {
    out.copy_from(y);
    for (wj, kj) in w.iter().zip(k) {
        if *wj != 0.0 {
            out.axpy(*wj, kj, 1.0);
        }
    }
}

impl<Eqn: OdeEquations<T = f64, V = FaerVec<f64>, C = FaerContext>> Stepper for Erk<'_, Eqn> {
    fn time(&self) -> f64 {
        self.t
    }

    fn state(&self) -> Vec<f64> {
        self.y.clone_as_vec()
    }

    fn set_stop_time(&mut self, t: f64) -> Result<(), String> {
        self.tstop = Some(t);
        if self.approach_stop()? {
            self.tstop = None;
            return Err(format!("stop time {t} s is the current time"));
        }
        Ok(())
    }

    fn step(&mut self) -> Result<OdeSolverStopReason<f64>, String> {
        let o = &self.problem.ode_options;
        let mut h = self.h;
        let mut attempts = 0;
        let factor = loop {
            self.attempt(h);
            let err = self.error();
            if err < 1.0 {
                let factor = self.factor(err);
                self.prev_error = Some(err);
                break factor;
            }
            // A step that is not finite is retried shortest.
            h *= match err.is_finite() {
                true => self.factor(err),
                false => bounds(o).0,
            };
            attempts += 1;
            self.failures += 1;
            self.prev_error = None;
            if attempts >= o.max_error_test_failures {
                return Err(format!(
                    "{attempts} error test failures in a row at t = {} s",
                    self.t
                ));
            }
            if h.abs() < o.min_timestep {
                return Err(format!("step size too small at t = {} s", self.t));
            }
        };
        self.accept(h);
        self.h = h * factor;
        if let (Some(g), Some(finder)) = (self.problem.eqn.root(), self.roots.as_ref()) {
            let dense = |t: f64, out: &mut FaerVec<f64>| {
                self.dense_into(t, out);
                Ok::<(), diffsol::error::DiffsolError>(())
            };
            if let Some((t, idx)) = finder.check_root(&dense, &g, &self.y, self.t) {
                return Ok(OdeSolverStopReason::RootFound(t, idx));
            }
        }
        if self.approach_stop()? {
            self.tstop = None;
            return Ok(OdeSolverStopReason::TstopReached);
        }
        Ok(OdeSolverStopReason::InternalTimestep)
    }

    fn interpolate(&self, t: f64) -> Result<Vec<f64>, String> {
        let (t0, _, h) = self.last;
        let slack = 100.0 * f64::EPSILON * (t0.abs() + h.abs());
        if h == 0.0 || t < t0 - slack || t > self.t + slack {
            return Err(format!(
                "dense output at {t} s outside the last step [{t0}, {}] s",
                self.t
            ));
        }
        let mut out = self.y.clone();
        self.dense_into(t, &mut out);
        Ok(out.clone_as_vec())
    }

    fn interpolate_sens(&self, _t: f64) -> Result<Vec<f64>, String> {
        Err("the explicit pairs integrate sensitivities in the state (fused form) only".into())
    }

    fn stats(&self) -> Stats {
        Stats {
            steps: self.steps,
            error_test_failures: self.failures,
            ..Stats::default()
        }
    }
}
