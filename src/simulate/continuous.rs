//! Responses read on the continuous solution: a peak, a crossing time
//! and an integral of outputs are located on the integrator's dense
//! output, step by step ([`crate::integrate::Step`]), not on the output
//! samples, so they do not depend on `dt_out`.
//!
//! - **Peak** (largest or smallest value, both forms): the response is
//!   evaluated at the ends and the middle of every accepted step. Each
//!   local extreme of that node sequence is refined by Brent's method on
//!   the step's interpolant over the node intervals beside it, then by one
//!   Newton step on `U̇ = 0` with central differences of the interpolant
//!   (`polish`). A step that ends rising is probed just before its end:
//!   falling there, the extreme is in its last interval and is refined
//!   while its interpolant is at hand; rising, it is in the next step or
//!   at the run's end. The run's ends count when the response falls away
//!   from them. The value and its
//!   gradient are taken at the refined time `t*` from the interpolated
//!   state and sensitivities: `dU*/dp = ∂U/∂y · s(t*) + ∂U/∂p`, the
//!   envelope theorem (`U̇(t*) = 0`, or `t*` an end of the run). All local
//!   extremes are kept, the extreme first ([`ResponseValue::critical`]).
//!   Between nodes a local extreme narrower than a quarter of a step can
//!   be missed; the steps resolve the motion to the integrator's
//!   tolerance, so such a feature is below that tolerance.
//! - **Crossing** of a level: the first node interval over which the
//!   response crosses the level in the asked direction brackets the root
//!   of the interpolant, found by bisection to the rounding of `t`;
//!   `dt*/dp = −(∂y/∂p)(t*) / ẏ(t*)` (implicit function theorem), with the
//!   slope `ẏ(t*)` a central difference of the interpolant over
//!   `10⁻⁶` of the step (error `O(10⁻¹² h²)` relative). A level not
//!   reached by the end gives the time extrapolated beyond it at the mean
//!   rate the level asks from the start (`CrossTrack::result`):
//!   continuous where the crossing leaves the run, so such a design is
//!   infeasible under a bound on the time, not a failed run.
//! - **Value at a time** of outputs: the interpolant of the step that
//!   holds the time, with the interpolated sensitivities (exact at any
//!   time, not only at an output time).
//! - **Final value** of outputs: the end state; the steps only carry the
//!   joint angles' unwrapping (a joint turning past ±π between two output
//!   times keeps its turns).
//! - **Integral** of outputs: three-point Gauss–Legendre quadrature of
//!   every step on its interpolant, with the gradient the same quadrature
//!   of the lanes; its error is that of the interpolant (the method's
//!   dense-output order), not the `O(Δt²)` of a trapezoidal rule on the
//!   output samples. (An integral of energies is an integrated state.)
//!
//! [`ResponseValue::critical`]: crate::mbs::responses::ResponseValue::critical

use super::sampled::{lanes_of, response_lanes};
use crate::error::Result;
use crate::integrate::Step;
use crate::mbs::responses::{Direction, ResponseKind, Sense};
use crate::mbs::series::{NoCrossing, Sample};
use crate::mbs::{Param, System};
use crate::scene::Response;

/// Node intervals per accepted step at which a peak or a crossing is
/// sought.
const NODES: usize = 2;

/// What a run leaves of each response read on the continuous solution.
#[derive(Debug, Default)]
pub struct Continuous {
    /// Per response of the scene: its tracker (None: not read here).
    tracks: Vec<Option<Track>>,
}

/// The reading of one response.
#[derive(Debug)]
enum Track {
    Peak(PeakTrack),
    Crossing(CrossTrack),
    Integral(Quadrature),
    /// A value at a time: the time, and the sample once read.
    At(f64, Option<Sample>, Vec<Option<f64>>),
    /// A final value of outputs: the angles' unwrapping at the last
    /// step's end.
    Final(Vec<Option<f64>>),
}

/// The result of a crossing: its time and gradient, or why there is none.
pub type CrossingResult = std::result::Result<(f64, Vec<f64>), NoCrossing>;

/// The response at one point: the scene, the system, the sensitivity
/// parameters and the state's length.
struct At<'a> {
    sys: &'a System,
    r: &'a Response,
    params: &'a [(String, Param)],
    n: usize,
}

