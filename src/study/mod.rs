//! Study files: TOML documents that say what to compute.
//!
//! A study file has a `[study]` table (name, description, seed, threads) and
//! one table per kind of work it asks for (`[panels]`, `[problem]`,
//! `[multistart]`, ...). Each module reads its own section with
//! [`Study::section`], so modules stay independent of one another; this module
//! only owns the common part and the error mapping. Angles in study files are
//! written in degrees and converted once, where a section is resolved.
//!
//! Every error names the file, the key, the value and what was expected.

pub mod keys;
pub mod memory;
pub mod toml_value;

use crate::error::{Error, Result};
use serde::de::DeserializeOwned;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The common `[study]` table.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct StudyMeta {
    /// Name of the study; results go to `results/<name>/`. Default: file stem.
    pub name: Option<String>,
    /// Free text shown in reports.
    #[serde(default)]
    pub description: String,
    /// Seed of every random choice in the study. Default 0 (documented so a
    /// run is reproducible even when the file gives none).
    #[serde(default)]
    pub seed: u64,
    /// Worker threads for drivers. Default: all cores.
    pub threads: Option<usize>,
}

/// A parsed study file: its path, the raw TOML table and the common metadata.
#[derive(Debug, Clone)]
pub struct Study {
    /// Where the study was read from (or a label for built-in studies).
    pub path: PathBuf,
    /// The original text (kept for the manifest).
    pub text: String,
    /// The whole document.
    pub table: toml::Table,
    /// The `[study]` table.
    pub meta: StudyMeta,
}

/// The largest study file read (4 MiB): a study is a few hundred lines;
/// a larger file is a mistake (a pasted table) that parsing, checking and
/// copying into `manifest.json` would multiply.
pub const MAX_STUDY_BYTES: u64 = 4 << 20;

