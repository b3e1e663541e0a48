//! The `[discretization]` and `[solver]` sections: the scene owns their conversion into the
//! engine's [`Discretization`] and [`SolverSettings`].
use super::{BuildError, DiscretizationSpec, SolverSpec, StepsSpec};
use crate::lcp::LcpMethod;
use crate::periodic::SolverSettings;
use crate::time::{Discretization, Pairing, Scheme};

/// `[discretization]`: the scheme, the steps per period and the optional pairing; `true` when
/// `steps = "auto"` (the steps returned are then a placeholder, chosen by
/// `PeriodicProblem::new_auto`).
pub fn discretization(spec: &DiscretizationSpec) -> Result<(Discretization, bool), BuildError> {
    let scheme = spec.scheme.parse::<Scheme>().map_err(|m| BuildError::field("discretization.scheme", m.to_string()))?;
    let pairing = match &spec.pairing {
        Some(p) => Some(p.parse::<Pairing>().map_err(|m| BuildError::field("discretization.pairing", m.to_string()))?),
        None => None,
    };
    let (steps, auto) = match &spec.steps {
        StepsSpec::Count(k) => (*k, false),
        StepsSpec::Named(a) if a == "auto" => (crate::periodic::MIN_STEPS, true),
        StepsSpec::Named(a) => {
            return Err(BuildError::field("discretization.steps", format!("is \"{a}\", must be a number of instants per period or \"auto\"")));
        }
        StepsSpec::Invalid(v) => return Err(BuildError::field("discretization.steps", format!("is {v}, must be a number of instants per period or \"auto\""))),
    };
    Ok((Discretization { scheme, steps, pairing }, auto))
}

/// `[solver]`: the defaults of [`SolverSettings`] with the given method, tolerance and
/// regularization, each checked.
pub fn solver_settings(spec: Option<&SolverSpec>) -> Result<SolverSettings, BuildError> {
    let mut s = SolverSettings::default();
    let Some(spec) = spec else { return Ok(s) };
    if let Some(m) = &spec.method {
        s.method = m.parse::<LcpMethod>().map_err(|e| BuildError::field("solver.method", e.to_string()))?;
    }
    // The negated comparisons below refuse NaN as well.
    if let Some(t) = spec.tolerance {
        if !(t.is_finite() && t > 0.0 && t < 1.0) {
            return Err(BuildError::field("solver.tolerance", format!("is {t}, must be in (0, 1)")));
        }
        s.tolerance = t;
    }
    if let Some(r) = spec.regularization {
        if !(r.is_finite() && r > 0.0 && r < 1.0) {
            return Err(BuildError::field("solver.regularization", format!("is {r}, must be in (0, 1) (relative to the largest entry of the LCP matrix)")));
        }
        s.regularization = Some(r);
    }
    Ok(s)
}
