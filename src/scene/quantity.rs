//! The output plan of a scene: output columns ([`Quantity`]) and
//! response functionals ([`Response`]) resolved to model indices.
//!
//! Every kind of output is registered once, in [`QuantityKind`]: its name
//! as written in study files, what the head of a dotted name must be, its
//! SI unit, its column layout and whether it has sensitivities
//! ([`QuantityKind::info`]). Parsing (`super::parts`), the CSV headers
//! ([`Quantity::headers`]) and the choice of sensitivity columns follow
//! from that table; adding an output is one variant, its row of the table
//! and its evaluation in `crate::simulate`. Response kinds are
//! [`ResponseKind`] (integral, peak, final, value_at, crossing,
//! frequency), each variant with its own parameters, built from
//! `[[scene.responses]] kind` and that kind's keys (`super::responses`).

use crate::mbs::responses::ResponseKind;
use crate::mbs::Energy;

/// A built response: `scale · Σ` outputs over the run, reduced by its
/// kind, or a natural frequency of a flexible body.
///
/// Two forms: sums of energies of a kind with an energy form
/// ([`ResponseKind::energy_form`]: `integral`, `peak` of the largest
/// value, `final`) are evaluated from the energies `terms` (integrals as
/// integrated states); every other response is sampled at the output
/// times from [`Response::outputs`] and reduced by `crate::mbs::series`.
#[derive(Debug, Clone, PartialEq)]
pub struct Response {
    /// The `[[scene.responses]] name`.
    pub name: String,
    /// How the series is reduced (or `frequency`), with the kind's
    /// parameters.
    pub kind: ResponseKind,
    /// The energies summed (energy form; empty in the sampled form).
    pub terms: Vec<Energy>,
    /// Dimensionless factor of the sum.
    pub scale: f64,
    /// For [`ResponseKind::Integral`] of energies: index of its
    /// integrated state in [`crate::mbs::Model::integrals`] (`None`
    /// otherwise).
    pub integral: Option<usize>,
    /// The outputs summed in the sampled form (empty in the energy form
    /// and for frequencies).
    pub outputs: Vec<ScalarOutput>,
    /// SI unit of the response's value (`ResponseKind::unit_of` of the
    /// outputs' unit).
    pub unit: String,
}

impl Response {
    /// The response's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// One scalar output of a response: a one-column [`Quantity`], or one
/// component (0, 1, 2 for x, y, z) of a three-column one
/// (`B3.position_z`, `tip.deflection_x`).
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarOutput {
    /// The output.
    pub quantity: Quantity,
    /// The column of a [`Columns::Xyz`] output (0 otherwise).
    pub component: usize,
}

/// What the head of an output name `<head>.<kind>` must name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Subject {
    /// The whole scene: the output is written as the kind's name alone
    /// (`energy`).
    Scene,
    /// A revolute, locked or driven joint (one with a relative angle).
    AngleJoint,
    /// A prismatic or cylindrical joint (one with a displacement).
    SlideJoint,
    /// Any joint.
    Joint,
    /// Any body.
    Body,
    /// A body with a `flexible` table.
    FlexBody,
    /// A marker on a node of a flexible body.
    FlexMarker,
}

impl Subject {
    /// How the head is written in messages (`<joint>`), empty for
    /// [`Subject::Scene`].
    pub fn name_pattern(self) -> &'static str {
        match self {
            Subject::Scene => "",
            Subject::AngleJoint => "<revolute, locked or driven joint>",
            Subject::SlideJoint => "<prismatic or cylindrical joint>",
            Subject::Joint => "<joint>",
            Subject::Body => "<body>",
            Subject::FlexBody => "<flexible body>",
            Subject::FlexMarker => "<marker on a flexible node>",
        }
    }
}

/// The columns an output writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Columns {
    /// One column `<name> [unit]`.
    One,
    /// Three columns `<name>_x|y|z [unit]` (global or body-frame axes).
    Xyz,
    /// Force and torque: `<joint>.force_x|y|z [N]`, `<joint>.torque_x|y|z
    /// [N*m]`.
    ForceTorque,
    /// One column per mode of the body, `<name>_1.. [unit]`.
    Modes,
}

/// The table row of a [`QuantityKind`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KindInfo {
    /// The name as written in study files: the whole output name for
    /// [`Subject::Scene`], else the part after the last dot.
    pub name: &'static str,
    /// What the head of the name must be.
    pub subject: Subject,
    /// SI unit written in the CSV header.
    pub unit: &'static str,
    /// Column layout.
    pub columns: Columns,
    /// Whether `sensitivities.csv` has its derivatives.
    pub sensitivity: bool,
}

/// Every kind of output column (`[scene.outputs] quantities`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QuantityKind {
    /// `<joint>.angle`: relative rotation of a revolute, locked or driven
    /// joint (rad), unwrapped to be continuous over the run.
    Angle,
    /// `<joint>.rate`: its rate (rad/s).
    Rate,
    /// `<joint>.displacement`: displacement of a prismatic or cylindrical
    /// joint along its axis (m).
    Displacement,
    /// `<joint>.velocity`: its rate (m/s).
    Velocity,
    /// `<joint>.reaction`: reaction force (N) and torque (N·m) of a joint.
    Reaction,
    /// `<body>.position`: global position of a body's centre of mass (of a
    /// flexible body: of its frame origin) (m).
    Position,
    /// `<body>.modal`: modal coordinates `w` of a flexible body (kg^0.5·m).
    Modal,
    /// `<body>.strain_energy`: `½ wᵀΛw` of a flexible body (J).
    StrainEnergy,
    /// `<body>.kinetic_energy`: kinetic energy of one body (J).
    KineticEnergy,
    /// `kinetic_energy`: kinetic energy of all bodies (J).
    TotalKineticEnergy,
    /// `<marker>.deflection`: elastic displacement `Φ_k w` of a marker on a
    /// flexible node, in the body's frame axes (m).
    Deflection,
    /// `energy`: total mechanical energy (J).
    Energy,
    /// `violation`: largest `|Φ|` of the position constraints (m or rad).
    Violation,
}

