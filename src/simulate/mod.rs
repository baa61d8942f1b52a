//! `plyscape simulate`: make a built scene's initial state consistent,
//! integrate, and write `history.csv` (time + outputs, SI units in the
//! header), `stats.csv` and an SVG of one output.
//!
//! A numerical failure during the integration (a step size underflow, a
//! non-finite output, the divergence guard of `crate::mbs::watch`)
//! keeps the rows computed before it: [`simulate_partial`] returns them
//! with the failure in [`Simulation::failure`], [`write_results`] writes
//! them with the failure in `stats.csv`. A scene in which nothing moves
//! (no body, or every body fixed) is not integrated: its constant state
//! is written at the output times.

use crate::error::{Error, Result};
use crate::integrate::{integrate_sens_stepped, integrate_stepped, Stats, Step, StepWatch};
use crate::mbs::post::energy::EnergyMonitor;
use crate::mbs::responses::ResponseValue;
use crate::mbs::Projection;
use crate::mbs::{Energy, Param, Reaction, System, Workspace};
use crate::report::csv::{sci, write_table};
use crate::report::{line_plot, Axes, Curve};
use crate::scene::quantity::QuantityKind;
use crate::scene::{Quantity, Scene};
use num_dual::Dual64;
use std::path::{Path, PathBuf};

mod continuous;
mod responses;
pub mod sampled;
pub mod spin;
pub mod weak;

/// Everything a simulation produced.
#[derive(Debug)]
pub struct Simulation {
    /// Headers of `history.csv` (`t [s]`, then every output with units).
    pub headers: Vec<String>,
    /// One row per output time: `[t, outputs..]`.
    pub rows: Vec<Vec<f64>>,
    /// Final state.
    pub y_end: Vec<f64>,
    /// The consistent initial state's projection (rank, dependent rows).
    pub projection: Projection,
    /// Integrator statistics.
    pub stats: Stats,
    /// Largest `|Φ|` over the output times.
    pub max_violation: f64,
    /// Largest energy change relative to a scale that does not vanish,
    /// `max |E − E0| / max(|E|, T, range of V)` over the run
    /// ([`EnergyMonitor`]), when the scene is conservative.
    pub energy_error: Option<f64>,
    /// Redundant equations (equations − rank) at the start.
    pub redundant: usize,
    /// The rows the kernel found dependent at the start and leaves out of
    /// the solve ([`Projection::dependent`]), labelled `<joint>.<equation>`
    /// ([`crate::mbs::Model::row_label`]). Which rows of a redundant set
    /// are named depends on the elimination order; their number and the
    /// motion do not.
    pub redundant_rows: Vec<String>,
    /// Number of constraint equations at the start.
    pub equations: usize,
    /// Headers of the output sensitivities (`t` first); only `t` when the
    /// scene asks for none.
    pub sens_headers: Vec<String>,
    /// One row per output time: `[t, ∂outputs/∂p_1.., ∂outputs/∂p_2..]`.
    pub sens_rows: Vec<Vec<f64>>,
    /// The scene's response functionals with their sensitivities (none
    /// after a failure).
    pub responses: Vec<ResponseValue>,
    /// Redundancy events: times the dropped constraint rows were chosen
    /// anew because one of them drifted ([`crate::mbs::watch`]).
    pub row_events: u64,
    /// The numerical failure that ended the integration early
    /// ([`simulate_partial`]); the rows are those computed before it.
    pub failure: Option<Error>,
    /// Warnings raised during the run: constraint rows nearly dependent
    /// at the start ([`weak`]), a flexible body turning fast without
    /// geometric stiffening ([`spin`]).
    pub warnings: Vec<String>,
}

/// The bound on the violation of a dropped constraint row, in units of
/// the integrator's absolute tolerance ([`crate::mbs::watch`]).
pub const ROW_BOUND_ATOL: f64 = 10.0;

/// Simulate a built scene (no files written); a numerical failure during
/// the integration is an error (the rows so far are dropped; see
/// [`simulate_partial`] to keep them).
pub fn simulate(scene: &Scene) -> Result<(System, Simulation)> {
    let (sys, mut sim) = simulate_partial(scene)?;
    match sim.failure.take() {
        Some(e) => Err(e),
        None => Ok((sys, sim)),
    }
}

