//! `[[scene.forces]]` data → [`Force`]s of the model: the Eq. 32
//! actuator of a revolute joint, spring-dampers between markers or along
//! a prismatic or cylindrical joint, torsion springs about a revolute
//! joint, and loads at a body's centre of mass
//! or at a marker. Each step names its key (`forces[k].<field>`) in
//! errors; what the scene's effects do not list is validated but not
//! built.

use super::build::find_body;
use super::parts::{finite3, initial_distance, load_table};
use super::spec::{Effect, ForceSpec, SceneSpec, SegmentSpec};
use crate::error::{Error, Result};
use crate::mbs::model::{Force, JointKind, Load, LoadFrame, Model, PiecewiseLaw, Segment};

impl SceneSpec {
    /// Gravity and the `[[scene.forces]]` the effects list builds;
    /// returns the model index of each scene force (None: not built).
    pub(super) fn add_forces(&self, model: &mut Model) -> Result<Vec<Option<usize>>> {
        if self.has(Effect::Gravity) {
            model.forces.push(Force::Gravity {
                g: finite3("gravity".into(), self.gravity)?,
            });
        }
        self.check_force_names()?;
        let mut force_index: Vec<Option<usize>> = vec![None; self.forces.len()];
        for (k, f) in self.forces.iter().enumerate() {
            let key = format!("forces[{k}]");
            let built = match f {
                ForceSpec::Actuator {
                    joint,
                    damping,
                    segments,
                    ..
                } => self.actuator(model, &key, joint, *damping, segments)?,
                ForceSpec::Spring { .. } => self.spring_of(model, &key, f)?,
                ForceSpec::Load {
                    body,
                    marker,
                    frame,
                    force,
                    torque,
                    table,
                } => {
                    let at = (body.as_deref(), marker.as_deref());
                    let load = load_of(&key, [*force, *torque], table.as_deref())?;
                    self.load(model, &key, at, frame.unwrap_or(LoadFrame::Global), load)?
                }
            };
            if let Some(force) = built {
                force_index[k] = Some(model.forces.len());
                model.forces.push(force);
            }
        }
        Ok(force_index)
    }

    /// Force names (for `<name>.stiffness` / `<name>.damping`) are
    /// non-empty and unique.
    fn check_force_names(&self) -> Result<()> {
        for (k, f) in self.forces.iter().enumerate() {
            let Some(name) = f.name() else { continue };
            let taken = self.forces[..k].iter().any(|g| g.name() == Some(name));
            if name.is_empty() || taken {
                return Err(Error::input(
                    format!("forces[{k}].name"),
                    format!("\"{name}\""),
                    "a unique, non-empty force name",
                ));
            }
        }
        Ok(())
    }

