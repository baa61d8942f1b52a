//! The evaluation journal: what lets a stage without tables of its own
//! (CMA-ES, `[discrete]`, `[front]`) continue after a kill.
//!
//! A stage's evaluations are appended to `journal/<stage>.log` in its
//! results directory as they finish, one line each, written whole by one
//! write: `f` or `g` (without or with gradients), the design, then every
//! value the evaluation returned, numbers in shortest round-trip form (so
//! a value read back has the same `f64` bits):
//!
//! ```text
//! {"journal":1,"stage":"evolve","scope":"","fingerprint":{...}}
//! f 1.25,-0.5;3.0625,-1.0
//! ```
//!
//! The stages are deterministic given the study's seed and the values of
//! their evaluations. So `run --resume` runs a stage again from its start
//! and serves every evaluation the journal holds from it: the stage
//! retraces its path (generation by generation for CMA-ES and NSGA-II,
//! subproblem by subproblem for the front, step by step for the discrete
//! searches) without simulating, and evaluates only from where the kill
//! stopped it. Its tables equal an uninterrupted run's; its manifest entry
//! counts the evaluations served from the journal (`replayed`).
//!
//! **What a resume trusts.** The header records the fingerprint of the
//! parts of the study an evaluation depends on
//! ([`Fingerprint::evaluation_only`]) and the stage's `scope` (the
//! front's objectives). A journal written for other evaluations is refused
//! (exit code 2) with what changed. The first and the last record are
//! evaluated again and must agree to [`fingerprint::RECHECK_RTOL`]
//! ([`fingerprint::agrees`]), which catches a change of the code. A
//! truncated last line (the kill came mid-write) is dropped, and an
//! evaluation that failed is not recorded: it fails again.
//!
//! Without `--resume` a stage starts a new journal. `plyscape run` removes
//! the journal folder once every section has finished ([`clear`]): the
//! committed results hold tables, not journals.

use super::fingerprint::{self, Fingerprint};
use crate::error::{Error, Result};
use crate::optimize::multiobjective::{piece_counts, MultiEvaluation, MultiProblem};
use crate::optimize::{Evaluation, Problem, Variable};
use crate::report::Progress;
use crate::study::Study;
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The journal format's version (first key of the header).
const VERSION: u32 = 1;

/// The folder of the journals in a results directory.
pub const FOLDER: &str = "journal";

/// A design's key: its bits and whether gradients were asked.
type Key = (Vec<u64>, bool);

/// The first line of a journal.
#[derive(Debug, Serialize, Deserialize)]
struct Header {
    journal: u32,
    stage: String,
    scope: String,
    fingerprint: Fingerprint,
}

/// One stage's journal: the records of an earlier run (on `--resume`) and
/// the file the new ones are appended to.
pub struct Journal {
    path: PathBuf,
    file: Mutex<std::fs::File>,
    earlier: HashMap<Key, Vec<f64>>,
    /// The earlier records the spot check evaluates again.
    checks: Vec<(Key, Vec<f64>)>,
    written: Mutex<HashSet<Key>>,
    replayed: AtomicUsize,
    /// The bar of the stage's current part ([`Journal::watch`]).
    progress: Mutex<Option<Progress>>,
}

