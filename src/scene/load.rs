//! A study → [`Scene`]: the `[scene]` section with the modal bases of its
//! panel bodies taken from the study's `[[panels]]`.
//!
//! [`load_scene`] builds one scene as the study file describes it. Both
//! compute mode derivatives only for the bodies whose ply angles are
//! sensitivity parameters ([`SceneSpec::prune_derivatives`]).
//! [`ScenePlan`] is the road of a design through the code: the section is
//! parsed and the panels are resolved (mesh, design map) once; each
//! [`BasisBuilder`] (sparsity pattern, symbolic factorization, element
//! geometry) is made once per panel and derivative approach and reused for
//! every later design; a design goes in as laminates (ply angles in rad,
//! [`crate::laminate::Laminate::with_design`]), never as text. Builders
//! are pooled, so one plan serves parallel evaluations: each evaluation
//! takes a builder from the pool (or makes one when all are busy) and
//! gives it back. Within one build, bodies whose bases have the same
//! content (mesh, support, lay-up at the design, modes, derivatives, ...)
//! share one computation ([`crate::panels::shared`]).

use super::build::Scene;
use super::parts::Stiffening;
use super::spec::{Effect, FlexKind, OutputSpec, SceneSpec};
use crate::error::{Error, Result};
use crate::fe::Panel;
use crate::integrate::SensitivityForm;
use crate::laminate::Laminate;
use crate::mbs::ModalBasis;
use crate::modal::ModeUpdate;
use crate::panels::shared::{BasisKey, SharedBases};
use crate::panels::BasisBuilder;
use crate::study::Study;
use std::cell::{Cell, RefCell};
use std::sync::Mutex;
use std::time::Instant;

/// What one [`ScenePlan::build_profiled`] computed: panel bases (and how
/// many with mode derivatives), the bases shared instead of computed, and
/// the wall time spent in them and in the whole build.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BuildProfile {
    /// Panel modal bases computed (a body at rest takes none).
    pub bases: usize,
    /// Of those, bases with mode derivatives (dΛ/dθ, dX/dθ).
    pub derivative_bases: usize,
    /// Panel bodies that got a copy of a basis computed for another body
    /// of the same build with the same content
    /// ([`crate::panels::shared`]), not counted in `bases`.
    pub shared_bases: usize,
    /// Wall time in the panel bases \[s\] (assembly, factorization,
    /// Lanczos, derivatives, basis conversion, and the copies and
    /// content comparisons of shared bases).
    pub bases_seconds: f64,
    /// Wall time of the whole build \[s\] (bases included).
    pub total_seconds: f64,
}

/// Read the `[scene]` section of a study and build it. Panel bodies take
/// their modal basis from the study's `[[panels]]` (built only when the
/// scene lists `flexibility`).
pub fn load_scene(study: &Study) -> Result<Scene> {
    let mut spec: SceneSpec = study.require_section("scene", "the multibody scene")?;
    spec.prune_derivatives();
    let panels = |name: &str, modes: usize, update: Option<ModeUpdate>, geometric: Stiffening| {
        let thickness = spec.thickness_variables(name);
        if modes == 0 {
            // A body at rest (`ground` module).
            let variables = (update, &thickness[..]);
            return crate::panels::basis::rest_basis_for_study(study, name, variables);
        }
        crate::panels::basis_for_study_thickness(
            study,
            name,
            modes,
            (update, &thickness),
            geometric,
        )
    };
    spec.build_with(&panels).map_err(study.locate("scene"))
}

/// A panel's basis builder for one derivative approach.
struct Prepared {
    panel: usize,
    update: Option<ModeUpdate>,
    builder: BasisBuilder,
}

/// A study's scene prepared for many designs (module doc).
pub struct ScenePlan {
    study: Study,
    spec: SceneSpec,
    panels: Vec<Panel>,
    pool: Mutex<Vec<Prepared>>,
}

impl ScenePlan {
    /// Parse `[scene]` and resolve `[[panels]]`. Errors name the file and
    /// key; no basis is computed yet.
    pub fn new(study: &Study) -> Result<ScenePlan> {
        Ok(ScenePlan {
            study: study.clone(),
            spec: study.require_section("scene", "the multibody scene")?,
            panels: crate::fe::panels_from_study(study)?,
            pool: Mutex::new(Vec::new()),
        })
    }

