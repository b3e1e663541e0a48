//! The `[reduction]` section: Craig–Bampton or massless-boundary reduction of the clamped
//! structure, with the contact DOFs (and `extra_boundary`) kept physical, and the outputs mapped
//! back through x = Φ q.
use super::contacts::Resolver;
use super::structure::DampingGiven;
use super::{BuildError, ReductionSpec};
use crate::model::{Contact, Force, Harmonic, Model, Rubbing, Structure};
use crate::periodic::{OutputMap, OutputSelection};
use crate::reduction::{CraigBamptonOptions, DEFAULT_MODES, Damping, Method, ReducedModel, ReductionError};

/// The full (clamped) model's parts that the reduction projects.
pub(super) struct FullModel<'a> {
    pub structure: &'a Structure,
    pub damping: &'a DampingGiven,
    pub forces: &'a [Force],
    pub contacts: &'a [Contact],
    /// Rubbing contacts: their sliding rows are kept physical like the contacts' rows.
    pub rubbing: &'a [Rubbing],
    pub frequency: f64,
}

/// The reduced model, the map of the outputs (scene DOF → reduced DOFs) and the reduction.
pub(super) fn reduce(
    spec: &ReductionSpec,
    full: FullModel,
    resolver: &Resolver,
    outputs: &OutputSelection,
    contact_rows: &[Vec<(usize, f64)>],
) -> Result<(Model, OutputMap, ReducedModel), BuildError> {
    let method = match spec.method.as_str() {
        "craig-bampton" => Method::CraigBampton,
        "massless-boundary" => Method::MasslessBoundary,
        other => return Err(BuildError::field("reduction.method", format!("is \"{other}\", expected \"craig-bampton\" or \"massless-boundary\""))),
    };
    let boundary = boundary(spec, full.contacts, full.rubbing, resolver)?;
    let damping = match (&full.damping.modal_ratios, full.damping.rayleigh, &full.structure.damping) {
        (Some(z), _, _) => Damping::ModalRatios(z.clone()),
        (None, Some((alpha, beta)), _) => Damping::Rayleigh { alpha, beta },
        (None, None, Some(c)) => Damping::Matrix(crate::reduction::to_sparse(c)),
        (None, None, None) => Damping::None,
    };
    let opts = CraigBamptonOptions { modes: spec.modes.unwrap_or(DEFAULT_MODES), ..Default::default() };
    // The damping given overrides the structure's matrix (no copy of M and K to drop it).
    let red = crate::reduction::reduce_structure(full.structure, method, &boundary, &opts, Some(&damping)).map_err(|e| match e {
        ReductionError::TooManyModes { requested, internal } => BuildError::field(
            "reduction.modes",
            format!("is {requested}, but only {internal} internal DOFs remain besides the {} boundary DOFs", boundary.len()),
        ),
        ReductionError::Damping(m) => BuildError::field("damping", m),
        other => BuildError::field("reduction", other.to_string()),
    })?;
    let row = |d: usize| -> Vec<(usize, f64)> {
        match red.reduced_dof(d) {
            Some(b) => vec![(b, 1.0)],
            None => red.basis_row(d).into_iter().enumerate().filter(|(_, c)| *c != 0.0).collect(),
        }
    };
    let mut forces = Vec::new();
    for f in full.forces {
        for (q, c) in row(f.dof) {
            forces.push(Force { dof: q, term: Harmonic { amplitude: f.term.amplitude * c, ..f.term.clone() } });
        }
    }
    // Every DOF of a contact's row is a boundary DOF: the row keeps its coefficients.
    let boundary_row = |row: &[(usize, f64)]| row.iter().map(|&(d, v)| (red.reduced_dof(d).expect("contacts and sliding rows are boundary DOFs"), v)).collect();
    let contacts = full.contacts.iter().map(|c| Contact { row: boundary_row(&c.row), ..c.clone() }).collect();
    let rubbing = full.rubbing.iter().map(|r| Rubbing { row: boundary_row(&r.row), ..r.clone() }).collect();
    let model = Model { structure: red.structure(), forces, contacts, frequency: full.frequency, frictions: Vec::new(), rubbing };
    let rows = outputs.dofs().into_iter().map(|u| (u, row(resolver.dofs.new_index(u).expect("checked")))).collect();
    let map = OutputMap { rows, contact_rows: contact_rows.to_vec(), effects: vec!["reduction".into()] };
    Ok((model, map, red))
}

/// The boundary DOFs (full numbering): the contacts', the rubbing contacts' sliding rows', then
/// `extra_boundary`, each once.
fn boundary(spec: &ReductionSpec, contacts: &[Contact], rubbing: &[Rubbing], resolver: &Resolver) -> Result<Vec<usize>, BuildError> {
    let mut boundary: Vec<usize> = Vec::new();
    for &(d, _) in contacts.iter().flat_map(|c| &c.row).chain(rubbing.iter().flat_map(|r| &r.row)) {
        if !boundary.contains(&d) {
            boundary.push(d);
        }
    }
    for (i, e) in spec.extra_boundary.iter().enumerate() {
        let (_, d) = resolver.output_pair(&format!("reduction.extra_boundary[{i}]"), e)?;
        if !boundary.contains(&d) {
            boundary.push(d);
        }
    }
    Ok(boundary)
}
