//! The variables of a scene problem ([`crate::explore::problem::scene_problem`]): what each
//! `[[scene_problem.variables]]` entry sets, and its sensitivity lanes.
//!
//! A variable's `sets` lists entries of two kinds, all of one kind per
//! variable:
//!
//! - **Ply angles** `"<panel>:<design variable>"`, e.g. `"panel3:theta_1_4"`:
//!   the angle (degrees in the study, radians in the laminate) of every ply
//!   of that `[[panels]]` design group (`design = [[1, 4], [2, 3]]` names
//!   `theta_1_4`, `theta_2_3`; `design = [[1], [2], [3], [4]]` gives one
//!   free angle per ply, `theta_1` .. `theta_4`, stacks with `B ≠ 0`
//!   included). The lanes are `<body>.design.<variable>` of every scene
//!   body built from that panel, per radian, so the variable's derivative
//!   is their sum times `π/180`. With `tied_lanes` the lanes of one
//!   variable are joined into one (`"B3.design.theta_1_4+B2.design.theta_1_4"`).
//! - **Ply thicknesses** `"<panel>:thickness_<plies>"`, e.g.
//!   `"panel3:thickness_1_4"`: the common thickness of those plies (any
//!   distinct 1-based plies, not only a design group; each ply set by at
//!   most one variable). The variable is in **millimetres** (its label
//!   `t_1_4 [mm]`), bounds > 0; the laminate gets metres. Stiffness and
//!   mass both move: the lanes `<body>.design.thickness_<plies>` (per
//!   metre) carry the derivatives of the eigenvalues, mode shapes and node
//!   masses ([`crate::panels::BasisBuilder::set_thickness`]), so the
//!   variable's derivative is their sum times 1e-3. A thickness ply that
//!   breaks the stack's mirror symmetry couples membrane and bending
//!   (B' ≠ 0): exact, but the mode derivatives are then solved on the
//!   whole pencil instead of the bending block.
//! - **Scene parameters** `"scene:<parameter>"`, e.g.
//!   `"scene:forces[0].damping"`, `"scene:forces[0].segments[2].slope"`,
//!   `"scene:B5.mass"`: any parameter `[scene] sensitivities` accepts
//!   (spring stiffness and damping, actuator damping, a segment's anchor or
//!   slope, a rigid body's mass), spelled as there. The variable is the
//!   parameter's value in its SI unit (no conversion), written into the
//!   built model before the run; its lane is the parameter itself (one
//!   lane per entry; a variable setting several parameters moves them
//!   together and sums their lanes).
//!
//! Every lane must be listed in `[scene] sensitivities`, so that the study
//! file shows what is differentiated.

use crate::error::{Error, Result};
use crate::optimize::Variable;
use crate::scene::{Scene, ScenePlan};
use crate::study::Study;

/// Prefix of a scene-parameter entry in `sets`.
const SCENE: &str = "scene:";

/// One `[[scene_problem.variables]]` entry.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariableSpec {
    /// Name in reports (e.g. `theta1_deg`, `damping`).
    pub name: String,
    /// `[lower, upper]`: degrees for ply angles, the parameter's SI unit
    /// for scene parameters.
    pub bounds: [f64; 2],
    /// Periodic ply angle (`upper − lower` must be 180°).
    #[serde(default)]
    pub periodic: bool,
    /// Entries this variable sets: `"<panel>:<design variable>"` (e.g.
    /// `"panel3:theta_1_4"`) or `"scene:<parameter>"` (e.g.
    /// `"scene:forces[0].damping"`), all of one kind.
    pub sets: Vec<String>,
}

/// What one `sets` entry writes.
#[derive(Debug, Clone)]
pub(crate) enum Target {
    /// The angle of these 0-based plies of `[[panels]]` entry `panel`.
    Plies {
        /// Index of the `[[panels]]` entry.
        panel: usize,
        /// 0-based plies of its design group.
        plies: Vec<usize>,
    },
    /// The common thickness (variable in mm) of these 0-based plies of
    /// `[[panels]]` entry `panel`.
    Thickness {
        /// Index of the `[[panels]]` entry.
        panel: usize,
        /// 0-based plies.
        plies: Vec<usize>,
    },
    /// A scene parameter, by its `[scene] sensitivities` name.
    Scene(String),
}

