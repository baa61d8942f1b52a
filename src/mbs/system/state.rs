//! The assembled system: the model and the layout of its state vector,
//! with the evaluation counters and the helpers every layer above reads
//! (parameter values, design-seed comparison).
//!
//! State vector `y`: the positions of every moving body, then their
//! velocities, then the integrated states. Body `s` has positions
//! `[r, p, w]` (3 + 4 + n: frame origin, Euler parameters, modal
//! coordinates; `n = 0` for a rigid body) at [`System::pos_off`] and
//! velocities `v_s = [ṙ, ω', ẇ]` (3 + 3 + n) at [`System::vel_off`]. The
//! layers above add the methods: kinematics (`crate::mbs::kinematics`),
//! constraint rows and their solve (`crate::mbs::constraints`), applied
//! forces (`crate::mbs::forces`), the right-hand side
//! (`crate::mbs::dynamics`), outputs (`crate::mbs::post`).

use crate::mbs::math::{cst, Scalar};
use crate::mbs::model::{Model, Param};
use std::cell::Cell;

/// Count one evaluation in `c`.
pub(crate) fn bump(c: &Cell<u64>) {
    c.set(c.get() + 1);
}

/// Evaluation counters (what is not built is never evaluated).
#[derive(Debug, Default)]
pub struct Counters {
    /// Redundancy events: constraint rows chosen anew during an
    /// integration because a dropped row's violation reached its bound
    /// ([`crate::mbs::watch`]).
    pub row_events: Cell<u64>,
    /// Right-hand-side evaluations ([`System::rhs`](crate::mbs::System::rhs)).
    pub rhs: Cell<u64>,
    /// Gravity force evaluations.
    pub gravity: Cell<u64>,
    /// Rotational spring-damper-actuator (Eq. 32) evaluations.
    pub actuators: Cell<u64>,
    /// Linear and joint spring-damper evaluations.
    pub springs: Cell<u64>,
    /// Body and marker load evaluations.
    pub loads: Cell<u64>,
    /// Flexible-body mass matrices and elastic forces built.
    pub flexible: Cell<u64>,
    /// Quadratic-velocity terms evaluated (per body).
    pub quadratic: Cell<u64>,
    /// Modal damping forces evaluated (per flexible body).
    pub modal_damping: Cell<u64>,
    /// Back-substitutions of the joint-load prestress iteration
    /// (`crate::mbs::constraints::prestress`).
    pub prestress_iterations: Cell<u64>,
    /// The last evaluation whose prestress iteration did not converge:
    /// time (s) and what failed (bodies, last change), for the error of
    /// the run it ends.
    pub prestress_failure: std::cell::RefCell<Option<(f64, String)>>,
}

/// The assembled system: model + state layout.
#[derive(Debug)]
pub struct System {
    /// The model the state is laid out for.
    pub model: Model,
    /// Body index → state slot (None for fixed bodies).
    pub slot: Vec<Option<usize>>,
    /// Slot → body index.
    pub moving: Vec<usize>,
    /// Slot → number of modal coordinates (0 for rigid bodies).
    pub modes: Vec<usize>,
    pos: Vec<usize>,
    vel: Vec<usize>,
    npos: usize,
    nvel: usize,
    /// Constraint rows left out of the solve (their multipliers are zero):
    /// equations found redundant at the projected initial state.
    pub(crate) drop: Vec<bool>,
    /// Bound on the violation of a dropped row before the rows are chosen
    /// anew during an integration ([`crate::mbs::watch`], m or rad);
    /// `None`: dropped rows are not watched.
    pub row_bound: Option<f64>,
    /// Evaluation counters, bumped through `&self`.
    pub counters: Counters,
}

impl System {
    /// Lay out the state of `model`.
    pub fn new(model: Model) -> System {
        let mut slot = Vec::with_capacity(model.bodies.len());
        let mut moving = Vec::new();
        let mut modes = Vec::new();
        let (mut pos, mut vel) = (Vec::new(), Vec::new());
        let (mut npos, mut nvel) = (0, 0);
        for (k, b) in model.bodies.iter().enumerate() {
            if b.fixed {
                slot.push(None);
            } else {
                slot.push(Some(moving.len()));
                moving.push(k);
                let n = b.flex.as_ref().map_or(0, |f| f.n());
                modes.push(n);
                pos.push(npos);
                vel.push(nvel);
                npos += 7 + n;
                nvel += 6 + n;
            }
        }
        System {
            model,
            slot,
            moving,
            modes,
            pos,
            vel,
            npos,
            nvel,
            drop: Vec::new(),
            row_bound: None,
            counters: Counters::default(),
        }
    }