    /// The `[scene]` section.
    pub fn spec(&self) -> &SceneSpec {
        &self.spec
    }

    /// Integrate with `method` from now on (overrides
    /// `[scene.integrator] method`).
    pub fn set_method(&mut self, method: crate::integrate::Method) {
        self.spec.integrator.method = method;
    }

    /// Integrate with the tolerances `rtol` and `atol` from now on
    /// (overrides `[scene.integrator]`).
    pub fn set_tolerances(&mut self, rtol: f64, atol: f64) {
        self.spec.integrator.rtol = rtol;
        self.spec.integrator.atol = atol;
    }

    /// Integrate forward sensitivities in `form` from now on (overrides
    /// `[scene.integrator] sensitivity_form`).
    pub fn set_sensitivity_form(&mut self, form: SensitivityForm) {
        self.spec.integrator.sensitivity_form = Some(form);
    }

    /// Compute the mode derivatives of every panel body that has them by
    /// `update` from now on (overrides each body's `derivatives`).
    pub fn set_mode_update(&mut self, update: ModeUpdate) {
        for b in &mut self.spec.bodies {
            if let Some(f) = b.flexible.as_mut().filter(|f| f.derivatives.is_some()) {
                f.derivatives = Some(update);
            }
        }
    }

    /// The `[[panels]]` entries, in file order, with the study's lay-ups.
    pub fn panels(&self) -> &[Panel] {
        &self.panels
    }

    /// Names of the bodies whose basis is panel `panel`'s modes.
    pub fn bodies_of_panel(&self, panel: &str) -> Vec<&str> {
        self.spec
            .bodies
            .iter()
            .filter(|b| {
                b.flexible
                    .as_ref()
                    .is_some_and(|f| f.kind == FlexKind::Panel && f.panel.as_deref() == Some(panel))
            })
            .map(|b| b.name.as_str())
            .collect()
    }

    /// The scene with panel `i` laid up as `laminates[i]` (one per
    /// `[[panels]]` entry, same ply count, angles in rad), the sensitivity
    /// parameters `sensitivities` (names as in `[scene] sensitivities`) and,
    /// with `outputs = false`, no output columns (responses need none).
    pub fn build(
        &self,
        laminates: &[Laminate],
        sensitivities: &[String],
        outputs: bool,
    ) -> Result<Scene> {
        Ok(self.build_profiled(laminates, sensitivities, outputs)?.0)
    }

    /// The scene with panel `i` laid up as `laminates[i]`, no sensitivity
    /// parameters and exactly the output columns `quantities` (names as in
    /// `[scene.outputs] quantities`, whose errors name that key; no plot).
    pub fn build_outputs(&self, laminates: &[Laminate], quantities: &[String]) -> Result<Scene> {
        let mut spec = self.spec.clone();
        spec.sensitivities = Vec::new();
        spec.outputs = OutputSpec {
            quantities: quantities.to_vec(),
            ..Default::default()
        };
        Ok(self.build_spec(spec, laminates)?.0)
    }

    /// [`ScenePlan::build`] with what it computed and its cost.
    pub fn build_profiled(
        &self,
        laminates: &[Laminate],
        sensitivities: &[String],
        outputs: bool,
    ) -> Result<(Scene, BuildProfile)> {
        let mut spec = self.spec.clone();
        spec.sensitivities = sensitivities.to_vec();
        if !outputs {
            spec.outputs = Default::default();
        }
        self.build_spec(spec, laminates)
    }

