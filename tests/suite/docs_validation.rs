//! `docs/validation.md` names, for every accuracy number, the test that
//! enforces it (`` `mbs/andrews.rs::andrews_angles_...` ``, relative to
//! `tests/suite/`). This checks that each named test exists, so a renamed
//! or deleted test cannot leave a claim without its check.

use std::path::Path;

/// The `file.rs::function` references of a page, in order.
fn test_references(text: &str) -> Vec<(String, String)> {
    text.split('`')
        .skip(1)
        .step_by(2)
        .filter_map(|code| {
            let (file, func) = code.split_once(".rs::")?;
            let ok = |s: &str| {
                !s.is_empty()
                    && s.chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '/')
            };
            (ok(file) && ok(func) && !func.contains('/'))
                .then(|| (format!("{file}.rs"), func.to_string()))
        })
        .collect()
}

#[test]
fn every_test_named_in_validation_md_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let page = std::fs::read_to_string(root.join("docs/validation.md")).unwrap();
    let refs = test_references(&page);
    assert!(refs.len() > 50, "only {} test references found", refs.len());
    let mut missing = Vec::new();
    for (file, func) in &refs {
        let path = root.join("tests/suite").join(file);
        let found = std::fs::read_to_string(&path)
            .map(|src| src.contains(&format!("fn {func}(")))
            .unwrap_or(false);
        if !found {
            missing.push(format!("{file}::{func}"));
        }
    }
    assert!(
        missing.is_empty(),
        "docs/validation.md names tests that do not exist: {missing:?}"
    );
}

#[test]
fn references_are_read_from_code_spans_only() {
    let text = "| a | `mbs/sens.rs::fused_equals_staggered` | plain mbs/x.rs::y |\n\
                `src/lib.rs` and `cargo test` are not references";
    assert_eq!(
        test_references(text),
        [(
            "mbs/sens.rs".to_string(),
            "fused_equals_staggered".to_string()
        )]
    );
}
