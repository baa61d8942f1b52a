//! The legs of one integration: stepping a diffsol solver through the
//! output times, locating the model's events, switching pieces with the
//! sensitivity jump, and restarting (module doc of [`super`]).
//!
//! One loop ([`Legs::run`]) serves every form of integration; what a leg
//! integrates (the states alone, the states with diffsol's forward
//! sensitivities, or the fused lanes) is an [`Integrand`]: its problem,
//! the solver it builds for each family of methods
//! ([`super::options::Scheme`]) and how a leg starts from an event. A new
//! method is a [`super::Method`] variant with its scheme; a new form is
//! an [`Integrand`].

use super::erk::Erk;
use super::ode::OdeModel;
use super::options::{Options, Scheme, Stats};
use super::pair::Pair;
use super::step::{DenseState, Step, StepWatch};
use super::stepper::{Diffsol, Stepper};
use crate::error::{Error, Result};
use diffsol::error::DiffsolError;
use diffsol::{
    FaerContext, FaerMat, FaerVec, LinearSolver, OdeEquationsImplicit, OdeSolverMethod,
    OdeSolverProblem, OdeSolverStopReason, Tableau,
};
use std::cell::{Cell, RefCell};
use std::time::Instant;

/// What the legs of one integration integrate: a diffsol problem and the
/// solvers built on it, one per family of methods, each starting from the
/// current leg's start (the initial state, then each event's). The
/// solvers are diffsol's plain ones unless a form provides its own (the
/// staggered form: the sensitivity solvers).
pub(super) trait Integrand {
    /// The problem's equations.
    type Eqn: OdeEquationsImplicit<T = f64, V = FaerVec<f64>, M = FaerMat<f64>, C = FaerContext>;

    /// The linear solver of the implicit methods' Newton matrix.
    type Lu: LinearSolver<FaerMat<f64>>;

    /// Where a solver's set-up error is reported (`integrate`, ..).
    const PLACE: &'static str;

    /// The problem integrated.
    fn problem(&self) -> &OdeSolverProblem<Self::Eqn>;

    /// Sensitivity lanes the solver integrates itself (diffsol's forward
    /// sensitivities; 0 without, and 0 in the fused form).
    fn nsens(&self) -> usize {
        0
    }

    /// In the fused form, the length of `y` in the solver's state
    /// `[y; s_1; ..; s_np]`.
    fn fused(&self) -> Option<usize> {
        None
    }

    /// A BDF solver on the problem (the calls of diffsol's `bdf`).
    fn bdf<'s>(&'s self) -> std::result::Result<impl OdeSolverMethod<'s, Self::Eqn>, DiffsolError>
    where
        Self::Eqn: 's,
    {
        self.problem().bdf::<Self::Lu>()
    }

    /// An SDIRK solver with `tableau` on the problem (the calls of
    /// diffsol's `esdirk34` with another tableau).
    fn sdirk<'s>(
        &'s self,
        tableau: Tableau<f64>,
    ) -> std::result::Result<impl OdeSolverMethod<'s, Self::Eqn>, DiffsolError>
    where
        Self::Eqn: 's,
    {
        let problem = self.problem();
        let state = problem.rk_state_and_consistent::<Self::Lu>(&tableau)?;
        problem.sdirk_solver::<Self::Lu, _>(state, tableau)
    }

    /// An explicit Runge–Kutta solver with `tableau` on the problem (the
    /// calls of diffsol's `tsit45` with another tableau).
    fn explicit_rk<'s>(
        &'s self,
        tableau: Tableau<f64>,
    ) -> std::result::Result<impl OdeSolverMethod<'s, Self::Eqn>, DiffsolError>
    where
        Self::Eqn: 's,
    {
        let problem = self.problem();
        let state = problem.rk_state(&tableau)?;
        problem.explicit_rk_solver(state, tableau)
    }

    /// An explicit pair stepped here ([`Erk`]) on the problem: the states
    /// alone or with the lanes in the state (the fused form).
    fn erk(&self, pair: Pair) -> Result<Erk<'_, Self::Eqn>> {
        Erk::new(self.problem(), pair)
            .map_err(|e| Error::numerical(format!("{}: solver set-up", Self::PLACE), e))
    }

    /// Run `leg`, which builds an implicit solver (its linear solver
    /// included) and drives it; the fused form sets the block count of its
    /// Newton matrix here.
    fn implicit<R>(&self, leg: impl FnOnce() -> R) -> R {
        leg()
    }

    /// Start the next leg at time `t` from state `y` and sensitivities `s`
    /// (lane-major; empty without).
    fn restart(&mut self, t: f64, y: Vec<f64>, s: Vec<f64>);
}

