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

/// `[solver]`: the defaults of [`SolverSettings`] with the given method and tolerance, each
/// checked; the removed `regularization` is refused with its remedy.
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
    if spec.regularization.is_some() {
        return Err(BuildError::field("solver.regularization", REGULARIZATION_REMOVED.to_string()));
    }
    Ok(s)
}

/// Why `[solver] regularization` is refused, and what to write instead.
const REGULARIZATION_REMOVED: &str = "was removed: its retry solved A + ε·max|A|·I, which is exactly the LCP of every contact made compliant with stiffness 1/(ε·max|A|), a different physical problem presented as the rigid one; remedy: delete the key and, if a compliant contact is what you mean, declare it on the contact with stiffness = … (a scale: the structure's own stiffness at the contact DOF, the diagonal entry of K there; larger is closer to rigid); for rigid contact use cds or galerkin with pairing = \"forward\" or bds1 with pairing = \"same\" (src/formulation.md §3), or add damping";

/// `[discretization] error_estimate`: whether every result gets an error estimate (default
/// `"richardson"`, a second solve at k/2; `"none"` skips it).
pub fn error_estimate(spec: &DiscretizationSpec) -> Result<bool, BuildError> {
    match spec.error_estimate.as_deref() {
        None | Some("richardson") => Ok(true),
        Some("none") => Ok(false),
        Some(v) => Err(BuildError::field(
            "discretization.error_estimate",
            format!("is \"{v}\", expected \"richardson\" (a second solve at k/2, the default) or \"none\" (no estimate, faster)"),
        )),
    }
}

/// `[discretization] period_multiple`: p ≥ 1 forcing periods per orbit (default 1). Negative or
/// zero values are refused here, sizes by the problem (p·steps instants).
pub fn period_multiple(spec: &DiscretizationSpec) -> Result<usize, BuildError> {
    match spec.period_multiple {
        None => Ok(1),
        Some(p) if p >= 1 => usize::try_from(p).map_err(|_| BuildError::field("discretization.period_multiple", format!("is {p}, too large"))),
        Some(p) => Err(BuildError::field(
            "discretization.period_multiple",
            format!("is {p}, must be a whole number of forcing periods ≥ 1 (1: T-periodic orbits, the default; 2: period-doubled orbits, …)"),
        )),
    }
}
