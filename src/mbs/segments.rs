//! Segment changes of piecewise-linear actuator laws (paper Eq. 32) as
//! integration events: the model's side of [`crate::integrate::OdeModel`]'s
//! events (the integrator locates roots, restarts legs and applies the
//! sensitivity jump; this file says where the roots are and which segment
//! follows).
//!
//! ## Method
//! Eq. 32 jumps at some breakpoints (0.01 N·m at θ = 3.08 rad, 0.045 N·m at
//! 3.02 rad) and changes slope at all of them. Picking the segment by the
//! value of θ inside the right-hand side makes `f` discontinuous in `y`:
//! the error controller then resolves the jump by rejecting and shrinking
//! steps (and a multistep method drops its order), with an error that the
//! local error estimate does not see. Instead, during one integration leg
//! every actuator keeps a *frozen* segment (its line extended past the
//! breakpoints, [`crate::mbs::Workspace::segments`]), so `f` is smooth.
//! Root functions `g = θ − b` for the two breakpoints bounding the current
//! segment are handed to diffsol, which locates a sign change on the dense
//! output of the accepted step (modified secant / Illinois iteration, time
//! tolerance `100 ε (|t| + |h|)`). At a genuine crossing the segment is
//! switched and the integrator restarted from `(t_e, y(t_e))`: no multistep
//! history and no Runge–Kutta stage crosses the discontinuity.
//!
//! A leg starts with θ on the breakpoint just crossed (within round-off,
//! on either side): that root function is offset by the round-off plus
//! `1e-14 (1 + |b|)` rad so that it starts strictly inside-signed, and an
//! immediate re-crossing still changes its sign. A sign change is
//! accepted as a segment change only if θ really leaves the segment there
//! (|θ − b| ≤ `1e-8 (1 + |b|)` and θ̇ pointing out of the segment): this
//! discards the jump of θ by 2π where the relative angle wraps at ±π.
//!
//! Limitation: a relative angle wrapping at ±π (a law whose θ range
//! leaves (−π, π]) is not an event; the frozen segment then continues
//! where evaluation by value would jump to the segment at −π.
//!
//! ## Sensitivities
//! With the switching surface `g(y(t_e), p) = 0`, the event time moves with
//! the parameters and the state sensitivities `s = ∂y/∂p` jump (Hiskens &
//! Pai, "Trajectory sensitivity analysis of hybrid systems", IEEE TCAS-I
//! 47(2), 2000, the switching-event case of their Eq. 13 family):
//! `dt_e/dp = −(g_y s⁻ + g_p)/(g_y f⁻)`, `s⁺ = s⁻ + (f⁻ − f⁺) dt_e/dp`,
//! with `f⁻`/`f⁺` the right-hand side with the old/new segment at the
//! event. Here `g = θ(y) − b` and the breakpoints `b` (the segments'
//! `lower`/`upper`) are not parameters: the anchor of [`super::Param::Anchor`]
//! and the slope of [`super::Param::Slope`] move the law's line, not its
//! interval, and damping, stiffness and mass
//! do not enter `g`. So `g_p = 0` for every [`super::Param`] (θ of a rigid joint
//! does not depend on a ply angle either), and `g_y v` is one dual-number
//! evaluation of θ at `y + ε v`.

use crate::mbs::model::{Force, PiecewiseLaw};
use crate::mbs::system::{BodyKin, System, Workspace};
use crate::mbs::watch::{Guard, RowWatch};
use num_dual::Dual64;

/// One actuator law whose segment can change.
#[derive(Debug, Clone)]
struct Switch {
    /// Index into the model's forces.
    force: usize,
    joint: usize,
    /// Breakpoints `b_0 < … < b_{m−1}` where the law changes segment.
    breaks: Vec<f64>,
    /// Segment of the law on interval `i`: `(b_{i−1}, b_i]` (with
    /// `b_{−1} = −∞`, `b_m = +∞`); `m + 1` entries.
    segs: Vec<usize>,
}