/// Simulate a built scene (no files written), keeping the output rows
/// (and sensitivity rows) computed before a numerical failure of the
/// integration: the failure is [`Simulation::failure`] and the responses
/// are empty. Errors before the integration (an inconsistent initial
/// state) are returned as errors.
pub fn simulate_partial(scene: &Scene) -> Result<(System, Simulation)> {
    let mut sys = System::new(scene.model.clone());
    let mut y0 = sys.initial_state();
    let projection = sys.project(scene.options.t0, &mut y0)?;
    sys.drop_rows(&projection.dependent);
    sys.watch_rows(ROW_BOUND_ATOL * scene.options.atol);
    let weak = weak::warning(&weak::weak_rows(&sys, scene.options.t0, &y0));
    let mut headers = vec!["t [s]".to_string()];
    for (label, q) in &scene.outputs {
        headers.extend(q.headers(label));
    }
    let mut ws = Workspace::<f64>::empty();
    let e0 = sys.energy(&y0, &mut ws);
    let conservative = sys.conservative();
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut max_violation = 0.0f64;
    let mut energy_monitor = EnergyMonitor::new(e0);
    let mut y_end = y0.clone();
    let wants_reactions = scene
        .outputs
        .iter()
        .any(|(_, q)| q.kind == QuantityKind::Reaction);
    let angle_columns = angle_columns(scene);
    let sens_quantities = sens_quantities(scene);
    let sens_headers = sens_headers(scene, &sens_quantities);
    let mut sens_rows = Vec::new();
    let n = y0.len();
    // The final sensitivities (for integral responses).
    let mut s_end = vec![0.0; n * scene.params.len()];
    let mut continuous = continuous::Continuous::new(&scene.responses);
    let mut spin = spin::SpinWatch::new(&sys);
    let mut within =
        |step: &Step<'_>| continuous.step((&sys, &scene.responses), (&scene.params, n), step);
    let mut observe = |t: f64, y: &[f64], s: &[f64]| {
        spin.observe(&sys, t, y);
        if !s.is_empty() {
            s_end.copy_from_slice(s);
        }
        if !scene.params.is_empty() {
            let mut row = vec![t];
            for (i, (_, p)) in scene.params.iter().enumerate() {
                let lane = &s[i * n..(i + 1) * n];
                row.extend(output_sensitivities(&sys, &sens_quantities, y, (lane, *p)));
            }
            sens_rows.push(row);
        }
        // The reactions' solve assembles the constraint rows at (t, y):
        // the violation is read from them instead of a second assembly.
        let reactions = wants_reactions.then(|| sys.reactions(t, y, &mut ws));
        let viol = if wants_reactions {
            ws.rows.iter().fold(0.0f64, |m, r| m.max(r.phi.abs()))
        } else {
            sys.violation(t, y, &mut ws)
        };
        max_violation = max_violation.max(viol);
        if conservative {
            energy_monitor.observe(&sys, y, &mut ws);
        }
        let mut row = output_row(&sys, scene, (t, y), &mut ws, reactions.as_deref(), viol);
        if let Some(prev) = rows.last() {
            unwrap_angles(&mut row, prev, &angle_columns);
        }
        if let Some(k) = row.iter().position(|v| !v.is_finite()) {
            return Err(Error::numerical_at(
                "simulate: outputs",
                t,
                format!("column {k} is not finite"),
            ));
        }
        rows.push(row);
        y_end.copy_from_slice(y);
        Ok(())
    };
    let run = run_scene(&sys, scene, &y0, (&mut observe, &mut within));
    let (stats, failure) = failure_of(&sys, run)?;
    let responses = if failure.is_none() {
        let end = responses::RunEnd {
            continuous: &continuous,
            y_end: &y_end,
            s_end: &s_end,
        };
        responses::evaluate_all(scene, &sys, &end)?
    } else {
        Vec::new()
    };
    let sim = Simulation {
        headers,
        rows,
        y_end,
        redundant: projection.equations - projection.rank,
        redundant_rows: projection
            .dependent
            .iter()
            .map(|&r| sys.model.row_label(r).unwrap_or_else(|| format!("row {r}")))
            .collect(),
        equations: projection.equations,
        projection,
        stats,
        max_violation,
        energy_error: conservative.then(|| energy_monitor.error()),
        sens_headers,
        sens_rows,
        responses,
        row_events: sys.counters.row_events.get(),
        failure,
        warnings: weak.into_iter().chain(spin.warnings).collect(),
    };
    Ok((sys, sim))
}

