//! The exploration drivers' entries in `manifest.json`, typed.
//!
//! Every driver entry is a [`DriverEntry`]: the threads and the resume flag
//! of the invocation, the study's fingerprint
//! ([`super::fingerprint::Fingerprint`], what `--resume` compares), then the command's own fields flattened beside them
//! ([`MultistartEntry`], [`EvolveEntry`], [`MapEntry`],
//! [`OptimumReportEntry`], [`MergeEntry`]). The file around them is
//! [`crate::report::manifest::Manifest`]; `started` and `ended` are added by
//! [`crate::report::record_command`].

use super::fingerprint::Fingerprint;
use serde::{Deserialize, Serialize};

/// A driver's entry: the invocation's threads and `--resume`, the study's
/// fingerprint, and the command's own fields `detail` at the same level.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DriverEntry<D> {
    /// Worker threads.
    pub threads: usize,
    /// `--resume` given.
    pub resume: bool,
    /// The fingerprint of the study the command ran
    /// ([`crate::explore::persist::fingerprint`]; absent in manifests written before them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fingerprint: Option<Fingerprint>,
    /// The command's fields.
    #[serde(flatten)]
    pub detail: D,
}

/// `multistart`: written with `complete = false` and no counts before the
/// runs start, then again with the counts when they end.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MultistartEntry {
    /// Every start this invocation owns has its row (or the function-call
    /// budget stopped the runs).
    pub complete: bool,
    /// The counts of a finished invocation.
    #[serde(flatten)]
    pub counts: Option<MultistartCounts>,
}

/// The counts of a finished multistart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MultistartCounts {
    /// Start points of the study (all shards).
    pub starts: usize,
    /// Rows in `runs.csv`.
    pub runs_in_tables: usize,
    /// Runs made by this invocation (the rest were read back).
    pub runs_this_invocation: usize,
    /// Function calls of the feasibility filter of the starts.
    pub filter_evaluations: usize,
    /// Wall time of the runs \[s\].
    pub wall_seconds: f64,
    /// How the runs in the tables ended, by class.
    #[serde(default)]
    pub classes: super::tables::ClassCounts,
    /// The study's one feasibility tolerance (certificate, CTMIN, CMA-ES).
    #[serde(default)]
    pub feasibility_tolerance: f64,
    /// Infeasible runs checked by a pure descent on the violation, and how
    /// many of those descents reached the feasible set.
    #[serde(default)]
    pub violation_checks: (usize, usize),
    /// The integration tolerance of a scene problem's evaluations (absent
    /// for a closed-form problem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// The noise measured at the first start (`[multistart] noise =
    /// "measured"`; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<NoiseRecord>,
    /// What the problem's evaluations reported ([`crate::optimize::Problem::notes`]:
    /// a mode count that split a repeated eigenvalue at some lay-up).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// The noise of the evaluation measured at one design (ECNoise,
/// [`crate::optimize::noise`]); a failed estimate is its reason, with σ
/// absent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseRecord {
    /// The design.
    pub x: Vec<f64>,
    /// σ of f (absent when the estimate failed).
    pub sigma_f: Option<f64>,
    /// σ of f relative to |f|.
    pub relative_f: Option<f64>,
    /// `level`, `h_too_small` or `h_too_large`.
    pub status_f: String,
    /// σ of each constraint (absent where its estimate failed).
    pub sigma_g: Vec<Option<f64>>,
    /// The allowance the runs' ends were settled with (relative to
    /// `max(|f|, 1)`).
    pub allowance: f64,
    /// Function calls spent on the measurement.
    pub evaluations: usize,
}

impl NoiseRecord {
    /// The record of `m`.
    pub fn of(m: &crate::optimize::noise::Measured) -> NoiseRecord {
        NoiseRecord {
            x: m.x.clone(),
            sigma_f: m.noise_f.sigma(),
            relative_f: m.relative_f(),
            status_f: m.noise_f.failure().unwrap_or("level").into(),
            sigma_g: m.noise_g.iter().map(|n| n.sigma()).collect(),
            allowance: m.allowance(),
            evaluations: m.evaluations,
        }
    }
}

/// `evolve`: the budget and TolFun, and the schedules.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvolveEntry {
    /// Function-call budget of each schedule.
    pub max_evaluations: usize,
    /// CMA-ES TolFun.
    pub tol_fun: f64,
    /// Evaluations served from the journal of a killed run (`run
    /// --resume`; absent when none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replayed: Option<usize>,
    /// One schedule's fields, or the list of several.
    #[serde(flatten)]
    pub schedules: EvolveSchedules,
}

/// The schedules of an `evolve` entry. One schedule's keys stand at the top
/// of the entry (as before lists existed); several are under `schedules`,
/// with `restarts` listing their names and `wall_seconds` their total.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum EvolveSchedules {
    /// A single schedule.
    One(ScheduleEntry),
    /// Several schedules, in the order they ran.
    Many {
        /// Summed wall time \[s\].
        wall_seconds: f64,
        /// The schedules' `restarts` names.
        restarts: Vec<String>,
        /// Each schedule's entry.
        schedules: Vec<ScheduleEntry>,
    },
}

/// One CMA-ES schedule of `evolve`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScheduleEntry {
    /// Method name as in `comparison.csv` (`cmaes`, `cmaes-bipop`).
    pub method: String,
    /// Solver name (`IPOP-CMA-ES`, `BIPOP-CMA-ES`).
    pub solver: String,
    /// `[evolve] restarts` name (`ipop`, `bipop`).
    pub restarts: String,
    /// Function calls.
    pub function_calls: usize,
    /// Wall time \[s\].
    pub wall_seconds: f64,
    /// Runs of the large-population regime.
    pub large_runs: usize,
    /// Runs of the small-population regime.
    pub small_runs: usize,
    /// Every CMA-ES run, in order.
    pub runs: Vec<CmaesRunEntry>,
}

