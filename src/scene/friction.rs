//! `[[friction]]`: Coulomb friction contacts under a constant normal load or a contact's normal
//! force (src/formulation.md §9).
//!
//! ```toml
//! [[friction]]
//! dof = 0                # the sliding DOF (node = … and direction = […]: not yet)
//! coefficient = 0.3      # μ
//! normal_force = 1.0     # constant normal load N: slip force μ·N
//! stiffness = 3.0        # optional: a Jenkins element (k_t in series with the slider)
//! ```
//! Rubbing in gross slip: `contact = i` with `sliding_velocity = V` (the counter-face of
//! `[[contact]]` i slides at V along `dof`, or along `direction = [tx, ty, tz]` or
//! `"tangential"` (the direction of rotation) at `node` or `dofs`, faster than the structure):
//! the friction force is μ·λ_n along V, no normal_force; with [reduction] too. `contact = i`
//! without `sliding_velocity`: coupled normal–tangential stick/slip, the slip force μ·λ_n of
//! `[[contact]]` i at each instant (rigid Coulomb along `dof`, no normal_force). `node` and
//! `direction` under a normal load are part of the interface but not yet solved: refused by name.
use super::contacts::Resolver;
use super::rotor::Rotor;
use super::{BuildError, DofSpec, NodeSpec, NormalSpec, Scene};
use crate::model::{Friction, Rubbing};
use serde::Deserialize;

/// One `[[friction]]` entry as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    pub dof: Option<usize>,
    /// Rubbing: the node the counter-face slides along, with `direction` (under a normal load:
    /// refused by name, not yet supported).
    pub node: Option<NodeSpec>,
    /// Rubbing: `[tx, ty, tz]` or `"tangential"` (the direction of rotation at the node).
    pub direction: Option<NormalSpec>,
    /// Rubbing: the node's DOFs (x, y, z) by index, with `position`, in Matrix Market scenes.
    pub dofs: Option<Vec<usize>>,
    pub position: Option<[f64; 3]>,
    /// μ ≥ 0.
    pub coefficient: f64,
    /// N ≥ 0, constant.
    pub normal_force: Option<f64>,
    /// Tangential stiffness k_t > 0 of a Jenkins element.
    pub stiffness: Option<f64>,
    /// The normal force of `[[contact]]` i: with `sliding_velocity`, rubbing in gross slip;
    /// without, coupled normal–tangential stick/slip.
    pub contact: Option<usize>,
    /// The counter-face's sliding speed V along `dof` (rubbing in gross slip).
    pub sliding_velocity: Option<f64>,
}

/// Keys of the interface that this version refuses, with what they would do.
const NOT_YET: [(&str, &str); 2] = [("node", "a friction contact on a named node"), ("direction", "a sliding direction over several DOFs")];

impl Scene {
    /// The `[[friction]]` entries in the full (clamped) numbering: Coulomb contacts under a
    /// normal load, and rubbing in gross slip (`contact` with `sliding_velocity`).
    pub(super) fn frictions(&self, resolver: &Resolver, rotor: Option<&Rotor>) -> Result<(Vec<Friction>, Vec<Rubbing>), BuildError> {
        let mut out = (Vec::new(), Vec::new());
        for (i, f) in self.friction.iter().enumerate() {
            match f.build(i, resolver, rotor)? {
                Built::Load(f) => out.0.push(f),
                Built::Rubbing(r) => out.1.push(r),
            }
        }
        if !out.0.is_empty() && !out.1.is_empty() {
            return Err(BuildError::field(
                "friction",
                "mixes rubbing (contact with sliding_velocity) and friction under a normal load: this version solves one kind per scene",
            ));
        }
        if !out.0.is_empty() && self.reduction.is_some() {
            return Err(BuildError::field(
                "friction",
                "under a normal load is not yet supported together with [reduction] (the friction DOFs would have to be kept physical); solve the full model",
            ));
        }
        Ok(out)
    }
}