    /// The Eq. 32 spring-damper-actuator of a revolute joint (None when
    /// the effects build neither its law nor its damping).
    fn actuator(
        &self,
        model: &Model,
        key: &str,
        joint: &str,
        damping: f64,
        segments: &[SegmentSpec],
    ) -> Result<Option<Force>> {
        let jt = model.joint(joint).ok_or_else(|| {
            Error::input(
                format!("{key}.joint"),
                joint,
                "the name of a joint in scene.joints",
            )
        })?;
        if !model.joints[jt].kind.has_angle()
            || matches!(model.joints[jt].kind, JointKind::Driven(_))
        {
            return Err(Error::input(
                format!("{key}.joint"),
                joint,
                "a free revolute (or cylindrical) joint",
            ));
        }
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(Error::input(
                format!("{key}.damping"),
                damping,
                "a finite damping ≥ 0 (N·m·s)",
            ));
        }
        let law = if self.has(Effect::Actuators) && !segments.is_empty() {
            let segs = segments
                .iter()
                .map(|s| Segment {
                    lower: s.lower,
                    upper: s.upper,
                    value: s.value,
                    slope: s.slope,
                    anchor: s.anchor,
                })
                .collect();
            Some(PiecewiseLaw::new(&format!("{key}.segments"), segs)?)
        } else {
            None
        };
        let c = self.damping_if_listed(damping);
        Ok((law.is_some() || c != 0.0).then_some(Force::Rotational {
            joint: jt,
            law,
            damping: c,
        }))
    }

    /// `damping` when the scene lists the `damping` effect, else 0.
    fn damping_if_listed(&self, damping: f64) -> f64 {
        if self.has(Effect::Damping) {
            damping
        } else {
            0.0
        }
    }

    /// A `type = "spring"` entry: between `marker_i` and `marker_j`, or
    /// along `joint` (exactly one of the two forms).
    fn spring_of(&self, model: &Model, key: &str, f: &ForceSpec) -> Result<Option<Force>> {
        let ForceSpec::Spring {
            marker_i,
            marker_j,
            joint,
            stiffness,
            damping,
            length,
            force,
            angle,
            torque,
            ..
        } = f
        else {
            unreachable!("spring_of is called with springs only")
        };
        let values = [*stiffness, *damping];
        let turning = joint
            .as_deref()
            .and_then(|j| model.joint(j))
            .is_some_and(|j| !model.joints[j].kind.has_slide());
        // Keys of the other kind of spring are refused, not ignored.
        let foreign = if turning {
            [("length", *length), ("force", *force)]
        } else {
            [("angle", *angle), ("torque", *torque)]
        };
        if let Some((name, Some(v))) = foreign.iter().find(|(_, v)| v.is_some()) {
            return Err(Error::input(
                format!("{key}.{name}"),
                v,
                if turning {
                    "no length or force on a torsion spring (angle, torque)"
                } else {
                    "angle and torque only on a torsion spring (joint = a revolute joint)"
                },
            ));
        }
        match (joint, marker_i, marker_j) {
            (Some(j), None, None) if turning => {
                self.torsion_spring(model, key, j, values, (*angle, *torque))
            }
            (Some(j), None, None) => self.joint_spring(model, key, j, values, (*length, *force)),
            (None, Some(a), Some(b)) => {
                if let Some(v) = force {
                    return Err(Error::input(
                        format!("{key}.force"),
                        v,
                        "no actuator force on a spring between markers (joint springs only)",
                    ));
                }
                self.spring(model, key, [a, b], values, *length)
            }
            (Some(j), _, _) => Err(Error::input(
                format!("{key}.joint"),
                j,
                "either joint (a spring along a joint) or marker_i and marker_j, not both",
            )),
            (None, a, _) => Err(Error::input(
                format!(
                    "{key}.{}",
                    if a.is_none() { "marker_i" } else { "marker_j" }
                ),
                "(missing)",
                "marker_i and marker_j (a spring between markers) or joint (a spring \
                 along a prismatic or cylindrical joint, or about a revolute joint)",
            )),
        }
    }

    /// A linear spring-damper between two markers (None without the
    /// `springs` effect); the rest length defaults to the initial distance.
    fn spring(
        &self,
        model: &Model,
        key: &str,
        [marker_i, marker_j]: [&String; 2],
        [stiffness, damping]: [f64; 2],
        length: Option<f64>,
    ) -> Result<Option<Force>> {
        let i = find_marker(model, format!("{key}.marker_i"), marker_i)?;
        let j = find_marker(model, format!("{key}.marker_j"), marker_j)?;
        let l0 = initial_distance(model, i, j);
        let length = length.unwrap_or(l0);
        for (name, v) in [
            ("stiffness", stiffness),
            ("damping", damping),
            ("length", length),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::input(
                    format!("{key}.{name}"),
                    v,
                    "a finite value ≥ 0",
                ));
            }
        }
        if l0 < 1e-9 {
            return Err(Error::input(
                format!("{key}.marker_j"),
                marker_j,
                "a point distinct from marker_i",
            ));
        }
        Ok(self.has(Effect::Springs).then_some(Force::SpringDamper {
            i,
            j,
            stiffness,
            damping: self.damping_if_listed(damping),
            length,
        }))
    }

    /// A spring-damper-actuator along the axis of a prismatic or
    /// cylindrical joint (None without the `springs` effect): rest
    /// displacement `length` (m, default 0), constant `force` (N, default
    /// 0) pushing body j along the axis.
    fn joint_spring(
        &self,
        model: &Model,
        key: &str,
        joint: &str,
        [stiffness, damping]: [f64; 2],
        (length, force): (Option<f64>, Option<f64>),
    ) -> Result<Option<Force>> {
        let sliding: Vec<&str> = model
            .joints
            .iter()
            .filter(|j| j.kind.has_slide() || j.kind == JointKind::Revolute)
            .map(|j| j.name.as_str())
            .collect();
        let jt = model
            .joint(joint)
            .filter(|&j| model.joints[j].kind.has_slide())
            .ok_or_else(|| {
                Error::input(
                    format!("{key}.joint"),
                    joint,
                    format!(
                        "the name of a prismatic, cylindrical or revolute joint in \
                         scene.joints ({})",
                        name_list(&sliding)
                    ),
                )
            })?;
        let (length, force) = (length.unwrap_or(0.0), force.unwrap_or(0.0));
        check_spring_values(
            key,
            [stiffness, damping],
            [("length", length), ("force", force)],
        )?;
        Ok(self.has(Effect::Springs).then_some(Force::JointSpring {
            joint: jt,
            stiffness,
            damping: self.damping_if_listed(damping),
            length,
            force,
        }))
    }

    /// A torsion spring-damper about a revolute joint (None without the
    /// `springs` effect): free angle `angle` (rad, default 0), constant
    /// preload `torque` (N·m, default 0) turning body j positively; the
    /// damping with the `damping` effect.
    fn torsion_spring(
        &self,
        model: &Model,
        key: &str,
        joint: &str,
        [stiffness, damping]: [f64; 2],
        (angle, torque): (Option<f64>, Option<f64>),
    ) -> Result<Option<Force>> {
        let jt = model.joint(joint).expect("a torsion spring names a joint");
        if !matches!(model.joints[jt].kind, JointKind::Revolute) {
            return Err(Error::input(
                format!("{key}.joint"),
                joint,
                "a revolute joint (a driven, locked, fixed or spherical joint has no free angle)",
            ));
        }
        let (angle, torque) = (angle.unwrap_or(0.0), torque.unwrap_or(0.0));
        check_spring_values(
            key,
            [stiffness, damping],
            [("angle", angle), ("torque", torque)],
        )?;
        Ok(self.has(Effect::Springs).then_some(Force::TorsionSpring {
            joint: jt,
            stiffness,
            damping: self.damping_if_listed(damping),
            angle,
            torque,
        }))
    }

    /// A load at a body's centre of mass or at a marker (exactly one of
    /// `at = (body, marker)`), in `frame` axes (`global` unless the study
    /// says `body`); None without the `loads` effect.
    fn load(
        &self,
        model: &Model,
        key: &str,
        at: (Option<&str>, Option<&str>),
        frame: LoadFrame,
        load: Load,
    ) -> Result<Option<Force>> {
        let force =
            match at {
                (Some(body), None) => {
                    let b = find_body(format!("{key}.body"), body, model)?.ok_or_else(|| {
                        Error::input(format!("{key}.body"), body, "a body (not ground)")
                    })?;
                    Force::BodyLoad {
                        body: b,
                        load,
                        frame,
                    }
                }
                (None, Some(marker)) => Force::MarkerLoad {
                    marker: find_marker(model, format!("{key}.marker"), marker)?,
                    load,
                    frame,
                },
                (Some(body), Some(_)) => return Err(Error::input(
                    format!("{key}.body"),
                    body,
                    "either body (a load at the centre of mass) or marker (a load at a point), \
                     not both",
                )),
                (None, None) => {
                    return Err(Error::input(
                        format!("{key}.body"),
                        "(missing)",
                        "body (a load at the centre of mass) or marker (a load at a point)",
                    ))
                }
            };
        Ok(self.has(Effect::Loads).then_some(force))
    }
}

