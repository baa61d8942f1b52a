//! The multibody [`System`] as an [`OdeModel`] for [`crate::integrate`]:
//! right-hand sides in `f64` and exact directional derivatives from one
//! dual-number evaluation of the same generic right-hand side, with the
//! Eq. 32 segment switching of [`super::segments`] as the model's events.
//!
//! Fused sensitivities ([`OdeModel::rhs_lanes`]) take one multi-lane
//! evaluation per stage: with `np` lanes the state is `y + Σ_i ε_i s_i`
//! and parameter `i` is `p_i + ε_i`, on num-dual's `Dual64` for one lane
//! and [`DualN<N>`] for 2, 4 or 8 (3–4 lanes in one 4-lane evaluation, 5–8
//! in one 8-lane evaluation, more in chunks of 8: the real part, the
//! factorizations of the constraint-space and mass solves and every
//! lane-independent product are paid once per evaluation, so one 8-lane
//! call costs less than two 4-lane ones; each lane's arithmetic is the
//! same whatever the width). The real part of the
//! result is `f` itself and dual part `i` is `J s_i + ∂f/∂p_i`, so no
//! separate `f64` evaluation is made; the real parts are computed by the
//! same operations as the `f64` right-hand side.

use super::segments::{Crossing, Events};
use crate::integrate::OdeModel;
use crate::mbs::math::{DualN, Scalar, MAX_LANES};
use crate::mbs::model::Param;
use crate::mbs::system::{BodyKin, System, Workspace};
use num_dual::Dual64;

/// Scratch of dual-number evaluations with `D`: workspace and state
/// buffers.
pub struct LaneWork<D: Scalar> {
    ws: Workspace<D>,
    y: Vec<D>,
    dy: Vec<D>,
}

impl<D: Scalar> LaneWork<D> {
    fn new(n: usize) -> LaneWork<D> {
        LaneWork {
            ws: Workspace::empty(),
            y: vec![D::from_parts(0.0, &vec![0.0; D::NL]); n],
            dy: vec![D::from_parts(0.0, &vec![0.0; D::NL]); n],
        }
    }
}

/// Scratch of one integration: workspaces for `f64` and dual evaluations
/// (one lane, and 2, 4 or 8 lanes for fused sensitivities), and body
/// kinematics for the root functions.
pub struct SystemWork {
    ws: Workspace<f64>,
    d1: LaneWork<Dual64>,
    d2: LaneWork<DualN<2>>,
    d4: LaneWork<DualN<4>>,
    d8: LaneWork<DualN<8>>,
    kin: Vec<BodyKin<f64>>,
}

impl System {
    /// One evaluation on `D` numbers of the lanes `first..first + k`
    /// (`k ≤ D::NL`, `k = lanes.len() / n`; padding lanes are zero): the
    /// value into `dy` (when asked) and dual part `l` into lane `first + l`
    /// of `dlanes`.
    #[allow(clippy::too_many_arguments)]
    fn eval_lanes<D: Scalar>(
        &self,
        lw: &mut LaneWork<D>,
        t: f64,
        y: &[f64],
        (names, p): (&[Param], &[f64]),
        (first, lanes): (usize, &[f64]),
        dy: Option<&mut [f64]>,
        dlanes: &mut [f64],
    ) {
        let n = y.len();
        let k = lanes.len() / n;
        let mut buf = [0.0f64; MAX_LANES];
        let buf = &mut buf[..D::NL];
        lw.ws.params.clear();
        for (j, par) in names.iter().enumerate() {
            buf.fill(0.0);
            if (first..first + k).contains(&j) {
                buf[j - first] = 1.0;
            }
            lw.ws.params.push((*par, D::from_parts(p[j], buf)));
        }
        for (c, yc) in y.iter().enumerate() {
            for (l, b) in buf.iter_mut().enumerate() {
                *b = if l < k { lanes[l * n + c] } else { 0.0 };
            }
            lw.y[c] = D::from_parts(*yc, buf);
        }
        self.rhs(t, &lw.y, &mut lw.dy, &mut lw.ws);
        if let Some(dy) = dy {
            for (o, d) in dy.iter_mut().zip(&lw.dy) {
                *o = d.re_part();
            }
        }
        for l in 0..k {
            let out = &mut dlanes[(first + l) * n..(first + l + 1) * n];
            for (o, d) in out.iter_mut().zip(&lw.dy) {
                *o = d.lane_part(l);
            }
        }
    }
}

impl OdeModel for System {
    type Param = Param;
    type Work = SystemWork;
    type Events = Events;
    type Crossing = Crossing;

    fn work(&self, n: usize) -> SystemWork {
        SystemWork {
            ws: Workspace::empty(),
            d1: LaneWork::new(n),
            d2: LaneWork::new(n),
            d4: LaneWork::new(n),
            d8: LaneWork::new(n),
            kin: Vec::new(),
        }
    }

