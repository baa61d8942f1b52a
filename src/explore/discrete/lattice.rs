//! The discrete sets of a study (`[discrete]`): each listed variable takes
//! values from a finite set, given as a list (`values`) or as a step from
//! the lower bound (`step`); a [`Lattice`] rounds designs to the sets and
//! names their neighbours, and [`OnSet`] evaluates a problem at the
//! rounded design through a [`Cache`] shared by the search methods.

use crate::error::{Error, Result};
use crate::optimize::{Evaluation, Problem, Variable};
use crate::study::Study;
use serde::Deserialize;
use std::collections::{HashMap, HashSet};
use std::sync::{Arc, Mutex, OnceLock};

/// The `[discrete]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscreteSection {
    /// The discrete variables (`[[discrete.variables]]`), by name; a
    /// variable not listed stays continuous.
    pub variables: Vec<DiscreteVariable>,
    /// Sample budget of the CMA-ES on the set (default 1000 designs asked
    /// for; repeats of a design already evaluated cost nothing).
    #[serde(default = "default_cmaes_samples")]
    pub cmaes_samples: usize,
    /// Lower bound of each discrete coordinate's standard deviation in
    /// the CMA-ES, in lattice steps (default 0.25).
    #[serde(default = "default_min_std")]
    pub min_std: f64,
    /// Enumerate every design when all variables are discrete and there
    /// are at most this many (default 4096).
    #[serde(default = "default_exhaustive_limit")]
    pub exhaustive_limit: usize,
}

fn default_cmaes_samples() -> usize {
    1000
}
fn default_min_std() -> f64 {
    0.25
}
fn default_exhaustive_limit() -> usize {
    4096
}

/// The most values one discrete variable may have (a `step` that would
/// give more is refused before anything runs).
pub const MAX_SET_SIZE: usize = 100_000;

/// One discrete variable: exactly one of `values` and `step`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscreteVariable {
    /// The problem variable's name.
    pub name: String,
    /// The allowed values, in the variable's units (distinct; within the
    /// bounds unless the variable is periodic, where they are distinct
    /// modulo the period).
    pub values: Option<Vec<f64>>,
    /// The allowed values `lower + k·step` within the bounds (a periodic
    /// variable: below `upper`, which is `lower` again).
    pub step: Option<f64>,
}

/// Read and check `[discrete]` without the problem (`None`: absent).
pub fn section(study: &Study) -> Result<Option<DiscreteSection>> {
    let Some(s) = study.section::<DiscreteSection>("discrete")? else {
        return Ok(None);
    };
    if s.variables.is_empty() {
        return Err(study.error(
            "discrete.variables",
            "[]",
            "at least one [[discrete.variables]] with name and values or step",
        ));
    }
    for (k, v) in s.variables.iter().enumerate() {
        if v.values.is_some() == v.step.is_some() {
            return Err(study.error(
                format!("discrete.variables[{k}]"),
                &v.name,
                "exactly one of `values = [...]` and `step = ...`",
            ));
        }
    }
    if !(s.min_std.is_finite() && s.min_std >= 0.0) {
        return Err(study.error("discrete.min_std", s.min_std, "a finite value >= 0"));
    }
    if s.cmaes_samples == 0 {
        return Err(study.error("discrete.cmaes_samples", 0, "a budget >= 1"));
    }
    Ok(Some(s))
}

/// The sets of a problem's variables: `None` for a continuous one, else
/// its members sorted ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct Lattice {
    vars: Vec<Variable>,
    sets: Vec<Option<Vec<f64>>>,
}