impl Study {
    /// Read and parse a study file.
    pub fn load(path: impl AsRef<Path>) -> Result<Study> {
        let path = path.as_ref();
        let refuse = |value: String, expected: &str| Error::Input {
            file: path.display().to_string(),
            key: String::new(),
            value,
            expected: expected.to_string(),
        };
        let size = std::fs::metadata(path)
            .map_err(|e| Error::io(path, e))?
            .len();
        if size > MAX_STUDY_BYTES {
            return Err(refuse(
                format!("{size} bytes"),
                &format!("a study file of at most {MAX_STUDY_BYTES} bytes (tables of values belong in CSV files)"),
            ));
        }
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let before = &e.as_bytes()[..at];
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let column = at
                - before
                    .iter()
                    .rposition(|&b| b == b'\n')
                    .map_or(0, |k| k + 1)
                + 1;
            refuse(
                format!("byte {at} (line {line}, column {column})"),
                "UTF-8 text (TOML files are UTF-8)",
            )
        })?;
        Study::parse(path, &text)
    }

    /// Parse study text; `path` is used in messages and for the default name.
    pub fn parse(path: impl AsRef<Path>, text: &str) -> Result<Study> {
        let path = path.as_ref().to_path_buf();
        let table: toml::Table = toml::from_str(text).map_err(|e| Error::Input {
            file: path.display().to_string(),
            key: String::new(),
            value: syntax_place(text, e.span()),
            expected: format!("valid TOML: {}", e.message().trim()),
        })?;
        let mut study = Study {
            path,
            text: text.to_string(),
            table,
            meta: StudyMeta::default(),
        };
        study.meta = study.section::<StudyMeta>("study")?.unwrap_or_default();
        if study.meta.threads == Some(0) {
            return Err(study.error("study.threads", 0, "a thread count >= 1"));
        }
        if let Some(name) = &study.meta.name {
            if name.is_empty() || name.contains(['/', '\\']) || name == "." || name == ".." {
                return Err(study.error(
                    "study.name",
                    name,
                    "a non-empty name without path separators",
                ));
            }
        }
        Ok(study)
    }

    /// The study's name: `[study] name`, else the file stem.
    pub fn name(&self) -> String {
        self.meta.name.clone().unwrap_or_else(|| {
            self.path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "study".into())
        })
    }

    /// Does the study have a top-level table `key`?
    pub fn has(&self, key: &str) -> bool {
        self.table.contains_key(key)
    }

    /// Deserialize the top-level section `key` into `T`, or `None` if absent.
    /// Serde errors (missing field, unknown field, wrong type, unknown kind)
    /// become input errors naming this file, the dotted key of the value
    /// that failed (e.g. `scene.joints[2].axis`, found by
    /// `serde_path_to_error`), that value, and serde's expectation (for a
    /// kind: the accepted names).
    pub fn section<T: DeserializeOwned>(&self, key: &str) -> Result<Option<T>> {
        let Some(v) = self.table.get(key) else {
            return Ok(None);
        };
        serde_path_to_error::deserialize::<_, T>(v.clone())
            .map(Some)
            .map_err(|e| {
                let path = e.path().clone();
                let (mut dotted, mut value) = locate_value(key, v, &path);
                // toml's message without its own (section-relative) key.
                let msg = e.into_inner().message().trim().replace('\n', " ");
                // Inside an internally tagged enum (`[[scene.forces]]`) the
                // path stops at the entry: an unknown kind is then found
                // by its value among the entry's keys.
                if let Some((k, found)) = value.and_then(|t| unknown_variant_in(&msg, t)) {
                    dotted = format!("{dotted}.{k}");
                    value = Some(found);
                }
                Error::Input {
                    file: self.path.display().to_string(),
                    key: dotted,
                    value: summarize_opt(value),
                    expected: expectation(&msg),
                }
            })
    }

    /// Like [`Study::section`] but the section must be present.
    pub fn require_section<T: DeserializeOwned>(&self, key: &str, what: &str) -> Result<T> {
        self.section(key)?
            .ok_or_else(|| self.error(key, "(missing)", format!("a [{key}] table: {what}")))
    }

    /// An input error in this file.
    pub fn error(
        &self,
        key: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) -> Error {
        Error::input(key, value, expected).in_file(&self.path, "")
    }

    /// Attach this file (and a key prefix) to a library-level input error.
    pub fn locate(&self, key_prefix: &str) -> impl Fn(Error) -> Error + '_ {
        let prefix = key_prefix.to_string();
        move |e| e.in_file(&self.path, &prefix)
    }

    /// The output directory `root/<name>`, created if needed.
    pub fn output_dir(&self, root: &Path) -> Result<PathBuf> {
        let dir = root.join(self.name());
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        Ok(dir)
    }
}

/// Serde's message turned into what the error's "expected ..." reads:
/// `unknown variant `x`, expected one of `a`, `b`` becomes
/// `one of `a`, `b` (unknown variant `x`)`, with `; did you mean `a`?`
/// when one name is near (at most a third of its letters off, at least
/// two), and `missing field `m`` becomes `the field `m` (missing)`.
fn expectation(msg: &str) -> String {
    if let Some((what, wanted)) = msg.rsplit_once(", expected ") {
        let typed = what.split('`').nth(1).unwrap_or("");
        match nearest(typed, wanted.split('`').skip(1).step_by(2)) {
            Some(near) => format!("{wanted} ({what}; did you mean `{near}`?)"),
            None => format!("{wanted} ({what})"),
        }
    } else if let Some(field) = msg.strip_prefix("missing field ") {
        format!("the field {field} (missing)")
    } else {
        msg.to_string()
    }
}

/// The name of `names` nearest to `typed` by edit distance (Levenshtein:
/// insertions, deletions, substitutions), when it is within
/// `max(2, len/3)` edits.
fn nearest<'a>(typed: &str, names: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let t = typed.to_lowercase();
    let limit = (t.chars().count() / 3).max(2);
    names
        .map(|n| (edit_distance(&t, &n.to_lowercase()), n))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n)
}

/// The edit distance between `a` and `b` (Levenshtein: insertions,
/// deletions, substitutions of characters; one row of the table at a
/// time).
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1)
                .min(row[j] + 1)
                .min(diagonal + usize::from(ca != *cb));
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// The key and value of the entry of `table` holding the unknown variant
/// that serde's `msg` names (`unknown variant `x`, expected ...`).
fn unknown_variant_in<'v>(msg: &str, table: &'v toml::Value) -> Option<(&'v str, &'v toml::Value)> {
    let name = msg.strip_prefix("unknown variant `")?.split('`').next()?;
    table
        .as_table()?
        .iter()
        .find(|(_, v)| v.as_str() == Some(name))
        .map(|(k, v)| (k.as_str(), v))
}

