//! Outputs in the user's numbering: the `[output]` section or its defaults, the [`OutputMap`]
//! from the scene's DOFs to the solved model's, and the problem that reports them.
use super::contacts::Resolver;
use super::{BuildError, DofSpec, Scene};
use crate::fe::DofMap;
use crate::model::{Force, Model};
use crate::periodic::{OutputMap, OutputSelection, PeriodicProblem, SolverSettings};
use crate::time::Discretization;

impl Scene {
    /// The outputs in the scene's numbering: `[output]`, or by default every DOF of a small
    /// inline model, else the contact (label) and loaded DOFs.
    pub(super) fn outputs(&self, resolver: &Resolver, dense_inline: bool, contact_dofs: &[usize], forces: &[Force]) -> Result<OutputSelection, BuildError> {
        let dofs = resolver.dofs;
        Ok(match &self.output {
            Some(o) => {
                let list = |name: &str, l: &[DofSpec]| -> Result<Vec<usize>, BuildError> {
                    l.iter().enumerate().map(|(i, d)| resolver.output(&format!("output.{name}[{i}]"), d)).collect()
                };
                OutputSelection {
                    displacement: list("displacement", &o.displacement)?,
                    velocity: list("velocity", &o.velocity)?,
                    acceleration: list("acceleration", &o.acceleration)?,
                    contacts: o.contacts,
                }
            }
            None if dense_inline => OutputSelection { displacement: dofs.new_to_old.clone(), velocity: vec![], acceleration: vec![], contacts: true },
            None => {
                // Large models: the contact and loaded DOFs, not every DOF.
                let mut d: Vec<usize> = contact_dofs.to_vec();
                d.extend(forces.iter().map(|f| dofs.new_to_old[f.dof]));
                d.sort_unstable();
                d.dedup();
                OutputSelection { displacement: d, velocity: vec![], acceleration: vec![], contacts: true }
            }
        })
    }
}

/// The map of an unreduced model: none when nothing is clamped (the numberings agree), else
/// each output's scene DOF → its clamped DOF.
pub(super) fn clamped_map(outputs: &OutputSelection, dofs: &DofMap, contact_rows: &[Vec<(usize, f64)>], clamped: bool) -> Option<OutputMap> {
    clamped.then(|| {
        let rows = outputs.dofs().into_iter().map(|u| (u, vec![(dofs.new_index(u).expect("checked"), 1.0)])).collect();
        OutputMap { rows, contact_rows: contact_rows.to_vec(), effects: vec![] }
    })
}

/// The problem with its outputs: directly in the model's numbering, or through `map`.
pub(super) fn problem(
    model: Model,
    (disc, auto): (Discretization, bool),
    outputs: OutputSelection,
    map: Option<OutputMap>,
    solver: SolverSettings,
) -> Result<PeriodicProblem, BuildError> {
    let new = if auto { PeriodicProblem::new_auto } else { PeriodicProblem::new };
    let Some(map) = map else {
        let n = model.n();
        for (name, list) in [("displacement", &outputs.displacement), ("velocity", &outputs.velocity), ("acceleration", &outputs.acceleration)] {
            if let Some((i, d)) = list.iter().enumerate().find(|(_, d)| **d >= n) {
                return Err(BuildError::field(format!("output.{name}[{i}]"), format!("DOF {d} does not exist, the model has DOFs 0 to {}", n - 1)));
            }
        }
        return Ok(new(model, disc, outputs, solver)?);
    };
    Ok(new(model, disc, OutputSelection::default(), solver).and_then(|p| p.with_output_map(outputs, map))?)
}
