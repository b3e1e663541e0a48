//! The `[reduction]` section: Craig–Bampton reduction of the clamped structure, with the contact
//! DOFs (and `extra_boundary`) kept physical, and the outputs mapped back through x = Φ q.
use super::contacts::Resolver;
use super::structure::DampingGiven;
use super::{BuildError, ReductionSpec};
use crate::model::{Contact, Force, Harmonic, Model, Structure};
use crate::periodic::{OutputMap, OutputSelection};
use crate::reduction::{CraigBamptonOptions, DEFAULT_MODES, Damping, ReducedModel, ReductionError};

/// The full (clamped) model's parts that the reduction projects.
pub(super) struct FullModel<'a> {
    pub structure: &'a Structure,
    pub damping: &'a DampingGiven,
    pub forces: &'a [Force],
    pub contacts: &'a [Contact],
    pub frequency: f64,
}

/// The reduced model, the map of the outputs (scene DOF → reduced DOFs) and the reduction.
pub(super) fn reduce(
    spec: &ReductionSpec,
    full: FullModel,
    resolver: &Resolver,
    outputs: &OutputSelection,
    contact_dofs: &[usize],
) -> Result<(Model, OutputMap, ReducedModel), BuildError> {
    if spec.method != "craig-bampton" {
        return Err(BuildError::field("reduction.method", format!("is \"{}\", expected \"craig-bampton\"", spec.method)));
    }
    let boundary = boundary(spec, full.contacts, resolver)?;
    let damping = match (&full.damping.modal_ratios, full.damping.rayleigh, &full.structure.damping) {
        (Some(z), _, _) => Damping::ModalRatios(z.clone()),
        (None, Some((alpha, beta)), _) => Damping::Rayleigh { alpha, beta },
        (None, None, Some(c)) => Damping::Matrix(crate::reduction::to_sparse(c)),
        (None, None, None) => Damping::None,
    };
    let undamped = Structure { mass: full.structure.mass.clone(), stiffness: full.structure.stiffness.clone(), damping: None };
    let opts = CraigBamptonOptions { modes: spec.modes.unwrap_or(DEFAULT_MODES), ..Default::default() };
    let red = crate::reduction::reduce_structure(&undamped, &boundary, &opts, Some(&damping)).map_err(|e| match e {
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
    let contacts = full.contacts.iter().map(|c| Contact { dof: red.reduced_dof(c.dof).expect("contacts are boundary DOFs"), ..c.clone() }).collect();
    let model = Model { structure: red.structure(), forces, contacts, frequency: full.frequency, frictions: Vec::new() };
    let rows = outputs.dofs().into_iter().map(|u| (u, row(resolver.dofs.new_index(u).expect("checked")))).collect();
    let map = OutputMap { rows, contact_dofs: contact_dofs.to_vec(), effects: vec!["reduction".into()] };
    Ok((model, map, red))
}

/// The boundary DOFs (full numbering): the contacts', then `extra_boundary`, each once.
fn boundary(spec: &ReductionSpec, contacts: &[Contact], resolver: &Resolver) -> Result<Vec<usize>, BuildError> {
    let mut boundary: Vec<usize> = Vec::new();
    for c in contacts {
        if !boundary.contains(&c.dof) {
            boundary.push(c.dof);
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
