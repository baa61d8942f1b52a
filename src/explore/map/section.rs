//! The `[map]` section ([`MapSection`]): the grid resolution, the
//! variable pairs drawn and the cells `--resume` evaluates again.

use crate::error::Result;
use crate::study::Study;
use serde::Deserialize;

/// The `[map]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSection {
    /// Grid points per axis (default 61).
    #[serde(default = "default_resolution")]
    pub resolution: usize,
    /// Variable pairs for more than two variables (default: consecutive
    /// pairs (0,1), (2,3), ...).
    pub pairs: Option<Vec<[usize; 2]>>,
    /// Cells evaluated again on `--resume` (default 2; see
    /// [`crate::explore::persist::fingerprint`]).
    #[serde(default = "default_resume_checks")]
    pub resume_checks: usize,
}

fn default_resolution() -> usize {
    61
}

fn default_resume_checks() -> usize {
    crate::explore::persist::fingerprint::DEFAULT_RESUME_CHECKS
}

/// Read and check `[map]` (default: 61 points per axis, consecutive pairs).
pub fn map_section(study: &Study) -> Result<MapSection> {
    let sec: MapSection = study.section("map")?.unwrap_or(MapSection {
        resolution: default_resolution(),
        pairs: None,
        resume_checks: default_resume_checks(),
    });
    if !(2..=2001).contains(&sec.resolution) {
        return Err(study.error("map.resolution", sec.resolution, "2 <= resolution <= 2001"));
    }
    Ok(sec)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_section_defaults_and_bounds() {
        let study = |text: &str| Study::parse("plan.toml", text).unwrap();
        let sec = map_section(&study("[problem]\nname = \"himmelblau\"\n")).unwrap();
        assert_eq!((sec.resolution, sec.pairs), (61, None));
        let e = map_section(&study("[map]\nresolution = 1\n")).unwrap_err();
        assert!(e.to_string().contains("map.resolution"), "{e}");
    }
}