fn locate_value<'v>(
    key: &str,
    section: &'v toml::Value,
    path: &serde_path_to_error::Path,
) -> (String, Option<&'v toml::Value>) {
    use serde_path_to_error::Segment;
    let mut dotted = key.to_string();
    let mut at = Some(section);
    for seg in path.iter() {
        match seg {
            Segment::Seq { index } => {
                dotted.push_str(&format!("[{index}]"));
                at = at.and_then(|v| v.get(*index));
            }
            Segment::Map { key } => {
                dotted.push('.');
                dotted.push_str(key);
                at = at.and_then(|v| v.get(key.as_str()));
            }
            Segment::Enum { variant } => {
                dotted.push('.');
                dotted.push_str(variant);
            }
            Segment::Unknown => {}
        }
    }
    (dotted, at)
}

/// [`summarize`], or `(missing)` when there is no value.
fn summarize_opt(v: Option<&toml::Value>) -> String {
    v.map_or_else(|| "(missing)".to_string(), summarize)
}

/// Short one-line rendering of a TOML value for messages.
fn summarize(v: &toml::Value) -> String {
    let s = match v {
        toml::Value::Table(_) => "(table)".to_string(),
        toml::Value::Array(a) => format!("(array of {})", a.len()),
        other => other.to_string(),
    };
    if s.len() > 60 {
        format!("{}...", &s[..57])
    } else {
        s
    }
}