    /// Leave the constraint rows `rows` out of every later solve (their
    /// multipliers are set to zero). For equations that are redundant by
    /// the geometry of the mechanism (found by [`System::project`]): on
    /// the constraint manifold they are implied by the others, so the
    /// accelerations do not change, while off the manifold (trial states
    /// of an implicit integrator) their slightly inconsistent stabilisation
    /// terms no longer meet a near-zero pivot. Transient singularities
    /// are still handled by the regularisation.
    pub fn drop_rows(&mut self, rows: &[usize]) {
        for &r in rows {
            if self.drop.len() <= r {
                self.drop.resize(r + 1, false);
            }
            self.drop[r] = true;
        }
    }

    /// Watch the dropped rows during integrations: when one's violation
    /// reaches `bound` (m or rad), the rows are chosen anew
    /// ([`crate::mbs::watch`]).
    pub fn watch_rows(&mut self, bound: f64) {
        self.row_bound = Some(bound);
    }

    /// Number of constraint equations (rows) of the model's joints.
    pub fn equations(&self) -> usize {
        self.model.joints.iter().map(|j| j.kind.equations()).sum()
    }

    /// Whether constraint row `r` is left out of the solve.
    pub fn dropped(&self, r: usize) -> bool {
        self.drop.get(r).copied().unwrap_or(false)
    }

    /// Number of moving bodies.
    pub fn nb(&self) -> usize {
        self.moving.len()
    }
    /// State length (positions + velocities + integrals).
    pub fn nstates(&self) -> usize {
        self.npos + self.nvel + self.model.integrals.len()
    }
    /// Offset of the integral states ([`Model::integrals`](crate::mbs::Model)).
    pub fn integral_off(&self) -> usize {
        self.npos + self.nvel
    }
    /// Offset of the velocity part of the state.
    pub fn voff(&self) -> usize {
        self.npos
    }
    /// Number of generalized velocities.
    pub fn nvel(&self) -> usize {
        self.nvel
    }
    /// Offset of body slot `s`'s positions `[r, p, w]` in the state.
    pub fn pos_off(&self, s: usize) -> usize {
        self.pos[s]
    }
    /// Offset of body slot `s`'s velocities `[ṙ, ω', ẇ]` in the state.
    pub fn vel_off(&self, s: usize) -> usize {
        self.npos + self.vel[s]
    }
    /// Offset of slot `s` in the velocity vector.
    pub(crate) fn vel_local(&self, s: usize) -> usize {
        self.vel[s]
    }
    /// Generalized velocities of slot `s` (`6 + modes`).
    pub fn dof(&self, s: usize) -> usize {
        6 + self.modes[s]
    }

    /// Initial state from the bodies' initial pose and velocity (modal
    /// coordinates and rates zero: undeformed at rest relative to the
    /// frame).
    pub fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.nstates()];
        for (s, &b) in self.moving.iter().enumerate() {
            let body = &self.model.bodies[b];
            let p = self.pos_off(s);
            y[p..p + 3].copy_from_slice(body.r0.as_slice());
            y[p + 3..p + 7].copy_from_slice(&body.p0);
            let o = self.vel_off(s);
            y[o..o + 3].copy_from_slice(body.v0.as_slice());
            y[o + 3..o + 6].copy_from_slice(body.w0.as_slice());
        }
        y
    }
}

/// How many earlier lifts of the invariants and node shapes a workspace
/// keeps besides the current ones: the staggered sensitivities cycle
/// through one set of design seeds per lane plus the empty set (`J·s`), so
/// three cover two design variables and the empty set with one to spare.
pub(crate) const SEED_SPARES: usize = 3;

/// Whether two lists of design seeds `(variable, δ)` are the same, every
/// dual component compared (`PartialEq` of num-dual's numbers compares the
/// real parts alone, which are zero for every seed).
pub(crate) fn same_seeds<T: Scalar>(a: &[(usize, T)], b: &[(usize, T)]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|((i, x), (j, y))| i == j && (*x - *y).is_exact_zero())
}

/// The value of parameter `which`: the override in `params` if present,
/// else the model's `default`.
#[inline]
pub(crate) fn pval<T: Scalar>(params: &[(Param, T)], which: Param, default: f64) -> T {
    params
        .iter()
        .find(|(p, _)| *p == which)
        .map_or_else(|| cst::<T>(default), |(_, v)| *v)
}