impl At<'_> {
    /// The value of the response (no lanes) at `t` of `step`.
    fn value(&self, step: &Step<'_>, t: f64, unwrap: &mut [Option<f64>]) -> Result<f64> {
        let (y, _) = step.at(t)?;
        Ok(response_lanes(self.sys, self.r, &y, &[], unwrap).0)
    }

    /// The value and gradient (one per parameter) at `t` of `step`.
    fn sample(&self, step: &Step<'_>, t: f64, unwrap: &mut [Option<f64>]) -> Result<Sample> {
        let (y, s) = step.at(t)?;
        let lanes = lanes_of(self.params, &s, self.n);
        let (v, g) = response_lanes(self.sys, self.r, &y, &lanes, unwrap);
        Ok((t, v, g))
    }

    /// The response's values at the nodes of `step` (signed by `sign`);
    /// `first` is the value at the step's start when it is known (the
    /// previous step's end: the state is continuous there).
    fn nodes(
        &self,
        step: &Step<'_>,
        (sign, first): (f64, Option<f64>),
        unwrap: &mut [Option<f64>],
    ) -> Result<([f64; NODES + 1], [f64; NODES + 1])> {
        let (a, b) = step.span;
        let mut ts = [0.0; NODES + 1];
        let mut ws = [0.0; NODES + 1];
        for j in 0..=NODES {
            ts[j] = if j == NODES {
                b
            } else {
                a + (b - a) * j as f64 / NODES as f64
            };
            ws[j] = match first.filter(|_| j == 0) {
                Some(w) => w,
                None => sign * self.value(step, ts[j], unwrap)?,
            };
        }
        Ok((ts, ws))
    }
}

impl Continuous {
    /// Trackers for the responses of `responses` read here (peaks; the
    /// crossings, values at a time, final values and integrals of
    /// outputs).
    pub fn new(responses: &[Response]) -> Continuous {
        let tracks = responses
            .iter()
            .map(|r| {
                let unwrap = vec![None; r.outputs.len()];
                match r.kind {
                    ResponseKind::Peak { sense } => {
                        Some(Track::Peak(PeakTrack::new(sense, unwrap)))
                    }
                    ResponseKind::Crossing { level, direction } if !r.outputs.is_empty() => {
                        Some(Track::Crossing(CrossTrack::new(level, direction, unwrap)))
                    }
                    ResponseKind::Integral if !r.outputs.is_empty() => {
                        Some(Track::Integral(Quadrature::new(unwrap)))
                    }
                    ResponseKind::ValueAt { time } if !r.outputs.is_empty() => {
                        Some(Track::At(time, None, unwrap))
                    }
                    ResponseKind::Final if !r.outputs.is_empty() => Some(Track::Final(unwrap)),
                    _ => None,
                }
            })
            .collect();
        Continuous { tracks }
    }

    /// Advance every tracker over one accepted step; `params` are the
    /// scene's sensitivity parameters (the lanes of the step's
    /// sensitivities), `n` the state's length.
    pub fn step(
        &mut self,
        (sys, responses): (&System, &[Response]),
        (params, n): (&[(String, Param)], usize),
        step: &Step<'_>,
    ) -> Result<()> {
        for (track, r) in self.tracks.iter_mut().zip(responses) {
            let at = At { sys, r, params, n };
            match track {
                Some(Track::Peak(p)) => p.step(&at, step)?,
                Some(Track::Crossing(c)) => c.step(&at, step)?,
                Some(Track::Integral(q)) => q.step(&at, step)?,
                Some(Track::At(time, found, unwrap)) => {
                    let (t0, t1) = step.span;
                    if found.is_none() && *time >= t0 && *time <= t1 {
                        *found = Some(at.sample(step, *time, unwrap)?);
                    }
                    at.value(step, t1, unwrap)?;
                }
                Some(Track::Final(unwrap)) => {
                    at.value(step, step.span.1, unwrap)?;
                }
                None => {}
            }
        }
        Ok(())
    }

