//! The repository explains itself: no study file, test, source file, docs
//! page or the README may point to files that live outside it (design
//! notes or paths of the machine the project was developed on). Such
//! explanations belong in `docs/` (`docs/sar_reconstruction.md` for the
//! antenna scene, `docs/numerics.md` for the numerical choices), and every
//! `docs/<page>.md` that the text names must exist.
//!
//! The strings searched for are assembled from pieces, so that this file
//! does not contain them and does not trip its own check.

use std::fs;
use std::path::{Path, PathBuf};

/// What the walk scans, relative to the crate root: directories
/// (recursively) and single files.
const ROOTS: [&str; 6] = ["studies", "tests", "benches", "src", "docs", "README.md"];

/// Text that marks a reference to something outside the repository: the
/// folder of the external design notes, a machine path, a path that climbs
/// out of the checkout, and the names of the external notes themselves.
fn needles() -> Vec<String> {
    vec![
        ["shared", "design"].join("/"),
        ["", "work", ""].join("/"),
        ["..", "shared"].join("/"),
        ["SAR", "MODEL"].join("_"),
        ["sar", "geometry.json"].join("_"),
        ["ARCHITECTURE", "md"].join("."),
        ["NUMERICS", "md"].join("."),
        ["STYLE", "md"].join("."),
    ]
}

/// One offending line: file (relative to the crate root), 1-based line
/// number, the needle found and the line itself.
#[derive(Debug, PartialEq)]
struct Hit {
    file: String,
    line: usize,
    needle: String,
    text: String,
}

/// Every line of `text` that contains one of `needles` (one hit per line
/// and needle).
fn scan(file: &str, text: &str, needles: &[String]) -> Vec<Hit> {
    let mut hits = Vec::new();
    for (k, line) in text.lines().enumerate() {
        for n in needles {
            if line.contains(n.as_str()) {
                hits.push(Hit {
                    file: file.to_string(),
                    line: k + 1,
                    needle: n.clone(),
                    text: line.trim().to_string(),
                });
            }
        }
    }
    hits
}

/// The `docs/<name>.md` pages that `text` names, with their line numbers.
fn docs_links(text: &str) -> Vec<(usize, String)> {
    let prefix = "docs/";
    let mut links = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let mut rest = line;
        while let Some(pos) = rest.find(prefix) {
            let after = &rest[pos + prefix.len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
                .collect();
            let name = name.trim_end_matches('.');
            if name.ends_with(".md") && name.len() > 3 {
                links.push((k + 1, format!("{prefix}{name}")));
            }
            rest = after;
        }
    }
    links
}

/// All files under the roots, sorted (deterministic messages).
fn files(root: &Path) -> Vec<PathBuf> {
    fn walk(p: &Path, out: &mut Vec<PathBuf>) {
        if p.is_dir() {
            let mut entries: Vec<PathBuf> = fs::read_dir(p)
                .unwrap_or_else(|e| panic!("cannot list {}: {e}", p.display()))
                .map(|e| e.unwrap().path())
                .collect();
            entries.sort();
            for e in entries {
                walk(&e, out);
            }
        } else if p.is_file() {
            out.push(p.to_path_buf());
        }
    }
    let mut out = Vec::new();
    for r in ROOTS {
        let p = root.join(r);
        assert!(p.exists(), "{} is missing", p.display());
        walk(&p, &mut out);
    }
    out
}

fn relative(root: &Path, p: &Path) -> String {
    p.strip_prefix(root).unwrap_or(p).display().to_string()
}

#[test]
fn no_text_points_outside_the_repository() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let needles = needles();
    let all = files(root);
    let mut hits = Vec::new();
    let mut broken = Vec::new();
    for p in &all {
        let bytes = fs::read(p).unwrap_or_else(|e| panic!("cannot read {}: {e}", p.display()));
        let text = String::from_utf8_lossy(&bytes);
        let name = relative(root, p);
        hits.extend(scan(&name, &text, &needles));
        for (line, link) in docs_links(&text) {
            if !root.join(&link).is_file() {
                broken.push(format!("{name}:{line}: {link} does not exist"));
            }
        }
    }
    // The walk must have seen the files that matter, or it proves nothing.
    for must in [
        "README.md",
        "docs/sar_reconstruction.md",
        "docs/numerics.md",
        "studies/main.toml",
        "src/lib.rs",
        "tests/suite/repo_self_contained.rs",
    ] {
        assert!(
            all.iter().any(|p| relative(root, p) == must),
            "the walk did not reach {must}"
        );
    }
    let report: Vec<String> = hits
        .iter()
        .map(|h| format!("{}:{}: `{}` in: {}", h.file, h.line, h.needle, h.text))
        .collect();
    assert!(
        report.is_empty(),
        "{} line(s) point outside the repository; explain in docs/ instead:\n{}",
        report.len(),
        report.join("\n")
    );
    assert!(
        broken.is_empty(),
        "links to missing docs pages:\n{}",
        broken.join("\n")
    );
}

#[test]
fn the_scan_finds_a_planted_reference() {
    // The check must be able to fail: plant each needle in a small text
    // and find it on the right line.
    let needles = needles();
    for n in &needles {
        let text = format!("first line\nsee {n} for details\nlast line\n");
        let hits = scan("planted.toml", &text, &needles);
        assert!(
            hits.iter()
                .any(|h| h.line == 2 && &h.needle == n && h.file == "planted.toml"),
            "{n:?} not found: {hits:?}"
        );
        assert!(hits.iter().all(|h| h.line == 2), "{hits:?}");
    }
    assert!(scan("clean.rs", "nothing to see\nhere\n", &needles).is_empty());
}

#[test]
fn docs_links_are_recognised() {
    let text =
        "see docs/sar_reconstruction.md §4.\n(docs/numerics.md, \"x\")\nno docs/ page; docs/x.rs\n";
    assert_eq!(
        docs_links(text),
        vec![
            (1, "docs/sar_reconstruction.md".to_string()),
            (2, "docs/numerics.md".to_string())
        ]
    );
}
