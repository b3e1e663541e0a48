//! The `[discretization]` and `[solver]` sections: the scene owns their conversion into the
//! engine's [`Discretization`] and [`SolverSettings`].
use super::{BuildError, DiscretizationSpec, SolverSpec, StepsSpec};
use crate::lcp::LcpMethod;
use crate::periodic::SolverSettings;
use crate::periodic::limits::{AccuracyTarget, AmplitudeMeasure};
use crate::time::{Discretization, Pairing, Scheme};

/// `[discretization]`: the scheme, the steps per period and the optional pairing; `true` when
/// `steps = "auto"` (the steps returned are then a placeholder, chosen by
/// `PeriodicProblem::new_auto`).
/// With `scheme = "auto"` the scheme returned is a placeholder (bds1, which has no stability
/// limit), replaced by `periodic::limits::auto_scheme` once the model is built.
pub fn discretization(spec: &DiscretizationSpec) -> Result<(Discretization, bool), BuildError> {
    let scheme = if spec.scheme == "auto" {
        Scheme::Bds1
    } else {
        spec.scheme.parse::<Scheme>().map_err(|m| BuildError::field("discretization.scheme", format!("{m}, or auto (chosen for discretization.tolerance)")))?
    };
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

/// `[discretization] scheme = "auto"` with its `tolerance`, `max_steps` and `time_budget`
/// (each checked); `None` for a named scheme, which must not carry them.
pub fn accuracy_target(spec: &DiscretizationSpec) -> Result<Option<AccuracyTarget>, BuildError> {
    if spec.scheme != "auto" {
        let given = [
            ("tolerance", spec.tolerance.is_some()),
            ("max_steps", spec.max_steps.is_some()),
            ("time_budget", spec.time_budget.is_some()),
            ("tolerance_of", spec.tolerance_of.is_some()),
        ];
        if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
            return Err(BuildError::field(
                format!("discretization.{key}"),
                format!("applies to scheme = \"auto\" only, but scheme = \"{}\"; remove the key or write scheme = \"auto\"", spec.scheme),
            ));
        }
        return Ok(None);
    }
    if spec.pairing.is_some() {
        return Err(BuildError::field(
            "discretization.pairing",
            "is given with scheme = \"auto\", which chooses the pairing with the scheme; remove the key or name a scheme".to_string(),
        ));
    }
    let mut t = AccuracyTarget::default();
    // The negated comparisons below refuse NaN as well.
    if let Some(tol) = spec.tolerance {
        if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
            return Err(BuildError::field(
                "discretization.tolerance",
                format!("is {tol}, must be in (0, 1): the wanted error relative to the peak-to-peak amplitude"),
            ));
        }
        t.tolerance = tol;
    }
    if let Some(k) = spec.max_steps {
        let lowest = 2 * crate::periodic::limits::AUTO_FIRST_STEPS as i64;
        if k < lowest || k > crate::periodic::MAX_STEPS as i64 {
            return Err(BuildError::field(
                "discretization.max_steps",
                format!("is {k}, must be between {lowest} and {} instants per period", crate::periodic::MAX_STEPS),
            ));
        }
        t.max_steps = k as usize;
    }
    if let Some(b) = spec.time_budget {
        if !(b.is_finite() && b > 0.0) {
            return Err(BuildError::field("discretization.time_budget", format!("is {b}, must be a positive number of seconds")));
        }
        t.time_budget = b;
    }
    if let Some(m) = &spec.tolerance_of {
        t.measure = AmplitudeMeasure::parse(m).ok_or_else(|| {
            BuildError::field(
                "discretization.tolerance_of",
                format!("is \"{m}\", must be \"largest\" (the largest output's peak-to-peak amplitude) or \"own\" (each output's own)"),
            )
        })?;
    }
    Ok(Some(t))
}

/// `scheme = "auto"`: moves `problem` (built with the placeholder) to the policy's scheme,
/// pairing and first k (`periodic::limits::auto_scheme`; a numeric `steps` raises the first k),
/// and returns the choice with its reasons.
pub fn choose_scheme(problem: &mut crate::periodic::PeriodicProblem, target: &AccuracyTarget, spec: &DiscretizationSpec) -> Result<String, BuildError> {
    let (mut disc, why) = crate::periodic::limits::auto_scheme(problem.model(), problem.omega_max(), target);
    if let StepsSpec::Count(k) = spec.steps {
        disc.steps = disc.steps.max(k);
    }
    problem.set_discretization(disc)?;
    if disc.pairing.is_none() {
        // Rigid on a massless DOF is a finite force: same pairing keeps it second order.
        let massless: Vec<usize> = (0..problem.model().contacts.len())
            .filter(|&i| {
                let c = &problem.model().contacts[i];
                c.compliance == crate::model::Compliance::Rigid && problem.model().contact_is_massless(c)
            })
            .collect();
        for i in massless {
            problem.set_contact_pairing(i, Some(Pairing::Same))?;
        }
    }
    let pairing = disc.pairing.map_or("per-contact".to_string(), |p| p.to_string());
    Ok(format!("scheme = \"auto\": {} with {pairing} pairing from k = {} for tolerance {:e}: {why}", disc.scheme, disc.steps, target.tolerance))
}