/// Integrate the scene from `y0`, with its sensitivities when it has
/// parameters, calling `observe(t, y, s)` at every output time and
/// `within` with every accepted step. A scene in which nothing moves is
/// not integrated: its constant state is observed at the output times and
/// makes one step over the run.
fn run_scene(
    sys: &System,
    scene: &Scene,
    y0: &[f64],
    (mut observe, within): (
        impl FnMut(f64, &[f64], &[f64]) -> Result<()>,
        &mut StepWatch<'_>,
    ),
) -> Result<Stats> {
    if sys.nb() == 0 {
        // Nothing moves: the state (integrals of zero energies included)
        // is constant; an integrator would not start on it.
        scene.options.validate().and_then(|_| {
            let s0 = vec![0.0; y0.len() * scene.params.len()];
            for &t in &scene.options.times {
                observe(t, y0, &s0)?;
            }
            let times = &scene.options.times;
            let (t0, t1) = (scene.options.t0, times.last().copied().unwrap_or(0.0));
            if t1 > t0 {
                let dense = |_t: f64| Ok((y0.to_vec(), s0.clone()));
                within(&Step::constant((t0, t1), &dense))?;
            }
            Ok(Stats::default())
        })
    } else if scene.params.is_empty() {
        integrate_stepped(sys, y0, &scene.options, |t, y| observe(t, y, &[]), within)
    } else {
        let params: Vec<Param> = scene.params.iter().map(|(_, p)| *p).collect();
        integrate_sens_stepped(sys, y0, &scene.options, &params, &mut observe, within)
    }
}

/// The statistics of a run and the numerical failure that ended it
/// early, if one did (the rows before it are kept); any other error is
/// returned.
fn failure_of(sys: &System, run: Result<Stats>) -> Result<(Stats, Option<Error>)> {
    match run {
        Ok(stats) => Ok((stats, None)),
        Err(Error::Numerical {
            place,
            time,
            detail,
        }) => {
            // A joint-load prestress iteration that did not converge names
            // its time and bodies.
            let detail = match sys.counters.prestress_failure.borrow().as_ref() {
                Some((t, what)) => format!("{detail}; at t = {t} s {what}"),
                None => detail,
            };
            Ok((
                Stats::default(),
                Some(Error::Numerical {
                    place,
                    time,
                    detail,
                }),
            ))
        }
        Err(e) => Err(e),
    }
}

/// Columns of `history.csv` that hold joint angles (column 0 is time).
fn angle_columns(scene: &Scene) -> Vec<usize> {
    let mut out = Vec::new();
    let mut col = 1;
    for (label, q) in &scene.outputs {
        if q.kind == QuantityKind::Angle {
            out.push(col);
        }
        col += q.headers(label).len();
    }
    out
}

/// Make the joint angles of `row` continuous with the previous row: a
/// relative angle is measured in (−π, π] (module doc of `crate::mbs`), so
/// a joint turning past ±π would jump by 2π between rows; the multiple of
/// 2π nearest to the previous value is added instead. Outputs are sampled
/// finely enough that a joint turns less than π between two rows.
fn unwrap_angles(row: &mut [f64], prev: &[f64], columns: &[usize]) {
    let turn = 2.0 * std::f64::consts::PI;
    for &c in columns {
        row[c] += turn * ((prev[c] - row[c]) / turn).round();
    }
}

/// The output columns that have sensitivities (by the table of
/// [`QuantityKind`]: angles, rates, joint displacements and velocities,
/// positions, modal coordinates, strain and kinetic energies, deflections).
fn sens_quantities(scene: &Scene) -> Vec<(String, Quantity)> {
    scene
        .outputs
        .iter()
        .filter(|(_, q)| q.kind.info().sensitivity)
        .cloned()
        .collect()
}