/// The problem variables and what each one sets: ply targets in the
/// panels, scene parameters, and sensitivity lanes of the scene.
pub(crate) struct Ties {
    /// The optimization variables.
    pub vars: Vec<Variable>,
    /// Per variable: what it sets.
    pub targets: Vec<Vec<Target>>,
    /// All sensitivity lanes, in the order they are passed to the scene.
    pub lanes: Vec<String>,
    /// Per variable: indices into `lanes`.
    pub lanes_of: Vec<Vec<usize>>,
    /// Per variable: its derivative per lane unit (`π/180` for a ply angle
    /// in degrees against lanes per radian, 1e-3 for a ply thickness in mm
    /// against lanes per metre, 1 for a scene parameter).
    pub scale: Vec<f64>,
}

/// The range of a ply-thickness variable's bounds (mm): from 1 µm to
/// 25 mm, about 200 times either way around the 0.125 mm of a
/// carbon/epoxy prepreg ply. Outside it the input is a slip of units or
/// of digits (a thickness in metres, a bound of 1e6), and every
/// evaluation would fail deep inside the modal analysis.
pub const PLY_THICKNESS_MM: (f64, f64) = (1e-3, 25.0);

/// Metres per unit of a ply-thickness variable (mm).
pub(crate) const THICKNESS_UNIT: f64 = 1e-3;

/// The kind of a `sets` entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Angle,
    Thickness,
    Scene,
}

/// The kind of a `sets` entry by its spelling.
fn kind_of(entry: &str) -> Kind {
    if entry.starts_with(SCENE) {
        Kind::Scene
    } else if entry
        .split_once(':')
        .is_some_and(|(_, v)| v.starts_with("thickness_"))
    {
        Kind::Thickness
    } else {
        Kind::Angle
    }
}

/// An input error on `scene_problem.<key>`.
pub(crate) fn problem_error(
    study: &Study,
    key: String,
    value: impl std::fmt::Display,
    expected: String,
) -> Error {
    study.error(format!("scene_problem.{key}"), value, expected)
}

impl Ties {
    /// Resolve `[[scene_problem.variables]]` against the plan's panels and
    /// scene (each panel design variable and scene parameter set by one
    /// problem variable).
    pub fn resolve(
        study: &Study,
        variables: &[VariableSpec],
        tied_lanes: bool,
        plan: &ScenePlan,
    ) -> Result<Ties> {
        if variables.is_empty() {
            return Err(problem_error(
                study,
                "variables".into(),
                "[]",
                "at least one variable".into(),
            ));
        }
        let mut ties = Ties {
            vars: Vec::new(),
            targets: Vec::new(),
            lanes: Vec::new(),
            lanes_of: Vec::new(),
            scale: Vec::new(),
        };
        let mut used: Vec<(usize, usize)> = Vec::new();
        let mut used_plies: Vec<(usize, usize)> = Vec::new();
        let mut used_scene: Vec<&str> = Vec::new();
        for (i, v) in variables.iter().enumerate() {
            let key = format!("variables[{i}]");
            if v.sets.is_empty() {
                return Err(problem_error(
                    study,
                    format!("{key}.sets"),
                    "[]",
                    "at least one \"<panel>:<design variable>\" or \"scene:<parameter>\"".into(),
                ));
            }
            let kind = kind_of(&v.sets[0]);
            let scene = kind == Kind::Scene;
            if let Some(k) = v.sets.iter().position(|e| kind_of(e) != kind) {
                return Err(problem_error(
                    study,
                    format!("{key}.sets[{k}]"),
                    format!("\"{}\"", v.sets[k]),
                    "entries of one kind per variable: ply angles \"<panel>:<design variable>\", \
                     ply thicknesses \"<panel>:thickness_<plies>\" or scene parameters \
                     \"scene:<parameter>\""
                        .into(),
                ));
            }
            if kind != Kind::Angle && v.periodic {
                return Err(problem_error(
                    study,
                    format!("{key}.periodic"),
                    true,
                    "false for a scene parameter or a ply thickness (only ply angles repeat)"
                        .into(),
                ));
            }
            let (lo, hi) = PLY_THICKNESS_MM;
            if kind == Kind::Thickness && !(v.bounds[0] >= lo && v.bounds[1] <= hi) {
                return Err(problem_error(
                    study,
                    format!("{key}.bounds"),
                    format!("[{}, {}]", v.bounds[0], v.bounds[1]),
                    format!(
                        "bounds within [{lo}, {hi}] mm for a ply thickness (the variable \
                         is in millimetres: a 0.125 mm ply is 0.125, not 0.000125)"
                    ),
                ));
            }
            ties.vars.push(variable(study, &key, v)?);
            let (mut t, mut names) = (Vec::new(), Vec::new());
            for (k, entry) in v.sets.iter().enumerate() {
                let key = format!("{key}.sets[{k}]");
                if scene {
                    let name = scene_entry(study, plan, &key, entry, &mut used_scene)?;
                    names.push(name.to_string());
                    t.push(Target::Scene(name.to_string()));
                } else if kind == Kind::Thickness {
                    let (target, lanes) = thickness(study, plan, &key, entry, &mut used_plies)?;
                    t.push(target);
                    names.extend(lanes);
                } else {
                    let (target, lanes) = tie(study, plan, &key, entry, &mut used)?;
                    t.push(target);
                    names.extend(lanes);
                }
            }
            if tied_lanes && !scene && names.len() > 1 {
                names = vec![names.join("+")];
            }
            let l: Vec<usize> = (ties.lanes.len()..ties.lanes.len() + names.len()).collect();
            ties.lanes.extend(names);
            ties.targets.push(t);
            ties.lanes_of.push(l);
            ties.scale.push(match kind {
                Kind::Scene => 1.0,
                Kind::Thickness => THICKNESS_UNIT,
                Kind::Angle => std::f64::consts::PI / 180.0,
            });
        }
        Ok(ties)
    }