impl Switch {
    /// Interval index of `θ`.
    fn interval(&self, theta: f64) -> usize {
        self.breaks.partition_point(|&b| b < theta)
    }
}

/// Breakpoints and segments of a law: every finite `lower`/`upper` is a
/// candidate; [`PiecewiseLaw::segment_index`] is constant between
/// consecutive candidates, so adjacent intervals with the same segment are
/// merged (the outer bounds of the boundary segments are not events).
fn switch_of(force: usize, joint: usize, law: &PiecewiseLaw) -> Switch {
    let mut cand: Vec<f64> = law
        .segments
        .iter()
        .flat_map(|s| [s.lower, s.upper])
        .filter(|v| v.is_finite())
        .collect();
    cand.sort_by(f64::total_cmp);
    cand.dedup();
    // Segment on each candidate interval: at its upper end (included by
    // the `lower < θ ≤ upper` convention), and above the last candidate.
    let mut segs: Vec<usize> = cand.iter().map(|&b| law.segment_index(b)).collect();
    if let Some(&last) = cand.last() {
        segs.push(law.segment_index(last + 1.0 + last.abs()));
    } else {
        segs.push(0);
    }
    let mut breaks = Vec::new();
    let mut merged = vec![segs[0]];
    for (k, &b) in cand.iter().enumerate() {
        if segs[k + 1] != segs[k] {
            breaks.push(b);
            merged.push(segs[k + 1]);
        }
    }
    Switch {
        force,
        joint,
        breaks,
        segs: merged,
    }
}

/// The event state of a system: the switching actuators and the interval
/// each one is frozen in, the dropped constraint rows watched for drift
/// and the divergence guard ([`crate::mbs::watch`]). Root functions are
/// laid out in that order: two per switch (when segment events are
/// enabled), one per dropped row, one per guarded body.
#[derive(Debug, Clone)]
pub struct Events {
    switches: Vec<Switch>,
    /// Current interval of each switch.
    mode: Vec<usize>,
    /// Per switch, `[s_lo, s_hi] ≥ 0`: the root functions are
    /// `θ − b_lo + s_lo` and `θ − b_hi − s_hi`, so that they are strictly
    /// inside-signed at the start of a leg even when θ sits on (or, by
    /// round-off, just past) the breakpoint it has just crossed; otherwise
    /// a re-crossing during the first step would show no sign change.
    /// Non-zero only within `1e-8 (1 + |b|)` of a breakpoint.
    shift: Vec<[f64; 2]>,
    nforces: usize,
    /// Whether segment changes are events (otherwise the laws are
    /// evaluated by value and no root function of a segment is active).
    pub enabled: bool,
    /// The dropped constraint rows, watched for drift.
    rows: RowWatch,
    /// The divergence guard of the flexible bodies.
    guard: Guard,
}

/// An accepted event.
#[derive(Debug, Clone, Copy)]
pub enum Crossing {
    /// Switch `switch` enters interval `to` (a segment change).
    Segment {
        /// The switch (index into the switching actuators).
        switch: usize,
        /// Its new interval.
        to: usize,
    },
    /// Dropped constraint row `row` reached its bound: rows chosen anew.
    Row {
        /// The row (index into the model's constraint rows).
        row: usize,
    },
    /// Guarded body `k` passed the divergence bound: the run ends.
    Diverged {
        /// Index of the body among the guarded ones.
        k: usize,
    },
}

impl Events {
    /// The switching actuators of `sys` (laws with at least one breakpoint).
    pub fn new(sys: &System, enabled: bool) -> Events {
        let mut switches = Vec::new();
        for (fi, f) in sys.model.forces.iter().enumerate() {
            if let Force::Rotational {
                joint,
                law: Some(law),
                ..
            } = f
            {
                let sw = switch_of(fi, *joint, law);
                if !sw.breaks.is_empty() {
                    switches.push(sw);
                }
            }
        }
        let mode = vec![0; switches.len()];
        let shift = vec![[0.0; 2]; switches.len()];
        Events {
            switches,
            mode,
            shift,
            nforces: sys.model.forces.len(),
            enabled,
            rows: RowWatch::new(sys),
            guard: Guard::new(sys),
        }
    }

