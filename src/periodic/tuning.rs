//! The knobs a front end turns on a built problem (FMU parameters and inputs, C API setters).
use super::{PeriodicProblem, SolveError};
use crate::time::Discretization;

/// The tunable knobs applied to a scene's problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tuning {
    /// ω [rad/s].
    pub frequency: f64,
    /// Multiplies every force amplitude.
    pub force_scale: f64,
    /// Added to every static clearance.
    pub gap_offset: f64,
    /// Multiplies every obstacle-motion amplitude.
    pub motion_scale: f64,
    /// Multiplies every friction contact's normal load N (so its slip force μN).
    pub normal_force_scale: f64,
}

impl Tuning {
    /// The scene's own values (scales 1, offset 0).
    pub fn of(p: &PeriodicProblem) -> Self {
        Tuning { frequency: p.model().frequency, force_scale: 1.0, gap_offset: 0.0, motion_scale: 1.0, normal_force_scale: 1.0 }
    }
    /// The point at fraction `lambda` of the straight way from these values to `to` (0: these).
    pub fn towards(&self, to: &Tuning, lambda: f64) -> Tuning {
        let at = |x: f64, y: f64| x + lambda * (y - x);
        Tuning {
            frequency: at(self.frequency, to.frequency),
            force_scale: at(self.force_scale, to.force_scale),
            gap_offset: at(self.gap_offset, to.gap_offset),
            motion_scale: at(self.motion_scale, to.motion_scale),
            normal_force_scale: at(self.normal_force_scale, to.normal_force_scale),
        }
    }
    /// `base` with these values and discretisation `disc`, validated again.
    pub fn apply(&self, base: &PeriodicProblem, disc: Discretization) -> Result<PeriodicProblem, SolveError> {
        let mut model = base.model().clone();
        model.frequency = self.frequency;
        model.forces.iter_mut().for_each(|f| f.term.amplitude *= self.force_scale);
        for c in &mut model.contacts {
            c.gap += self.gap_offset;
            c.motion.iter_mut().for_each(|h| h.amplitude *= self.motion_scale);
        }
        model.frictions.iter_mut().for_each(|f| f.normal_force *= self.normal_force_scale);
        // The output map stays: a reduced or clamped scene reports in the user's numbering.
        base.with_model(model, disc)
    }
}
