//! Branches of friction orbits (src/formulation.md §9): the normal load's optimal curve and any
//! other parameter. No pseudo-arclength here (the friction step map has no tangent predictor):
//! each point is the friction LCP's certified solve (bds1; dense Lemke, or friction shooting
//! by size) at its parameter value. That suffices
//! because the orbit is unique at each value: with a constant normal load the LCP's matrix is
//! positive semi-definite and its slip velocity unique (§9), so the branch is a graph over the
//! parameter, without folds. Why no multipliers: they need the step map; the orbit of a passive
//! structure under a monotone friction law is incrementally stable (the energy of the difference
//! of two motions never grows: Brogliato, Nonsmooth Mechanics, 3rd ed. 2016, §3.4), so each point
//! is reported stable with an empty multiplier column.
use super::{Branch, BranchPoint, ContinuationSettings, Parameter, amplitudes};
use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver};

/// The golden section stops when its bracket is this narrow, relative to |to − from|.
const OPTIMUM_TOLERANCE: f64 = 1e-4;

/// Solves `problem` at evenly spaced values from `from` to `to` (1/`max_step` intervals, at most
/// `max_points` points), then refines the least amplitude of the first displacement output (the
/// optimal normal load for `normal_force`) by golden section when it lies inside the range.
pub(super) fn walk(
    problem: &PeriodicProblem,
    param: Parameter,
    from: f64,
    to: f64,
    settings: &ContinuationSettings,
    on_point: &dyn Fn(&BranchPoint),
) -> Result<Branch, Error> {
    let name = param.name();
    if problem.model().frictions.is_empty() {
        return Err(Error::input(format!(
            "--param {name}: the scene has no [[friction]] contact whose normal load could vary; add one or continue another parameter"
        )));
    }
    if !problem.model().contacts.is_empty() {
        return Err(Error::input(
            "continuation of a scene with both [[contact]] and [[friction]]: not yet supported (the orbit may not be unique, and friction rows have no step map to follow it); solve points with `solve`, or remove the contacts",
        ));
    }
    let mut solver = PeriodicSolver::new(problem.clone());
    let mut solve_at = |lambda: f64| -> Result<BranchPoint, Error> {
        let mut p = problem.clone();
        param.apply(&mut p, lambda)?;
        solver.update_problem(p);
        let r = solver.solve().map_err(|e| Error::from(e).context(format!("the friction orbit at {name} = {lambda}")))?;
        Ok(BranchPoint::discrete(lambda, amplitudes(solver.problem(), &r)))
    };
    let intervals = ((1.0 / settings.max_step).ceil() as usize).clamp(1, settings.max_points.max(2) - 1);
    let mut points = Vec::with_capacity(intervals + 1);
    for i in 0..=intervals {
        let lambda = if i == intervals { to } else { from + (to - from) * i as f64 / intervals as f64 };
        let p = solve_at(lambda)?;
        on_point(&p);
        points.push(p);
    }
    let mut stop = "reached".to_string();
    let least = |p: &BranchPoint| p.amplitude.first().copied().unwrap_or(0.0);
    let i = (0..points.len()).min_by(|&a, &b| least(&points[a]).total_cmp(&least(&points[b]))).unwrap_or(0);
    // Interior only: below both ends by more than round-off (a stuck plateau is flat to 1e-15).
    let ends = least(&points[0]).min(least(&points[points.len() - 1]));
    if i > 0 && i + 1 < points.len() && least(&points[i]) < ends * (1.0 - 1e-9) {
        // Golden section on [λ_{i−1}, λ_{i+1}] (the sampled minimum's neighbours).
        let (a, b) = (points[i - 1].parameter, points[i + 1].parameter);
        let f = |lambda: f64| solve_at(lambda).map(|p| (least(&p), p));
        let (_, _, mut best) = super::optimal_load::golden(f, a, b, OPTIMUM_TOLERANCE * (to - from).abs(), -1.0)?;
        let dof = problem.outputs().displacement.first().map_or(String::new(), |d| format!(" of DOF {d}"));
        best.detail = format!("least amplitude{dof} (golden section to {OPTIMUM_TOLERANCE:e} of the range)");
        stop = format!("reached; least amplitude{dof} {:.6e} at {name} = {:.6e}", least(&best), best.parameter);
        let dir = (to - from).signum();
        let at = points.partition_point(|p| (p.parameter - best.parameter) * dir < 0.0);
        points.insert(at, best);
    }
    Ok(Branch { parameter: param, points, stop, marches: 0, period_multiple: 1, label: "T".to_string() })
}
