//! Sizes that cannot fit are refused before anything is allocated: an
//! estimate of the memory a model size needs, compared with what the
//! machine has available (`MemAvailable` of `/proc/meminfo` on Linux; no
//! check where the figure is unknown).
//!
//! The estimates come from measured peaks (release build, 2-core x86_64
//! VM, `/usr/bin/time -f %M`), rounded up:
//! - a panel analysis (mesh, stiffness and mass, factorization, 14 modes
//!   and their derivatives) of the 1.994 m × 1.3 m SAR panel: 45 MB at 32
//!   divisions (4 152 DOF), 158 MB at 64 (15 984), 539 MB at 128
//!   (65 784), 1.22 GB at 192 (about 147 000): 8.2–10.9 KB per degree of
//!   freedom; estimated as 12 KB per node DOF (6 per mesh node);
//! - a closed-form beam body with `m` modes per plane (2m columns, lumped
//!   masses at ~19 m Gauss points): 113 MB at m = 200 and 398 MB at
//!   m = 400, ∝ m²: estimated as 2.6 KB · m² + 10 MB.

use crate::error::{Error, Result};

/// Bytes per panel degree of freedom (see the module doc).
pub const PANEL_BYTES_PER_DOF: f64 = 12.0e3;

/// Estimated bytes of a closed-form beam body with `m` modes per plane.
pub fn beam_bytes(m: usize) -> f64 {
    2.6e3 * (m as f64).powi(2) + 1.0e7
}

/// The memory the machine has available now \[bytes\], where known.
pub fn available_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Refuse `key = value` when `what` is estimated to need more than the
/// available memory (`available`, bytes; `None`: no check).
pub fn require_fits(
    key: &str,
    value: impl std::fmt::Display,
    what: &str,
    estimate: f64,
    available: Option<f64>,
) -> Result<()> {
    match available {
        Some(a) if estimate > a => Err(Error::input(
            key,
            value,
            format!(
                "a size that fits in memory: {what} needs about {:.1} GiB, \
                 this machine has {:.1} GiB available",
                estimate / GIB,
                a / GIB
            ),
        )),
        _ => Ok(()),
    }
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

#[cfg(test)]
mod tests {
    use super::*;

    // The panel estimate against the peak of real runs: the integration
    // test `panel_memory_estimate_bounds_the_measured_peak`.
    #[test]
    fn refusal_names_both_sizes() {
        let e = require_fits(
            "modes",
            100_000,
            "the beam",
            beam_bytes(100_000),
            Some(8.0 * GIB),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("`modes` = 100000") && e.contains("24214.4 GiB"),
            "{e}"
        );
        assert!(e.contains("8.0 GiB available"), "{e}");
        assert!(require_fits("modes", 4, "the beam", beam_bytes(4), Some(8.0 * GIB)).is_ok());
        assert!(require_fits("modes", 4, "the beam", 1e30, None).is_ok());
    }
}
