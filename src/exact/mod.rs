//! Independent references: semi-analytic periodic orbits of the 1-DOF oscillator
//! m x'' + c x' + k x = F cos Ωt (forcing phase 0), with and without a unilateral stop
//! (src/formulation.md §6), and the multi-DOF linear steady state (src/formulation.md §6.1).
//!
//! Sign convention (src/formulation.md §1, `model` module): the stop acts on x with direction s = +1, i.e.
//! x ≤ g0 (clearance g0 − x ≥ 0), and its compressive force z ≥ 0 pushes the mass by −z:
//! m x'' + c x' + k x = F cos Ωt − z.
//!
//! These solvers use closed-form flows of the linear phases (a 2×2 matrix exponential plus the
//! particular solution of the cosine forcing) and do not use the crate's `lcp`, `time` or
//! periodic assembly code, so that they can test it.
mod compliant;
mod flow;
mod friction;
mod linear;
mod persistent;
mod rigid;

pub use compliant::CompliantStopOrbit;
pub use friction::{FrictionOrbit, FrictionOscillator, den_hartog_amplitude};
pub use linear::{LinearOrbit, LinearResponse, linear_response_dense};
pub use persistent::PersistentContact;
pub use rigid::{RigidRegime, RigidStopOrbit};

use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};

/// Why a reference cannot be computed: the parameter, its value and why, or the orbit sought
/// does not exist for these parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExactError {
    /// A parameter (`mass`, `gap`, `seed`, …) is out of range or leads nowhere.
    #[error("{field}: {message}")]
    Param { field: String, message: String },
    /// No periodic solution of the sought kind (resonance, no stable orbit).
    #[error("{0}")]
    NoSolution(String),
}

impl ExactError {
    pub fn param(field: impl Into<String>, message: impl Into<String>) -> Self {
        ExactError::Param { field: field.into(), message: message.into() }
    }
}

impl From<ExactError> for crate::Error {
    fn from(e: ExactError) -> Self {
        crate::Error::input(e.to_string())
    }
}

/// The forced 1-DOF oscillator m x'' + c x' + k x = F cos Ωt.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Oscillator {
    /// m > 0.
    pub mass: f64,
    /// c ≥ 0.
    pub damping: f64,
    /// k ≥ 0 (> 0 for the contact orbits).
    pub stiffness: f64,
    /// F (finite; ≥ 0 for [`RigidStopOrbit`]).
    pub force: f64,
    /// Ω > 0 [rad/s].
    pub omega: f64,
}

impl Oscillator {
    pub fn new(mass: f64, damping: f64, stiffness: f64, force: f64, omega: f64) -> Self {
        Oscillator { mass, damping, stiffness, force, omega }
    }

    /// Every error names the parameter and its value.
    pub fn validate(&self) -> Result<(), ExactError> {
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(ExactError::param("mass", format!("is {}, must be finite and > 0", self.mass)));
        }
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return Err(ExactError::param("damping", format!("is {}, must be finite and ≥ 0", self.damping)));
        }
        if !(self.stiffness.is_finite() && self.stiffness >= 0.0) {
            return Err(ExactError::param("stiffness", format!("is {}, must be finite and ≥ 0", self.stiffness)));
        }
        if !self.force.is_finite() {
            return Err(ExactError::param("force", format!("is {}, must be finite", self.force)));
        }
        if !(self.omega.is_finite() && self.omega > 0.0) {
            return Err(ExactError::param("omega", format!("is {}, must be finite and > 0", self.omega)));
        }
        Ok(())
    }

    pub(crate) fn require_stiffness(&self) -> Result<(), ExactError> {
        if self.stiffness > 0.0 { Ok(()) } else { Err(ExactError::param("stiffness", format!("is {}, the contact orbits need k > 0", self.stiffness))) }
    }

    /// T = 2π/Ω.
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega
    }

    /// The same oscillator as a 1-DOF [`Model`] (DOF 0, forcing F cos Ωt, damping `None` when
    /// c = 0) with the given contacts.
    pub fn model(&self, contacts: Vec<Contact>) -> Model {
        let one = |v: f64| Matrix::from_rows(&[vec![v]]);
        Model {
            structure: Structure {
                mass: one(self.mass),
                stiffness: one(self.stiffness),
                damping: if self.damping > 0.0 { Some(one(self.damping)) } else { None },
            },
            forces: vec![Force { dof: 0, term: Harmonic { amplitude: self.force, harmonic: 1, phase: 0.0 } }],
            contacts,
            frequency: self.omega,
            frictions: Vec::new(),
            rubbing: Vec::new(),
        }
    }

    /// A static stop x ≤ gap on DOF 0 (direction +1).
    pub fn stop(gap: f64, compliance: Compliance) -> Contact {
        Contact::on_dof(0, 1.0, gap, compliance)
    }
}

pub(crate) fn check_finite(name: &str, v: f64) -> Result<(), ExactError> {
    if v.is_finite() { Ok(()) } else { Err(ExactError::param(name, format!("is {v}, must be finite"))) }
}
