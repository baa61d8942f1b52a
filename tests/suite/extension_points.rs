//! The walks of docs/contributing.md ("Where to add things") checked where
//! a test can: an extension point is one place when every variant of its
//! enum (every name of its table) is spelled out in the files the walk
//! names and nowhere else. A second file that matches over all variants
//! of an enum, or lists all names of a table, is a second list to keep in
//! step by hand, and fails here.
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Every library source file (tests left out: `tests.rs`, `*_tests.rs`
/// and whatever follows `#[cfg(test)]`; comment lines left out), as (path
/// under `src/`, text).
fn sources() -> Vec<(String, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).expect("src/ readable") {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    walk(&root, &mut files);
    files
        .into_iter()
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            name != "tests.rs" && !name.ends_with("_tests.rs")
        })
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("a source file");
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            // Comments name variants without being a list to keep in step.
            let text: String = code
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n");
            let rel = p.strip_prefix(&root).expect("under src/");
            (rel.to_string_lossy().replace('\\', "/"), text)
        })
        .collect()
}

/// The variants of `pub enum <name>` in `src/<file>`: the identifiers that
/// open a line at the enum's first indentation level.
fn variants(file: &str, name: &str) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(file);
    let text = std::fs::read_to_string(path).expect("the enum's file");
    let start = text
        .find(&format!("pub enum {name} {{"))
        .unwrap_or_else(|| panic!("pub enum {name} in src/{file}"));
    let body = &text[start..];
    let body = &body[body.find('\n').unwrap_or(0)..body.find("\n}").unwrap_or(body.len())];
    body.lines()
        .filter(|l| l.starts_with("    ") && !l.starts_with("     "))
        .map(str::trim)
        .filter(|l| l.starts_with(|c: char| c.is_ascii_uppercase()))
        .map(|l| {
            l.split(|c: char| !c.is_alphanumeric() && c != '_')
                .next()
                .unwrap_or("")
                .to_string()
        })
        .collect()
}

/// The files that spell out every one of `names`.
fn files_naming_all(names: &[String]) -> BTreeSet<String> {
    assert!(names.len() >= 2, "too few names to tell: {names:?}");
    sources()
        .into_iter()
        .filter(|(_, text)| names.iter().all(|n| text.contains(n.as_str())))
        .map(|(path, _)| path)
        .collect()
}

fn set(files: &[&str]) -> BTreeSet<String> {
    files.iter().map(|f| f.to_string()).collect()
}

/// Every `Enum::Variant` of `pub enum <name>` in `src/<file>`.
fn qualified(file: &str, name: &str) -> Vec<String> {
    variants(file, name)
        .into_iter()
        .map(|v| format!("{name}::{v}"))
        .collect()
}

#[test]
fn a_response_kind_is_three_files_one_per_layer() {
    let kinds = qualified("mbs/post/responses.rs", "ResponseKind");
    assert!(
        kinds.contains(&"ResponseKind::Crossing".to_string()),
        "{kinds:?}"
    );
    assert_eq!(
        files_naming_all(&kinds),
        set(&[
            "mbs/post/responses.rs",
            "scene/responses.rs",
            "simulate/responses.rs"
        ])
    );
    // The names: their text in mbs, the study's keys read into the
    // variant in scene (`kind_of`).
    let names = qualified("mbs/post/responses.rs", "ResponseKindName");
    assert_eq!(
        files_naming_all(&names),
        set(&["mbs/post/responses.rs", "scene/responses.rs"])
    );
}

#[test]
fn a_local_method_is_named_in_one_place() {
    let methods = qualified("explore/local/solvers.rs", "LocalMethod");
    assert!(methods.len() >= 3, "{methods:?}");
    assert_eq!(
        files_naming_all(&methods),
        set(&["explore/local/solvers.rs"])
    );
}

#[test]
fn an_integrator_method_is_named_in_one_place() {
    let methods = qualified("integrate/options.rs", "Method");
    assert!(
        methods.contains(&"Method::Tsit45".to_string()),
        "{methods:?}"
    );
    assert_eq!(files_naming_all(&methods), set(&["integrate/options.rs"]));
}

#[test]
fn a_test_problem_is_one_row_of_the_table() {
    let names: Vec<String> = plyscape::explore::problem::problems::TEST_PROBLEMS
        .iter()
        .map(|t| format!("\"{}\"", t.name))
        .collect();
    assert_eq!(
        files_naming_all(&names),
        set(&["explore/problem/problems.rs"])
    );
}

#[test]
fn a_section_is_one_entry_of_the_registry() {
    let keys: Vec<String> = plyscape::sections::registry::SECTIONS
        .iter()
        .map(|s| format!("\"{}\"", s.key))
        .collect();
    assert_eq!(files_naming_all(&keys), set(&["sections/registry.rs"]));
}
