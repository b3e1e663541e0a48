//! The continued parameter and how it sets a problem.
use crate::error::Error;
use crate::periodic::PeriodicProblem;

/// The continued parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameter {
    /// The excitation frequency ω [rad/s] (the period T = 2π/ω; k steps per period).
    Frequency,
    /// A factor on every force amplitude of the scene (1: the scene's forces).
    ForceScale,
    /// A length added to every contact's static clearance (0: the scene's gaps; negative closes
    /// them, a preload).
    GapOffset,
    /// The casing's rotation speed Ω [rad/s]: the excitation frequency is ω = lobes·Ω (engine
    /// order; the front end reads `lobes` from the scene's casing).
    Speed { lobes: u32 },
    /// The normal load N of every friction contact (force unit; 0: free, large: stuck): the
    /// optimal-normal-load curve.
    NormalForce,
}

impl Parameter {
    /// From its CLI name.
    pub fn parse(name: &str) -> Result<Parameter, Error> {
        match name {
            "frequency" => Ok(Parameter::Frequency),
            "force_scale" => Ok(Parameter::ForceScale),
            "gap_offset" => Ok(Parameter::GapOffset),
            "normal_force" => Ok(Parameter::NormalForce),
            "speed" => Err(Error::input("--param speed: the casing's lobes are needed (ω = lobes·Ω): the scene's [casing] gives them")),
            other => Err(Error::input(format!("--param: is \"{other}\"; continuation takes frequency, speed, force_scale, gap_offset or normal_force"))),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Parameter::Frequency => "frequency",
            Parameter::ForceScale => "force_scale",
            Parameter::GapOffset => "gap_offset",
            Parameter::Speed { .. } => "speed",
            Parameter::NormalForce => "normal_force",
        }
    }
    /// What the parameter is, for an axis or a column, with its quantity.
    pub fn describe(self) -> (&'static str, crate::model::Quantity) {
        use crate::model::Quantity;
        match self {
            Parameter::Frequency => ("excitation frequency ω", Quantity::Frequency),
            Parameter::ForceScale => ("force scale (× the scene's forces)", Quantity::Ratio),
            Parameter::GapOffset => ("gap offset (added to every clearance)", Quantity::Length),
            Parameter::Speed { .. } => ("casing speed Ω (ω = lobes·Ω)", Quantity::Frequency),
            Parameter::NormalForce => ("normal load N of every friction contact", Quantity::Force),
        }
    }
    /// Sets the parameter of `problem` (the scene's, unchanged until now) to `value`, checked.
    pub(super) fn apply(self, problem: &mut PeriodicProblem, value: f64) -> Result<(), Error> {
        match self {
            Parameter::Frequency => problem.set_frequency(value).map_err(Error::from),
            Parameter::Speed { lobes } => problem.set_frequency(f64::from(lobes) * value).map_err(Error::from),
            Parameter::ForceScale | Parameter::GapOffset => {
                if !value.is_finite() {
                    return Err(Error::input(format!("{}: is {value}, must be finite", self.name())));
                }
                let mut model = problem.model().clone();
                if self == Parameter::ForceScale {
                    model.forces.iter_mut().for_each(|f| f.term.amplitude *= value);
                } else {
                    model.contacts.iter_mut().for_each(|c| c.gap += value);
                }
                *problem = problem.with_model(model, problem.discretization())?;
                Ok(())
            }
            Parameter::NormalForce => {
                let mut model = problem.model().clone();
                if model.frictions.is_empty() {
                    return Err(Error::input(
                        "--param normal_force: the scene has no [[friction]] contact whose normal load could vary; add one or continue another parameter",
                    ));
                }
                // Checked by the model (finite, ≥ 0) with the field named.
                model.frictions.iter_mut().for_each(|f| f.normal_force = value);
                *problem = problem.with_model(model, problem.discretization())?;
                Ok(())
            }
        }
    }
}