/// One CMA-ES run between restarts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CmaesRunEntry {
    /// `large` or `small`.
    pub regime: String,
    /// Population size λ.
    pub lambda: usize,
    /// Initial step size, as a fraction of each variable's range.
    pub sigma0: f64,
    /// Function evaluations of the run.
    pub evaluations: usize,
    /// Generations of the run.
    pub generations: usize,
}

/// `map`: written with `complete = false` before the first cell, then
/// again when every table is whole.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapEntry {
    /// Every slice's table has all its cells (absent in manifests written
    /// before resumable maps, which wrote the entry at the end only).
    #[serde(default = "whole")]
    pub complete: bool,
    /// Grid points per axis.
    pub resolution: usize,
    /// With more than two variables: the design the slices pass through
    /// (each held variable's value, by name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slices_through: Option<std::collections::BTreeMap<String, f64>>,
}

fn whole() -> bool {
    true
}

/// `optimum_report`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OptimumReportEntry {
    /// The reported start index.
    pub start: usize,
    /// The files written, by name.
    pub files: Vec<String>,
    /// Wall time of the report \[s\].
    pub wall_seconds: f64,
}

/// `merge`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MergeEntry {
    /// Always true: a merge takes finished shards only.
    pub complete: bool,
    /// The shard directories merged.
    pub merged_from: Vec<String>,
    /// The longest shard's multistart wall time \[s\].
    pub wall_seconds: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn schedule(restarts: &str, calls: usize) -> ScheduleEntry {
        ScheduleEntry {
            method: "cmaes".into(),
            solver: "IPOP-CMA-ES".into(),
            restarts: restarts.into(),
            function_calls: calls,
            wall_seconds: 0.25,
            large_runs: 1,
            small_runs: 0,
            runs: vec![CmaesRunEntry {
                regime: "large".into(),
                lambda: 6,
                sigma0: 0.3,
                evaluations: calls,
                generations: calls / 6,
            }],
        }
    }

    #[test]
    fn entries_serialize_flat_and_round_trip() {
        let first = DriverEntry {
            threads: 2,
            resume: false,
            fingerprint: None,
            detail: MultistartEntry {
                complete: false,
                counts: None,
            },
        };
        let v = serde_json::to_value(&first).unwrap();
        assert_eq!(v, json!({"threads": 2, "resume": false, "complete": false}));
        assert_eq!(
            serde_json::from_value::<DriverEntry<MultistartEntry>>(v).unwrap(),
            first
        );
        let done = DriverEntry {
            threads: 2,
            resume: true,
            fingerprint: None,
            detail: MultistartEntry {
                complete: true,
                counts: Some(MultistartCounts {
                    starts: 64,
                    runs_in_tables: 64,
                    runs_this_invocation: 10,
                    filter_evaluations: 0,
                    wall_seconds: 90.5,
                    classes: crate::explore::persist::tables::ClassCounts {
                        runs: 64,
                        converged: 40,
                        stopped: 3,
                        infeasible: 20,
                        infeasible_stationary: 18,
                        infeasible_stalled: 1,
                        failed: 1,
                    },
                    feasibility_tolerance: 1e-6,
                    violation_checks: (8, 1),
                    rtol: Some(1e-7),
                    noise: Some(NoiseRecord {
                        x: vec![55.0, -55.0],
                        sigma_f: None,
                        relative_f: None,
                        status_f: "h_too_large".into(),
                        sigma_g: vec![Some(2e-8)],
                        allowance: 3e-8,
                        evaluations: 24,
                    }),
                    notes: vec![],
                }),
            },
        };
        let v = serde_json::to_value(&done).unwrap();
        assert_eq!(v["runs_this_invocation"], 10);
        assert_eq!(v["wall_seconds"], 90.5);
        assert_eq!(
            serde_json::from_value::<DriverEntry<MultistartEntry>>(v).unwrap(),
            done
        );
    }

    #[test]
    fn evolve_entry_keeps_one_schedule_at_the_top_and_lists_several() {
        let one = EvolveEntry {
            replayed: None,
            max_evaluations: 600,
            tol_fun: 1e-12,
            schedules: EvolveSchedules::One(schedule("ipop", 600)),
        };
        let v = serde_json::to_value(&one).unwrap();
        assert_eq!(v["restarts"], "ipop");
        assert_eq!(v["runs"][0]["lambda"], 6);
        assert!(v.get("schedules").is_none());
        assert_eq!(serde_json::from_value::<EvolveEntry>(v).unwrap(), one);
        let many = EvolveEntry {
            replayed: None,
            max_evaluations: 600,
            tol_fun: 1e-6,
            schedules: EvolveSchedules::Many {
                wall_seconds: 0.5,
                restarts: vec!["ipop".into(), "bipop".into()],
                schedules: vec![schedule("ipop", 600), schedule("bipop", 594)],
            },
        };
        let v = serde_json::to_value(&many).unwrap();
        assert_eq!(v["restarts"], json!(["ipop", "bipop"]));
        assert_eq!(v["schedules"][1]["function_calls"], 594);
        assert_eq!(serde_json::from_value::<EvolveEntry>(v).unwrap(), many);
    }
}