    /// The local extremes of peak response `k`, the extreme first (empty
    /// when no step was taken); `end` gives the response at the run's end
    /// with its gradient, asked for only when the response rises to it.
    pub fn extremes(&self, k: usize, end: impl FnOnce() -> Sample) -> Vec<Sample> {
        match &self.tracks[k] {
            Some(Track::Peak(p)) => p.extremes(p.rises_at_end.then(end)),
            _ => Vec::new(),
        }
    }

    /// The first crossing of crossing response `k`, or its time
    /// extrapolated beyond the run's end when the level is not reached
    /// (`CrossTrack::result`; `end` gives the response at the end).
    pub fn crossing(&self, k: usize, end: impl FnOnce() -> Sample) -> Option<CrossingResult> {
        match &self.tracks[k] {
            Some(Track::Crossing(c)) => Some(c.result(end)),
            _ => None,
        }
    }

    /// The value at a time of response `k` (None: the time is outside the
    /// run).
    pub fn value_at(&self, k: usize) -> Option<Sample> {
        match &self.tracks[k] {
            Some(Track::At(_, found, _)) => found.clone(),
            _ => None,
        }
    }

    /// Response `k` (a final value or a peak of outputs or of energies)
    /// at the end state `y` with its gradient along `lanes` (the angles
    /// unwrapped over the run's steps).
    pub fn final_value(
        &self,
        (sys, r, k): (&System, &Response, usize),
        y: &[f64],
        lanes: &[(&[f64], Param)],
    ) -> (f64, Vec<f64>) {
        let mut unwrap = match &self.tracks[k] {
            Some(Track::Final(u)) => u.clone(),
            Some(Track::Peak(p)) => p.unwrap.clone(),
            Some(Track::Crossing(c)) => c.unwrap.clone(),
            _ => vec![None; r.outputs.len()],
        };
        response_lanes(sys, r, y, lanes, &mut unwrap)
    }

    /// The integral of integral response `k` with its gradient.
    pub fn integral(&self, k: usize) -> Option<(f64, Vec<f64>)> {
        match &self.tracks[k] {
            Some(Track::Integral(q)) => q.total.clone(),
            _ => None,
        }
    }
}

/// A peak's tracker: the local extremes of `sign · U(t)` found so far.
#[derive(Debug)]
struct PeakTrack {
    /// +1 for the largest value, −1 for the smallest.
    sign: f64,
    /// The signed values at the last two nodes of the previous step (the
    /// one before its end, and its end).
    last: Option<(f64, f64)>,
    /// Whether the previous step ended rising after a local extreme
    /// already refined in it: its end is then no extreme.
    refined_before_end: bool,
    /// Whether the response rises (signed) at the last step's end: the
    /// end of the run is then a candidate.
    rises_at_end: bool,
    /// The refined local extremes (signed).
    found: Vec<Sample>,
    /// The response at the start of the run (a response constant over the
    /// run has no strict local extreme).
    start: Option<Sample>,
    /// The outputs' last values (angle unwrapping).
    unwrap: Vec<Option<f64>>,
}

impl PeakTrack {
    fn new(sense: Sense, unwrap: Vec<Option<f64>>) -> PeakTrack {
        let sign = match sense {
            Sense::Max => 1.0,
            Sense::Min => -1.0,
        };
        PeakTrack {
            sign,
            last: None,
            refined_before_end: false,
            rises_at_end: false,
            found: Vec::new(),
            start: None,
            unwrap,
        }
    }

