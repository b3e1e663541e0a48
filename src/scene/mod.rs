//! Scene files (TOML): the user's description of a periodic contact problem.
//! Parsing checks types and keys; [`Scene::build`] checks values and builds the model.
//!
//! The room: `spec` (the TOML schema), `structure` (dense rows, Matrix Market files or the blade
//! generator; damping; clamping), `contacts` (forces, contacts, node names, casing motion, with
//! `casing` the casing's formula), `reduce` (Craig–Bampton), `outputs` (outputs in the user's
//! numbering, the [`OutputMap`](crate::periodic::OutputMap)), `units` (`[units]` and DOF names), `settings` (discretization and solver settings) and `error`.
pub mod casing;
mod contacts;
mod error;
mod files;
mod friction;
mod outputs;
pub mod profile;
mod reduce;
mod rotor;
mod settings;
mod spec;
mod structure;
mod units;

pub use casing::Casing;
pub use error::{BuildError, SceneError};
pub use files::FileReference;
pub use friction::FrictionSpec;
pub use settings::{accuracy_target, discretization, error_estimate, period_multiple, solver_settings};
pub use spec::*;

use crate::fe::{Blade, DofMap, NodeMap};
use crate::model::{Labels, Model, Structure};
use crate::periodic::PeriodicProblem;
use crate::periodic::limits::AccuracyTarget;
use crate::reduction::ReducedModel;
use contacts::Resolver;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A built scene: the problem to solve and what it was made from.
#[derive(Clone, Debug)]
pub struct SceneModel {
    /// Ready to solve. With a reduction its model is the reduced one; outputs and contact DOFs
    /// are reported in the scene's numbering either way.
    pub problem: PeriodicProblem,
    /// The full structure after clamping (`structure.fixed`), damping included when it is defined
    /// on the full model (`matrix` or `rayleigh`).
    pub full: Structure,
    /// Scene numbering (the matrices' or the generator's) → full (clamped) numbering.
    pub dofs: DofMap,
    /// Node number → its DOFs per direction in the scene's numbering (and position when known):
    /// the blade generator's (node = index + 1) or a CalculiX job's `.dof` map; `None` for matrices.
    pub nodes: Option<NodeMap>,
    /// The Craig–Bampton reduction, if `[reduction]`.
    pub reduction: Option<ReducedModel>,
    /// The checked casing, if `[casing]`.
    pub casing: Option<Casing>,
    /// The scene's DOF that labels each contact (its normal's largest |coefficient|), in
    /// contact order.
    pub contact_dofs: Vec<usize>,
    /// Each contact's row of B (unit normal) in the scene's numbering, in contact order.
    pub contact_rows: Vec<Vec<(usize, f64)>>,
    /// The scene's units (`[units]`, labels only) and DOF names, for the front ends.
    pub labels: Labels,
    /// Wall times of the set-up [s].
    pub timings: BuildTimings,
    /// `[discretization] error_estimate`: estimate the error of every result (default true).
    pub error_estimate: bool,
    /// `[discretization] scheme = "auto"`: the accuracy the front ends refine k for (the CLI's
    /// `solve` by `analysis::scheme_auto`; the FMU and the C API solve at the first k).
    pub accuracy_target: Option<AccuracyTarget>,
    /// With `scheme = "auto"`: the policy's choice of scheme, pairing and first k, and why.
    pub scheme_choice: Option<String>,
    /// `[discretization] polish`: refine by the event-fitted polish (default false).
    pub polish: bool,
    /// `[output] stability`: the front ends report the Floquet stability of every result
    /// (default false).
    pub stability: bool,
}

/// Wall times of [`Scene::build`] [s].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildTimings {
    /// Reading matrices or meshing and assembling the blade.
    pub structure: f64,
    /// The Craig–Bampton reduction (0 without).
    pub reduction: f64,
    pub total: f64,
}

/// Where the structure came from: named nodes exist only for a generator.
enum Source {
    Inline,
    Files,
    Blade(Box<Blade>),
}