/// The load of a `type = "load"` entry: constant `force`, `torque` or a
/// time `table`.
fn load_of(key: &str, [force, torque]: [[f64; 3]; 2], table: Option<&[[f64; 7]]>) -> Result<Load> {
    let force = finite3(format!("{key}.force"), force)?;
    let torque = finite3(format!("{key}.torque"), torque)?;
    Ok(match table {
        None => Load::Constant { force, torque },
        Some(rows) => Load::Table(load_table(&format!("{key}.table"), rows)?),
    })
}

/// A marker by name; an unknown name is an input error on `key` listing
/// the scene's markers.
fn find_marker(model: &Model, key: String, name: &str) -> Result<usize> {
    model.marker(name).ok_or_else(|| {
        let names: Vec<&str> = model.markers.iter().map(|m| m.name.as_str()).collect();
        Error::input(
            key,
            name,
            format!(
                "the name of a marker: one of scene.markers or a joint's <joint>.i / <joint>.j ({})",
                name_list(&names)
            ),
        )
    })
}

/// `a, b, c` (the first 12, then `…`), or `none in this scene`.
fn name_list(names: &[&str]) -> String {
    match names.len() {
        0 => "none in this scene".into(),
        n if n <= 12 => names.join(", "),
        _ => format!("{}, …", names[..12].join(", ")),
    }
}

/// A joint spring's `stiffness` and `damping` finite and ≥ 0, and its two
/// free values (free length and preload, or free angle and preload)
/// finite; the error names `<key>.<name>`.
fn check_spring_values(key: &str, [k, c]: [f64; 2], free: [(&str, f64); 2]) -> Result<()> {
    for (name, v) in [("stiffness", k), ("damping", c)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::input(
                format!("{key}.{name}"),
                v,
                "a finite value ≥ 0",
            ));
        }
    }
    for (name, v) in free {
        if !v.is_finite() {
            return Err(Error::input(format!("{key}.{name}"), v, "a finite value"));
        }
    }
    Ok(())
}