impl Journal {
    /// Open `dir/journal/<stage>.log`: with `resume` keep and read an
    /// earlier journal (refused when its header is not this study's
    /// evaluations with this `scope`), else start a new one.
    pub fn open(study: &Study, dir: &Path, stage: &str, scope: &str, resume: bool) -> Result<Self> {
        let folder = dir.join(FOLDER);
        std::fs::create_dir_all(&folder).map_err(|e| Error::io(&folder, e))?;
        let path = folder.join(format!("{stage}.log"));
        let header = Header {
            journal: VERSION,
            stage: stage.into(),
            scope: scope.into(),
            fingerprint: Fingerprint::of_study(study).evaluation_only(),
        };
        let mut records = Vec::new();
        if resume && path.exists() {
            records = read(study, &path, &header)?;
        }
        let mut file = std::fs::File::create(&path).map_err(|e| Error::io(&path, e))?;
        let mut text = serde_json::to_string(&header)
            .map_err(|e| Error::io(&path, std::io::Error::other(e)))?
            + "\n";
        for (key, values) in &records {
            text += &line(key, values);
        }
        file.write_all(text.as_bytes())
            .map_err(|e| Error::io(&path, e))?;
        let checks = match records.len() {
            0 => vec![],
            1 => vec![records[0].clone()],
            n => vec![records[0].clone(), records[n - 1].clone()],
        };
        let written = records.iter().map(|(k, _)| k.clone()).collect();
        Ok(Journal {
            path,
            file: Mutex::new(file),
            earlier: records.into_iter().collect(),
            checks,
            written: Mutex::new(written),
            replayed: AtomicUsize::new(0),
            progress: Mutex::new(None),
        })
    }

    /// Count the stage's evaluations from now on on `bar` (one step per
    /// evaluation asked, served or run), finishing the bar before; `None`
    /// only finishes it.
    pub fn watch(&self, bar: Option<Progress>) {
        if let Ok(mut p) = self.progress.lock() {
            if let Some(old) = p.take() {
                old.finish();
            }
            *p = bar;
        }
    }

    fn tick(&self) {
        if let Ok(p) = self.progress.lock() {
            if let Some(p) = p.as_ref() {
                p.tick();
            }
        }
    }

    /// Evaluations served from the earlier run.
    pub fn replayed(&self) -> usize {
        self.replayed.load(Ordering::Relaxed)
    }

    /// Records read from the earlier run.
    pub fn earlier(&self) -> usize {
        self.earlier.len()
    }

    /// On stderr (unless `quiet`), after a resumed stage: how many of its
    /// evaluations the journal served.
    pub fn report(&self, stage: &str, quiet: bool) {
        if !quiet && !self.earlier.is_empty() {
            eprintln!(
                "{stage}: {} evaluations served from {} ({} recorded before the stop)",
                self.replayed(),
                self.path.display(),
                self.earlier.len()
            );
        }
    }

    fn lookup(&self, key: &Key) -> Option<&Vec<f64>> {
        let v = self.earlier.get(key)?;
        self.replayed.fetch_add(1, Ordering::Relaxed);
        Some(v)
    }

    fn record(&self, key: Key, values: &[f64]) -> Result<()> {
        let poisoned = || Error::numerical("explore::journal", "an evaluation thread panicked");
        if !self
            .written
            .lock()
            .map_err(|_| poisoned())?
            .insert(key.clone())
        {
            return Ok(());
        }
        let text = line(&key, values);
        let mut file = self.file.lock().map_err(|_| poisoned())?;
        file.write_all(text.as_bytes())
            .map_err(|e| Error::io(&self.path, e))
    }

