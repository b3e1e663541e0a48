//! Coulomb friction contacts (src/formulation.md §9): one more kind of row of B.
//!
//! Sign conventions (the same as a unilateral contact's, whose force z acts as −Bᵀz):
//! - the row b (a sliding direction over DOFs) gives the tangential displacement u = b x and the
//!   slip velocity v = b ẋ;
//! - the friction force f acts on the structure as −bᵀ f, so f has the sign of the slip:
//!   f = μN·sign(v) while slipping, |f| ≤ μN while stuck (v = 0), and f·v ≥ 0 is the power
//!   dissipated (the energy per cycle is ∮ f v dt ≥ 0).
//! - with a tangential stiffness k_t (a Jenkins element: a spring in series with the slider) the
//!   slider's velocity v − ḟ/k_t takes the place of v.
use super::ModelError;

/// A Coulomb friction contact under a constant normal load, or pressed by the normal force of a
/// unilateral contact (coupled normal–tangential friction, src/formulation.md §9).
#[derive(Clone, Debug, PartialEq)]
pub struct Friction {
    /// The sliding direction as a row of B: (model DOF, coefficient) terms.
    pub row: Vec<(usize, f64)>,
    /// Friction coefficient μ ≥ 0.
    pub coefficient: f64,
    /// Normal load N ≥ 0 (constant).
    pub normal_force: f64,
    /// Tangential stiffness k_t > 0 of a Jenkins element; `None`: rigid Coulomb.
    pub stiffness: Option<f64>,
    /// Coupled: the index of the contact whose normal force λ_n presses the faces together (slip
    /// force μ·λ_n at each instant; `normal_force` is then 0); `None`: the constant load N.
    pub contact: Option<usize>,
}

impl Friction {
    /// A friction contact sliding along one DOF.
    pub fn on_dof(dof: usize, coefficient: f64, normal_force: f64, stiffness: Option<f64>) -> Self {
        Friction { row: vec![(dof, 1.0)], coefficient, normal_force, stiffness, contact: None }
    }

    /// A rigid Coulomb contact sliding along one DOF, pressed by the normal force of contact
    /// `contact` (coupled normal–tangential friction).
    pub fn coupled(dof: usize, coefficient: f64, contact: usize) -> Self {
        Friction { row: vec![(dof, 1.0)], coefficient, normal_force: 0.0, stiffness: None, contact: Some(contact) }
    }

    /// The slip force μN of the constant normal load: the largest friction force the contact
    /// transmits (0 for a coupled contact, whose bound μ·λ_n varies with its contact's force).
    pub fn slip_force(&self) -> f64 {
        if self.contact.is_some() { 0.0 } else { self.coefficient * self.normal_force }
    }

    /// Checks friction `i` of a model with `n` DOFs and `contacts` contacts; fields are named as in
    /// the scene.
    pub(super) fn check(&self, i: usize, n: usize, contacts: usize) -> Result<(), ModelError> {
        let field = |f: &str| format!("friction[{i}].{f}");
        if let Some(c) = self.contact {
            if c >= contacts {
                return Err(ModelError::new(
                    field("contact"),
                    format!("is {c}, the model has {contacts} contact(s): give the index of the [[contact]] whose normal force presses this friction contact"),
                ));
            }
            if self.stiffness.is_some() || self.normal_force != 0.0 {
                return Err(ModelError::new(
                    field("contact"),
                    "a coupled friction contact takes its normal force from the contact and is rigid Coulomb in this version: leave out normal_force and stiffness",
                ));
            }
        }
        if self.row.is_empty() {
            return Err(ModelError::new(field("dof"), "is missing: a friction contact needs a sliding direction"));
        }
        for &(d, c) in &self.row {
            if d >= n {
                return Err(ModelError::new(field("dof"), format!("is {d}, the model has DOFs 0..{}", n - 1)));
            }
            if !c.is_finite() {
                return Err(ModelError::new(field("direction"), format!("has the coefficient {c}, must be finite")));
            }
        }
        if !(self.coefficient.is_finite() && self.coefficient >= 0.0) {
            return Err(ModelError::new(field("coefficient"), format!("is {}, a friction coefficient μ must be finite and ≥ 0", self.coefficient)));
        }
        if !(self.normal_force.is_finite() && self.normal_force >= 0.0) {
            return Err(ModelError::new(
                field("normal_force"),
                format!("is {}, a normal load must be finite and ≥ 0 (compressive); a tensile load cannot hold friction", self.normal_force),
            ));
        }
        if !self.slip_force().is_finite() {
            return Err(ModelError::new(
                field("normal_force"),
                format!("μ·N = {}·{} overflows floating point; rescale the units", self.coefficient, self.normal_force),
            ));
        }
        if let Some(k) = self.stiffness
            && !(k.is_finite() && k > 0.0 && (1.0 / k).is_finite())
        {
            return Err(ModelError::new(
                field("stiffness"),
                format!("is {k}, a tangential stiffness must be finite and > 0 (omit it for rigid Coulomb friction)"),
            ));
        }
        Ok(())
    }
}

/// Rubbing in gross slip (src/formulation.md §9): the counter-face of contact `contact` slides
/// along `row` at `sliding_velocity`, faster than the structure ever moves along it, so the
/// friction force is μ·λ_n along the counter-face's motion. The contact force on the structure
/// is −(n − μ·sign(V)·t)ᵀ λ_n: the LCP keeps its size and loses its symmetry.
#[derive(Clone, Debug, PartialEq)]
pub struct Rubbing {
    /// Index of the `[[contact]]` whose normal force presses the faces together.
    pub contact: usize,
    /// The sliding direction t as (model DOF, coefficient) terms.
    pub row: Vec<(usize, f64)>,
    /// Friction coefficient μ ≥ 0.
    pub coefficient: f64,
    /// The counter-face's speed V along t (≠ 0); its sign sets the friction's direction.
    pub sliding_velocity: f64,
}

impl Rubbing {
    /// −μ·sign(V): the tangential row's force per unit normal force (a row's force z acts as −tᵀz).
    pub fn traction(&self) -> f64 {
        -self.coefficient * self.sliding_velocity.signum()
    }

    /// Checks rubbing `i` (scene key `friction[i]`) of a model with `n` DOFs and `contacts` contacts.
    pub(super) fn check(&self, i: usize, n: usize, contacts: usize) -> Result<(), ModelError> {
        let field = |f: &str| format!("friction[{i}].{f}");
        if self.contact >= contacts {
            return Err(ModelError::new(
                field("contact"),
                format!("is {}, the model has {contacts} contact(s): give the index of a [[contact]]", self.contact),
            ));
        }
        if self.row.is_empty() || self.row.iter().any(|&(d, c)| d >= n || !c.is_finite()) {
            return Err(ModelError::new(field("direction"), format!("{:?} is not a sliding direction over DOFs 0..{n} with finite coefficients", self.row)));
        }
        if !(self.coefficient.is_finite() && self.coefficient >= 0.0) {
            return Err(ModelError::new(field("coefficient"), format!("is {}, a friction coefficient μ must be finite and ≥ 0", self.coefficient)));
        }
        if !(self.sliding_velocity.is_finite() && self.sliding_velocity != 0.0) {
            return Err(ModelError::new(
                field("sliding_velocity"),
                format!("is {}, the counter-face's speed must be finite and ≠ 0 (its sign gives the friction's direction)", self.sliding_velocity),
            ));
        }
        Ok(())
    }
}