    /// Build `spec` (this plan's scene with its sensitivities and outputs
    /// chosen) with the panels laid up as `laminates`.
    fn build_spec(
        &self,
        mut spec: SceneSpec,
        laminates: &[Laminate],
    ) -> Result<(Scene, BuildProfile)> {
        let t0 = Instant::now();
        if laminates.len() != self.panels.len() {
            return Err(Error::input(
                "laminates",
                laminates.len(),
                format!("one laminate per [[panels]] entry ({})", self.panels.len()),
            ));
        }
        spec.prune_derivatives();
        let profile = Cell::new(BuildProfile::default());
        let uses = self.panel_uses(&spec);
        let shared = RefCell::new(SharedBases::new(&self.panels, laminates, &uses));
        let bases =
            |name: &str, modes: usize, update: Option<ModeUpdate>, geometric: Stiffening| {
                let t = Instant::now();
                let thickness = spec.thickness_variables(name);
                let key = (self.panels.iter())
                    .position(|p| p.name == name)
                    .filter(|&i| shared.borrow().shareable(i))
                    .map(|i| {
                        let input = (&self.panels[i], &laminates[i]);
                        BasisKey::new(input, modes, update, geometric, &thickness)
                    });
                let found = key.as_ref().and_then(|k| shared.borrow().find(k).cloned());
                let mut p = profile.get();
                let basis = match found {
                    Some(b) => {
                        p.shared_bases += 1;
                        Ok(b)
                    }
                    None => {
                        let basis =
                            self.basis(name, modes, (update, geometric), (laminates, &thickness));
                        // A body at rest takes no eigen-analysis (modes = 0).
                        let computed = usize::from(modes > 0);
                        p.bases += computed;
                        p.derivative_bases += computed * usize::from(update.is_some());
                        if let (Some(k), Ok(b)) = (key, &basis) {
                            shared.borrow_mut().keep(k, b);
                        }
                        basis
                    }
                };
                p.bases_seconds += t.elapsed().as_secs_f64();
                profile.set(p);
                basis
            };
        let scene = spec
            .build_with(&bases)
            .map_err(self.study.locate("scene"))?;
        let mut p = profile.get();
        p.total_seconds = t0.elapsed().as_secs_f64();
        Ok((scene, p))
    }

    /// How many flexible bodies of `spec` take their basis from each
    /// `[[panels]]` entry (none when the scene runs without
    /// `flexibility`).
    fn panel_uses(&self, spec: &SceneSpec) -> Vec<usize> {
        let mut uses = vec![0; self.panels.len()];
        if !spec.has(Effect::Flexibility) {
            return uses;
        }
        let panel_names = spec.bodies.iter().filter_map(|b| {
            let f = b.flexible.as_ref()?;
            (f.kind == FlexKind::Panel).then_some(f.panel.as_deref()?)
        });
        for name in panel_names {
            if let Some(i) = self.panels.iter().position(|p| p.name == name) {
                uses[i] += 1;
            }
        }
        uses
    }

    /// The basis of panel `name` with lay-up `laminates[i]`, from a pooled
    /// builder; with its geometric stiffness when `geometric`. `modes = 0`:
    /// the basis of a body at rest, without a builder
    /// ([`crate::panels::basis::rest_basis`]).
    fn basis(
        &self,
        name: &str,
        modes: usize,
        (update, geometric): (Option<ModeUpdate>, Stiffening),
        (laminates, thickness): (&[Laminate], &[String]),
    ) -> Result<ModalBasis> {
        let Some(i) = self.panels.iter().position(|p| p.name == name) else {
            return Err(crate::panels::unknown_panel(
                &self.study,
                name,
                &self.panels,
            ));
        };
        let located = |e: Error| {
            crate::panels::in_panel(e, name).in_file(&self.study.path, &format!("panels[{i}]"))
        };
        if modes == 0 {
            let variables = (update, thickness);
            return crate::panels::basis::rest_basis(&self.panels[i], &laminates[i], variables)
                .map_err(located);
        }
        let taken = {
            let mut pool = self.pool.lock().unwrap_or_else(|p| p.into_inner());
            let k = pool.iter().position(|p| p.panel == i && p.update == update);
            k.map(|k| pool.swap_remove(k))
        };
        let mut prepared = match taken {
            Some(p) => p,
            None => Prepared {
                panel: i,
                update,
                builder: BasisBuilder::new(&self.panels[i], update).map_err(located)?,
            },
        };
        prepared.builder.set_geometric(geometric.is_some());
        prepared.builder.set_joint_points(geometric.unwrap_or(&[]));
        let basis = match prepared.builder.set_thickness(thickness) {
            Ok(()) => prepared.builder.basis(&laminates[i], modes),
            Err(e) => Err(e),
        }
        .map_err(located);
        self.pool
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .push(prepared);
        basis
    }
}