/// Where a TOML syntax error sits: `line L, column C: <the line>` (1-based,
/// columns in characters), or `(file)` when the parser gives no place.
fn syntax_place(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    let Some(at) = span.map(|s| s.start.min(text.len())) else {
        return "(file)".into();
    };
    let at = (0..=at)
        .rev()
        .find(|&k| text.is_char_boundary(k))
        .unwrap_or(0);
    let start = text[..at].rfind('\n').map_or(0, |k| k + 1);
    let end = text[at..].find('\n').map_or(text.len(), |k| at + k);
    let line = text[..at].matches('\n').count() + 1;
    let column = text[start..at].chars().count() + 1;
    format!(
        "line {line}, column {column}: `{}`",
        text[start..end].trim_end()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Demo {
        #[allow(dead_code)]
        starts: usize,
    }

    #[test]
    fn name_defaults_to_stem_and_sections_map_errors() {
        let s = Study::parse(
            "studies/demo.toml",
            "[study]\nseed = 3\n[demo]\nstarts = -1\n",
        )
        .unwrap();
        assert_eq!(s.name(), "demo");
        assert_eq!(s.meta.seed, 3);
        let e = s.section::<Demo>("demo").unwrap_err().to_string();
        assert!(
            e.starts_with("studies/demo.toml: `demo.starts` = -1"),
            "{e}"
        );
        assert!(s.section::<Demo>("absent").unwrap().is_none());
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Joint {
        name: String,
        axis: [f64; 3],
    }

    #[derive(Debug, Deserialize)]
    #[serde(rename_all = "snake_case")]
    #[allow(dead_code)]
    enum Kind {
        Beam,
        Panel,
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Nested {
        joints: Vec<Joint>,
        #[serde(default)]
        kinds: Vec<Kind>,
    }

    fn input_error(e: Error) -> (String, String, String, String) {
        match e {
            Error::Input {
                file,
                key,
                value,
                expected,
            } => (file, key, value, expected),
            other => panic!("expected an input error, got {other:?}"),
        }
    }

    /// A bad value deep inside a section names the file, the dotted key
    /// down to that value, the value itself and serde's expectation.
    #[test]
    fn nested_errors_name_the_dotted_key_and_the_value() {
        let joint = |axis: &str| format!("[[scene.joints]]\nname = \"j\"\naxis = {axis}\n");
        let text =
            joint("[0.0, 0.0, 1.0]") + &joint("[0.0, 0.0, 1.0]") + &joint("[0.0, \"z\", 1.0]");
        let s = Study::parse("studies/nested.toml", &text).unwrap();
        let (file, key, value, expected) = input_error(s.section::<Nested>("scene").unwrap_err());
        assert_eq!(file, "studies/nested.toml");
        assert_eq!(key, "scene.joints[2].axis[1]");
        assert_eq!(value, "\"z\"");
        assert!(
            expected.contains("f64") || expected.contains("float"),
            "{expected}"
        );
        let e = s.section::<Nested>("scene").unwrap_err().to_string();
        assert!(
            e.starts_with("studies/nested.toml: `scene.joints[2].axis[1]` = \"z\""),
            "{e}"
        );

        // A wrong length names the array (shown by its length).
        let s = Study::parse("n.toml", &joint("[0.0, 1.0]")).unwrap();
        let (_, key, value, _) = input_error(s.section::<Nested>("scene").unwrap_err());
        assert_eq!(
            (key.as_str(), value.as_str()),
            ("scene.joints[0].axis", "(array of 2)")
        );

        // An unknown kind lists the accepted names.
        let text =
            "[scene]\nkinds = [\"beam\", \"plate\"]\n".to_string() + &joint("[0.0, 0.0, 1.0]");
        let s = Study::parse("k.toml", &text).unwrap();
        let (_, key, value, expected) = input_error(s.section::<Nested>("scene").unwrap_err());
        assert_eq!(
            (key.as_str(), value.as_str()),
            ("scene.kinds[1]", "\"plate\"")
        );
        assert!(expected.contains("`beam` or `panel`"), "{expected}");

        // An unknown key is named with its place; a missing one names the
        // table it is missing from.
        let s = Study::parse("u.toml", &joint("[0.0, 0.0, 1.0]").replace("name", "nmae")).unwrap();
        let (_, key, _, expected) = input_error(s.section::<Nested>("scene").unwrap_err());
        assert!(key.starts_with("scene.joints[0]"), "{key}");
        assert!(expected.contains("nmae"), "{expected}");
        assert!(expected.contains("did you mean `name`?"), "{expected}");
        // Nothing near: no suggestion.
        let s = Study::parse(
            "u.toml",
            &joint("[0.0, 0.0, 1.0]").replace("name", "zzzzzz"),
        )
        .unwrap();
        let (_, _, _, expected) = input_error(s.section::<Nested>("scene").unwrap_err());
        assert!(!expected.contains("did you mean"), "{expected}");
    }

    #[test]
    fn zero_threads_rejected() {
        let e = Study::parse("a.toml", "[study]\nthreads = 0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("study.threads") && e.contains("thread count"),
            "{e}"
        );
    }

    #[test]
    fn non_utf8_and_oversized_files_are_refused_with_a_place() {
        let dir = std::env::temp_dir().join(format!("plyscape-study-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("latin1.toml");
        std::fs::write(&bad, b"[study]\nname = \"caf\xe9\"\n").unwrap();
        let e = Study::load(&bad).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let msg = e.to_string();
        assert!(
            msg.contains("byte 19 (line 2, column 12)") && msg.contains("UTF-8"),
            "{msg}"
        );
        let big = dir.join("big.toml");
        let line = format!("# {}\n", "x".repeat(1 << 16));
        std::fs::write(&big, line.repeat(80)).unwrap();
        let msg = Study::load(&big).unwrap_err().to_string();
        assert!(msg.contains("at most 4194304 bytes"), "{msg}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_toml_names_file() {
        let e = Study::parse("b.toml", "[study\n").unwrap_err().to_string();
        assert!(e.starts_with("b.toml"), "{e}");
    }

    #[test]
    fn toml_syntax_errors_give_line_column_and_the_line() {
        let text = "[study]\nname = \"x\"\n\n[scene]\ngravity = [0.0, 0.0 -9.81]\n";
        let e = Study::parse("s.toml", text).unwrap_err().to_string();
        println!("{e}");
        assert!(
            e.contains("line 5, column") && e.contains("gravity = [0.0, 0.0 -9.81]"),
            "{e}"
        );
    }
}
