//! The fast-rotation warning of `plyscape simulate`.
//!
//! A linear floating frame without geometric stiffening loses the
//! centrifugal stiffening of a spinning body: its bending frequencies
//! drop as the spin rate grows (`ω_j² − Ω²` for a beam spun about an axis
//! normal to its bending plane) and the deflection grows without bound
//! once `Ω` passes the first one (Kane, Ryan & Banerjee, J. Guidance
//! 10(2), 1987). Already at `Ω = 0.3 ω_1` the first frequency is off by
//! about 5 % (`1 − √(1 − 0.09)`).
//!
//! So each flexible body of a scene *without* the `geometric_stiffening`
//! effect is watched at the output times: the first time the magnitude of
//! its frame's angular velocity `|ω|` (rad/s) exceeds `c · ω_1`, with
//! `c` the scene's `spin_warning_fraction` (default [`SPIN_FRACTION`]) and `ω_1 = √λ_1` the lowest nonzero
//! eigenvalue of its modal basis (the first bending frequency of the
//! basis as built: free or constrained, in rad/s), one warning names the
//! body, the time, `|ω|` and `ω_1`. A body warns once per run; scenes
//! with the effect never warn.

use crate::mbs::system::BodyKin;
use crate::mbs::System;

pub use crate::mbs::model::SPIN_WARNING_FRACTION as SPIN_FRACTION;

/// One flexible body under watch.
#[derive(Debug, Clone)]
struct Spinning {
    /// State slot of the body.
    slot: usize,
    /// Its first nonzero modal frequency `ω_1` (rad/s).
    omega1: f64,
    /// Whether it has warned already.
    warned: bool,
}

/// The fast-rotation watch of a system's flexible bodies (module doc).
#[derive(Debug, Clone)]
pub struct SpinWatch {
    bodies: Vec<Spinning>,
    /// The fraction `c` of the module doc.
    fraction: f64,
    kin: Vec<BodyKin<f64>>,
    /// The warnings so far, in the order they were raised.
    pub warnings: Vec<String>,
}

impl SpinWatch {
    /// Watch every moving flexible body of `sys` (none when the model has
    /// the geometric stiffening effect).
    pub fn new(sys: &System) -> SpinWatch {
        let mut bodies = Vec::new();
        if !sys.model.geometric_stiffening {
            for (slot, &b) in sys.moving.iter().enumerate() {
                let Some(flex) = &sys.model.bodies[b].flex else {
                    continue;
                };
                let lowest = flex
                    .basis
                    .eigenvalues
                    .iter()
                    .copied()
                    .filter(|&l| l > 0.0)
                    .fold(f64::INFINITY, f64::min);
                if lowest.is_finite() && sys.modes[slot] > 0 {
                    bodies.push(Spinning {
                        slot,
                        omega1: lowest.sqrt(),
                        warned: false,
                    });
                }
            }
        }
        SpinWatch {
            bodies,
            fraction: sys.model.spin_warning_fraction.unwrap_or(SPIN_FRACTION),
            kin: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// Check the state `y` at time `t`; a body turning faster than the
    /// fraction of its first frequency for the first time adds its
    /// warning.
    pub fn observe(&mut self, sys: &System, t: f64, y: &[f64]) {
        if self.bodies.iter().all(|b| b.warned) {
            return;
        }
        sys.body_kin(y, &[], &mut self.kin);
        for b in self.bodies.iter_mut().filter(|b| !b.warned) {
            let w = self.kin[b.slot].w.norm();
            if w > self.fraction * b.omega1 {
                b.warned = true;
                self.warnings.push(format!(
                    "warning: body `{}` turns at |ω| = {w:.4} rad/s at t = {t:.4} s, above \
                     {} × its first modal frequency {:.4} rad/s, without the \
                     `geometric_stiffening` effect: its deflections are not reliable \
                     (add \"geometric_stiffening\" to [scene] effects)",
                    sys.model.bodies[sys.moving[b.slot]].name, self.fraction, b.omega1
                ));
            }
        }
    }
}