impl Lattice {
    /// The lattice of `section` over `vars`. Errors name
    /// `discrete.variables[k].<key>` (without the file).
    pub fn new(vars: &[Variable], section: &DiscreteSection) -> Result<Lattice> {
        let mut sets: Vec<Option<Vec<f64>>> = vec![None; vars.len()];
        for (k, d) in section.variables.iter().enumerate() {
            let key = |s: &str| format!("discrete.variables[{k}].{s}");
            let names: Vec<&str> = vars.iter().map(|v| v.name.as_str()).collect();
            let i = vars.iter().position(|v| v.name == d.name).ok_or_else(|| {
                Error::input(
                    key("name"),
                    format!("\"{}\"", d.name),
                    format!("a variable of the problem: {}", names.join(", ")),
                )
            })?;
            if sets[i].is_some() {
                return Err(Error::input(key("name"), &d.name, "each variable once"));
            }
            let v = &vars[i];
            let members = match (&d.values, d.step) {
                (Some(values), _) => {
                    for &x in values {
                        let inside = v.period.is_some() || (v.lower..=v.upper).contains(&x);
                        if !(x.is_finite() && inside) {
                            return Err(Error::input(
                                key("values"),
                                x,
                                format!("values within [{}, {}]", v.lower, v.upper),
                            ));
                        }
                    }
                    let mut m = values.clone();
                    m.sort_by(f64::total_cmp);
                    m
                }
                (None, Some(step)) => {
                    let range = v.upper - v.lower;
                    if !(step.is_finite() && step > 0.0 && step <= range) {
                        return Err(Error::input(
                            key("step"),
                            step,
                            format!("a step in (0, {range}]"),
                        ));
                    }
                    let count = range / step;
                    if count > MAX_SET_SIZE as f64 {
                        return Err(Error::input(
                            key("step"),
                            format!("{step:?}"),
                            format!(
                                "a step giving at most {MAX_SET_SIZE} values ({count:.3e} on \
                                 a range of {range})"
                            ),
                        ));
                    }
                    if v.period.is_some() && (count - count.round()).abs() > 1e-9 * count {
                        return Err(Error::input(
                            key("step"),
                            step,
                            format!(
                                "a step that divides the period {range} (it fits {count:.4} \
                                 times: the values would leave a gap of {:.4} at the wrap)",
                                range - count.floor() * step
                            ),
                        ));
                    }
                    let slack = 1e-9 * range;
                    (0..)
                        .map(|j| v.lower + j as f64 * step)
                        .take_while(|&x| match v.period {
                            Some(_) => x < v.upper - slack,
                            None => x <= v.upper + slack,
                        })
                        .map(|x| x.min(v.upper))
                        .collect()
                }
                (None, None) => unreachable!("checked by section()"),
            };
            let distinct = members
                .windows(2)
                .all(|w| v.difference(w[1], w[0]).abs() > 1e-12 * (v.upper - v.lower));
            let wraps = members.len() > 1
                && v.difference(members[0], members[members.len() - 1]).abs()
                    <= 1e-12 * (v.upper - v.lower);
            if members.is_empty() || !distinct || wraps {
                return Err(Error::input(
                    key(if d.step.is_some() { "step" } else { "values" }),
                    format!("{members:?}"),
                    "at least one value, all distinct (modulo the period of a periodic variable)",
                ));
            }
            sets[i] = Some(members);
        }
        Ok(Lattice {
            vars: vars.to_vec(),
            sets,
        })
    }

    /// The variables.
    pub fn variables(&self) -> &[Variable] {
        &self.vars
    }

    /// The set of variable `i` (`None`: continuous).
    pub fn set(&self, i: usize) -> Option<&[f64]> {
        self.sets[i].as_deref()
    }

    /// Are all variables discrete?
    pub fn all_discrete(&self) -> bool {
        self.sets.iter().all(Option::is_some)
    }

    /// Number of designs when all variables are discrete.
    pub fn size(&self) -> Option<usize> {
        self.sets
            .iter()
            .try_fold(1usize, |acc, s| acc.checked_mul(s.as_ref()?.len()))
    }

    /// Index of the member of set `i` nearest to `x` (on the circle for a
    /// periodic variable; ties go to the lower member).
    pub fn nearest(&self, i: usize, x: f64) -> Option<usize> {
        let v = &self.vars[i];
        let set = self.sets[i].as_ref()?;
        let dist = |m: f64| v.difference(x, m).abs();
        (0..set.len()).min_by(|&a, &b| dist(set[a]).total_cmp(&dist(set[b])))
    }

