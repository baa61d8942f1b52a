//! The multibody [`System`] as an [`OdeModel`] for [`crate::integrate`]:
//! right-hand sides in `f64` and exact directional derivatives from one
//! dual-number evaluation of the same generic right-hand side, with the
//! Eq. 32 segment switching of [`super::segments`] as the model's events.

use super::dynamics::System;
use super::model::Param;
use super::segments::{Crossing, Events};
use super::workspace::{BodyKin, Workspace};
use crate::integrate::OdeModel;
use num_dual::Dual64;

/// Scratch of one integration: workspaces for `f64` and dual evaluations,
/// dual state buffers and body kinematics for the root functions.
pub struct SystemWork {
    ws: Workspace<f64>,
    wsd: Workspace<Dual64>,
    yd: Vec<Dual64>,
    dyd: Vec<Dual64>,
    kin: Vec<BodyKin<f64>>,
}

impl OdeModel for System {
    type Param = Param;
    type Work = SystemWork;
    type Events = Events;
    type Crossing = Crossing;

    fn work(&self, n: usize) -> SystemWork {
        SystemWork {
            ws: Workspace::empty(),
            wsd: Workspace::empty(),
            yd: vec![Dual64::from(0.0); n],
            dyd: vec![Dual64::from(0.0); n],
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
        w.wsd.params.clear();
        for (k, par) in names.iter().enumerate() {
            w.wsd
                .params
                .push((*par, Dual64::new(p[k], vp.map_or(0.0, |v| v[k]))));
        }
        for k in 0..y.len() {
            w.yd[k] = Dual64::new(y[k], vy.map_or(0.0, |v| v[k]));
        }
        self.rhs(t, &w.yd, &mut w.dyd, &mut w.wsd);
        for (o, d) in out.iter_mut().zip(&w.dyd) {
            *o = d.eps;
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
        w.wsd.segments = segs;
    }

    fn nroots(&self, ev: &Events) -> usize {
        ev.nroots()
    }

    fn roots(&self, ev: &Events, w: &mut SystemWork, y: &[f64], g: &mut [f64]) {
        ev.roots(self, y, &mut w.kin, g)
    }

    fn roots_dir(&self, ev: &Events, y: &[f64], v: &[f64], g: &mut [f64]) {
        ev.roots_jvp(self, y, v, g)
    }

    fn classify(&self, ev: &Events, idx: usize, y: &[f64]) -> Option<Crossing> {
        ev.classify(self, idx, y)
    }

    fn switch(&self, ev: &mut Events, c: Crossing, y: &[f64]) {
        ev.switch(self, c, y)
    }

    fn crossing_dir(&self, ev: &Events, c: Crossing, y: &[f64], v: &[f64]) -> f64 {
        ev.crossing_dir(self, c, y, v)
    }

    fn crossing_label(&self, ev: &Events, c: Crossing) -> String {
        format!("actuator forces[{}]", ev.force_of(c))
    }
}