/// Headers of `sensitivities.csv`: `t [s]`, then per parameter the
/// derivative of every output of `quantities`, with units.
fn sens_headers(scene: &Scene, quantities: &[(String, Quantity)]) -> Vec<String> {
    let mut headers = vec!["t [s]".to_string()];
    for (pname, _) in &scene.params {
        for (label, q) in quantities {
            for h in q.headers(label) {
                let (name, unit) = h.split_once(" [").unwrap_or((h.as_str(), "-]"));
                let unit = unit.trim_end_matches(']');
                headers.push(format!("d({name})/d({pname}) [{unit} per SI unit of p]"));
            }
        }
    }
    headers
}

/// One row of `history.csv` at `(t, y)`: the scene's outputs, with the
/// reactions and the violation already computed at that state.
fn output_row(
    sys: &System,
    scene: &Scene,
    at: (f64, &[f64]),
    ws: &mut Workspace<f64>,
    reactions: Option<&[Reaction]>,
    viol: f64,
) -> Vec<f64> {
    let (t, y) = at;
    let mut row = vec![t];
    for (_, q) in &scene.outputs {
        let (i, n) = (q.of, q.modes);
        match q.kind {
            QuantityKind::Angle => row.push(sys.angle(y, i, ws).0),
            QuantityKind::Rate => row.push(sys.angle(y, i, ws).1),
            QuantityKind::Displacement => row.push(sys.slide(y, i, ws).0),
            QuantityKind::Velocity => row.push(sys.slide(y, i, ws).1),
            QuantityKind::Reaction => {
                let r = reactions.map(|r| r[i]).unwrap_or(Reaction {
                    force: Default::default(),
                    torque: Default::default(),
                });
                row.extend(r.force.iter().chain(r.torque.iter()));
            }
            QuantityKind::Position => match sys.slot[i] {
                Some(s) => {
                    let p = sys.pos_off(s);
                    row.extend_from_slice(&y[p..p + 3])
                }
                None => row.extend(sys.model.bodies[i].r0.iter()),
            },
            QuantityKind::Modal => match sys.slot[i] {
                Some(s) => {
                    let p = sys.pos_off(s) + 7;
                    row.extend_from_slice(&y[p..p + n])
                }
                None => row.extend(std::iter::repeat_n(0.0, n)),
            },
            QuantityKind::StrainEnergy => {
                row.push(sys.slot[i].map_or(0.0, |s| sys.strain_energy(y, s)))
            }
            QuantityKind::KineticEnergy | QuantityKind::TotalKineticEnergy => {
                row.push(sys.energy_sum(&kinetic_terms(sys, q), y, ws))
            }
            QuantityKind::Deflection => row.extend(sys.deflection(y, i).iter()),
            QuantityKind::Energy => row.push(sys.energy(y, ws)),
            QuantityKind::Violation => row.push(viol),
        }
    }
    row
}

/// Exact derivatives of the outputs along the state sensitivity
/// `s = ∂y/∂p` of parameter `p`: one dual-number evaluation of each output
/// at `y + ε s` (with the design seed of `p` when it is a ply-angle
/// variable, so that `dX/dθ` and `dΛ/dθ` enter explicitly).
fn output_sensitivities(
    sys: &System,
    quantities: &[(String, Quantity)],
    y: &[f64],
    lane: (&[f64], Param),
) -> Vec<f64> {
    let (s, param) = lane;
    let yd: Vec<Dual64> = y.iter().zip(s).map(|(&a, &b)| Dual64::new(a, b)).collect();
    let seeds = vec![(
        param,
        Dual64::new(param.value(&sys.model).unwrap_or(0.0), 1.0),
    )];
    let mut kin = Vec::new();
    sys.body_kin(&yd, &seeds, &mut kin);
    let mut out = Vec::new();
    for (_, q) in quantities {
        let (i, n) = (q.of, q.modes);
        match q.kind {
            QuantityKind::Angle => out.push(sys.joint_angle(&kin, i).0.eps),
            QuantityKind::Rate => out.push(sys.joint_angle(&kin, i).1.eps),
            QuantityKind::Displacement => out.push(sys.joint_slide(&kin, i).0.eps),
            QuantityKind::Velocity => out.push(sys.joint_slide(&kin, i).1.eps),
            QuantityKind::Position => match sys.slot[i] {
                Some(k) => {
                    let p = sys.pos_off(k);
                    out.extend_from_slice(&s[p..p + 3])
                }
                None => out.extend([0.0; 3]),
            },
            QuantityKind::Modal => match sys.slot[i] {
                Some(k) => {
                    let p = sys.pos_off(k) + 7;
                    out.extend_from_slice(&s[p..p + n])
                }
                None => out.extend(std::iter::repeat_n(0.0, n)),
            },
            QuantityKind::StrainEnergy => out.push(match sys.slot[i] {
                Some(k) => sys.strain_energy_dual(&yd, k, &kin[k].design).eps,
                None => 0.0,
            }),
            QuantityKind::KineticEnergy | QuantityKind::TotalKineticEnergy => {
                let mut ws = Workspace::empty();
                ws.params = seeds.clone();
                out.push(sys.energy_sum(&kinetic_terms(sys, q), &yd, &mut ws).eps);
            }
            QuantityKind::Deflection => {
                let d = sys.deflection_kin(&kin, i);
                out.extend(d.iter().map(|v| v.eps));
            }
            // No sensitivities (`QuantityKind::info`): not in `quantities`.
            QuantityKind::Reaction | QuantityKind::Energy | QuantityKind::Violation => {}
        }
    }
    out
}