/// diffsol counts nonlinear-solver failures over the WHOLE integration
/// (`max_nonlinear_solver_failures`, default 50) and aborts past the cap,
/// so a long, healthy BDF run whose Newton iteration occasionally fails
/// (each failure just refreshes the Jacobian and cuts the step, as in
/// CVODE, whose cap is per step) ends in an error: the Bricard linkage at
/// rtol 1e-4 did at t = 0.45 s. The cap is lifted; a genuine divergence
/// still ends, with its time, when the step falls below `min_timestep`
/// (1e-13 s; each failure cuts the step by 0.3, so after about 30
/// consecutive failures from a 1e-3 s step).
pub(super) fn lift_failure_cap(o: &mut diffsol::OdeSolverOptions<f64>) {
    o.max_nonlinear_solver_failures = usize::MAX / 2;
}

/// An accepted change of piece: time, state and sensitivities (before the
/// jump; [`Legs::jump`] applies it in place) and the crossing.
pub(super) struct Event<C> {
    pub(super) t: f64,
    pub(super) y: Vec<f64>,
    pub(super) s: Vec<f64>,
    pub(super) crossing: C,
}

/// The legs of one integration: output bookkeeping across restarts.
pub(super) struct Legs<'c, M: OdeModel> {
    pub(super) opts: &'c Options,
    /// Sensitivity lanes the solver integrates itself (diffsol's forward
    /// sensitivities; 0 without, and 0 in the fused form).
    pub(super) nsens: usize,
    /// Fused form: the solver's state is `[y; s_1; ..; s_np]` and `y` has
    /// this length.
    pub(super) fused: Option<usize>,
    /// Next output time to emit.
    pub(super) next: usize,
    pub(super) model: &'c M,
    pub(super) events: &'c RefCell<M::Events>,
    pub(super) work: &'c RefCell<M::Work>,
    /// The sensitivity parameters and their values (empty without).
    pub(super) params: (&'c [M::Param], &'c [f64]),
}

impl<'c, M: OdeModel> Legs<'c, M> {
    /// The legs of an integration of `model` with `opts` (its events, its
    /// work space and the sensitivity parameters with their values) of
    /// what `integrand` integrates, from the first output time.
    pub(super) fn new(
        opts: &'c Options,
        model: &'c M,
        (events, work): (&'c RefCell<M::Events>, &'c RefCell<M::Work>),
        params: (&'c [M::Param], &'c [f64]),
        integrand: &impl Integrand,
    ) -> Self {
        Legs {
            opts,
            nsens: integrand.nsens(),
            fused: integrand.fused(),
            next: 0,
            model,
            events,
            work,
            params,
        }
    }