    /// One step: every node that is a local extreme of the node sequence
    /// is refined over the node intervals beside it in this step. A step
    /// that ends rising is probed just before its end: falling there, the
    /// extreme lies in its last interval and is refined now (its
    /// interpolant is gone afterwards); rising, the next step holds it
    /// (its first node is then a local extreme of the sequence), or the
    /// run's end does.
    fn step(&mut self, at: &At<'_>, step: &Step<'_>) -> Result<()> {
        if self.start.is_none() {
            let s = at.sample(step, step.span.0, &mut self.unwrap.clone())?;
            self.start = Some(self.signed(s));
        }
        let first = self.last.map(|l| l.1);
        let (ts, ws) = at.nodes(step, (self.sign, first), &mut self.unwrap)?;
        for j in 0..NODES {
            let left = if j == 0 {
                self.last.map(|l| l.0)
            } else {
                Some(ws[j - 1])
            };
            if left.is_some_and(|l| l > ws[j]) || ws[j] <= ws[j + 1] {
                continue;
            }
            if j == 0 && self.refined_before_end {
                continue;
            }
            let lo = ts[j.saturating_sub(1)];
            let found = self.refine(at, step, (lo, ts[j + 1]))?;
            self.found.push(found);
        }
        let (a, b) = step.span;
        let (before, end) = (ws[NODES - 1], ws[NODES]);
        self.refined_before_end = false;
        self.rises_at_end = false;
        if end > before {
            let probe = b - 1e-6 * (b - a);
            let w = self.sign * at.value(step, probe, &mut self.unwrap.clone())?;
            if w > end {
                let found = self.refine(at, step, (ts[NODES - 1], b))?;
                self.found.push(found);
                self.refined_before_end = true;
            } else {
                self.rises_at_end = true;
            }
        }
        self.last = Some((before, end));
        Ok(())
    }

    /// The signed extreme of the response over `[lo, hi]` in `step`
    /// (Brent's method on the interpolant), with its gradient.
    fn refine(&self, at: &At<'_>, step: &Step<'_>, (lo, hi): (f64, f64)) -> Result<Sample> {
        let mut unwrap = self.unwrap.clone();
        let mut err = None;
        let sign = self.sign;
        let t = brent_max(
            |t| match at.value(step, t, &mut unwrap) {
                Ok(v) => sign * v,
                Err(e) => {
                    err.get_or_insert(e);
                    f64::NEG_INFINITY
                }
            },
            (lo, hi),
        );
        if let Some(e) = err {
            return Err(e);
        }
        let t = polish(|t| at.value(step, t, &mut self.unwrap.clone()), t, (lo, hi))?;
        let s = at.sample(step, t, &mut self.unwrap.clone())?;
        Ok(self.signed(s))
    }

    fn signed(&self, (t, v, g): Sample) -> Sample {
        (t, self.sign * v, g.iter().map(|x| self.sign * x).collect())
    }

    /// The local extremes in the response's own sign, the extreme first,
    /// then by decreasing (signed) value; `end` is the response at the
    /// run's end (a candidate when it rises to it).
    fn extremes(&self, end: Option<Sample>) -> Vec<Sample> {
        let mut all = self.found.clone();
        if self.rises_at_end {
            all.extend(end.map(|s| self.signed(s)));
        }
        if all.is_empty() {
            all.extend(self.start.clone());
        }
        all.sort_by(|a, b| b.1.total_cmp(&a.1));
        all.into_iter().map(|s| self.signed(s)).collect()
    }
}

/// A crossing's tracker: the first crossing of a level, once found.
#[derive(Debug)]
struct CrossTrack {
    level: f64,
    dir: Direction,
    /// The first crossing, once found.
    found: Option<CrossingResult>,
    /// The range of the response over the nodes so far.
    range: (f64, f64),
    /// The run's start time and the response's value there.
    first: Option<(f64, f64)>,
    unwrap: Vec<Option<f64>>,
}

impl CrossTrack {
    fn new(level: f64, dir: Direction, unwrap: Vec<Option<f64>>) -> CrossTrack {
        CrossTrack {
            level,
            dir,
            found: None,
            range: (f64::INFINITY, f64::NEG_INFINITY),
            first: None,
            unwrap,
        }
    }

    fn crosses(&self, a: f64, b: f64) -> bool {
        let up = a < self.level && b >= self.level;
        let down = a > self.level && b <= self.level;
        match self.dir {
            Direction::Up => up,
            Direction::Down => down,
            Direction::Either => up || down,
        }
    }