    /// The constraint rows left out of the solve now, for
    /// [`Workspace::drop`] (`None`: the system's set).
    pub fn dropped(&self) -> Option<Vec<bool>> {
        self.rows.mask()
    }

    /// Number of segment root functions.
    fn nseg(&self) -> usize {
        if self.active() {
            2 * self.switches.len()
        } else {
            0
        }
    }

    /// Whether root functions are active.
    pub fn active(&self) -> bool {
        self.enabled && !self.switches.is_empty()
    }

    /// Number of root functions handed to diffsol (two per switch, one
    /// per dropped row, one per guarded body; one constant function when
    /// there are none, as diffsol needs ≥ 1).
    pub fn nroots(&self) -> usize {
        (self.nseg() + self.rows.nroots() + self.guard.nroots()).max(1)
    }

    /// Freeze every switch in the interval of its current θ at `y`.
    pub fn start(&mut self, sys: &System, y: &[f64]) {
        let mut kin = Vec::new();
        sys.body_kin(y, &[], &mut kin);
        for (k, sw) in self.switches.iter().enumerate() {
            let (th, _) = sys.joint_angle(&kin, sw.joint);
            self.mode[k] = sw.interval(th);
        }
        for k in 0..self.switches.len() {
            self.set_shift(sys, k, &kin);
        }
    }

    /// Recompute `shift[k]` from θ at the kinematics `kin` (module doc of
    /// the field).
    fn set_shift(&mut self, sys: &System, k: usize, kin: &[BodyKin<f64>]) {
        let sw = &self.switches[k];
        let i = self.mode[k];
        let (th, _) = sys.joint_angle(kin, sw.joint);
        let near = |b: f64| (th - b).abs() <= 1e-8 * (1.0 + b.abs());
        let margin = |b: f64| 1e-14 * (1.0 + b.abs());
        let mut sh = [0.0; 2];
        if let Some(&b) = i.checked_sub(1).and_then(|j| sw.breaks.get(j)) {
            if near(b) {
                sh[0] = (b - th).max(0.0) + margin(b);
            }
        }
        if let Some(&b) = sw.breaks.get(i) {
            if near(b) {
                sh[1] = (th - b).max(0.0) + margin(b);
            }
        }
        self.shift[k] = sh;
    }

    /// Frozen segment per force for [`super::Workspace::segments`] (empty when
    /// events are off: segments by value).
    pub fn segments(&self) -> Vec<usize> {
        if !self.active() {
            return Vec::new();
        }
        let mut out = vec![usize::MAX; self.nforces];
        for (sw, &i) in self.switches.iter().zip(&self.mode) {
            out[sw.force] = sw.segs[i];
        }
        out
    }

    /// Root functions at `(t, y)`: the segments' (below), then the
    /// dropped rows' and the guard's ([`crate::mbs::watch`]); a constant 1
    /// when there are none. `kin` and `ws` are scratch.
    pub fn roots(
        &self,
        sys: &System,
        (t, y): (f64, &[f64]),
        (kin, ws): (&mut Vec<BodyKin<f64>>, &mut Workspace<f64>),
        g: &mut [f64],
    ) {
        g.fill(1.0);
        let (ns, nr) = (self.nseg(), self.rows.nroots());
        self.rows.roots(sys, t, y, ws, &mut g[ns..ns + nr]);
        self.guard.roots(y, &mut g[ns + nr..]);
        self.segment_roots(sys, y, kin, g);
    }