    /// Integrate leg after leg until the end time, calling `observe(t, y,
    /// s)` at every output time and `within` with every accepted step
    /// ([`Step`]), and return the statistics; `calls` count
    /// the right-hand sides and the directional derivatives. Every method
    /// and every form goes through here: the solver of the method's
    /// family comes from `integrand`, and a new leg starts from each event
    /// ([`Legs::end_leg`]).
    pub(super) fn run<I: Integrand>(
        mut self,
        integrand: &mut I,
        calls: (&Cell<u64>, &Cell<u64>),
        mut observe: impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
        within: &mut StepWatch<'_>,
    ) -> Result<Stats> {
        let start = Instant::now();
        let observer_time = Cell::new(0.0f64);
        let mut observe = |t: f64, y: &[f64], s: &[f64]| {
            let t0 = Instant::now();
            let r = observe(t, y, s);
            observer_time.set(observer_time.get() + t0.elapsed().as_secs_f64());
            r
        };
        let mut within = |step: &Step<'_>| {
            let t0 = Instant::now();
            let r = within(step);
            observer_time.set(observer_time.get() + t0.elapsed().as_secs_f64());
            r
        };
        let within: &mut StepWatch<'_> = &mut within;
        let setup = |e: DiffsolError| {
            Error::numerical(format!("{}: solver set-up", I::PLACE), e.to_string())
        };
        let mut stats = Stats::default();
        loop {
            let leg = match self.opts.method.scheme() {
                Scheme::Bdf => integrand.implicit(|| {
                    let solver = Diffsol::new(integrand.bdf().map_err(setup)?);
                    self.drive(solver, (&mut observe, within))
                })?,
                Scheme::Sdirk(tableau) => integrand.implicit(|| {
                    let solver = Diffsol::new(integrand.sdirk(tableau).map_err(setup)?);
                    self.drive(solver, (&mut observe, within))
                })?,
                Scheme::ExplicitRk(tableau) => {
                    let solver = Diffsol::new(integrand.explicit_rk(tableau).map_err(setup)?);
                    self.drive(solver, (&mut observe, within))?
                }
                Scheme::Pair(pair) => self.drive(integrand.erk(pair)?, (&mut observe, within))?,
            };
            let Some(e) = self.end_leg(&mut stats, leg, &mut observe)? else {
                break;
            };
            integrand.restart(e.t, e.y, e.s);
        }
        Ok(stats.finish(start, observer_time.get(), (calls.0.get(), calls.1.get())))
    }

    /// A solver state as `(y, lanes)`: in the fused form the lanes follow
    /// `y` in the state; otherwise there are none here.
    fn split(&self, mut z: Vec<f64>) -> (Vec<f64>, Vec<f64>) {
        match self.fused {
            Some(n) => {
                let s = z.split_off(n);
                (z, s)
            }
            None => (z, Vec::new()),
        }
    }

    /// Step a solver through the output times until the end or an
    /// accepted segment change; with `nsens > 0` the sensitivities
    /// (`nsens` lanes of the state length, lane-major) are interpolated
    /// too and handed to `observe` after the state; every accepted step
    /// goes to `within` with its dense output, ending at the event when
    /// it located one. Outputs after an event are not served by this leg
    /// (its law is extended past the breakpoint there).
    fn drive(
        &mut self,
        mut solver: impl Stepper,
        (observe, within): (
            &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
            &mut StepWatch<'_>,
        ),
    ) -> Result<(Stats, Option<Event<M::Crossing>>)> {
        let opts = self.opts;
        let times = &opts.times;
        let nsens = self.nsens;
        let t_end = times[times.len() - 1];
        solver
            .set_stop_time(t_end)
            .map_err(|e| Error::numerical("integrate: stop time", e))?;
        // Output times at the start (first leg only: later legs start
        // after the outputs already served).
        while self.next < times.len() && times[self.next] <= opts.t0 {
            let (y, mut s0) = self.split(solver.state());
            if self.fused.is_none() {
                // Initial sensitivities are zero (the initial state is given).
                s0 = vec![0.0; y.len() * nsens];
            }
            emit(times[self.next], &y, &s0, observe)?;
            self.next += 1;
        }
        let mut event = None;
        loop {
            let t_before = solver.time();
            let reason = solver.step().map_err(|e| {
                Error::numerical_at(
                    format!("integrate: {} step", opts.method.name()),
                    t_before,
                    e,
                )
            })?;
            let mut t = solver.time();
            if let OdeSolverStopReason::RootFound(tr, idx) = reason {
                let (yr, s_fused) = self.split(
                    solver
                        .interpolate(tr)
                        .map_err(|e| Error::numerical_at("integrate: event state", tr, e))?,
                );
                let crossing = self.model.classify(&self.events.borrow(), idx, tr, &yr);
                if let Some(crossing) = crossing {
                    let s = if nsens > 0 {
                        solver.interpolate_sens(tr).map_err(|e| {
                            Error::numerical_at("integrate: event sensitivities", tr, e)
                        })?
                    } else {
                        s_fused
                    };
                    t = tr;
                    event = Some(Event {
                        t: tr,
                        y: yr,
                        s,
                        crossing,
                    });
                }
            }
            if t > t_before {
                let dense = |tq: f64| self.dense(&solver, tq);
                within(&Step {
                    span: (t_before, t),
                    dense: &dense,
                })?;
            }
            while self.next < times.len() && times[self.next] <= t {
                let tq = times[self.next];
                if let Some(e) = event.as_ref().filter(|e| e.t == tq) {
                    emit(tq, &e.y, &e.s, observe)?;
                    self.next += 1;
                    continue;
                }
                let (y, sens) = self.dense(&solver, tq)?;
                emit(tq, &y, &sens, observe)?;
                self.next += 1;
            }
            if event.is_some()
                || matches!(reason, OdeSolverStopReason::TstopReached)
                || self.next >= times.len()
            {
                break;
            }
        }
        Ok((solver.stats(), event))
    }

    /// The state and the sensitivities (lane-major) at `tq` in the last
    /// accepted step of `solver`, from its dense output (its state at the
    /// step's end).
    fn dense(&self, solver: &impl Stepper, tq: f64) -> Result<DenseState> {
        let y = if tq == solver.time() {
            solver.state()
        } else {
            solver
                .interpolate(tq)
                .map_err(|e| Error::numerical_at("integrate: dense output", tq, e))?
        };
        let (y, s_fused) = self.split(y);
        if self.nsens == 0 {
            return Ok((y, s_fused));
        }
        let sens = solver
            .interpolate_sens(tq)
            .map_err(|e| Error::numerical_at("integrate: sensitivity output", tq, e))?;
        Ok((y, sens))
    }

    /// The end of a leg: count it; at an event, end the integration with
    /// an error if the model halts there ([`OdeModel::halt`]: the outputs
    /// up to the event are already served), else switch the piece (the
    /// sensitivities jump), refreeze the model's pieces, and return the
    /// event when a new leg must start from it.
    fn end_leg(
        &mut self,
        stats: &mut Stats,
        leg: (Stats, Option<Event<M::Crossing>>),
        observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
    ) -> Result<Option<Event<M::Crossing>>> {
        stats.absorb(&leg.0);
        let Some(mut e) = leg.1 else { return Ok(None) };
        if let Some((place, detail)) = self
            .model
            .halt(&self.events.borrow(), e.crossing, e.t, &e.y)
        {
            return Err(Error::numerical_at(place, e.t, detail));
        }
        stats.events += 1;
        stats.last_event = Some(e.t);
        self.jump(&mut e)?;
        self.model
            .freeze(&self.events.borrow(), &mut self.work.borrow_mut());
        if !self.restart_or_finish(&e, observe)? {
            return Ok(None);
        }
        stats.restarts += 1;
        Ok(Some(e))
    }

    /// Switch the piece at event `e` and, with sensitivity lanes, apply
    /// the jump `s⁺ = s⁻ + (f⁻ − f⁺) dt_e/dp` with
    /// `dt_e/dp = −g_y s⁻ / (g_y f⁻)` (module doc; `g_p = 0`) in place.
    fn jump(&mut self, e: &mut Event<M::Crossing>) -> Result<()> {
        let (model, c) = (self.model, e.crossing);
        let mut ev = self.events.borrow_mut();
        if e.s.is_empty() {
            model.switch(&mut ev, c, e.t, &e.y);
            return Ok(());
        }
        let n = e.y.len();
        let mut work = self.work.borrow_mut();
        let (mut fm, mut fp) = (vec![0.0; n], vec![0.0; n]);
        model.freeze(&ev, &mut work);
        model.rhs(&mut work, e.t, &e.y, self.params, &mut fm);
        model.switch(&mut ev, c, e.t, &e.y);
        model.freeze(&ev, &mut work);
        model.rhs(&mut work, e.t, &e.y, self.params, &mut fp);
        let den = model.crossing_dir(&ev, c, e.t, &e.y, &fm);
        if den.is_nan() || den.abs() <= 1e-12 {
            return Err(Error::numerical_at(
                "integrate: segment event",
                e.t,
                format!(
                    "{} grazes a breakpoint (dθ/dt = {den:e}): the event \
                     time is not differentiable",
                    model.crossing_label(&ev, c)
                ),
            ));
        }
        for lane in e.s.chunks_mut(n) {
            let tau = -model.crossing_dir(&ev, c, e.t, &e.y, lane) / den;
            for k in 0..n {
                lane[k] += (fm[k] - fp[k]) * tau;
            }
        }
        Ok(())
    }

    /// After the switch at event `e` (sensitivities already jumped):
    /// whether a new leg must start. An event at the end time, or so close
    /// to it that no step fits (`≤ 1e-12 (1 + |t_end|)`), serves the
    /// remaining outputs from the event state instead.
    fn restart_or_finish(
        &mut self,
        e: &Event<M::Crossing>,
        observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
    ) -> Result<bool> {
        let times = &self.opts.times;
        if self.next >= times.len() {
            return Ok(false);
        }
        let t_end = times[times.len() - 1];
        if t_end - e.t > 1e-12 * (1.0 + t_end.abs()) {
            return Ok(true);
        }
        while self.next < times.len() {
            emit(times[self.next], &e.y, &e.s, observe)?;
            self.next += 1;
        }
        Ok(false)
    }
}

fn emit(
    t: f64,
    y: &[f64],
    sens: &[f64],
    observe: &mut impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
) -> Result<()> {
    if let Some(k) = y.iter().chain(sens).position(|v| !v.is_finite()) {
        return Err(Error::numerical_at(
            "integrate: state",
            t,
            format!("component {k} of the state/sensitivities is not finite"),
        ));
    }
    observe(t, y, sens)
}
