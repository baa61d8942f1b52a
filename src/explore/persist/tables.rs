//! The tables of an exploration and how they reach the disk safely.
//!
//! - `runs.csv` is appended one complete line per finished run (one
//!   `write_all` plus flush), so killing the process leaves at worst a
//!   truncated last line. [`read_runs`] detects such a line (no final
//!   newline, or the wrong number of fields), cuts it off, says so on stderr
//!   and returns how many bytes it removed: a repaired file, never a silently
//!   kept half row.
//! - Final tables are written whole to a temporary file and renamed over the
//!   old one ([`write_atomic`]), so a reader sees the old or the new table.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a table
//! read back gives the same `f64` bits and a resumed or merged run writes
//! byte-identical tables. Missing values (failed run, no constraints) are
//! empty fields; no NaN is ever written.

use crate::error::{Error, Result};
use crate::optimize::kkt::{Certificate, EndClass};
use crate::optimize::Variable;
use crate::report::csv::read_csv_lines;
pub use crate::report::csv::{csv_line, num, write_atomic, write_bytes_atomic};
use std::path::Path;

/// The result of a run that did not fail.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// Final design.
    pub x: Vec<f64>,
    /// Objective there.
    pub f: f64,
    /// Constraints there.
    pub g: Vec<f64>,
}

impl RunResult {
    /// Largest constraint (`-inf` without constraints).
    pub fn max_g(&self) -> f64 {
        self.g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
}

/// One row of `runs.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Start index (position in the study's list of starts).
    pub start: usize,
    /// Start design.
    pub x0: Vec<f64>,
    /// `None` when the run failed (the reason is in `exit`).
    pub result: Option<RunResult>,
    /// Termination reason, or `error: ...`.
    pub exit: String,
    /// Iterations of the local solver.
    pub iterations: usize,
    /// Function evaluations of this run.
    pub function_calls: usize,
    /// Gradient evaluations of this run.
    pub gradient_calls: usize,
    /// Wall time of this run \[s\] (not reproducible; excluded from checks).
    pub wall_seconds: f64,
    /// Optimum id after clustering (empty while running; only certified
    /// runs belong to an optimum).
    pub optimum: Option<usize>,
    /// The Kuhn–Tucker certificate of the end design (`None`: the run
    /// failed, or its certificate could not be computed, said in `polish`).
    pub certificate: Option<Certificate>,
    /// How the polish from the solver's end stopped (its termination, or
    /// `error: ...`); empty when no polish ran.
    pub polish: String,
}

/// The class column of a row: the certificate's class, `failed` for a run
/// without result, `uncertified` for a result without certificate.
pub fn class_name(row: &RunRecord) -> &'static str {
    match (&row.result, &row.certificate) {
        (None, _) => "failed",
        (Some(_), None) => "uncertified",
        (Some(_), Some(c)) => c.class.name(),
    }
}

/// How the runs ended, by class (`runs.csv`'s `class` column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct ClassCounts {
    /// All runs in the tables.
    pub runs: usize,
    /// Certified optima: feasible, Kuhn–Tucker conditions met.
    pub converged: usize,
    /// Feasible but not stationary (stopped short, also after the polish).
    pub stopped: usize,
    /// Not feasible within the tolerance.
    pub infeasible: usize,
    /// Of the infeasible: at a stationary point of the violation (descent
    /// on the violation cannot reach the feasible set from there).
    pub infeasible_stationary: usize,
    /// Of the infeasible, the others whose restoration stalled (exit
    /// `infeasible`: no shortening of the restoration step lowered the
    /// violation, or three steps in a row lowered it by less than 1 %): a
    /// kink or a flat valley of the violation the gradient test cannot see.
    #[serde(default)]
    pub infeasible_stalled: usize,
    /// Failed runs (an error) and results whose certificate failed.
    pub failed: usize,
}

impl ClassCounts {
    /// Count the classes of `runs`.
    pub fn of(runs: &[RunRecord]) -> ClassCounts {
        let mut c = ClassCounts {
            runs: runs.len(),
            ..Default::default()
        };
        for r in runs {
            match class_name(r) {
                "converged" => c.converged += 1,
                "stopped" => c.stopped += 1,
                "infeasible" => {
                    c.infeasible += 1;
                    let stationary = r.certificate.as_ref().and_then(|c| c.violation_stationary);
                    if stationary == Some(true) {
                        c.infeasible_stationary += 1;
                    } else if r.exit == "infeasible" {
                        c.infeasible_stalled += 1;
                    }
                }
                _ => c.failed += 1,
            }
        }
        c
    }