impl Scene {
    /// Reads and parses a scene file. Relative paths inside it resolve against its folder.
    pub fn load(path: &Path) -> Result<(Scene, PathBuf), SceneError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::new(&file, format!("cannot read the scene file: {e}")))?;
        let scene = Scene::parse(&text, &file)?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok((scene, dir))
    }

    /// Parses scene text; `file` names the source in messages.
    pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
        toml::from_str::<Scene>(text).map_err(|e| SceneError::new(file, spec::explain_toml_error(&e)))
    }

    /// Sets the excitation frequency ω (with a casing, the rotation speed becomes ω / lobes).
    pub fn set_frequency(&mut self, omega: f64) {
        self.excitation.frequency = omega;
        if let Some(c) = &mut self.casing {
            c.speed = None;
        }
    }

    /// Builds the model and the problem, checking every value. `file` names the source in
    /// messages; relative Matrix Market paths resolve against its folder.
    pub fn to_problem(&self, file: &str) -> Result<PeriodicProblem, SceneError> {
        Ok(self.build(file)?.problem)
    }

    /// [`Scene::to_problem`] keeping what the problem was built from.
    pub fn build(&self, file: &str) -> Result<SceneModel, SceneError> {
        let dir = Path::new(file).parent().map(Path::to_path_buf).unwrap_or_default();
        self.build_in(file, &dir)
    }

    /// [`Scene::build`] with relative paths resolved against `dir`.
    pub fn build_in(&self, file: &str, dir: &Path) -> Result<SceneModel, SceneError> {
        self.assemble(dir).map_err(|e| SceneError::at(file, e))
    }

    /// The steps of [`Scene::build_in`], in the order their checks are reported.
    fn assemble(&self, dir: &Path) -> Result<SceneModel, BuildError> {
        let t0 = Instant::now();
        // The structure in the scene's numbering, damped on the full model, then clamped.
        let (source, structure, nodes) = self.structure_source(dir)?;
        let t_structure = t0.elapsed().as_secs_f64();
        let n_user = structure.mass.nrows();
        let labels = self.labels(&source)?;
        let (full, damping) = self.damped(structure, dir)?;
        let (full, dofs) = self.clamp(full, &source, nodes.as_ref())?;
        let resolver = Resolver { source: &source, dofs: &dofs, n_user, nodes: nodes.as_ref() };

        // Forces and contacts in the full numbering (user DOF kept for the labels), the casing.
        let forces = self.forces(&resolver)?;
        let casing = self.checked_casing(dir)?;
        let rotor = self.rotor(casing.as_ref(), &source)?;
        let mut placed = self.contacts(&resolver, rotor.as_ref())?;
        self.casing_motion(&mut placed, casing.as_ref(), &source, rotor)?;
        let spec_pairings = self.contact_pairings()?;
        let pairings: Vec<_> = placed.iter().map(|p| spec_pairings[p.spec]).collect();
        let contact_rows: Vec<Vec<(usize, f64)>> = placed.iter().map(|p| p.user_row.clone()).collect();
        let contact_dofs: Vec<usize> = contact_rows.iter().map(|r| crate::model::label_of(r).0).collect();
        let contacts: Vec<_> = placed.into_iter().map(|p| p.contact).collect();
        let (frictions, rubbing) = self.frictions(&resolver)?;
        let outputs = self.outputs(&resolver, matches!(source, Source::Inline), &contact_dofs, &forces)?;

        // The reduction, or the full model.
        let t_red = Instant::now();
        let frequency = self.excitation.frequency;
        let (model, map, reduction) = match &self.reduction {
            None => {
                let map = outputs::clamped_map(&outputs, &dofs, &contact_rows, !self.structure.fixed.is_empty());
                (Model { structure: full.clone(), forces, contacts, frequency, frictions, rubbing }, map, None)
            }
            Some(spec) => {
                let parts = reduce::FullModel { structure: &full, damping: &damping, forces: &forces, contacts: &contacts, frequency };
                let (model, map, red) = reduce::reduce(spec, parts, &resolver, &outputs, &contact_rows)?;
                (model, Some(map), Some(red))
            }
        };
        let t_reduction = if reduction.is_some() { t_red.elapsed().as_secs_f64() } else { 0.0 };
        model.validate().map_err(|e| self.name_matrix_file(e))?;

        let (disc, auto) = discretization(&self.discretization)?;
        let solver = solver_settings(self.solver.as_ref())?;
        let estimate = error_estimate(&self.discretization)?;
        let target = accuracy_target(&self.discretization)?;
        let mut problem = outputs::problem(model, (disc, auto), outputs, map, solver)?;
        if let Some((i, _)) = pairings.iter().enumerate().find(|(_, p)| p.is_some() && target.is_some()) {
            let why = "is given with discretization.scheme = \"auto\", which chooses the pairing with the scheme; remove the key or name a scheme";
            return Err(BuildError::field(format!("contact[{i}].pairing"), why.to_string()));
        }
        for (i, p) in pairings.into_iter().enumerate().filter(|(_, p)| p.is_some()) {
            problem.set_contact_pairing(i, p)?;
        }
        let scheme_choice = match &target {
            Some(t) => Some(settings::choose_scheme(&mut problem, t, &self.discretization)?),
            None => None,
        };
        problem.set_period_multiple(period_multiple(&self.discretization)?)?;
        let timings = BuildTimings { structure: t_structure, reduction: t_reduction, total: t0.elapsed().as_secs_f64() };
        let stability = self.output.as_ref().is_some_and(|o| o.stability);
        Ok(SceneModel {
            problem,
            full,
            dofs,
            nodes,
            reduction,
            casing,
            contact_dofs,
            contact_rows,
            labels,
            timings,
            error_estimate: estimate,
            accuracy_target: target,
            scheme_choice,
            polish: self.discretization.polish,
            stability,
        })
    }
}
