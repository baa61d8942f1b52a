//! The local (gradient-based) optimizers behind one interface.
//!
//! A [`LocalSolver`] runs from one start to one [`LocalOutcome`], handing
//! its iteration records to an [`Observer`]. The option sets of the argmin
//! solvers of this crate are local solvers themselves: [`MmfdOptions`]
//! runs [`super::mmfd::Mmfd`], [`SqpOptions`] runs [`super::sqp::Sqp`], so
//! a driver that holds a `&dyn LocalSolver` (the multistart, the front's
//! subproblems, the polish, a gradient check) runs whichever a study
//! names. A new argmin solver of this crate becomes a local solver with
//! one `impl` here; the study's name for it is given in
//! `crate::explore::local`.

use super::mmfd::{self, MmfdOptions};
use super::sqp::{self, SqpOptions};
use super::{LocalOutcome, Observer, Problem};
use crate::error::Result;

/// A local optimizer: one run from a start.
pub trait LocalSolver: Sync + Send {
    /// The name in tables (`mmfd`, `sqp`, ...).
    fn name(&self) -> &str;

    /// Minimize `problem` from `x0`; one record per iteration goes to
    /// `observer` (the start first).
    fn minimize(
        &self,
        problem: &dyn Problem,
        x0: &[f64],
        observer: &mut dyn Observer,
    ) -> Result<LocalOutcome>;
}

/// A closure `(problem, x0, observer) -> outcome` is a local solver too
/// (name `custom`): tests and callers with a one-off optimizer.
impl<F> LocalSolver for F
where
    F: Fn(&dyn Problem, &[f64], &mut dyn Observer) -> Result<LocalOutcome> + Sync + Send,
{
    fn name(&self) -> &str {
        "custom"
    }

    fn minimize(
        &self,
        problem: &dyn Problem,
        x0: &[f64],
        observer: &mut dyn Observer,
    ) -> Result<LocalOutcome> {
        self(problem, x0, observer)
    }
}

impl LocalSolver for MmfdOptions {
    fn name(&self) -> &str {
        "mmfd"
    }

    fn minimize(
        &self,
        problem: &dyn Problem,
        x0: &[f64],
        observer: &mut dyn Observer,
    ) -> Result<LocalOutcome> {
        mmfd::minimize(problem, x0, self, observer)
    }
}

impl LocalSolver for SqpOptions {
    fn name(&self) -> &str {
        "sqp"
    }

    fn minimize(
        &self,
        problem: &dyn Problem,
        x0: &[f64],
        observer: &mut dyn Observer,
    ) -> Result<LocalOutcome> {
        sqp::minimize(problem, x0, self, observer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::{testproblems, NoObserver};

    /// Through the trait object each solver gives exactly what its own
    /// `minimize` gives (HS 35 from its standard start).
    #[test]
    fn trait_objects_run_the_solvers_they_wrap() {
        let p = testproblems::hs35();
        let solvers: Vec<Box<dyn LocalSolver>> = vec![
            Box::new(MmfdOptions::dot()),
            Box::new(SqpOptions::default()),
        ];
        let direct = [
            mmfd::minimize(&p, &p.x0, &MmfdOptions::dot(), &mut NoObserver).unwrap(),
            sqp::minimize(&p, &p.x0, &SqpOptions::default(), &mut NoObserver).unwrap(),
        ];
        for (s, d) in solvers.iter().zip(&direct) {
            assert_eq!(
                &s.minimize(&p, &p.x0, &mut NoObserver).unwrap(),
                d,
                "{}",
                s.name()
            );
        }
        assert_eq!(solvers[0].name(), "mmfd");
        assert_eq!(solvers[1].name(), "sqp");
    }
}