    /// Segment root functions at `y`: `θ_k − b_{i−1}` (> 0 inside) and
    /// `θ_k − b_i` (≤ 0 inside) for switch `k` in interval `i`; a constant
    /// ±1 where the interval is unbounded.
    fn segment_roots(&self, sys: &System, y: &[f64], kin: &mut Vec<BodyKin<f64>>, g: &mut [f64]) {
        if !self.active() {
            return;
        }
        sys.body_kin(y, &[], kin);
        for (k, (sw, &i)) in self.switches.iter().zip(&self.mode).enumerate() {
            let (th, _) = sys.joint_angle(kin, sw.joint);
            let [s_lo, s_hi] = self.shift[k];
            g[2 * k] = if i > 0 {
                th - sw.breaks[i - 1] + s_lo
            } else {
                1.0
            };
            g[2 * k + 1] = match sw.breaks.get(i) {
                Some(b) => th - b - s_hi,
                None => -1.0,
            };
        }
    }

    /// `g_y v` of every root function at `(t, y)` (exact, one dual
    /// evaluation of the joint angles, and of the dropped rows, at
    /// `y + ε v`).
    pub fn roots_jvp(&self, sys: &System, t: f64, y: &[f64], v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        let (ns, nr) = (self.nseg(), self.rows.nroots());
        self.rows.roots_dir(sys, t, y, v, &mut out[ns..ns + nr]);
        self.guard.roots_dir(y, v, &mut out[ns + nr..]);
        if !self.active() {
            return;
        }
        let yd: Vec<Dual64> = y.iter().zip(v).map(|(&a, &b)| Dual64::new(a, b)).collect();
        let mut kin = Vec::new();
        sys.body_kin(&yd, &[], &mut kin);
        for (k, sw) in self.switches.iter().enumerate() {
            let (th, _) = sys.joint_angle(&kin, sw.joint);
            out[2 * k] = if self.mode[k] > 0 { th.eps } else { 0.0 };
            out[2 * k + 1] = if self.mode[k] < sw.breaks.len() {
                th.eps
            } else {
                0.0
            };
        }
    }

    /// Whether the sign change of root `idx` at the state `y` is a genuine
    /// exit from the current segment: θ within `1e-8 (1 + |b|)` rad of the
    /// breakpoint (not a 2π wrap of the angle) and θ̇ pointing out of the
    /// interval (not the re-crossing of the breakpoint just passed).
    ///
    /// A dropped row's root is genuine when its violation has reached the
    /// bound, a guarded body's when its deflection bound has passed the
    /// limit.
    pub fn classify(&self, sys: &System, idx: usize, t: f64, y: &[f64]) -> Option<Crossing> {
        let (ns, nr) = (self.nseg(), self.rows.nroots());
        if idx >= ns + nr {
            let k = idx - ns - nr;
            return (k < self.guard.nroots() && self.guard.passed(k, y))
                .then_some(Crossing::Diverged { k });
        }
        if idx >= ns {
            let row = self.rows.row(idx - ns);
            return self
                .rows
                .reached(sys, row, t, y)
                .then_some(Crossing::Row { row });
        }
        if !self.active() || idx >= 2 * self.switches.len() {
            return None;
        }
        let (k, upper) = (idx / 2, idx % 2 == 1);
        let sw = &self.switches[k];
        let i = self.mode[k];
        let b = if upper {
            *sw.breaks.get(i)?
        } else {
            sw.breaks[i.checked_sub(1)?]
        };
        let mut kin = Vec::new();
        sys.body_kin(y, &[], &mut kin);
        let (th, thd) = sys.joint_angle(&kin, sw.joint);
        if (th - b).abs() > 1e-8 * (1.0 + b.abs()) {
            return None;
        }
        match (upper, thd) {
            (true, d) if d > 0.0 => Some(Crossing::Segment {
                switch: k,
                to: i + 1,
            }),
            (false, d) if d < 0.0 => Some(Crossing::Segment {
                switch: k,
                to: i - 1,
            }),
            _ => None,
        }
    }

