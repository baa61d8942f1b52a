//! [`Stepper`]: what the legs (`super::legs`) ask of a solver, so that
//! diffsol's solvers ([`Diffsol`]) and the explicit pairs stepped here
//! (`super::erk`) are driven by the same loop.

use super::options::Stats;
use diffsol::{FaerVec, OdeEquations, OdeSolverMethod, OdeSolverStopReason, Vector};
use std::marker::PhantomData;

/// A solver stepping one leg: its errors are messages (the legs place them).
pub(super) trait Stepper {
    /// The time reached (the last accepted step's end).
    fn time(&self) -> f64;
    /// The state at [`Stepper::time`].
    fn state(&self) -> Vec<f64>;
    /// End the integration exactly at `t`.
    fn set_stop_time(&mut self, t: f64) -> Result<(), String>;
    /// One accepted step.
    fn step(&mut self) -> Result<OdeSolverStopReason<f64>, String>;
    /// The dense output at `t` in the last accepted step.
    fn interpolate(&self, t: f64) -> Result<Vec<f64>, String>;
    /// The forward sensitivities (lane-major) at `t` in the last accepted
    /// step, for solvers that integrate them apart from the state.
    fn interpolate_sens(&self, t: f64) -> Result<Vec<f64>, String>;
    /// The counters of the leg so far (steps, Jacobians, failures).
    fn stats(&self) -> Stats;
}

/// The solver's lifetime and equations, which a [`Diffsol`] only names.
type Names<'a, Eqn> = PhantomData<(&'a (), fn() -> Eqn)>;

/// A diffsol solver as a [`Stepper`].
pub(super) struct Diffsol<'a, Eqn, S>(S, Names<'a, Eqn>);

impl<'a, Eqn, S> Diffsol<'a, Eqn, S>
where
    Eqn: OdeEquations<T = f64, V = FaerVec<f64>> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    pub(super) fn new(solver: S) -> Self {
        Diffsol(solver, PhantomData)
    }
}

impl<'a, Eqn, S> Stepper for Diffsol<'a, Eqn, S>
where
    Eqn: OdeEquations<T = f64, V = FaerVec<f64>> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    fn time(&self) -> f64 {
        self.0.state().t
    }

    fn state(&self) -> Vec<f64> {
        self.0.state().y.clone_as_vec()
    }

    fn set_stop_time(&mut self, t: f64) -> Result<(), String> {
        self.0.set_stop_time(t).map_err(|e| e.to_string())
    }

    fn step(&mut self) -> Result<OdeSolverStopReason<f64>, String> {
        self.0.step().map_err(|e| e.to_string())
    }

    fn interpolate(&self, t: f64) -> Result<Vec<f64>, String> {
        self.0
            .interpolate(t)
            .map(|y| y.clone_as_vec())
            .map_err(|e| e.to_string())
    }

    fn interpolate_sens(&self, t: f64) -> Result<Vec<f64>, String> {
        self.0
            .interpolate_sens(t)
            .map(|s| s.clone_as_vec())
            .map_err(|e| e.to_string())
    }

    fn stats(&self) -> Stats {
        let st = self.0.get_statistics();
        Stats {
            steps: st.number_of_steps,
            jacobians: st.number_of_linear_solver_setups,
            error_test_failures: st.number_of_error_test_failures,
            nonlinear_iterations: st.number_of_nonlinear_solver_iterations,
            nonlinear_failures: st.number_of_nonlinear_solver_fails,
            ..Stats::default()
        }
    }
}