    fn step(&mut self, at: &At<'_>, step: &Step<'_>) -> Result<()> {
        if self.found.is_some() {
            return Ok(());
        }
        let (ts, vs) = at.nodes(step, (1.0, None), &mut self.unwrap)?;
        self.first.get_or_insert((ts[0], vs[0]));
        for v in vs {
            self.range = (self.range.0.min(v), self.range.1.max(v));
        }
        let Some(j) = (1..=NODES).find(|&j| self.crosses(vs[j - 1], vs[j])) else {
            return Ok(());
        };
        // Bisection on the interpolant between the bracketing nodes.
        let mut unwrap = self.unwrap.clone();
        let (mut a, mut b) = (ts[j - 1], ts[j]);
        let below = vs[j - 1] < self.level;
        if vs[j] == self.level {
            a = b;
        }
        while b - a > 4.0 * f64::EPSILON * b.abs().max(a.abs()).max(1e-300) {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            if (at.value(step, m, &mut unwrap)? < self.level) == below {
                a = m;
            } else {
                b = m;
            }
        }
        let t = if a == b { a } else { 0.5 * (a + b) };
        let (_, _, grad) = at.sample(step, t, &mut self.unwrap.clone())?;
        let (t0, t1) = step.span;
        let d = 1e-6 * (t1 - t0);
        let (lo, hi) = ((t - d).max(t0), (t + d).min(t1));
        let slope =
            (at.value(step, hi, &mut unwrap)? - at.value(step, lo, &mut unwrap)?) / (hi - lo);
        self.found = Some(if slope == 0.0 || !slope.is_finite() {
            Err(NoCrossing::Flat(t))
        } else {
            Ok((t, grad.iter().map(|g| -g / slope).collect()))
        });
        Ok(())
    }

    /// The first crossing; when the level is not reached by the end
    /// (`end`: time, value and gradient there) on the asked side, the
    /// crossing time extrapolated at the mean rate the level asks from
    /// the start, `r = |L − y(t₀)| / (t_end − t₀)` (held fixed):
    /// `t* = t_end + |L − y(t_end)| / r`, with `dt*/dp = ∓(∂y/∂p)(t_end)/r`.
    /// It is continuous where the crossing leaves the run (`t* → t_end`),
    /// so a design that does not reach the level is a value of the
    /// response, beyond `t_end` (a bound on it is then violated, the run
    /// is not failed).
    fn result(&self, end: impl FnOnce() -> Sample) -> CrossingResult {
        let never = Err(NoCrossing::Never(self.range.0, self.range.1));
        if let Some(found) = &self.found {
            return found.clone();
        }
        let Some((t0, v0)) = self.first else {
            return never;
        };
        let (t_end, v, g) = end();
        let short = match self.dir {
            Direction::Up => self.level - v,
            Direction::Down => v - self.level,
            Direction::Either => (self.level - v).abs(),
        };
        let rate = (self.level - v0).abs() / (t_end - t0);
        if !(short > 0.0 && rate > 0.0 && rate.is_finite()) {
            return never;
        }
        // ∂(short)/∂p = ∓ ∂y/∂p.
        let side = match self.dir {
            Direction::Up => -1.0,
            Direction::Down => 1.0,
            Direction::Either => -(self.level - v).signum(),
        };
        Ok((
            t_end + short / rate,
            g.iter().map(|gi| side * gi / rate).collect(),
        ))
    }
}

/// An integral's tracker: three-point Gauss–Legendre quadrature of every
/// step.
#[derive(Debug)]
struct Quadrature {
    total: Option<(f64, Vec<f64>)>,
    unwrap: Vec<Option<f64>>,
}

impl Quadrature {
    fn new(unwrap: Vec<Option<f64>>) -> Quadrature {
        Quadrature {
            total: None,
            unwrap,
        }
    }

    fn step(&mut self, at: &At<'_>, step: &Step<'_>) -> Result<()> {
        // Nodes ±√(3/5) and 0 on [−1, 1], weights 5/9, 8/9, 5/9.
        let x = (0.6f64).sqrt();
        let (a, b) = step.span;
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        for (xi, wi) in [(-x, 5.0 / 9.0), (0.0, 8.0 / 9.0), (x, 5.0 / 9.0)] {
            let (_, v, g) = at.sample(step, mid + half * xi, &mut self.unwrap)?;
            let (value, grad) = self.total.get_or_insert_with(|| (0.0, vec![0.0; g.len()]));
            *value += half * wi * v;
            for (acc, gi) in grad.iter_mut().zip(&g) {
                *acc += half * wi * gi;
            }
        }
        Ok(())
    }
}

