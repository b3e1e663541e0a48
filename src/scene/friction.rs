//! `[[friction]]`: Coulomb friction contacts under a constant normal load (src/formulation.md §9).
//!
//! ```toml
//! [[friction]]
//! dof = 0                # the sliding DOF (node = … and direction = […]: not yet)
//! coefficient = 0.3      # μ
//! normal_force = 1.0     # constant normal load N: slip force μ·N
//! stiffness = 3.0        # optional: a Jenkins element (k_t in series with the slider)
//! ```
//! `contact` (the normal force of a `[[contact]]`) and `sliding_velocity` (rubbing) are part of
//! the interface but not yet solved: they are refused by name, never ignored.
use super::contacts::Resolver;
use super::{BuildError, DofSpec, Scene};
use crate::model::Friction;
use serde::Deserialize;

/// One `[[friction]]` entry as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    pub dof: Option<usize>,
    /// A node with a sliding `direction`: kept to be refused by name (not yet supported).
    pub node: Option<toml::Value>,
    pub direction: Option<toml::Value>,
    /// μ ≥ 0.
    pub coefficient: f64,
    /// N ≥ 0, constant.
    pub normal_force: Option<f64>,
    /// Tangential stiffness k_t > 0 of a Jenkins element.
    pub stiffness: Option<f64>,
    /// The normal force of `[[contact]]` i (coupled normal–tangential): not yet supported.
    pub contact: Option<toml::Value>,
    /// The counter-face's sliding speed (rubbing): not yet supported.
    pub sliding_velocity: Option<toml::Value>,
}

/// Keys of the interface that this version refuses, with what they would do.
const NOT_YET: [(&str, &str); 4] = [
    ("contact", "coupled normal–tangential friction (the normal force of a [[contact]])"),
    ("sliding_velocity", "rubbing against a counter-face sliding at a given speed"),
    ("node", "a friction contact on a named node"),
    ("direction", "a sliding direction over several DOFs"),
];

impl Scene {
    /// The `[[friction]]` entries in the full (clamped) numbering.
    pub(super) fn frictions(&self, resolver: &Resolver) -> Result<Vec<Friction>, BuildError> {
        if !self.friction.is_empty() && self.reduction.is_some() {
            return Err(BuildError::field(
                "friction",
                "is not yet supported together with [reduction] (the friction DOFs would have to be kept physical); solve the full model",
            ));
        }
        self.friction.iter().enumerate().map(|(i, f)| f.build(i, resolver)).collect()
    }
}

impl FrictionSpec {
    fn build(&self, i: usize, resolver: &Resolver) -> Result<Friction, BuildError> {
        let given = [self.contact.is_some(), self.sliding_velocity.is_some(), self.node.is_some(), self.direction.is_some()];
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
        let Some(normal_force) = self.normal_force else {
            return Err(BuildError::field(format!("friction[{i}]"), "needs normal_force = N (a constant normal load ≥ 0)"));
        };
        Ok(Friction::on_dof(full, self.coefficient, normal_force, self.stiffness))
    }
}
