//! Time integration of an ODE system given by the [`OdeModel`] trait, with
//! `diffsol`. The integrator knows nothing of multibody dynamics: the
//! multibody system implements the trait in `crate::mbs::ode`.
//!
//! The paper (§3.1) integrates with a variable-step, variable-order
//! multistep method; diffsol's variable-order BDF ([`Method::Bdf`], the
//! default) is that family. The explicit Tsitouras 5(4) pair
//! ([`Method::Tsit45`]) and the ESDIRK 3(4) method ([`Method::Esdirk34`])
//! are selectable for comparison, and Verner's explicit 6(5) pair
//! ([`Method::Vern65`]), which has more stages than diffsol's explicit
//! solver holds, is stepped by this module's own driver (`erk`). Implicit methods need Jacobian-vector
//! products `J v`; they are exact, from one evaluation of the generic
//! right-hand side on `num_dual::Dual64` numbers `y + ε v`.
//!
//! Output is dense: the solver steps freely and the state is interpolated
//! at the requested times, handed to an observer.
//!
//! ## Events
//! A piecewise-smooth model (the Eq. 32 actuator laws of the multibody
//! system) describes its pieces as events through the trait: during one
//! integration leg every piece is frozen ([`OdeModel::freeze`]), so the
//! right-hand side is smooth; the model's root functions
//! ([`OdeModel::roots`]) are handed to diffsol, which locates a sign
//! change on the dense output of the accepted step; the model says whether
//! it is a genuine crossing ([`OdeModel::classify`]) and switches the piece
//! ([`OdeModel::switch`]); a fresh solver restarts from `(t_e, y(t_e))`, so
//! no multistep history and no Runge–Kutta stage crosses the
//! discontinuity. [`Options::events`] switches this off (the model then
//! picks its pieces by value).
//!
//! With the switching surface `g(y(t_e), p) = 0` the event time moves with
//! the parameters and the state sensitivities `s = ∂y/∂p` jump (Hiskens &
//! Pai, "Trajectory sensitivity analysis of hybrid systems", IEEE TCAS-I
//! 47(2), 2000, the switching-event case of their Eq. 13 family):
//! `dt_e/dp = −(g_y s⁻ + g_p)/(g_y f⁻)`, `s⁺ = s⁻ + (f⁻ − f⁺) dt_e/dp`,
//! with `f⁻`/`f⁺` the right-hand side with the old/new piece at the event.
//! The trait's switching surfaces do not depend on the parameters
//! (`g_p = 0`), and `g_y v` is [`OdeModel::crossing_dir`].

mod block_lu;
mod erk;
#[cfg(test)]
mod erk_tests;
mod fused;
mod legs;
mod ode;
mod options;
mod pair;
#[cfg(test)]
mod pair_tests;
mod plain;
mod sens;
mod step;
mod stepper;
#[cfg(test)]
mod tests;

pub use ode::OdeModel;
pub use options::{Method, Options, SensitivityForm, Stats};
pub use plain::{integrate, integrate_stepped};
pub use sens::{integrate_sens, integrate_sens_stepped};
pub use step::{DenseState, Step, StepWatch};