/// The kinetic energy terms of output `<body>.kinetic_energy` (one body)
/// or `kinetic_energy` (every body).
fn kinetic_terms(sys: &System, q: &Quantity) -> Vec<Energy> {
    match q.kind {
        QuantityKind::TotalKineticEnergy => Energy::kinetic_total(&sys.model),
        _ => vec![Energy::Kinetic(q.of)],
    }
}

/// Write `history.csv`, `stats.csv`, `sensitivities.csv` and
/// `responses.csv` (when the scene has them) and (if asked)
/// `<plot_file or output>.svg` into `dir`, through [`crate::report`].
/// Every file holds only what the same build reproduces bit for bit: the
/// wall-clock times (`Stats::wall`, `Stats::observer_wall`) go to the
/// command's entry in `manifest.json` (see `cli::run_scene`), so a rerun
/// of a committed study leaves its tables unchanged.
pub fn write_results(scene: &Scene, sim: &Simulation, dir: &Path) -> Result<Vec<PathBuf>> {
    let sci_rows = |rows: &[Vec<f64>]| -> Vec<Vec<String>> {
        rows.iter()
            .map(|r| r.iter().map(|v| sci(*v, 12)).collect())
            .collect()
    };
    let hist = dir.join("history.csv");
    write_table(&hist, &sim.headers, &sci_rows(&sim.rows))?;
    let stats_path = dir.join("stats.csv");
    let s = &sim.stats;
    let p = &sim.projection;
    let records: Vec<(&str, String)> = vec![
        ("method", scene.options.method.name().to_string()),
        ("rtol", format!("{:e}", scene.options.rtol)),
        ("atol", format!("{:e}", scene.options.atol)),
        ("steps", s.steps.to_string()),
        ("rhs_calls", s.rhs_calls.to_string()),
        ("jvp_calls", s.jvp_calls.to_string()),
        ("jacobians", s.jacobians.to_string()),
        ("error_test_failures", s.error_test_failures.to_string()),
        ("nonlinear_iterations", s.nonlinear_iterations.to_string()),
        ("nonlinear_failures", s.nonlinear_failures.to_string()),
        ("events", scene.options.events.to_string()),
        (
            "segment_events",
            (s.events as u64).saturating_sub(sim.row_events).to_string(),
        ),
        ("restarts", s.restarts.to_string()),
        ("equations", sim.equations.to_string()),
        ("redundant_equations", sim.redundant.to_string()),
        ("redundant_rows", redundant_rows(sim)),
        ("initial_violation", format!("{:.3e}", p.phi_before)),
        (
            "position_correction",
            format!("{:.3e}", p.position_correction),
        ),
        (
            "velocity_correction",
            format!("{:.3e}", p.velocity_correction),
        ),
        ("max_violation", format!("{:.3e}", sim.max_violation)),
        (
            "energy_error",
            sim.energy_error
                .map_or("n/a".into(), |e| format!("{e:.3e}")),
        ),
    ];
    let failed = sim.failure.is_some();
    let mut rows: Vec<Vec<String>> = records
        .into_iter()
        .map(|(k, v)| {
            let v = if failed && INTEGRATOR_COUNTERS.contains(&k) {
                "n/a".into()
            } else {
                v
            };
            vec![k.to_string(), v, stat_unit(k).to_string()]
        })
        .collect();
    rows.extend(event_and_failure_rows(sim));
    write_table(&stats_path, &["quantity", "value", "unit"], &rows)?;
    let mut written = vec![hist, stats_path];
    if !sim.sens_rows.is_empty() {
        let path = dir.join("sensitivities.csv");
        write_table(&path, &sim.sens_headers, &sci_rows(&sim.sens_rows))?;
        written.push(path);
    }
    if !sim.responses.is_empty() {
        let path = dir.join("responses.csv");
        let mut head = vec![
            "response".to_string(),
            "kind".into(),
            "value".into(),
            "unit".into(),
            "time [s]".into(),
        ];
        head.extend(scene.params.iter().map(|(p, _)| format!("d/d({p})")));
        let rows: Vec<Vec<String>> = sim
            .responses
            .iter()
            .map(|r| {
                let mut rec = vec![
                    r.name.clone(),
                    r.kind.to_string(),
                    sci(r.value, 12),
                    r.unit.clone(),
                    r.time.map_or(String::new(), |t| format!("{t:.6}")),
                ];
                rec.extend(r.gradient.iter().map(|g| sci(*g, 12)));
                rec
            })
            .collect();
        write_table(&path, &head, &rows)?;
        written.push(path);
    }
    if let Some(name) = &scene.plot {
        let col = sim
            .headers
            .iter()
            .position(|h| h.starts_with(name.as_str()));
        if let Some(col) = col {
            let stem = scene.plot_file.as_deref().unwrap_or(name);
            let path = dir.join(format!("{stem}.svg"));
            plot_column(&path, &sim.headers[col], &sim.rows, col)?;
            written.push(path);
        }
    }
    Ok(written)
}