/// One Newton step on `U̇(t) = 0` from Brent's `t` inside `(lo, hi)`,
/// with central differences of the interpolant over `d = 10⁻⁴ (hi − lo)`.
/// Brent's method compares values, so it locates a smooth extreme only
/// to `√(ε |U| / |Ü|)`, where `U` is flat; the gradient read there
/// (envelope theorem) is off by `∂U̇/∂p · δt`. The slope's rounding is
/// `ε |U| / d` instead, which puts `t*` about `10⁻⁴ (hi − lo)`-times
/// closer. An end of the interval, a step out of it or a slope that does
/// not turn keeps `t`.
fn polish(mut u: impl FnMut(f64) -> Result<f64>, t: f64, (lo, hi): (f64, f64)) -> Result<f64> {
    let d = 1e-4 * (hi - lo);
    if t - d <= lo || t + d >= hi {
        return Ok(t);
    }
    let (um, u0, up) = (u(t - d)?, u(t)?, u(t + d)?);
    let (slope, curvature) = ((up - um) / (2.0 * d), (up - 2.0 * u0 + um) / (d * d));
    if curvature == 0.0 || !curvature.is_finite() {
        return Ok(t);
    }
    let next = t - slope / curvature;
    Ok(if (next - t).abs() <= d && next > lo && next < hi {
        next
    } else {
        t
    })
}

/// The maximizer of `f` over `[a, b]` by Brent's method (golden-section
/// steps, parabolic steps where they are safe), to a time tolerance of
/// `10⁻⁹ (b − a)` plus the rounding of `t`; an end of the interval when
/// `f` is monotone over it (to that tolerance).
fn brent_max(mut f: impl FnMut(f64) -> f64, (a, b): (f64, f64)) -> f64 {
    let golden = 0.5 * (3.0 - 5f64.sqrt());
    let (mut lo, mut hi) = (a, b);
    let mut x = lo + golden * (hi - lo);
    let (mut w, mut v) = (x, x);
    let mut fx = -f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..100 {
        let m = 0.5 * (lo + hi);
        let tol = 1e-9 * (b - a) + 4.0 * f64::EPSILON * x.abs();
        if (x - m).abs() <= 2.0 * tol - 0.5 * (hi - lo) {
            break;
        }
        let mut golden_step = true;
        if e.abs() > tol {
            // A parabola through x, w, v.
            let r = (x - w) * (fx - fv);
            let q0 = (x - v) * (fx - fw);
            let mut p = (x - v) * q0 - (x - w) * r;
            let mut q = 2.0 * (q0 - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            if p.abs() < (0.5 * q * e).abs() && p > q * (lo - x) && p < q * (hi - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - lo < 2.0 * tol || hi - u < 2.0 * tol {
                    d = if x < m { tol } else { -tol };
                }
                golden_step = false;
            }
        }
        if golden_step {
            e = if x < m { hi - x } else { lo - x };
            d = golden * e;
        }
        let u = if d.abs() >= tol {
            x + d
        } else {
            x + tol.copysign(d)
        };
        let fu = -f(u);
        if fu <= fx {
            if u < x {
                hi = x;
            } else {
                lo = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                lo = u;
            } else {
                hi = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    // A monotone f: the better end.
    let (fa, fb) = (-f(a), -f(b));
    if fa < fx && fa <= fb {
        a
    } else if fb < fx {
        b
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::brent_max;

    #[test]
    fn brent_finds_an_interior_maximum_and_a_monotone_end() {
        // −(t − 0.3)² + 1 peaks at 0.3 (closed form).
        let t = brent_max(|t| 1.0 - (t - 0.3) * (t - 0.3), (0.0, 1.0));
        assert!((t - 0.3).abs() < 1e-8, "{t}");
        // sin t on [0, π/2 − 0.1] rises: its maximum is the right end.
        let b = std::f64::consts::FRAC_PI_2 - 0.1;
        assert_eq!(brent_max(f64::sin, (0.0, b)), b);
        assert_eq!(brent_max(|t| -t, (2.0, 3.0)), 2.0);
        // cos on [2, 5] is smallest at π: its negation peaks there.
        let t = brent_max(|t| -t.cos(), (2.0, 5.0));
        assert!((t - std::f64::consts::PI).abs() < 1e-8, "{t}");
    }
}
