//! The one error type of plyscape.
//!
//! Two families matter to a user:
//! - [`Error::Input`]: something in a study file (or an API argument) is wrong.
//!   It names the file, the key (a dotted TOML path such as
//!   `panels[0].plies[2].thickness`), the offending value and what was
//!   expected. Library code that does not know the file leaves it empty; the
//!   study layer fills it in with [`Error::in_file`].
//! - [`Error::Numerical`]: a computation failed (singular matrix, no
//!   convergence, step-size underflow). It names the place (module and
//!   object), the simulated time when there is one, and the numbers.
//!
//! Nothing in plyscape panics on bad input or writes a NaN to a report: such
//! cases become one of these values.

use std::fmt;
use std::path::{Path, PathBuf};

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Every failure plyscape reports.
#[derive(Debug)]
pub enum Error {
    /// Bad input. `file` may be empty when the value came through the API.
    Input {
        /// The study file (empty when not known yet).
        file: String,
        /// The dotted key of the value, e.g. `panels[0].plies[2].thickness`.
        key: String,
        /// The offending value as written.
        value: String,
        /// What was expected instead.
        expected: String,
    },
    /// A numerical failure with its place, time (if any) and the numbers.
    Numerical {
        /// Module and object where it failed, e.g. `explore::map`.
        place: String,
        /// Simulated time \[s\] when the failure happened during a simulation.
        time: Option<f64>,
        /// What failed, with the numbers.
        detail: String,
    },
    /// A file could not be read or written.
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A CSV file could not be read or written, or is corrupt.
    Csv {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the row or column where known.
        detail: String,
    },
}

impl Error {
    /// Bad input, without a file yet (library level).
    pub fn input(
        key: impl Into<String>,
        value: impl fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        Error::Input {
            file: String::new(),
            key: key.into(),
            value: value.to_string(),
            expected: expected.into(),
        }
    }

    /// A numerical failure at `place` (no time).
    pub fn numerical(place: impl Into<String>, detail: impl Into<String>) -> Self {
        Error::Numerical {
            place: place.into(),
            time: None,
            detail: detail.into(),
        }
    }

    /// A numerical failure at `place` at simulated time `t` \[s\].
    pub fn numerical_at(place: impl Into<String>, t: f64, detail: impl Into<String>) -> Self {
        Error::Numerical {
            place: place.into(),
            time: Some(t),
            detail: detail.into(),
        }
    }

    /// An I/O failure on `path`.
    pub fn io(path: impl AsRef<Path>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.as_ref().to_path_buf(),
            source,
        }
    }

    /// A CSV failure on `path`.
    pub fn csv(path: impl AsRef<Path>, detail: impl fmt::Display) -> Self {
        Error::Csv {
            path: path.as_ref().to_path_buf(),
            detail: detail.to_string(),
        }
    }

    /// Prefix the place of a numerical failure with `prefix` (e.g. the
    /// panel or the design it happened at); other errors are unchanged.
    pub fn at_place(self, prefix: &str) -> Self {
        match self {
            Error::Numerical {
                place,
                time,
                detail,
            } => Error::Numerical {
                place: format!("{prefix}: {place}"),
                time,
                detail,
            },
            other => other,
        }
    }

    /// Attach the study file and a key prefix to an input error: a library
    /// error with key `plies[1].thickness` raised while reading section
    /// `panels[0]` of `study.toml` becomes `study.toml: panels[0].plies[1].thickness`.
    /// An error already placed in a file keeps its file and key (they are
    /// the ones its writer wrote: a top-level `[[panels]]` entry stays
    /// `panels[0]` when the scene that uses it adds `scene`). Other
    /// variants pass through unchanged.
    pub fn in_file(self, file: impl AsRef<Path>, key_prefix: &str) -> Self {
        match self {
            Error::Input {
                file: f,
                key,
                value,
                expected,
            } if f.is_empty() => {
                let file = file.as_ref().display().to_string();
                let key = match (key_prefix.is_empty(), key.is_empty()) {
                    (true, _) => key,
                    (false, true) => key_prefix.to_string(),
                    (false, false) if key.starts_with('[') => format!("{key_prefix}{key}"),
                    (false, false) => format!("{key_prefix}.{key}"),
                };
                Error::Input {
                    file,
                    key,
                    value,
                    expected,
                }
            }
            other => other,
        }
    }

    /// Process exit code for this error: 2 for bad input, 3 for numerical
    /// failure, 4 for I/O and CSV problems.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Input { .. } => 2,
            Error::Numerical { .. } => 3,
            Error::Io { .. } | Error::Csv { .. } => 4,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input {
                file,
                key,
                value,
                expected,
            } => {
                match (file.is_empty(), key.is_empty()) {
                    (true, _) => write!(f, "invalid input: `{key}` = {value}: expected {expected}"),
                    // A file-level error (TOML syntax): the place is the value.
                    (false, true) => write!(f, "{file}: {value}: expected {expected}"),
                    (false, false) => write!(f, "{file}: `{key}` = {value}: expected {expected}"),
                }
            }
            Error::Numerical {
                place,
                time: Some(t),
                detail,
            } => write!(f, "numerical failure in {place} at t = {t:.6e} s: {detail}"),
            Error::Numerical {
                place,
                time: None,
                detail,
            } => write!(f, "numerical failure in {place}: {detail}"),
            Error::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Error::Csv { path, detail } => write!(f, "{}: {detail}", path.display()),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Fail with an input error unless `value` is finite and strictly positive.
pub fn require_positive(key: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::input(key, value, "a finite value > 0"))
    }
}

/// Fail with an input error unless `value` is finite.
pub fn require_finite(key: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::input(key, value, "a finite number"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_file_prefixes_keys_and_names_file() {
        let e = Error::input("plies[1].thickness", -1.0, "a finite value > 0")
            .in_file("studies/x.toml", "panels[0]");
        let msg = e.to_string();
        assert_eq!(
            msg,
            "studies/x.toml: `panels[0].plies[1].thickness` = -1: expected a finite value > 0"
        );
        assert_eq!(e.exit_code(), 2);
        // Placed once, placed for good: the scene that builds the panel
        // does not rename the top-level `[[panels]]` entry.
        let again = Error::input("plies[1].thickness", -1.0, "a finite value > 0")
            .in_file("studies/x.toml", "panels[0]")
            .in_file("studies/x.toml", "scene");
        assert_eq!(again.to_string(), msg);
    }

    #[test]
    fn numerical_carries_time() {
        let e = Error::numerical_at("mbs::joint R3", 1.25, "singular");
        assert!(e.to_string().contains("at t = 1.250000e0 s"));
        assert_eq!(e.exit_code(), 3);
    }
}