    /// `count / runs` (0 without runs).
    pub fn share(&self, count: usize) -> f64 {
        if self.runs == 0 {
            0.0
        } else {
            count as f64 / self.runs as f64
        }
    }

    /// One line: counts and shares of each class.
    pub fn summary(&self) -> String {
        let pct = |k: usize| 100.0 * self.share(k);
        format!(
            "{} converged ({:.1} %), {} stopped ({:.1} %), {} infeasible ({:.1} %; {} at a \
             stationary point of the violation, {} where descent on it stalled), {} failed",
            self.converged,
            pct(self.converged),
            self.stopped,
            pct(self.stopped),
            self.infeasible,
            pct(self.infeasible),
            self.infeasible_stationary,
            self.infeasible_stalled,
            self.failed
        )
    }
}

fn opt_num(x: Option<f64>) -> String {
    x.map(num).unwrap_or_default()
}

/// Header of `runs.csv` for these variables and `m` constraints.
pub fn runs_header(vars: &[Variable], m: usize) -> Vec<String> {
    let mut h = vec!["start".to_string()];
    h.extend(vars.iter().map(|v| format!("x0_{}", v.name)));
    h.extend(vars.iter().map(|v| format!("x_{}", v.name)));
    h.push("f".into());
    h.extend((1..=m).map(|j| format!("g{j}")));
    h.extend(["max_g"].map(String::from));
    h.extend(certificate_header(m));
    h.extend(
        [
            "exit",
            "polish",
            "iterations",
            "function_calls",
            "gradient_calls",
            "wall_seconds",
            "optimum",
        ]
        .map(String::from),
    );
    h
}

/// The certificate columns of `runs.csv` (after `max_g`).
fn certificate_header(m: usize) -> Vec<String> {
    let mut h = vec!["class".to_string(), "kt_residual".into()];
    h.extend((1..=m).map(|j| format!("lambda{j}")));
    h.extend(["violation_residual", "violation_stationary"].map(String::from));
    h
}

impl RunRecord {
    /// The fields of this row (see [`runs_header`]).
    pub fn fields(&self, n: usize, m: usize) -> Vec<String> {
        let mut r = vec![self.start.to_string()];
        r.extend(self.x0.iter().map(|&v| num(v)));
        match &self.result {
            Some(res) => {
                r.extend(res.x.iter().map(|&v| num(v)));
                r.push(num(res.f));
                r.extend(res.g.iter().map(|&v| num(v)));
                r.push(if m > 0 {
                    num(res.max_g())
                } else {
                    String::new()
                });
            }
            None => r.extend(std::iter::repeat_n(String::new(), n + 1 + m + 1)),
        }
        r.push(class_name(self).into());
        let c = self.certificate.as_ref();
        r.push(opt_num(c.and_then(|c| c.kt_residual)));
        for j in 0..m {
            r.push(opt_num(c.and_then(|c| c.multipliers[j])));
        }
        r.push(opt_num(c.and_then(|c| c.violation_residual)));
        r.push(
            c.and_then(|c| c.violation_stationary)
                .map(|b| b.to_string())
                .unwrap_or_default(),
        );
        r.push(self.exit.replace(['\n', '\r'], " "));
        r.push(self.polish.replace(['\n', '\r'], " "));
        r.push(self.iterations.to_string());
        r.push(self.function_calls.to_string());
        r.push(self.gradient_calls.to_string());
        r.push(num(self.wall_seconds));
        r.push(self.optimum.map(|o| o.to_string()).unwrap_or_default());
        r
    }

