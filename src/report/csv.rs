//! CSV tables: the one writer of every table the tool writes.
//!
//! A table is a header row and rows of text cells, written whole to a
//! temporary file and renamed over the old one ([`write_atomic`]), so a
//! reader sees the old or the new table, never half of one. Cells are
//! formatted by the caller: [`num`] (shortest round-trip text, so a table
//! read back gives the same `f64` bits) or [`sci`] (fixed significant
//! digits, for histories). Units go in the header cells (`t [s]`).
//! Appending tables (resumable sweeps) write whole lines made by
//! [`csv_line`] and read back only their whole lines ([`read_csv_lines`]:
//! a torn last line is left for the caller to cut).

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Shortest round-trip text of a float (never NaN: callers check):
/// positional for `1e-4 <= |x| < 1e15` and zero, scientific otherwise.
pub fn num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || (1e-4..1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Scientific text with `digits` digits after the point (`{:.12e}` for
/// `digits = 12`).
pub fn sci(x: f64, digits: usize) -> String {
    format!("{x:.digits$e}")
}

/// One CSV line (with newline) for these fields.
pub fn csv_line(fields: &[String]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(fields)
        .map_err(|e| Error::csv("(memory)", e))?;
    w.into_inner()
        .map_err(|e| Error::csv("(memory)", e.error()))
}

/// Write `lines` (header first) to `path` atomically (temporary + rename).
pub fn write_atomic(path: &Path, rows: &[Vec<String>]) -> Result<()> {
    let mut bytes = Vec::new();
    for r in rows {
        bytes.extend(csv_line(r)?);
    }
    write_bytes_atomic(path, &bytes)
}

/// Write `bytes` to `path` through a temporary file and a rename.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension("tmp");
    let mut f = std::fs::File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
    f.write_all(bytes).map_err(|e| Error::io(&tmp, e))?;
    f.sync_all().map_err(|e| Error::io(&tmp, e))?;
    drop(f);
    std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
}

/// Write a table: `header`, then `rows` (all as text cells), atomically.
pub fn write_table<S: AsRef<str>>(path: &Path, header: &[S], rows: &[Vec<String>]) -> Result<()> {
    let mut bytes = csv_line(
        &header
            .iter()
            .map(|h| h.as_ref().to_string())
            .collect::<Vec<_>>(),
    )?;
    for r in rows {
        bytes.extend(csv_line(r)?);
    }
    write_bytes_atomic(path, &bytes)
}

/// A table built row by row in memory and written whole, atomically, by
/// [`Table::finish`] (the first row is the header).
pub struct Table {
    path: std::path::PathBuf,
    writer: csv::Writer<Vec<u8>>,
}

impl Table {
    /// An empty table to be written to `path`.
    pub fn new(path: &Path) -> Table {
        Table {
            path: path.to_path_buf(),
            writer: csv::Writer::from_writer(Vec::new()),
        }
    }

    /// Append one row of text cells.
    pub fn row<I, S>(&mut self, cells: I) -> Result<()>
    where
        I: IntoIterator<Item = S>,
        S: AsRef<str>,
    {
        let cells: Vec<String> = cells.into_iter().map(|c| c.as_ref().to_string()).collect();
        self.writer
            .write_record(&cells)
            .map_err(|e| Error::csv(&self.path, e))
    }

    /// Write the table (temporary file + rename) and return its path.
    pub fn finish(self) -> Result<std::path::PathBuf> {
        let bytes = self
            .writer
            .into_inner()
            .map_err(|e| Error::csv(&self.path, e.error()))?;
        write_bytes_atomic(&self.path, &bytes)?;
        Ok(self.path)
    }
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

/// A table appended one whole line at a time (one `write_all` of the line,
/// then a flush), so a killed process leaves at worst a torn last line.
pub struct Appender {
    file: std::fs::File,
    path: std::path::PathBuf,
}

impl Appender {
    /// Open `path` for appending (`fresh`: emptied first); `header` is
    /// written when the file is empty or new.
    pub fn open(path: &Path, header: &[String], fresh: bool) -> Result<Appender> {
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .write(true)
            .append(!fresh)
            .truncate(fresh)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        if len == 0 {
            file.write_all(&csv_line(header)?)
                .map_err(|e| Error::io(path, e))?;
        }
        Ok(Appender {
            file,
            path: path.to_path_buf(),
        })
    }

    /// Append one row as a single write and flush it.
    pub fn row(&mut self, fields: &[String]) -> Result<()> {
        let line = csv_line(fields)?;
        self.file
            .write_all(&line)
            .and_then(|_| self.file.flush())
            .map_err(|e| Error::io(&self.path, e))
    }
}

/// Cut `path` to its first `keep` bytes (its whole lines, as
/// [`read_csv_lines`] counts them) and sync it to disk.
pub fn cut_torn_line(path: &Path, keep: usize) -> Result<()> {
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|e| Error::io(path, e))?;
    f.set_len(keep as u64).map_err(|e| Error::io(path, e))?;
    f.sync_all().map_err(|e| Error::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_are_written_whole_and_quoted() {
        let dir = std::env::temp_dir().join(format!("plyscape-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.csv");
        let rows = vec![
            vec!["a,b".to_string(), sci(0.5, 3)],
            vec![num(1e-7), num(2.0)],
        ];
        write_table(&path, &["name", "value [m]"], &rows).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, "name,value [m]\n\"a,b\",5.000e-1\n1e-7,2\n");
        assert!(!path.with_extension("tmp").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
