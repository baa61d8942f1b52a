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
use crate::optimize::Variable;
pub use crate::report::csv::{csv_line, num, write_atomic, write_bytes_atomic};
use std::io::Write;
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
    /// Optimum id after clustering (empty while running).
    pub optimum: Option<usize>,
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
    h.extend(
        [
            "max_g",
            "exit",
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
        r.push(self.exit.replace(['\n', '\r'], " "));
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
        let base = 1 + 2 * n + 1 + m + 1;
        let result = if f(1 + n + n).is_empty() {
            None
        } else {
            Some(RunResult {
                x: vec(1 + n, n)?,
                f: float(1 + 2 * n)?,
                g: vec(2 + 2 * n, m)?,
            })
        };
        Ok(RunRecord {
            start: int(0)?,
            x0,
            result,
            exit: f(base).to_string(),
            iterations: int(base + 1)?,
            function_calls: int(base + 2)?,
            gradient_calls: int(base + 3)?,
            wall_seconds: float(base + 4)?,
            optimum: if f(base + 5).is_empty() {
                None
            } else {
                Some(int(base + 5)?)
            },
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
        let f = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        f.set_len(keep as u64).map_err(|e| Error::io(path, e))?;
        f.sync_all().map_err(|e| Error::io(path, e))?;
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

/// The whole lines of a resumable CSV table (`runs.csv`, a map's table).
pub struct CsvLines {
    /// Length of the file (bytes).
    pub len: usize,
    /// Length of its whole lines (up to the last newline).
    pub keep: usize,
    /// The data records after the header, each with the byte where its
    /// line starts (where a torn last line is cut).
    pub rows: Vec<(csv::StringRecord, usize)>,
}

/// Read a table's whole lines (`None` when the file does not exist); a
/// first line other than `header` is refused as "header .. `what`".
pub fn read_csv_lines(path: &Path, header: &[String], what: &str) -> Result<Option<CsvLines>> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Error::io(path, e)),
    };
    let keep = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(&bytes[..keep]);
    let mut rows = Vec::new();
    for r in reader.records() {
        let r = r.map_err(|e| Error::csv(path, e))?;
        let at = r.position().map_or(0, |p| p.byte() as usize);
        rows.push((r, at));
    }
    if let Some((first, _)) = rows.first() {
        if first.iter().ne(header.iter().map(String::as_str)) {
            return Err(Error::csv(
                path,
                format!(
                    "header {:?} {what} (expected {:?})",
                    first.iter().collect::<Vec<_>>().join(","),
                    header.join(",")
                ),
            ));
        }
        rows.remove(0);
    }
    Ok(Some(CsvLines {
        len: bytes.len(),
        keep,
        rows,
    }))
}

/// Appends complete lines to `runs.csv`, flushing after each.
pub struct RunsAppender {
    file: std::fs::File,
    path: std::path::PathBuf,
    n: usize,
    m: usize,
}

impl RunsAppender {
    /// Open for appending; writes the header if the file is empty or new.
    pub fn open(path: &Path, vars: &[Variable], m: usize) -> Result<Self> {
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        if len == 0 {
            file.write_all(&csv_line(&runs_header(vars, m))?)
                .map_err(|e| Error::io(path, e))?;
        }
        Ok(RunsAppender {
            file,
            path: path.to_path_buf(),
            n: vars.len(),
            m,
        })
    }

    /// Append one row as a single write and flush it.
    pub fn append(&mut self, row: &RunRecord) -> Result<()> {
        let line = csv_line(&row.fields(self.n, self.m))?;
        self.file
            .write_all(&line)
            .and_then(|_| self.file.flush())
            .map_err(|e| Error::io(&self.path, e))
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