    /// Parse a row written by [`RunRecord::fields`].
    fn parse(rec: &csv::StringRecord, n: usize, m: usize) -> std::result::Result<Self, String> {
        let f = |i: usize| rec.get(i).unwrap_or("");
        let float = |i: usize| -> std::result::Result<f64, String> {
            f(i).parse::<f64>()
                .map_err(|_| format!("field {} = \"{}\" is not a number", i + 1, f(i)))
        };
        let int = |i: usize| -> std::result::Result<usize, String> {
            f(i).parse::<usize>()
                .map_err(|_| format!("field {} = \"{}\" is not a count", i + 1, f(i)))
        };
        let vec = |a: usize, len: usize| {
            (a..a + len)
                .map(float)
                .collect::<std::result::Result<Vec<_>, _>>()
        };
        let x0 = vec(1, n)?;
        let opt_float = |i: usize| -> std::result::Result<Option<f64>, String> {
            if f(i).is_empty() {
                Ok(None)
            } else {
                float(i).map(Some)
            }
        };
        let at = 1 + 2 * n + 1 + m + 1; // the class column
        let base = at + 2 + m + 2;
        let result = if f(1 + n + n).is_empty() {
            None
        } else {
            Some(RunResult {
                x: vec(1 + n, n)?,
                f: float(1 + 2 * n)?,
                g: vec(2 + 2 * n, m)?,
            })
        };
        let certificate = match (&result, EndClass::parse(f(at))) {
            (Some(res), Some(class)) => Some(Certificate {
                class,
                max_g: res.max_g(),
                kt_residual: opt_float(at + 1)?,
                multipliers: (0..m)
                    .map(|j| opt_float(at + 2 + j))
                    .collect::<std::result::Result<_, _>>()?,
                violation_residual: opt_float(at + 2 + m)?,
                violation_stationary: match f(at + 3 + m) {
                    "" => None,
                    s => Some(s.parse::<bool>().map_err(|_| {
                        format!("field {} = \"{s}\" is not true/false", at + 4 + m)
                    })?),
                },
                decrease_left: None,
                at_noise: None,
            }),
            _ if ["failed", "uncertified"].contains(&f(at)) => None,
            _ => {
                return Err(format!(
                    "field {} = \"{}\" is not a run class",
                    at + 1,
                    f(at)
                ))
            }
        };
        Ok(RunRecord {
            start: int(0)?,
            x0,
            result,
            exit: f(base).to_string(),
            polish: f(base + 1).to_string(),
            iterations: int(base + 2)?,
            function_calls: int(base + 3)?,
            gradient_calls: int(base + 4)?,
            wall_seconds: float(base + 5)?,
            optimum: if f(base + 6).is_empty() {
                None
            } else {
                Some(int(base + 6)?)
            },
            certificate,
        })
    }
}

/// Rows read back from `runs.csv`, and how many bytes of a torn last line
/// were removed.
#[derive(Debug)]
pub struct ReadRuns {
    /// Complete rows in file order.
    pub rows: Vec<RunRecord>,
    /// Bytes removed from the end (0: file was intact).
    pub repaired_bytes: usize,
}

/// Read `runs.csv`, repairing a torn last line in place. A missing file is
/// an empty table; a wrong header or a bad row before the last is an error.
pub fn read_runs(path: &Path, vars: &[Variable], m: usize) -> Result<ReadRuns> {
    let (read, keep) = scan_runs(path, vars, m)?;
    if read.repaired_bytes > 0 {
        crate::report::csv::cut_torn_line(path, keep)?;
        eprintln!(
            "warning: {}: removed a torn last line ({} bytes) left by an interrupted run; that start will run again",
            path.display(),
            read.repaired_bytes
        );
    }
    Ok(read)
}

/// Read `runs.csv` without touching it: the rows, the size of a torn last
/// line (`repaired_bytes`, what [`read_runs`] would cut) and the length of
/// the intact part.
pub fn scan_runs(path: &Path, vars: &[Variable], m: usize) -> Result<(ReadRuns, usize)> {
    let header = runs_header(vars, m);
    let width = header.len();
    let Some(lines) = read_csv_lines(path, &header, "does not match this study")? else {
        return Ok((
            ReadRuns {
                rows: vec![],
                repaired_bytes: 0,
            },
            0,
        ));
    };
    let mut keep = lines.keep;
    let mut rows = Vec::new();
    for (i, (r, at)) in lines.rows.iter().enumerate() {
        let k = i + 1; // the header is record 0
        let parsed = if r.len() == width {
            RunRecord::parse(r, vars.len(), m)
        } else {
            Err(format!("{} fields, expected {width}", r.len()))
        };
        match parsed {
            Ok(row) => rows.push(row),
            // A bad last line is a torn write: cut it off.
            Err(_) if i + 1 == lines.rows.len() => keep = *at,
            Err(e) => {
                return Err(Error::csv(path, format!("line {}: {e}", k + 1)));
            }
        }
    }
    Ok((
        ReadRuns {
            rows,
            repaired_bytes: lines.len - keep,
        },
        keep,
    ))
}

