//! The key reference of the book (`docs/reference.md`) checked against
//! the keys the study sections accept, as the section registry generates
//! them (`plyscape::sections::registry::accepted_keys`).
//!
//! `docs/reference.md` is read as: a heading line holding a table path in
//! backticks and brackets (`` ### `[[scene.bodies]]` ``) sets the current
//! table; a table row whose first cell is a key in backticks
//! (`` | `name` | ... ``) names the key `<table>.<key>`.
use plyscape::sections::registry::accepted_keys;
use std::collections::BTreeSet;

/// The keys and the top-level tables `docs/reference.md` documents.
fn documented_keys(text: &str) -> (BTreeSet<String>, BTreeSet<String>) {
    let mut keys = BTreeSet::new();
    let mut tables = BTreeSet::new();
    let mut table: Option<String> = None;
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('#') {
            table = line
                .split('`')
                .skip(1)
                .step_by(2)
                .find(|s| s.starts_with('['))
                .map(|s| s.trim_matches(['[', ']']).to_string());
            if let Some(t) = &table {
                tables.insert(t.split('.').next().unwrap_or(t).to_string());
            }
        } else if let (Some(t), Some(row)) = (&table, line.strip_prefix("| `")) {
            if let Some(key) = row.split('`').next() {
                keys.insert(format!("{t}.{key}"));
            }
        }
    }
    (keys, tables)
}

#[test]
fn reference_lists_exactly_the_accepted_keys() {
    let (accepted, sections) = accepted_keys();
    let (documented, tables) = documented_keys(include_str!("../../docs/reference.md"));
    let missing: Vec<_> = accepted.difference(&documented).collect();
    let unknown: Vec<_> = documented.difference(&accepted).collect();
    assert!(
        missing.is_empty() && unknown.is_empty(),
        "docs/reference.md lacks {missing:?} and lists keys no section accepts: {unknown:?}"
    );
    assert_eq!(tables, sections, "sections in docs/reference.md");
}

#[test]
fn probe_finds_nested_tagged_and_free_keys() {
    let (keys, _) = accepted_keys();
    for k in [
        "scene.bodies.flexible.kind",
        "scene.forces.type",
        "scene.forces.segments.anchor",
        "scene.forces.table",
        "scene.integrator.method",
        "panels.material.e1",
        "multistart.mmfd.delobj",
        "evolve.restarts",
        "modes.reference_hz",
        "compare",
    ] {
        if k == "compare" {
            assert!(!keys.iter().any(|x| x.starts_with("compare.")));
        } else {
            assert!(keys.contains(k), "{k} not found in {keys:?}");
        }
    }
    assert!(!keys.iter().any(|k| k.contains('\u{0}')));
}

#[test]
fn reference_parser_reads_headings_and_rows() {
    let text = "## `[scene]`\n| key | type |\n|---|---|\n| `effects` | list |\n\
                ### `[[scene.bodies]]` (array)\n| `name` | string |\nplain | `x` |\n";
    let (keys, tables) = documented_keys(text);
    let want: BTreeSet<String> = ["scene.effects", "scene.bodies.name"]
        .map(String::from)
        .into();
    assert_eq!(keys, want);
    assert_eq!(tables, BTreeSet::from(["scene".to_string()]));
}