    /// Evaluate the spot-check records again with `evaluate` and refuse a
    /// journal whose values are not reproduced.
    fn spot_check(&self, evaluate: impl Fn(&[f64], bool) -> Result<Vec<f64>>) -> Result<()> {
        for ((bits, gradients), stored) in &self.checks {
            let x: Vec<f64> = bits.iter().map(|&b| f64::from_bits(b)).collect();
            let now = evaluate(&x, *gradients)?;
            let same = now.len() == stored.len()
                && fingerprint::agrees(stored[0], &stored[1..], now[0], &now[1..]);
            if !same {
                return Err(Error::input(
                    "--resume",
                    self.path.display(),
                    format!(
                        "a journal this code reproduces, but at x = {x:?} it holds {:?} and the \
                         evaluation gives {:?}: the code or the journal changed; rerun without \
                         --resume",
                        &stored[..stored.len().min(4)],
                        &now[..now.len().min(4)]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A record's line: `f|g x0,x1,..;v0,v1,..` and a newline.
fn line((bits, gradients): &Key, values: &[f64]) -> String {
    let join = |v: &mut dyn Iterator<Item = f64>| {
        v.map(|x| format!("{x:?}")).collect::<Vec<_>>().join(",")
    };
    let x = join(&mut bits.iter().map(|&b| f64::from_bits(b)));
    let kind = if *gradients { 'g' } else { 'f' };
    format!("{kind} {x};{}\n", join(&mut values.iter().copied()))
}

/// Parse one record line (without its newline); `None` when malformed.
fn parse(text: &str) -> Option<(Key, Vec<f64>)> {
    let (kind, rest) = text.split_once(' ')?;
    let gradients = match kind {
        "f" => false,
        "g" => true,
        _ => return None,
    };
    let (x, v) = rest.split_once(';')?;
    let numbers =
        |s: &str| -> Option<Vec<f64>> { s.split(',').map(|t| t.parse::<f64>().ok()).collect() };
    let x = numbers(x)?;
    let v = numbers(v)?;
    Some(((x.iter().map(|v| v.to_bits()).collect(), gradients), v))
}

/// The records of the journal at `path`, checked against `now`'s header;
/// a last line without its newline (cut by a kill) is dropped.
fn read(study: &Study, path: &Path, now: &Header) -> Result<Vec<(Key, Vec<f64>)>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let complete = match text.rfind('\n') {
        Some(end) => &text[..end],
        None => return Ok(Vec::new()),
    };
    let mut lines = complete.lines();
    let bad = |what: String| {
        Error::input(
            "--resume",
            path.display(),
            format!("a journal written by plyscape ({what}); rerun without --resume"),
        )
    };
    let header: Header = lines
        .next()
        .and_then(|l| serde_json::from_str(l).ok())
        .ok_or_else(|| bad("its first line is not a journal header".into()))?;
    if (header.journal, &header.stage, &header.scope) != (now.journal, &now.stage, &now.scope) {
        return Err(bad(format!(
            "its header is for stage `{}` ({}), not `{}` ({})",
            header.stage, header.scope, now.stage, now.scope
        )));
    }
    let changed = now
        .fingerprint
        .differences(&header.fingerprint, None, &study.table);
    if !changed.is_empty() {
        return Err(Error::input(
            "--resume",
            path.display(),
            format!(
                "a journal of this study's evaluations, but since it was written: {}; rerun \
                 without --resume, or undo the change",
                changed.join(", ")
            ),
        )
        .in_file(&study.path, ""));
    }
    let mut out = Vec::new();
    for (k, l) in lines.enumerate() {
        out.push(parse(l).ok_or_else(|| bad(format!("line {} is not a record", k + 2)))?);
    }
    Ok(out)
}

/// Remove the journals of the results directory `dir` (every stage ran to
/// its end).
pub fn clear(dir: &Path) -> Result<()> {
    let folder = dir.join(FOLDER);
    match std::fs::remove_dir_all(&folder) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(Error::io(&folder, e)),
    }
}

/// An evaluation as the journal's values and back, given the design's
/// size `n`, the objectives `k` and the constraints `m`.
trait Values: Sized {
    fn values(&self) -> Vec<f64>;
    fn from_values(v: &[f64], gradients: bool, n: usize, km: (usize, usize)) -> Option<Self>;
}

/// `[f.., g.., (grad f rows.., grad g rows..)]` with `k` objectives.
fn split(v: &[f64], gradients: bool, n: usize, (k, m): (usize, usize)) -> Option<Parts> {
    let len = (k + m) * if gradients { 1 + n } else { 1 };
    if v.len() != len {
        return None;
    }
    let rows = |from: usize, count: usize| -> Vec<Vec<f64>> {
        (0..count)
            .map(|r| v[from + r * n..from + (r + 1) * n].to_vec())
            .collect()
    };
    let grads = gradients.then(|| (rows(k + m, k), rows(k + m + k * n, m)));
    Some((v[..k].to_vec(), v[k..k + m].to_vec(), grads))
}

/// Objectives, constraints and (gradients of both).
type Parts = (Vec<f64>, Vec<f64>, Option<(Vec<Vec<f64>>, Vec<Vec<f64>>)>);

/// `[f.., g..]`, then with the objectives' gradient rows `gf` also those
/// rows and the constraints' (`gg`; none for a problem without
/// constraints).
fn join(f: &[f64], g: &[f64], gf: Option<&[Vec<f64>]>, gg: Option<&[Vec<f64>]>) -> Vec<f64> {
    let mut v: Vec<f64> = f.iter().chain(g).copied().collect();
    if let Some(gf) = gf {
        v.extend(gf.iter().chain(gg.unwrap_or_default()).flatten());
    }
    v
}

impl Values for Evaluation {
    fn values(&self) -> Vec<f64> {
        let gf = self.grad_f.as_ref().map(std::slice::from_ref);
        join(&[self.f], &self.g, gf, self.grad_g.as_deref())
    }
    fn from_values(v: &[f64], gradients: bool, n: usize, km: (usize, usize)) -> Option<Self> {
        let (f, g, grads) = split(v, gradients, n, km)?;
        let (grad_f, grad_g) = match grads {
            Some((mut gf, gg)) => (gf.pop(), Some(gg)),
            None => (None, None),
        };
        Some(Evaluation {
            f: f[0],
            g,
            grad_f,
            grad_g,
        })
    }
}

/// The further pieces of objectives that are maxima are kept as more
/// objectives after `f` (`k` counts them); [`with_pieces`] moves them
/// back.
impl Values for MultiEvaluation {
    fn values(&self) -> Vec<f64> {
        let f: Vec<f64> = self.f.iter().chain(&self.pieces).copied().collect();
        let gf = self.grad_f.as_ref().map(|gf| {
            let mut rows = gf.clone();
            rows.extend(self.grad_pieces.iter().flatten().cloned());
            rows
        });
        join(&f, &self.g, gf.as_deref(), self.grad_g.as_deref())
    }
    fn from_values(v: &[f64], gradients: bool, n: usize, km: (usize, usize)) -> Option<Self> {
        let (f, g, grads) = split(v, gradients, n, km)?;
        let (grad_f, grad_g) = grads.map_or((None, None), |(a, b)| (Some(a), Some(b)));
        Some(MultiEvaluation::smooth((f, g), grad_f, grad_g))
    }
}

/// `e` with its objectives after the first `k` moved to its pieces (an
/// evaluation read back from the journal; one with `k` objectives is
/// returned as it is).
fn with_pieces(mut e: MultiEvaluation, k: usize) -> MultiEvaluation {
    if e.f.len() > k {
        e.pieces = e.f.split_off(k);
        e.grad_pieces = e.grad_f.as_mut().map(|rows| rows.split_off(k));
    }
    e
}

/// Serve `x` from the journal or evaluate it with `evaluate` and record it.
fn through<E: Values>(
    journal: &Journal,
    (x, gradients): (&[f64], bool),
    dims: (usize, (usize, usize)),
    evaluate: impl FnOnce() -> Result<E>,
) -> Result<E> {
    let key = (x.iter().map(|v| v.to_bits()).collect(), gradients);
    journal.tick();
    if let Some(v) = journal.lookup(&key) {
        let e = E::from_values(v, gradients, dims.0, dims.1);
        return e.ok_or_else(|| {
            Error::input(
                "--resume",
                journal.path.display(),
                format!(
                    "a record of {} values for this problem at x = {x:?}; rerun without --resume",
                    v.len()
                ),
            )
        });
    }
    let e = evaluate()?;
    journal.record(key, &e.values())?;
    Ok(e)
}

/// A problem whose evaluations go through a [`Journal`].
pub struct Journaled<'a> {
    inner: &'a dyn Problem,
    journal: &'a Journal,
}

impl<'a> Journaled<'a> {
    /// Wrap `inner`; on resume the journal's spot check runs first.
    pub fn new(inner: &'a dyn Problem, journal: &'a Journal) -> Result<Self> {
        journal.spot_check(|x, g| Ok(inner.evaluate(x, g)?.values()))?;
        Ok(Journaled { inner, journal })
    }
}

impl Problem for Journaled<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        let dims = (x.len(), (1, self.inner.n_constraints()));
        through(self.journal, (x, gradients), dims, || {
            self.inner.evaluate(x, gradients)
        })
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn objective_label(&self) -> String {
        self.inner.objective_label()
    }
    fn variable_label(&self, i: usize) -> String {
        self.inner.variable_label(i)
    }
    fn last_evaluated(&self) -> Option<Vec<f64>> {
        self.inner.last_evaluated()
    }
    fn tolerance(&self) -> Option<f64> {
        self.inner.tolerance()
    }
    fn notes(&self) -> Vec<String> {
        self.inner.notes()
    }
}

/// A multi-objective problem whose evaluations go through a [`Journal`].
pub struct JournaledMulti<'a> {
    inner: &'a dyn MultiProblem,
    journal: &'a Journal,
    /// Objectives and constraints.
    km: (usize, usize),
    /// The objectives' further pieces (journaled after the objectives).
    pieces: usize,
}

impl<'a> JournaledMulti<'a> {
    /// Wrap `inner`; on resume the journal's spot check runs first.
    pub fn new(inner: &'a dyn MultiProblem, journal: &'a Journal) -> Result<Self> {
        journal.spot_check(|x, g| Ok(inner.evaluate(x, g)?.values()))?;
        let pieces: usize = piece_counts(inner).iter().map(|k| k - 1).sum();
        let km = (inner.objective_names().len(), inner.n_constraints());
        Ok(JournaledMulti {
            inner,
            journal,
            km,
            pieces,
        })
    }
}

impl MultiProblem for JournaledMulti<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn objective_names(&self) -> Vec<String> {
        self.inner.objective_names()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<MultiEvaluation> {
        let (k, m) = self.km;
        let e = through(
            self.journal,
            (x, gradients),
            (x.len(), (k + self.pieces, m)),
            || self.inner.evaluate(x, gradients),
        )?;
        Ok(with_pieces(e, k))
    }
    fn objective_pieces(&self, i: usize) -> usize {
        self.inner.objective_pieces(i)
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn objective_label(&self, i: usize) -> String {
        self.inner.objective_label(i)
    }
    fn objective_unit(&self, i: usize) -> Option<String> {
        self.inner.objective_unit(i)
    }
    fn objective_scale(&self, i: usize) -> f64 {
        self.inner.objective_scale(i)
    }
    fn variable_label(&self, i: usize) -> String {
        self.inner.variable_label(i)
    }
    fn simulations(&self) -> Option<usize> {
        self.inner.simulations()
    }
    fn known_front(&self) -> Option<Vec<Vec<f64>>> {
        self.inner.known_front()
    }
    fn start(&self) -> Vec<f64> {
        self.inner.start()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::testproblems::hs21;

    fn study(text: &str) -> Study {
        Study::parse("k.toml", text).unwrap()
    }

    const STUDY: &str = "[study]\nname = \"k\"\n[problem]\nname = \"hs21\"\n";

    fn folder(tag: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("plyscape-journal-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn evaluations_come_back_with_their_bits_and_gradients() {
        let e = Evaluation {
            f: 0.1 + 0.2,
            g: vec![-0.0, 1e-300, f64::MAX],
            grad_f: Some(vec![1.0 / 3.0, -2.5]),
            grad_g: Some(vec![vec![1.0, 2.0], vec![3.0, 4.0], vec![5.0, 6.0]]),
        };
        let v = e.values();
        let ((bits, g), back) = parse(line(&(vec![1, 2], true), &v).trim_end()).unwrap();
        assert_eq!((bits, g), (vec![1, 2], true));
        let back = Evaluation::from_values(&back, true, 2, (1, 3)).unwrap();
        assert_eq!(back.f.to_bits(), e.f.to_bits());
        assert_eq!(back.g[0].to_bits(), (-0.0f64).to_bits());
        assert_eq!(back, e);
        let m = MultiEvaluation::smooth((vec![1.5, 2.5], vec![]), None, None);
        assert_eq!(
            MultiEvaluation::from_values(&m.values(), false, 3, (2, 0)),
            Some(m)
        );
        // Gradients without constraints (`grad_g` absent) keep their length.
        let free = Evaluation {
            f: 1.0,
            g: vec![],
            grad_f: Some(vec![2.0]),
            grad_g: None,
        };
        let back = Evaluation::from_values(&free.values(), true, 1, (1, 0)).unwrap();
        assert_eq!((back.grad_f, back.grad_g), (Some(vec![2.0]), Some(vec![])));
        // A record of the wrong length for the problem is not an evaluation.
        assert!(Evaluation::from_values(&[1.0, 2.0], false, 2, (1, 2)).is_none());
    }

    #[test]
    fn a_resumed_journal_serves_its_records_and_drops_a_cut_line() {
        let dir = folder("serve");
        let s = study(STUDY);
        let p = hs21();
        let x = [2.0, 1.5];
        {
            let j = Journal::open(&s, &dir, "evolve", "", false).unwrap();
            let q = Journaled::new(&p, &j).unwrap();
            q.evaluate(&x, true).unwrap();
            q.evaluate(&[3.0, 0.5], false).unwrap();
            assert_eq!(j.replayed(), 0);
        }
        let path = dir.join(FOLDER).join("evolve.log");
        // A kill mid-write leaves part of a line.
        let mut text = std::fs::read_to_string(&path).unwrap();
        text += "f 1.0,2";
        std::fs::write(&path, text).unwrap();
        let j = Journal::open(&s, &dir, "evolve", "", true).unwrap();
        assert_eq!(j.earlier(), 2);
        let q = Journaled::new(&p, &j).unwrap();
        assert_eq!(q.evaluate(&x, true).unwrap(), p.evaluate(&x, true).unwrap());
        // Without gradients the design was not recorded: evaluated now.
        q.evaluate(&x, false).unwrap();
        assert_eq!(j.replayed(), 1);
        // Without --resume the journal starts again.
        let j = Journal::open(&s, &dir, "evolve", "", false).unwrap();
        assert_eq!(j.earlier(), 0);
        clear(&dir).unwrap();
        assert!(!dir.join(FOLDER).exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_journal_of_other_evaluations_or_values_is_refused() {
        let dir = folder("refuse");
        let s = study(STUDY);
        let p = hs21();
        {
            let j = Journal::open(&s, &dir, "front", "f1,f2", false).unwrap();
            Journaled::new(&p, &j)
                .unwrap()
                .evaluate(&[2.0, 1.5], false)
                .unwrap();
        }
        // Another problem: refused with what changed.
        let other = study("[study]\nname = \"k\"\n[problem]\nname = \"hs35\"\n");
        let e = Journal::open(&other, &dir, "front", "f1,f2", true)
            .err()
            .unwrap();
        assert!(e.to_string().contains("problem changed"), "{e}");
        // Other objectives: refused.
        let e = Journal::open(&s, &dir, "front", "f2,f1", true)
            .err()
            .unwrap();
        assert!(e.to_string().contains("not `front` (f2,f1)"), "{e}");
        // A value edited in the journal: the spot check refuses it.
        let path = dir.join(FOLDER).join("front.log");
        let text = std::fs::read_to_string(&path).unwrap();
        let f = p.evaluate(&[2.0, 1.5], false).unwrap().f;
        std::fs::write(&path, text.replace(&format!(";{f:?},"), ";1.0,")).unwrap();
        let j = Journal::open(&s, &dir, "front", "f1,f2", true).unwrap();
        let e = Journaled::new(&p, &j).err().unwrap();
        assert!(
            e.to_string().contains("the code or the journal changed"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
