//! Why a corrector of the exact walk found no solution: a typed reason for its callers and stops.
use super::MAX_ITERATIONS;

/// Why a corrector ([`super::Family::correct`]) found no solution, at its `iteration` (from 1): each
/// calls for another cure (a shorter step, a merge, another signature), so the walk's stops name it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in super::super) enum Failure {
    /// The signature's orbit could not be built at the iterate's λ (a phase's flow or modes).
    Build { iteration: usize, lambda: f64 },
    /// The iterate's event times left their order within the period (an event passed its neighbour).
    Unordered { iteration: usize },
    /// The shooting residual at the iterate could not be had (a flow or a reset failed) or is not finite.
    Residual { iteration: usize },
    /// The Jacobian at the iterate could not be had (its variational flow or the orbits at λ ± h).
    Jacobian { iteration: usize },
    /// The bordered Jacobian is singular (no LU solve).
    Singular { iteration: usize },
    /// A correction above 1 of the scaled unknowns (or not finite): the predictor outside Newton's basin.
    Diverged { iteration: usize, correction: f64 },
    /// A search's trial whose fresh-Jacobian corrections stopped decreasing ([`super::STALL_FROM`]).
    Stalled { iteration: usize, correction: f64 },
    /// [`MAX_ITERATIONS`] spent, the last correction still above the convergence test.
    Exhausted { correction: f64 },
}

impl Failure {
    /// The iteration it failed at (from 1).
    pub fn iteration(&self) -> usize {
        match *self {
            Failure::Build { iteration, .. }
            | Failure::Unordered { iteration }
            | Failure::Residual { iteration }
            | Failure::Jacobian { iteration }
            | Failure::Singular { iteration }
            | Failure::Diverged { iteration, .. }
            | Failure::Stalled { iteration, .. } => iteration,
            Failure::Exhausted { .. } => MAX_ITERATIONS,
        }
    }
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let i = self.iteration();
        match self {
            Failure::Build { lambda, .. } => write!(f, "the orbit of the signature could not be built at λ = {lambda} (iteration {i})"),
            Failure::Unordered { .. } => write!(f, "the event times left their order within the period (iteration {i})"),
            Failure::Residual { .. } => write!(f, "the shooting residual could not be had or is not finite (iteration {i})"),
            Failure::Jacobian { .. } => write!(f, "the Jacobian could not be had (iteration {i})"),
            Failure::Singular { .. } => write!(f, "the bordered Jacobian is singular (iteration {i})"),
            Failure::Diverged { correction, .. } => {
                write!(f, "the correction {correction:.1e} of the scaled unknowns exceeds 1 (iteration {i}): the predictor is outside Newton's basin")
            }
            Failure::Stalled { correction, .. } => write!(f, "the corrections stopped decreasing at {correction:.1e} (iteration {i})"),
            Failure::Exhausted { correction } => write!(f, "{i} iterations spent, the last correction {correction:.1e}"),
        }
    }
}