    /// Is variable `i` a scene parameter (not a ply angle in degrees)?
    pub fn is_scene(&self, i: usize) -> bool {
        matches!(self.targets[i].first(), Some(Target::Scene(_)))
    }

    /// Is variable `i` a ply thickness (in mm)?
    pub fn is_thickness(&self, i: usize) -> bool {
        matches!(self.targets[i].first(), Some(Target::Thickness { .. }))
    }

    /// The label of variable `i` named `name` in tables and plots: ply
    /// angles in degrees (`theta1_deg` → `θ1 [deg]`), ply thicknesses in
    /// millimetres (`t_1_4 [mm]`), scene parameters in SI units
    /// (`damping [SI]`).
    pub fn variable_label(&self, i: usize, name: &str) -> String {
        if self.is_scene(i) {
            return format!("{name} [SI]");
        }
        if self.is_thickness(i) {
            let name = name.strip_suffix("_mm").unwrap_or(name);
            return format!("{name} [mm]");
        }
        let name = name.strip_suffix("_deg").unwrap_or(name);
        match name.strip_prefix("theta") {
            Some(rest) => format!("θ{rest} [deg]"),
            None => format!("{name} [deg]"),
        }
    }

    /// The panels' lay-ups at design `x`: each angle variable (degrees)
    /// in every ply of its targets (radians), each thickness variable (mm)
    /// in every ply of its targets (metres), the other plies as in the
    /// study (`panels`, the plan's). Errors: a thickness ≤ 0 or not
    /// finite (input error naming the ply).
    pub fn laminates_at(
        &self,
        panels: &[crate::fe::Panel],
        x: &[f64],
    ) -> Result<Vec<crate::laminate::Laminate>> {
        let mut angles: Vec<Vec<f64>> = panels.iter().map(|p| p.laminate.angles()).collect();
        let mut thick: Vec<Vec<f64>> = panels
            .iter()
            .map(|p| p.laminate.plies().iter().map(|q| q.thickness).collect())
            .collect();
        for (xi, targets) in x.iter().zip(&self.targets) {
            for t in targets {
                match t {
                    Target::Plies { panel, plies } => {
                        for &k in plies {
                            angles[*panel][k] = xi.to_radians();
                        }
                    }
                    Target::Thickness { panel, plies } => {
                        for &k in plies {
                            thick[*panel][k] = xi * THICKNESS_UNIT;
                        }
                    }
                    Target::Scene(_) => {}
                }
            }
        }
        panels
            .iter()
            .zip(angles.iter().zip(&thick))
            .map(|(p, (a, t))| p.laminate.with_angles(a)?.with_thicknesses(t))
            .collect()
    }