/// Appends complete lines to `runs.csv`, flushing after each.
pub struct RunsAppender {
    table: crate::report::csv::Appender,
    n: usize,
    m: usize,
}

impl RunsAppender {
    /// Open for appending; writes the header if the file is empty or new.
    pub fn open(path: &Path, vars: &[Variable], m: usize) -> Result<Self> {
        let table = crate::report::csv::Appender::open(path, &runs_header(vars, m), false)?;
        let n = vars.len();
        Ok(RunsAppender { table, n, m })
    }

    /// Append one row as a single write and flush it.
    pub fn append(&mut self, row: &RunRecord) -> Result<()> {
        self.table.row(&row.fields(self.n, self.m))
    }
}

/// The value of an optional float field.
pub fn field(x: Option<f64>) -> String {
    opt_num(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vars() -> Vec<Variable> {
        vec![
            Variable::bounded("a", -1.0, 1.0).unwrap(),
            Variable::bounded("b", -1.0, 1.0).unwrap(),
        ]
    }

    fn row(start: usize, ok: bool) -> RunRecord {
        RunRecord {
            start,
            x0: vec![0.1 * start as f64, -1.0 / 3.0],
            result: ok.then(|| RunResult {
                x: vec![std::f64::consts::PI / 7.0, 1e-300],
                f: -2.5e-17,
                g: vec![0.25],
            }),
            exit: if ok {
                "kuhn_tucker".into()
            } else {
                "error: a, \"b\"\nc".into()
            },
            iterations: 3,
            function_calls: 17,
            gradient_calls: 4,
            wall_seconds: 0.125,
            optimum: None,
            certificate: ok.then(|| Certificate {
                class: EndClass::Infeasible,
                max_g: 0.25,
                kt_residual: None,
                multipliers: vec![None],
                violation_residual: Some(1.0 / 3.0),
                violation_stationary: Some(false),
                decrease_left: None,
                at_noise: None,
            }),
            polish: if ok {
                "relative_change".into()
            } else {
                String::new()
            },
        }
    }

    #[test]
    fn numbers_round_trip_exactly() {
        for x in [
            0.0,
            -0.0,
            1e-300,
            -2.5e-17,
            1.0 / 3.0,
            123456.789,
            1e15,
            5e-324,
            f64::MAX,
        ] {
            assert_eq!(num(x).parse::<f64>().unwrap().to_bits(), x.to_bits(), "{x}");
        }
        assert_eq!(num(1.5e-14), "1.5e-14");
        assert_eq!(num(0.25), "0.25");
    }

    #[test]
    fn rows_round_trip_and_torn_line_is_repaired() {
        let dir = std::env::temp_dir().join(format!("plyscape-tables-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("runs.csv");
        let _ = std::fs::remove_file(&path);
        let mut app = RunsAppender::open(&path, &vars(), 1).unwrap();
        for (i, ok) in [(0, true), (1, false), (2, true)] {
            app.append(&row(i, ok)).unwrap();
        }
        drop(app);
        let intact = std::fs::read(&path).unwrap();
        let back = read_runs(&path, &vars(), 1).unwrap();
        assert_eq!(back.repaired_bytes, 0);
        let mut expect: Vec<RunRecord> = [(0, true), (1, false), (2, true)]
            .iter()
            .map(|&(i, ok)| row(i, ok))
            .collect();
        expect[1].exit = "error: a, \"b\" c".into();
        assert_eq!(back.rows, expect);
        // Tear the last line at every possible byte: always repaired to the
        // two complete rows before it.
        let last_start = intact[..intact.len() - 1]
            .iter()
            .rposition(|&b| b == b'\n')
            .unwrap()
            + 1;
        for cut in last_start + 1..intact.len() {
            std::fs::write(&path, &intact[..cut]).unwrap();
            let back = read_runs(&path, &vars(), 1).unwrap();
            assert_eq!(back.rows, expect[..2], "cut at {cut}");
            assert_eq!(back.repaired_bytes, cut - last_start);
            assert_eq!(std::fs::read(&path).unwrap(), intact[..last_start]);
        }
        // A corrupt line in the middle is an error, not a repair.
        let mut bad = intact.clone();
        bad[last_start - 3] = b'x';
        std::fs::write(&path, &bad).unwrap();
        assert!(read_runs(&path, &vars(), 1).is_err());
        // A header for another problem is an error.
        std::fs::write(&path, &intact).unwrap();
        assert!(read_runs(&path, &vars(), 2).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