    /// `x` with every discrete coordinate moved to its nearest member.
    pub fn round(&self, x: &[f64]) -> Vec<f64> {
        (0..x.len())
            .map(|i| match self.nearest(i, x[i]) {
                Some(k) => self.sets[i].as_ref().expect("discrete")[k],
                None => x[i],
            })
            .collect()
    }

    /// Is `x` on the lattice (every discrete coordinate a member)?
    pub fn contains(&self, x: &[f64]) -> bool {
        (0..x.len()).all(|i| match &self.sets[i] {
            Some(set) => set.contains(&x[i]),
            None => true,
        })
    }

    /// The designs one set member away from `x` (on the lattice) in one
    /// discrete coordinate: the next lower and higher members, cyclic for a
    /// periodic variable, none beyond the ends otherwise.
    pub fn neighbours(&self, x: &[f64]) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        for i in 0..x.len() {
            let (Some(set), Some(k)) = (&self.sets[i], self.nearest(i, x[i])) else {
                continue;
            };
            let len = set.len();
            let periodic = self.vars[i].period.is_some();
            let mut js = Vec::new();
            if k > 0 {
                js.push(k - 1);
            } else if periodic && len > 2 {
                js.push(len - 1);
            }
            if k + 1 < len {
                js.push(k + 1);
            } else if periodic && len > 2 {
                js.push(0);
            }
            for j in js {
                let mut y = x.to_vec();
                y[i] = set[j];
                out.push(y);
            }
        }
        out
    }

    /// Every design of an all-discrete lattice, the first variable varying
    /// slowest (`None` when a variable is continuous).
    pub fn enumerate(&self) -> Option<Vec<Vec<f64>>> {
        let mut out = vec![Vec::new()];
        for set in &self.sets {
            let set = set.as_ref()?;
            out = out
                .into_iter()
                .flat_map(|p: Vec<f64>| {
                    set.iter().map(move |&v| {
                        let mut q = p.clone();
                        q.push(v);
                        q
                    })
                })
                .collect();
        }
        Some(out)
    }

    /// The mean spacing of set `i` as a fraction of the variable's range
    /// (a periodic set spans the period; a single member counts as the
    /// whole range); 0 for a continuous variable.
    pub fn step_fraction(&self, i: usize) -> f64 {
        let v = &self.vars[i];
        let range = v.upper - v.lower;
        match &self.sets[i] {
            None => 0.0,
            Some(set) if v.period.is_some() => 1.0 / set.len() as f64,
            Some(set) if set.len() > 1 => {
                (set[set.len() - 1] - set[0]) / (set.len() - 1) as f64 / range
            }
            Some(_) => 1.0,
        }
    }
}

/// The bit pattern of a design, as a map key.
fn key(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

type Slot = Arc<OnceLock<std::result::Result<Evaluation, String>>>;

/// Evaluations of designs on the lattice, shared by the methods: each
/// design is simulated once, whichever method asks first (a second thread
/// asking for the same design waits for the first one's result).
#[derive(Default)]
pub struct Cache {
    slots: Mutex<HashMap<Vec<u64>, Slot>>,
}

impl Cache {
    /// Designs simulated so far.
    pub fn len(&self) -> usize {
        self.slots.lock().expect("no panics").len()
    }

    /// Whether nothing was simulated yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// f and g of `problem` at `x` (without gradients), simulated once.
    pub fn evaluate(&self, problem: &dyn Problem, x: &[f64]) -> Result<Evaluation> {
        let slot = self
            .slots
            .lock()
            .expect("no panics")
            .entry(key(x))
            .or_default()
            .clone();
        slot.get_or_init(|| problem.evaluate(x, false).map_err(|e| e.to_string()))
            .clone()
            .map_err(|e| Error::numerical("explore::discrete", format!("at {x:?}: {e}")))
    }
}

/// A problem evaluated at the design rounded to the lattice, through the
/// shared [`Cache`]; it remembers which designs it asked for (one method's
/// cost, as if it ran alone).
pub struct OnSet<'a> {
    /// The problem.
    pub inner: &'a dyn Problem,
    /// The sets.
    pub lattice: &'a Lattice,
    /// The shared evaluations.
    pub cache: &'a Cache,
    visited: Mutex<HashSet<Vec<u64>>>,
    asked: std::sync::atomic::AtomicUsize,
}

