//! The `[evolve]` section ([`EvolveSection`]) with its checked plan
//! ([`EvolvePlan`]: the restart schedules, [`schedules`]), and the
//! `[compare]` section ([`CompareSection`], no keys). Every check names
//! the study file and the dotted key it refuses.

use crate::error::{Error, Result};
use crate::optimize::cmaes::Restarts;
use crate::study::Study;
use serde::Deserialize;

/// The `[evolve]` section.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct EvolveSection {
    /// Evaluation budget of each schedule. Default: under `compare`, the
    /// function calls the multistart used; alone, 100 per start of
    /// `[multistart]`, else 10 000.
    pub max_evaluations: Option<usize>,
    /// CMA-ES restart schedule ([`crate::optimize::cmaes::Restarts`]):
    /// `ipop` (default), `bipop`, or a list of distinct names
    /// (`["ipop", "bipop"]`), run one after another on the same budget and
    /// seed; read by [`schedules`].
    pub restarts: Option<toml::Value>,
    /// CMA-ES TolFun: a run restarts when its best f of the recent
    /// generations and every f of the current one lie within this range.
    /// Default 1e-12, for exact objectives; an objective from a simulation
    /// carries the integrator's noise (adaptive steps: about 1e-8 of f at
    /// rtol 1e-6), below which no progress is real, and a run whose f
    /// never settles within 1e-12 never restarts: set it above the noise.
    pub tol_fun: Option<f64>,
    /// Stop a schedule when a design feasible to the tolerance reaches
    /// `f <= target` (stop reason `target_reached`). Default: none.
    pub target: Option<f64>,
    /// Active CMA-ES (negative weights for the worst samples). Default
    /// false.
    #[serde(default)]
    pub active: bool,
}

/// A checked `[evolve]`.
#[derive(Debug, Clone)]
pub struct EvolvePlan {
    /// The section.
    pub section: EvolveSection,
    /// The restart schedules, in the order they run (at least one).
    pub schedules: Vec<Restarts>,
}

/// Read and check `[evolve]` (absent: defaults). Errors name the file and
/// `evolve.<key>`.
pub fn evolve_plan(study: &Study) -> Result<EvolvePlan> {
    let section: EvolveSection = study.section("evolve")?.unwrap_or_default();
    if section.max_evaluations == Some(0) {
        return Err(study.error("evolve.max_evaluations", 0, "a budget >= 1"));
    }
    if let Some(t) = section.tol_fun {
        if !(t.is_finite() && t >= 0.0) {
            return Err(study.error("evolve.tol_fun", t, "a finite range >= 0"));
        }
    }
    if let Some(t) = section.target {
        if !t.is_finite() {
            return Err(study.error("evolve.target", t, "a finite objective value"));
        }
    }
    let schedules = schedules(section.restarts.as_ref()).map_err(study.locate("evolve"))?;
    Ok(EvolvePlan { section, schedules })
}

/// The schedules of a `restarts` value: absent, IPOP; a name, that
/// schedule; a non-empty list of distinct names, those in order. Errors
/// name the key `restarts` (`restarts[k]` for the k-th list entry).
pub fn schedules(value: Option<&toml::Value>) -> Result<Vec<Restarts>> {
    let names = Restarts::NAMES;
    let list = match value {
        None => return Ok(vec![Restarts::default()]),
        Some(toml::Value::String(name)) => return Ok(vec![Restarts::parse(name)?]),
        Some(toml::Value::Array(list)) if !list.is_empty() => list,
        Some(other) => {
            return Err(Error::input(
                "restarts",
                other,
                format!(
                    "one of {names}, or a non-empty list of them (\"ipop\", [\"ipop\", \"bipop\"])"
                ),
            ))
        }
    };
    let mut out: Vec<Restarts> = Vec::new();
    for (k, v) in list.iter().enumerate() {
        let key = format!("restarts[{k}]");
        let r = v
            .as_str()
            .and_then(|name| Restarts::parse(name).ok())
            .ok_or_else(|| Error::input(&key, v, format!("one of {names}")))?;
        if let Some(j) = out.iter().position(|&earlier| earlier == r) {
            return Err(Error::input(
                key,
                v,
                format!("each schedule once (it is restarts[{j}] already)"),
            ));
        }
        out.push(r);
    }
    Ok(out)
}

/// The `[compare]` section (no keys).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CompareSection {}

/// Read `[compare]` (no keys; absent is fine).
pub fn compare_section(study: &Study) -> Result<Option<CompareSection>> {
    study.section::<CompareSection>("compare")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn study(text: &str) -> Study {
        Study::parse("plan.toml", text).unwrap()
    }

    const HIMMELBLAU: &str = "[study]\nseed = 7\n[problem]\nname = \"himmelblau\"\n";

    #[test]
    fn evolve_plan_reads_schedules_and_refuses_repeats() {
        let s = study(HIMMELBLAU);
        let plan = evolve_plan(&s).unwrap();
        assert_eq!(plan.schedules, [Restarts::Ipop]);
        let s = study(&format!(
            "{HIMMELBLAU}[evolve]\nrestarts = [\"bipop\", \"ipop\"]\n"
        ));
        assert_eq!(
            evolve_plan(&s).unwrap().schedules,
            [Restarts::Bipop, Restarts::Ipop]
        );
        let s = study(&format!(
            "{HIMMELBLAU}[evolve]\nrestarts = [\"ipop\", \"ipop\"]\n"
        ));
        let e = evolve_plan(&s).unwrap_err().to_string();
        assert!(
            e.contains("evolve.restarts[1]") && e.contains("restarts[0]"),
            "{e}"
        );
        let s = study(&format!(
            "{HIMMELBLAU}[evolve]\ntarget = 1e-6\nactive = true\n"
        ));
        let plan = evolve_plan(&s).unwrap();
        assert_eq!(
            (plan.section.target, plan.section.active),
            (Some(1e-6), true)
        );
        let s = study(&format!("{HIMMELBLAU}[evolve]\ntarget = nan\n"));
        let e = evolve_plan(&s).unwrap_err().to_string();
        assert!(e.contains("evolve.target"), "{e}");
        let s = study(&format!("{HIMMELBLAU}[evolve]\nmax_evaluations = 0\n"));
        let e = evolve_plan(&s).unwrap_err().to_string();
        assert!(e.contains("evolve.max_evaluations"), "{e}");
    }
}