    /// Write the scene parameters of design `x` into `scene` (built from
    /// `plan`); ply angles are not touched (they go in as laminates).
    pub fn apply_scene(&self, plan: &ScenePlan, scene: &mut Scene, x: &[f64]) -> Result<()> {
        for (xi, targets) in x.iter().zip(&self.targets) {
            for t in targets {
                if let Target::Scene(name) = t {
                    let p = plan.spec().param_of(scene, name).ok_or_else(|| {
                        Error::input(
                            "scene_problem.variables.sets",
                            format!("\"{SCENE}{name}\""),
                            "a parameter of a force the scene's effects build \
                             (the scene has none of this name)",
                        )
                    })?;
                    p.set(&mut scene.model, *xi);
                }
            }
        }
        Ok(())
    }
}

/// One `[[scene_problem.variables]]` entry as an optimization variable.
fn variable(study: &Study, key: &str, v: &VariableSpec) -> Result<Variable> {
    let [lo, hi] = v.bounds;
    if v.periodic {
        if !(lo.is_finite() && hi - lo == 180.0) {
            return Err(problem_error(
                study,
                format!("{key}.bounds"),
                format!("[{lo}, {hi}]"),
                "finite bounds 180° apart (ply angles repeat every 180°)".into(),
            ));
        }
        Variable::periodic(v.name.clone(), lo, 180.0)
    } else {
        Variable::bounded(v.name.clone(), lo, hi)
    }
    .map_err(|e| e.in_file(&study.path, &format!("scene_problem.{key}")))
}

/// One `"scene:<parameter>"` entry: the parameter's name, which must be a
/// plain (not tied, not ply-angle) entry of `[scene] sensitivities` set by
/// no other variable. Whether the scene has that parameter is known once a
/// design is built (the first evaluation); the name's form is checked here.
fn scene_entry<'a>(
    study: &Study,
    plan: &ScenePlan,
    key: &str,
    entry: &'a str,
    used: &mut Vec<&'a str>,
) -> Result<&'a str> {
    let bad =
        |expected: String| problem_error(study, key.to_string(), format!("\"{entry}\""), expected);
    let name = entry.strip_prefix(SCENE).unwrap_or(entry).trim();
    if name.is_empty() || name.contains('+') || name.contains(".design.") {
        return Err(bad(
            "\"scene:<parameter>\" with a mass, stiffness, damping, anchor or slope \
             as in [scene] sensitivities (ply angles are \"<panel>:<design variable>\")"
                .into(),
        ));
    }
    if used.contains(&name) {
        return Err(bad(
            "each scene parameter set by one problem variable".into()
        ));
    }
    used.push(name);
    let listed = &plan.spec().sensitivities;
    if !listed.iter().any(|l| l == name) {
        return Err(study.error(
            "scene.sensitivities",
            format!("{listed:?}"),
            format!("a list containing \"{name}\" (the gradient of scene_problem.{key})"),
        ));
    }
    Ok(name)
}

/// One `"<panel>:<design variable>"` entry: the plies it sets and the
/// scene's sensitivity lanes of the bodies built from that panel (each
/// must be listed in `[scene] sensitivities`). `used` holds the panel
/// design variables already tied.
fn tie(
    study: &Study,
    plan: &ScenePlan,
    key: &str,
    entry: &str,
    used: &mut Vec<(usize, usize)>,
) -> Result<(Target, Vec<String>)> {
    let bad =
        |expected: String| problem_error(study, key.to_string(), format!("\"{entry}\""), expected);
    let panels = plan.panels();
    let (pname, dname) = entry.split_once(':').ok_or_else(|| {
        bad(
            "\"<panel>:<design variable>\" (e.g. \"panel3:theta_1_4\") or \"scene:<parameter>\""
                .into(),
        )
    })?;
    let p = panel_index(panels, pname, ", or \"scene\"").map_err(&bad)?;
    let names = design_names(&panels[p].design);
    let Some(d) = names.iter().position(|n| n == dname) else {
        return Err(bad(format!(
            "a design variable of panel {pname} after ':' ({})",
            names.join(", ")
        )));
    };
    if used.contains(&(p, d)) {
        return Err(bad(
            "each panel design variable set by one problem variable".into(),
        ));
    }
    used.push((p, d));
    let lanes = panel_lanes(study, plan, key, entry, pname, dname)?;
    let target = Target::Plies {
        panel: p,
        plies: panels[p].design.groups()[d].clone(),
    };
    Ok((target, lanes))
}