impl<'a> OnSet<'a> {
    /// A view of `inner` on `lattice` with no design asked for yet.
    pub fn new(inner: &'a dyn Problem, lattice: &'a Lattice, cache: &'a Cache) -> Self {
        OnSet {
            inner,
            lattice,
            cache,
            visited: Mutex::new(HashSet::new()),
            asked: Default::default(),
        }
    }

    /// Distinct designs asked for (what this method alone would simulate).
    pub fn evaluations(&self) -> usize {
        self.visited.lock().expect("no panics").len()
    }

    /// Designs asked for, repeats included.
    pub fn samples(&self) -> usize {
        self.asked.load(std::sync::atomic::Ordering::Relaxed)
    }
}

impl Problem for OnSet<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        if gradients {
            return Err(Error::numerical(
                "explore::discrete",
                "a design on a discrete set has no gradient",
            ));
        }
        let xr = self.lattice.round(x);
        self.asked
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.visited.lock().expect("no panics").insert(key(&xr));
        self.cache.evaluate(self.inner, &xr)
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn angles() -> Vec<Variable> {
        vec![
            Variable::periodic("t1", -90.0, 180.0).unwrap(),
            Variable::bounded("x", 0.0, 1.0).unwrap(),
        ]
    }

    fn section(vars: Vec<DiscreteVariable>) -> DiscreteSection {
        DiscreteSection {
            variables: vars,
            cmaes_samples: 10,
            min_std: 0.25,
            exhaustive_limit: 100,
        }
    }

    fn var(name: &str, values: Option<Vec<f64>>, step: Option<f64>) -> DiscreteVariable {
        DiscreteVariable {
            name: name.into(),
            values,
            step,
        }
    }

    #[test]
    fn steps_round_on_the_circle_and_neighbours_wrap() {
        let l = Lattice::new(
            &angles(),
            &section(vec![
                var("t1", None, Some(15.0)),
                var("x", None, Some(0.25)),
            ]),
        )
        .unwrap();
        // 15° steps from −90 below 90 (≡ −90): 12 members; 0..1 by 0.25: 5.
        assert_eq!(l.set(0).unwrap().len(), 12);
        assert_eq!(l.set(1).unwrap(), [0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!(l.size(), Some(60));
        // 88° is 2° from 90 ≡ −90 on the circle, 13° from 75.
        assert_eq!(l.round(&[88.0, 0.9]), [-90.0, 1.0]);
        assert!(l.contains(&[-90.0, 1.0]) && !l.contains(&[-89.0, 1.0]));
        let n = l.neighbours(&[-90.0, 1.0]);
        assert_eq!(n, [vec![75.0, 1.0], vec![-75.0, 1.0], vec![-90.0, 0.75]]);
        assert_eq!(l.enumerate().unwrap().len(), 60);
        assert!((l.step_fraction(0) - 1.0 / 12.0).abs() < 1e-15);
        assert!((l.step_fraction(1) - 0.25).abs() < 1e-15);
    }

    #[test]
    fn bad_sets_are_refused_with_their_key() {
        let cases = [
            (var("t1", Some(vec![-90.0, 90.0]), None), "values"),
            (var("x", Some(vec![0.5, 1.5]), None), "values"),
            (var("x", None, Some(2.0)), "step"),
            (var("y", None, Some(0.5)), "name"),
            // 180/7 is no whole number: a 5° gap at the wrap.
            (var("t1", None, Some(7.0)), "step"),
            // 1.8e11 values.
            (var("t1", None, Some(1e-9)), "step"),
        ];
        for (v, key) in cases {
            let e = Lattice::new(&angles(), &section(vec![v]))
                .unwrap_err()
                .to_string();
            assert!(e.contains(&format!("discrete.variables[0].{key}")), "{e}");
        }
        // A continuous variable stays as it is.
        let l = Lattice::new(&angles(), &section(vec![var("x", None, Some(0.5))])).unwrap();
        assert_eq!(l.round(&[12.3, 0.3]), [12.3, 0.5]);
        assert!(!l.all_discrete() && l.enumerate().is_none());
    }
}
