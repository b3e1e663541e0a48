//! The exact walk's start from a grid solve: at the range's start, and where the walk re-enters
//! the exact orbit from an orbit of the discrete walk after stopping short ([`super::super::reentry`]).
use super::family::Node;
use super::{Walk, Walked, begin, check};
use crate::analysis::continuation::{BranchPoint, ContinuationSettings, Parameter};
use crate::analysis::polish;
use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver};

/// An exact walk started: its first point pushed, not yet reported.
pub(in crate::analysis::continuation) struct Started<'a> {
    walk: Walk<'a>,
    here: Node,
}

impl Started<'_> {
    /// The start's point: the exact orbit at the start's λ.
    pub(in crate::analysis::continuation) fn point(&self) -> &BranchPoint {
        &self.walk.points[0]
    }

    /// The walk from the start (its point reported first) until λ passes `to` or `from`, or it stops short.
    pub(in crate::analysis::continuation) fn follow(mut self, from: f64, to: f64, settings: &ContinuationSettings, on_point: &dyn Fn(&BranchPoint)) -> Walked {
        self.walk.report(on_point);
        self.walk.follow(self.here, from, to, settings, on_point)
    }
}

/// The exact orbit at λ = `at` as the walk starts from it: the grid LCP (cold, or warm-started
/// from `active_set`, a discrete orbit's, to stay on its branch), the polish, the orbit closed as
/// a function of the parameter, its tangent towards `to`; λ scaled by `rho` in the unknowns.
pub(in crate::analysis::continuation) fn start<'a>(
    problem: &'a PeriodicProblem,
    param: Parameter,
    at: f64,
    to: f64,
    rho: f64,
    active_set: Option<&[usize]>,
) -> Result<Started<'a>, Error> {
    check(problem)?;
    let mut start = problem.clone();
    param.apply(&mut start, at)?;
    let mut solver = PeriodicSolver::new(start.clone());
    if let Some(set) = active_set {
        solver.set_warm_start(set);
    }
    let r = solver.solve().map_err(|e| Error::from(e).context(format!("the start of the continuation at {} = {at}", param.name())))?;
    let polished = polish::polish_noted(&start, &r).map_err(|e| Error::solve(format!("no exact orbit at {} = {at}: {e}", param.name())))?;
    let (mut walk, here) = begin(problem, param, at, to, rho, &polished.orbit)?;
    // Say how the start's event sequence was had where the grid's did not hold as read.
    walk.push(&here, None, polished.note);
    Ok(Started { walk, here })
}