/// One `"<panel>:thickness_<plies>"` entry: the plies whose common
/// thickness it sets and the scene's sensitivity lanes
/// `<body>.design.thickness_<plies>` of the bodies built from that panel
/// (each listed in `[scene] sensitivities`). `used`: (panel, ply) pairs
/// already set by a thickness variable.
fn thickness(
    study: &Study,
    plan: &ScenePlan,
    key: &str,
    entry: &str,
    used: &mut Vec<(usize, usize)>,
) -> Result<(Target, Vec<String>)> {
    let bad =
        |expected: String| problem_error(study, key.to_string(), format!("\"{entry}\""), expected);
    let panels = plan.panels();
    let (pname, dname) = entry
        .split_once(':')
        .ok_or_else(|| bad("\"<panel>:thickness_<plies>\"".into()))?;
    let p = panel_index(panels, pname, "").map_err(&bad)?;
    let n = panels[p].laminate.plies().len();
    let plies = crate::panels::thickness_group(dname, n).map_err(|_| {
        bad(format!(
            "thickness_<ply>[_<ply>...] after ':' with distinct ply numbers in 1..={n}"
        ))
    })?;
    if let Some(&k) = plies.iter().find(|&&k| used.contains(&(p, k))) {
        return Err(bad(format!(
            "each ply's thickness set by one problem variable (ply {} of panel {pname} is \
             set twice)",
            k + 1
        )));
    }
    used.extend(plies.iter().map(|&k| (p, k)));
    let lanes = panel_lanes(study, plan, key, entry, pname, dname)?;
    Ok((Target::Thickness { panel: p, plies }, lanes))
}

/// The index of the panel named `pname`, or what a `sets` entry expects
/// before its ':' (the panels' names, then `also`).
fn panel_index(
    panels: &[crate::fe::Panel],
    pname: &str,
    also: &str,
) -> std::result::Result<usize, String> {
    panels.iter().position(|p| p.name == pname).ok_or_else(|| {
        let names: Vec<&str> = panels.iter().map(|p| p.name.as_str()).collect();
        format!("a [[panels]] name before ':' ({}){also}", names.join(", "))
    })
}

/// The sensitivity lanes `<body>.design.<dname>` of every scene body built
/// from panel `pname`, for the `sets` entry `entry` of variable `key`:
/// errors when no flexible body uses the panel or a lane is not listed in
/// `[scene] sensitivities`.
fn panel_lanes(
    study: &Study,
    plan: &ScenePlan,
    key: &str,
    entry: &str,
    pname: &str,
    dname: &str,
) -> Result<Vec<String>> {
    let bodies = plan.bodies_of_panel(pname);
    if bodies.is_empty() {
        return Err(problem_error(
            study,
            key.to_string(),
            format!("\"{entry}\""),
            format!("a panel of a flexible scene body (no [[scene.bodies]] uses panel {pname})"),
        ));
    }
    let listed = &plan.spec().sensitivities;
    bodies
        .iter()
        .map(|b| {
            let lane = format!("{b}.design.{dname}");
            if listed.contains(&lane) {
                Ok(lane)
            } else {
                Err(study.error(
                    "scene.sensitivities",
                    format!("{listed:?}"),
                    format!("a list containing \"{lane}\" (the gradient of scene_problem.{key})"),
                ))
            }
        })
        .collect()
}

/// Names of a panel's design variables (`theta_1_4` for plies 1 and 4),
/// as the modal basis names them.
fn design_names(map: &crate::laminate::DesignMap) -> Vec<String> {
    map.groups()
        .iter()
        .map(|g| {
            let plies: Vec<String> = g.iter().map(|k| (k + 1).to_string()).collect();
            format!("theta_{}", plies.join("_"))
        })
        .collect()
}