impl QuantityKind {
    /// Every kind, in the order of the documentation and of messages.
    pub const ALL: [QuantityKind; 13] = [
        QuantityKind::Energy,
        QuantityKind::Violation,
        QuantityKind::TotalKineticEnergy,
        QuantityKind::Angle,
        QuantityKind::Rate,
        QuantityKind::Reaction,
        QuantityKind::Displacement,
        QuantityKind::Velocity,
        QuantityKind::Position,
        QuantityKind::KineticEnergy,
        QuantityKind::Modal,
        QuantityKind::StrainEnergy,
        QuantityKind::Deflection,
    ];

    /// The table: name, subject, unit, columns and sensitivities of each
    /// kind.
    pub fn info(self) -> KindInfo {
        use Columns::*;
        use Subject::*;
        let row = |name, subject, unit, columns, sensitivity| KindInfo {
            name,
            subject,
            unit,
            columns,
            sensitivity,
        };
        match self {
            QuantityKind::Angle => row("angle", AngleJoint, "rad", One, true),
            QuantityKind::Rate => row("rate", AngleJoint, "rad/s", One, true),
            QuantityKind::Displacement => row("displacement", SlideJoint, "m", One, true),
            QuantityKind::Velocity => row("velocity", SlideJoint, "m/s", One, true),
            QuantityKind::Reaction => row("reaction", Joint, "N, N*m", ForceTorque, false),
            QuantityKind::Position => row("position", Body, "m", Xyz, true),
            QuantityKind::Modal => row("modal", FlexBody, "kg^0.5*m", Modes, true),
            QuantityKind::StrainEnergy => row("strain_energy", FlexBody, "J", One, true),
            QuantityKind::KineticEnergy => row("kinetic_energy", Body, "J", One, true),
            QuantityKind::TotalKineticEnergy => row("kinetic_energy", Scene, "J", One, true),
            QuantityKind::Deflection => row("deflection", FlexMarker, "m", Xyz, true),
            QuantityKind::Energy => row("energy", Scene, "J", One, false),
            QuantityKind::Violation => row("violation", Scene, "m|rad", One, false),
        }
    }

    /// The kind an output name is written with: `name` alone for the
    /// whole scene (`dotted = false`), else the part after the last dot.
    pub fn find(name: &str, dotted: bool) -> Option<QuantityKind> {
        QuantityKind::ALL.into_iter().find(|k| {
            let i = k.info();
            i.name == name && (i.subject != Subject::Scene) == dotted
        })
    }

    /// The accepted output names, for messages: `energy, ..,
    /// <joint>.reaction, ..`.
    pub fn accepted() -> String {
        let names: Vec<String> = QuantityKind::ALL
            .iter()
            .map(|k| {
                let i = k.info();
                match i.subject {
                    Subject::Scene => i.name.to_string(),
                    s => format!("{}.{}", s.name_pattern(), i.name),
                }
            })
            .collect();
        names.join(", ")
    }
}

/// One output column group: a kind of output of one joint, body or marker
/// (`of`, an index into the model's list; 0 for the whole scene).
#[derive(Debug, Clone, PartialEq)]
pub struct Quantity {
    /// What is written.
    pub kind: QuantityKind,
    /// Index of the joint, body or marker the output is of (0 for
    /// [`Subject::Scene`] kinds).
    pub of: usize,
    /// Number of columns of a [`Columns::Modes`] output (the body's modes;
    /// 0 when the scene runs the body rigid); 0 otherwise.
    pub modes: usize,
}

impl Quantity {
    /// An output of `kind` of joint, body or marker `of`.
    pub fn new(kind: QuantityKind, of: usize) -> Quantity {
        Quantity { kind, of, modes: 0 }
    }

    /// CSV column headers with SI units.
    pub fn headers(&self, label: &str) -> Vec<String> {
        const XYZ: [&str; 3] = ["x", "y", "z"];
        let info = self.kind.info();
        let unit = info.unit;
        match info.columns {
            Columns::One => vec![format!("{label} [{unit}]")],
            Columns::Xyz => XYZ
                .iter()
                .map(|c| format!("{label}_{c} [{unit}]"))
                .collect(),
            Columns::ForceTorque => {
                let base = label.trim_end_matches(".reaction");
                let mut h: Vec<String> = XYZ
                    .iter()
                    .map(|c| format!("{base}.force_{c} [N]"))
                    .collect();
                h.extend(XYZ.iter().map(|c| format!("{base}.torque_{c} [N*m]")));
                h
            }
            Columns::Modes => (1..=self.modes)
                .map(|j| format!("{label}_{j} [{unit}]"))
                .collect(),
        }
    }
}

/// Is the output name `name` one of the one-column forms (`energy`,
/// `violation`, `kinetic_energy`, `<joint>.angle|rate|displacement|velocity`,
/// `<body>.strain_energy|kinetic_energy`)? By its form only: whether the
/// joint or body exists is known when the scene is built.
pub fn scalar_output(name: &str) -> bool {
    let kind = match name.rsplit_once('.') {
        Some((head, what)) if !head.is_empty() => QuantityKind::find(what, true),
        _ => QuantityKind::find(name, false),
    };
    kind.is_some_and(|k| k.info().columns == Columns::One)
}
