//! The output plan of a scene: output columns ([`Quantity`]) and
//! response functionals ([`Response`]) resolved to model indices.

use crate::mbs::Energy;

/// A built response: a functional of a sum of energies over the run.
#[derive(Debug, Clone, PartialEq)]
pub enum Response {
    /// `∫ scale·Σ terms dt`: index into [`crate::mbs::Model::integrals`].
    Integral { name: String, index: usize },
    /// `max_t scale·Σ terms(t)` at its critical time point.
    Peak {
        name: String,
        terms: Vec<Energy>,
        scale: f64,
    },
    /// `scale·Σ terms` at the end time.
    Final {
        name: String,
        terms: Vec<Energy>,
        scale: f64,
    },
}

impl Response {
    /// The response's name.
    pub fn name(&self) -> &str {
        match self {
            Response::Integral { name, .. }
            | Response::Peak { name, .. }
            | Response::Final { name, .. } => name,
        }
    }
}

/// One output column.
#[derive(Debug, Clone, PartialEq)]
pub enum Quantity {
    Angle(usize),
    Rate(usize),
    /// Displacement of a prismatic or cylindrical joint along its axis (m).
    Displacement(usize),
    /// Its rate (m/s).
    Velocity(usize),
    /// Reaction force (3) and torque (3) of a joint.
    Reaction(usize),
    /// Global position of a body's centre of mass (of a flexible body:
    /// of its frame origin).
    Position(usize),
    /// Modal coordinates `w` of a flexible body (body, n: n columns).
    Modal(usize, usize),
    /// Strain energy `½ wᵀΛw` of a flexible body (J).
    Strain(usize),
    /// Kinetic energy of a body, or of all bodies (`None`) (J).
    Kinetic(Option<usize>),
    /// Elastic displacement `Φ_k w` of a marker on a flexible node, in
    /// the body's frame axes (m).
    Deflection(usize),
    Energy,
    Violation,
}

/// Is the output name `name` one of the one-column forms (`energy`,
/// `violation`, `kinetic_energy`, `<joint>.angle|rate|displacement|velocity`,
/// `<body>.strain_energy|kinetic_energy`)? By its form only: whether the
/// joint or body exists is known when the scene is built.
pub fn scalar_output(name: &str) -> bool {
    const WHOLE: [&str; 3] = ["energy", "violation", "kinetic_energy"];
    const SUFFIXES: [&str; 6] = [
        "angle",
        "rate",
        "displacement",
        "velocity",
        "strain_energy",
        "kinetic_energy",
    ];
    WHOLE.contains(&name)
        || name
            .rsplit_once('.')
            .is_some_and(|(head, what)| !head.is_empty() && SUFFIXES.contains(&what))
}

impl Quantity {
    /// CSV column headers with SI units.
    pub fn headers(&self, label: &str) -> Vec<String> {
        match self {
            Quantity::Angle(_) => vec![format!("{label} [rad]")],
            Quantity::Rate(_) => vec![format!("{label} [rad/s]")],
            Quantity::Displacement(_) => vec![format!("{label} [m]")],
            Quantity::Velocity(_) => vec![format!("{label} [m/s]")],
            Quantity::Reaction(_) => {
                let base = label.trim_end_matches(".reaction");
                let mut h: Vec<String> = ["x", "y", "z"]
                    .iter()
                    .map(|c| format!("{base}.force_{c} [N]"))
                    .collect();
                h.extend(
                    ["x", "y", "z"]
                        .iter()
                        .map(|c| format!("{base}.torque_{c} [N*m]")),
                );
                h
            }
            Quantity::Position(_) => ["x", "y", "z"]
                .iter()
                .map(|c| format!("{label}_{c} [m]"))
                .collect(),
            Quantity::Modal(_, n) => (1..=*n)
                .map(|j| format!("{label}_{j} [kg^0.5*m]"))
                .collect(),
            Quantity::Strain(_) | Quantity::Kinetic(_) => vec![format!("{label} [J]")],
            Quantity::Deflection(_) => ["x", "y", "z"]
                .iter()
                .map(|c| format!("{label}_{c} [m]"))
                .collect(),
            Quantity::Energy => vec!["energy [J]".into()],
            Quantity::Violation => vec!["violation [m|rad]".into()],
        }
    }
}