    /// Switch to the segment after crossing `c` at `(t, y)`, or choose
    /// the dropped rows anew; a divergence changes nothing (the run ends,
    /// [`Events::halt`]).
    pub fn switch(&mut self, sys: &System, c: Crossing, t: f64, y: &[f64]) {
        match c {
            Crossing::Segment { switch, to } => {
                let mut kin = Vec::new();
                sys.body_kin(y, &[], &mut kin);
                self.mode[switch] = to;
                self.set_shift(sys, switch, &kin);
            }
            Crossing::Row { .. } => self.rows.rechoose(sys, t, y),
            Crossing::Diverged { .. } => {}
        }
    }

    /// `(place, message)` of the error that ends the run at crossing `c`
    /// at `y`: a guarded body passed the divergence bound.
    pub fn halt(&self, sys: &System, c: Crossing, y: &[f64]) -> Option<(String, String)> {
        match c {
            Crossing::Diverged { k } => Some((
                "simulate: divergence guard".to_string(),
                self.guard.message(sys, k, y),
            )),
            _ => None,
        }
    }

    /// `g_y v` of the root function of crossing `c` at `(t, y)` (θ of its
    /// joint, or the row, at `y + ε v`).
    pub fn crossing_dir(&self, sys: &System, c: Crossing, t: f64, y: &[f64], v: &[f64]) -> f64 {
        match c {
            Crossing::Segment { switch, .. } => {
                let yd: Vec<Dual64> = y.iter().zip(v).map(|(&a, &b)| Dual64::new(a, b)).collect();
                let mut kin = Vec::new();
                sys.body_kin(&yd, &[], &mut kin);
                sys.joint_angle(&kin, self.switches[switch].joint).0.eps
            }
            Crossing::Row { row } => self.rows.crossing_dir(sys, row, t, y, v),
            Crossing::Diverged { .. } => 0.0,
        }
    }

    /// What crossing `c` is, for messages: `actuator forces[3]` (its
    /// actuator's force index), `redundant row pin.x`, `divergence guard`.
    pub fn label(&self, sys: &System, c: Crossing) -> String {
        match c {
            Crossing::Segment { switch, .. } => {
                format!("actuator forces[{}]", self.switches[switch].force)
            }
            Crossing::Row { row } => format!(
                "redundant row {}",
                sys.model
                    .row_label(row)
                    .unwrap_or_else(|| format!("row {row}"))
            ),
            Crossing::Diverged { .. } => "divergence guard".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::Segment;

    fn seg(lower: f64, upper: f64, value: f64) -> Segment {
        Segment {
            lower,
            upper,
            value,
            slope: 0.0,
            anchor: 0.0,
        }
    }

    #[test]
    fn breakpoints_of_eq32_layout() {
        // The interval layout of Eq. 32 (docs/sar_reconstruction.md §5):
        // the outer bound 3.12 of the top segment is not a breakpoint (the
        // line extends).
        let law = PiecewiseLaw::new(
            "law",
            vec![
                seg(3.08, 3.12, 0.0),
                seg(3.02, 3.08, 0.0),
                seg(2.63, 3.02, 0.0),
                seg(0.2, 2.63, 0.0),
                seg(-0.2, 0.2, 0.0),
                seg(f64::NEG_INFINITY, -0.2, 0.0),
            ],
        )
        .unwrap();
        let sw = switch_of(0, 0, &law);
        assert_eq!(sw.breaks, vec![-0.2, 0.2, 2.63, 3.02, 3.08]);
        // Sorted by lower: index 0 is the (−∞, −0.2] segment.
        assert_eq!(sw.segs, vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(sw.interval(3.12), 5);
        assert_eq!(sw.interval(3.08), 4);
        assert_eq!(sw.segs[sw.interval(3.05)], law.segment_index(3.05));
        assert_eq!(sw.segs[sw.interval(-5.0)], law.segment_index(-5.0));
    }
}