    fn param_value(&self, p: Param) -> Option<f64> {
        p.value(&self.model)
    }

    fn rhs(
        &self,
        w: &mut SystemWork,
        t: f64,
        y: &[f64],
        params: (&[Param], &[f64]),
        dy: &mut [f64],
    ) {
        let (names, p) = params;
        w.ws.params.clear();
        w.ws.params
            .extend(names.iter().copied().zip(p.iter().copied()));
        self.rhs(t, y, dy, &mut w.ws);
    }

    fn rhs_dir(
        &self,
        w: &mut SystemWork,
        t: f64,
        y: &[f64],
        params: (&[Param], &[f64]),
        seeds: (Option<&[f64]>, Option<&[f64]>),
        out: &mut [f64],
    ) {
        let ((names, p), (vy, vp)) = (params, seeds);
        let d = &mut w.d1;
        d.ws.params.clear();
        for (k, par) in names.iter().enumerate() {
            d.ws.params
                .push((*par, Dual64::new(p[k], vp.map_or(0.0, |v| v[k]))));
        }
        for k in 0..y.len() {
            d.y[k] = Dual64::new(y[k], vy.map_or(0.0, |v| v[k]));
        }
        self.rhs(t, &d.y, &mut d.dy, &mut d.ws);
        for (o, d) in out.iter_mut().zip(&d.dy) {
            *o = d.eps;
        }
    }

    fn rhs_lanes(
        &self,
        w: &mut SystemWork,
        t: f64,
        y: &[f64],
        params: (&[Param], &[f64]),
        lanes: &[f64],
        dy: &mut [f64],
        dlanes: &mut [f64],
    ) -> usize {
        let n = y.len();
        let np = lanes.len() / n.max(1);
        match np {
            0 => {
                OdeModel::rhs(self, w, t, y, params, dy);
                0
            }
            1 => {
                self.eval_lanes(&mut w.d1, t, y, params, (0, lanes), Some(dy), dlanes);
                1
            }
            2 => {
                self.eval_lanes(&mut w.d2, t, y, params, (0, lanes), Some(dy), dlanes);
                1
            }
            3 | 4 => {
                self.eval_lanes(&mut w.d4, t, y, params, (0, lanes), Some(dy), dlanes);
                1
            }
            _ => {
                let mut dy = Some(dy);
                for (c, chunk) in lanes.chunks(8 * n).enumerate() {
                    let lanes = (8 * c, chunk);
                    self.eval_lanes(&mut w.d8, t, y, params, lanes, dy.take(), dlanes);
                }
                np.div_ceil(8)
            }
        }
    }

    fn events(&self, enabled: bool, y0: &[f64]) -> Events {
        let mut ev = Events::new(self, enabled);
        ev.start(self, y0);
        ev
    }

    fn freeze(&self, ev: &Events, w: &mut SystemWork) {
        let segs = ev.segments();
        w.ws.segments = segs.clone();
        w.d1.ws.segments = segs.clone();
        w.d2.ws.segments = segs.clone();
        w.d4.ws.segments = segs.clone();
        w.d8.ws.segments = segs;
        let drop = ev.dropped();
        w.ws.drop = drop.clone();
        w.d1.ws.drop = drop.clone();
        w.d2.ws.drop = drop.clone();
        w.d4.ws.drop = drop.clone();
        w.d8.ws.drop = drop;
    }

    fn nroots(&self, ev: &Events) -> usize {
        ev.nroots()
    }

    fn roots(&self, ev: &Events, w: &mut SystemWork, t: f64, y: &[f64], g: &mut [f64]) {
        ev.roots(self, (t, y), (&mut w.kin, &mut w.ws), g)
    }

    fn roots_dir(&self, ev: &Events, t: f64, y: &[f64], v: &[f64], g: &mut [f64]) {
        ev.roots_jvp(self, t, y, v, g)
    }

    fn classify(&self, ev: &Events, idx: usize, t: f64, y: &[f64]) -> Option<Crossing> {
        ev.classify(self, idx, t, y)
    }

    fn halt(&self, ev: &Events, c: Crossing, _t: f64, y: &[f64]) -> Option<(String, String)> {
        ev.halt(self, c, y)
    }

    fn switch(&self, ev: &mut Events, c: Crossing, t: f64, y: &[f64]) {
        ev.switch(self, c, t, y)
    }

    fn crossing_dir(&self, ev: &Events, c: Crossing, t: f64, y: &[f64], v: &[f64]) -> f64 {
        ev.crossing_dir(self, c, t, y, v)
    }

    fn crossing_label(&self, ev: &Events, c: Crossing) -> String {
        ev.label(self, c)
    }
}
