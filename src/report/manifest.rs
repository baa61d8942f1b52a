//! `manifest.json`: the typed form of the file every command writes next to
//! its tables ([`super::record_command`]).
//!
//! The file is [`Manifest`] serialized through [`serde_json::Value`], so its
//! keys come out sorted as they always did; each command's entry under
//! `commands` is kept as JSON, since every command writes its own typed
//! entry (the exploration drivers' are in `explore::persist::manifest`).

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The shard of a multistart a results directory holds (`--shard i/n`;
/// `0/1` for an unsharded run).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardRecord {
    /// Shard index `i`, 0-based.
    pub index: usize,
    /// Shard count `n`.
    pub count: usize,
}

/// The whole `manifest.json`. Missing keys read as their defaults, so an
/// older manifest still gives its commands back.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Manifest {
    /// `CARGO_PKG_VERSION` of the writer.
    pub plyscape_version: String,
    /// [`super::GIT_COMMIT`] of the writer.
    pub git_commit: String,
    /// The study file as given on the command line.
    pub study_file: String,
    /// The study's name (the results directory's name).
    pub study_name: String,
    /// `[study] seed`.
    pub seed: u64,
    /// Worker threads of the last command.
    pub threads: usize,
    /// Versions of the crates in the build (`Cargo.lock`).
    pub crates: BTreeMap<String, String>,
    /// Written by the exploration drivers only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shard: Option<ShardRecord>,
    /// The command that wrote the file last.
    pub last_command: String,
    /// One entry per command on this study text, by command name.
    pub commands: BTreeMap<String, serde_json::Value>,
    /// The study text the tables come from.
    pub study_text: String,
}

impl Manifest {
    /// Read `dir/manifest.json`.
    pub fn read(dir: &Path) -> Result<Manifest> {
        let path = dir.join("manifest.json");
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        serde_json::from_str(&text).map_err(|e| Error::csv(&path, e))
    }

    /// The text of `manifest.json`: pretty JSON with sorted keys.
    pub fn to_text(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(&serde_json::to_value(self)?)
    }

    /// The entry of `command`, read as `T` (`None`: no such entry, or not
    /// of that form).
    pub fn entry<T: serde::de::DeserializeOwned>(&self, command: &str) -> Option<T> {
        serde_json::from_value(self.commands.get(command)?.clone()).ok()
    }
}

/// A serializable value as the JSON object of a manifest entry (an error
/// when it serializes to anything but an object).
pub fn entry_map<T: Serialize>(value: &T) -> Result<serde_json::Map<String, serde_json::Value>> {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::Object(m)) => Ok(m),
        Ok(other) => Err(Error::csv(
            "manifest.json",
            format!("an entry must be a JSON object, not {other}"),
        )),
        Err(e) => Err(Error::csv("manifest.json", e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifest_round_trips_with_sorted_keys() {
        let mut m = Manifest {
            plyscape_version: "0.1.0".into(),
            git_commit: "abc".into(),
            study_file: "studies/x.toml".into(),
            study_name: "x".into(),
            seed: 3,
            threads: 2,
            crates: [("rayon".to_string(), "1.10.0".to_string())].into(),
            shard: Some(ShardRecord { index: 1, count: 4 }),
            last_command: "map".into(),
            commands: BTreeMap::new(),
            study_text: "[study]\n".into(),
        };
        m.commands.insert(
            "map".into(),
            serde_json::json!({"resolution": 19, "threads": 2}),
        );
        let text = m.to_text().unwrap();
        assert_eq!(serde_json::from_str::<Manifest>(&text).unwrap(), m);
        let keys: Vec<usize> = ["commands", "crates", "git_commit", "last_command", "seed"]
            .iter()
            .map(|k| text.find(&format!("\"{k}\"")).unwrap())
            .collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]), "{text}");
        // Without a shard there is no `shard` key; a bare object reads back.
        m.shard = None;
        assert!(!m.to_text().unwrap().contains("shard"));
        let bare: Manifest = serde_json::from_str("{\"study_text\": \"t\"}").unwrap();
        assert_eq!((bare.study_text.as_str(), bare.commands.len()), ("t", 0));
        assert!(entry_map(&3).is_err());
    }
}