/// The rows of `stats.csv` that only some runs have: `redundancy_events`
/// (when the dropped rows were chosen anew) and, after a failure,
/// `status` = `failed` with `failure_time`, `failure_place` and
/// `failure_message`; the integrator's counters are then not known (the
/// failed integration returns none) and read `n/a`.
fn event_and_failure_rows(sim: &Simulation) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    if sim.row_events > 0 {
        out.push(vec![
            "redundancy_events".into(),
            sim.row_events.to_string(),
            "-".into(),
        ]);
    }
    if let Some(Error::Numerical {
        place,
        time,
        detail,
    }) = &sim.failure
    {
        out.push(vec!["status".into(), "failed".into(), "-".into()]);
        out.push(vec![
            "failure_time".into(),
            time.map_or("n/a".into(), |t| format!("{t:.6e}")),
            "s".into(),
        ]);
        out.push(vec!["failure_place".into(), place.clone(), "-".into()]);
        out.push(vec!["failure_message".into(), detail.clone(), "-".into()]);
    }
    out
}

/// The integrator's counters in `stats.csv` (`n/a` after a failure).
const INTEGRATOR_COUNTERS: [&str; 9] = [
    "steps",
    "rhs_calls",
    "jvp_calls",
    "jacobians",
    "error_test_failures",
    "nonlinear_iterations",
    "nonlinear_failures",
    "segment_events",
    "restarts",
];

/// The unit of a `stats.csv` quantity (`-`: a count, a name or a ratio).
fn stat_unit(quantity: &str) -> &'static str {
    match quantity {
        // Constraint rows mix lengths and rotations: the largest residual.
        "initial_violation" | "position_correction" | "max_violation" => "m or rad",
        "velocity_correction" => "m/s or rad/s",
        "atol" => "state units",
        _ => "-",
    }
}

/// Plot column `col` of `rows` against time (column 0) into an SVG file.
pub fn plot_column(path: &Path, label: &str, rows: &[Vec<f64>], col: usize) -> Result<()> {
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[col])).collect();
    line_plot(
        path,
        &Axes {
            title: &format!("{label} against time"),
            x: "t [s]",
            y: label,
            scale: crate::report::Scale::Linear,
        },
        &[Curve {
            label: label.to_string(),
            points,
        }],
    )
}