/// One `[[friction]]` entry built.
enum Built {
    Load(Friction),
    Rubbing(Rubbing),
}

impl FrictionSpec {
    fn build(&self, i: usize, resolver: &Resolver, rotor: Option<&Rotor>) -> Result<Built, BuildError> {
        if let (Some(contact), Some(sliding_velocity)) = (self.contact, self.sliding_velocity) {
            return self.rubbing(i, resolver, rotor, contact, sliding_velocity).map(Built::Rubbing);
        }
        if self.sliding_velocity.is_some() {
            return Err(BuildError::field(
                format!("friction[{i}].sliding_velocity"),
                "needs contact = index: rubbing presses with the normal force of that [[contact]] (a constant normal_force with a sliding counter-face is not yet supported)",
            ));
        }
        let given = [self.node.is_some() || self.dofs.is_some() || self.position.is_some(), self.direction.is_some()];
        if let Some(((key, what), _)) = NOT_YET.iter().zip(given).find(|(_, g)| *g) {
            return Err(BuildError::field(
                format!("friction[{i}].{key}"),
                format!(
                    "is not yet supported ({what}); this version solves Coulomb friction on one DOF under a constant normal load: give dof = index and normal_force = N"
                ),
            ));
        }
        let Some(dof) = self.dof else {
            return Err(BuildError::field(format!("friction[{i}]"), "needs dof = index (the sliding DOF)"));
        };
        let (_, full) = resolver.output_pair(&format!("friction[{i}].dof"), &DofSpec::Index(dof))?;
        if let Some(contact) = self.contact {
            let refused = [("normal_force", self.normal_force.is_some()), ("stiffness", self.stiffness.is_some())];
            if let Some((key, _)) = refused.iter().find(|(_, g)| *g) {
                return Err(BuildError::field(
                    format!("friction[{i}].{key}"),
                    format!(
                        "is not taken by coupled friction (contact = {contact} without sliding_velocity) in this version: the normal force is the contact's, the friction rigid Coulomb"
                    ),
                ));
            }
            return Ok(Built::Load(Friction::coupled(full, self.coefficient, contact)));
        }
        let Some(normal_force) = self.normal_force else {
            return Err(BuildError::field(format!("friction[{i}]"), "needs normal_force = N (a constant normal load ≥ 0)"));
        };
        Ok(Built::Load(Friction::on_dof(full, self.coefficient, normal_force, self.stiffness)))
    }

    /// Rubbing in gross slip on `[[contact]]` `contact`, sliding along `dof`, or along `direction`
    /// at `node` or `dofs`.
    fn rubbing(&self, i: usize, resolver: &Resolver, rotor: Option<&Rotor>, contact: usize, sliding_velocity: f64) -> Result<Rubbing, BuildError> {
        let refused = [("normal_force", self.normal_force.is_some()), ("stiffness", self.stiffness.is_some())];
        if let Some((key, _)) = refused.iter().find(|(_, g)| *g) {
            return Err(BuildError::field(
                format!("friction[{i}].{key}"),
                "is not taken by rubbing in gross slip (contact with sliding_velocity) in this version: the normal force is the contact's, the friction rigid Coulomb",
            ));
        }
        let field = format!("friction[{i}]");
        let row = match (self.dof, &self.direction) {
            (Some(dof), None) if self.node.is_none() && self.dofs.is_none() => {
                vec![(resolver.output_pair(&format!("{field}.dof"), &DofSpec::Index(dof))?.1, 1.0)]
            }
            (None, Some(direction)) => resolver.sliding_row(&field, (self.node.as_ref(), self.dofs.as_deref(), self.position), direction, rotor)?,
            _ => {
                return Err(BuildError::field(
                    field,
                    "needs the sliding direction: dof = index, or direction = [tx, ty, tz] or \"tangential\" with node = … or dofs = [i, j, k] (not both)",
                ));
            }
        };
        Ok(Rubbing { contact, row, coefficient: self.coefficient, sliding_velocity })
    }
}