/// The rigid-body content of each flexible body's modes
/// ([`crate::panels::rigid`]): per body the kept modes' largest content
/// (mode, frequency, content) and every mode dropped for exceeding the
/// limit. Returns `(lines, warnings)`: one line per body with a screened
/// basis, one warning per dropped mode. Mode numbers count the computed
/// modes (ascending frequency, 1-based).
pub fn rigid_summary(scene: &Scene) -> (Vec<String>, Vec<String>) {
    let (mut lines, mut warnings) = (Vec::new(), Vec::new());
    for b in &scene.model.bodies {
        let Some(f) = &b.flex else { continue };
        let r = &f.basis.rigid;
        if r.content.is_empty() {
            continue;
        }
        let hz = |l: f64| l.sqrt() / (2.0 * std::f64::consts::PI);
        // Computed-mode numbers of the kept modes.
        let kept: Vec<usize> = (1..=r.content.len() + r.dropped.len())
            .filter(|m| r.dropped.iter().all(|d| d.mode != *m))
            .collect();
        let (j, c) = r
            .content
            .iter()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |a, (j, &c)| if c > a.1 { (j, c) } else { a },
            );
        let c = if c >= 1e-3 {
            format!("{c:.4}")
        } else {
            format!("{c:.1e}")
        };
        let mut line = format!(
            "{} modes: {} kept, largest rigid content {c} (mode {}, {:.3} Hz)",
            b.name,
            r.content.len(),
            kept[j],
            hz(f.basis.eigenvalues[j])
        );
        if !r.dropped.is_empty() {
            let d: Vec<String> = r
                .dropped
                .iter()
                .map(|d| format!("{} ({:.3} Hz, {:.7})", d.mode, d.frequency_hz, d.content))
                .collect();
            line += &format!("; dropped (content > {}): {}", r.limit, d.join(", "));
        }
        if let Some((asked, used)) = r.split {
            line +=
                &format!("; {asked} elastic modes asked split a repeated eigenvalue: {used} used");
            let tol = crate::modal::DerivativeOptions::default().cluster_tol;
            warnings.push(format!(
                "warning: {}: {asked} elastic modes split a repeated eigenvalue at this lay-up \
                 (the last mode asked and the first left out differ by less than {tol:e} \
                 relative); the cluster is left out whole: {used} modes used",
                b.name
            ));
        }
        for d in &r.dropped {
            warnings.push(format!(
                "warning: {}: mode {} ({:.3} Hz) dropped from the modal basis: rigid-body \
                 content {:.7} > {} (almost a rigid motion of the frame)",
                b.name, d.mode, d.frequency_hz, d.content, r.limit
            ));
        }
        lines.push(line);
    }
    (lines, warnings)
}

/// The dependent rows as one table cell: labels separated by spaces, or
/// `none`.
fn redundant_rows(sim: &Simulation) -> String {
    if sim.redundant_rows.is_empty() {
        "none".into()
    } else {
        sim.redundant_rows.join(" ")
    }
}

/// One-paragraph summary for the terminal.
pub fn summary(sim: &Simulation) -> String {
    let s = &sim.stats;
    let mut text = format!(
        "constraints: {} equations, {} redundant ({}); initial |Φ| {:.2e} (position correction {:.2e}, velocity {:.2e})\n\
         max constraint violation {:.2e}; energy error {}\n\
         integrator: {} steps, {} rhs calls, {} Jacobian-vector products, {} Jacobians, {} error-test failures, {} segment events ({} restarts); wall {:.3} ms (+ {:.3} ms outputs)",
        sim.equations,
        sim.redundant,
        redundant_rows(sim),
        sim.projection.phi_before,
        sim.projection.position_correction,
        sim.projection.velocity_correction,
        sim.max_violation,
        sim.energy_error.map_or("n/a (non-conservative scene)".into(), |e| format!("{e:.2e}")),
        s.steps,
        s.rhs_calls,
        s.jvp_calls,
        s.jacobians,
        s.error_test_failures,
        (s.events as u64).saturating_sub(sim.row_events),
        s.restarts,
        s.wall * 1e3,
        s.observer_wall * 1e3
    );
    if sim.row_events > 0 {
        text += &format!(
            "\nredundancy events: {} (dropped constraint rows chosen anew)",
            sim.row_events
        );
    }
    for r in &sim.responses {
        text += &format!(
            "\nresponse {} ({}): {:.6e}{}",
            r.name,
            r.kind,
            r.value,
            r.time
                .map_or(String::new(), |t| format!(" at t = {t:.4} s"))
        );
    }
    text
}
