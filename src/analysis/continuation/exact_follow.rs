//! The front ends' re-solve on the exact branch (issue 24 item 4): where the scene has an exact
//! orbit (compliant or rigid contacts, one forcing period, a polish that succeeds), a change of one knob is
//! a step of the exact walk ([`exact::step`], the walk `continue` uses) from the current exact
//! orbit. The branch reaches the new value: the grid LCP is solved on it (warm-started from the
//! current active set, then from the exact orbit's) and the exact orbit goes on. The branch folds
//! on the way (the fold located on the exact orbit): the response jumps to the orbit the grid LCP
//! finds without the old branch, polished. Elsewhere [`super::resolve`] falls back to the discrete
//! follow ([`super::follow`]).
use super::exact::{self, Stepped};
use super::follow::{Current, JUMP_MIN, Jump, Resolved, Stability, amplitude};
use super::{Parameter, floquet};
use crate::analysis::polish::{self, PolishedOrbit};
use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver, Tuning};
use crate::response::Response;
use crate::time::Discretization;

/// The largest model whose re-solves follow the exact branch where the orbit's Jacobian falls back
/// to finite differences (2n + events + 1 shooting runs each). Where the variational flow applies
/// (`PolishedOrbit::shooting_jacobian`: compliant switches, plastic impacts, releases, massless
/// closings) a Jacobian is one flow of the period and its variation, and no size limit applies.
const MAX_DOFS_DIFFERENCES: usize = 8;

/// A knob change below this (relative) keeps the current exact orbit.
const ROUND_OFF: f64 = 1e-12;

/// The one knob that changed from `a` to `b`, as the continued parameter: (parameter, its values
/// at `a` and `b`, the tuning whose problem the exact family varies: that knob at its neutral value,
/// as [`Parameter`] scales the scene's forces and offsets its gaps). `Err(why)` otherwise.
fn knob(a: &Tuning, b: &Tuning) -> Result<(Parameter, f64, f64, Tuning), &'static str> {
    let changed = [a.frequency != b.frequency, a.force_scale != b.force_scale, a.gap_offset != b.gap_offset, a.motion_scale != b.motion_scale];
    match changed {
        [true, false, false, false] => Ok((Parameter::Frequency, a.frequency, b.frequency, *a)),
        [false, true, false, false] => Ok((Parameter::ForceScale, a.force_scale, b.force_scale, Tuning { force_scale: 1.0, ..*a })),
        [false, false, true, false] => Ok((Parameter::GapOffset, a.gap_offset, b.gap_offset, Tuning { gap_offset: 0.0, ..*a })),
        [false, false, false, true] => Err("the obstacle-motion scale is not a parameter of the exact walk"),
        _ => Err("more than one knob changed at once (the exact walk continues in one)"),
    }
}

/// The stability of an exact orbit: the multipliers of its exact monodromy; none where its Schur
/// form did not converge (no NaN reported as a stability).
pub(super) fn exact_stability(orbit: &PolishedOrbit) -> Option<Stability> {
    let multipliers = floquet::multipliers(orbit.monodromy());
    let largest = floquet::largest(&multipliers);
    largest.is_finite().then_some(Stability { stable: largest <= 1.0, largest, multipliers })
}

/// The active set (the LCP's z indices, step-major) of the grid response `r`'s contact phases:
/// the instants whose paired clearance is negative (compliant), or whose impulse per step is
/// positive (rigid: its clearance is never negative).
fn active_set_of(r: &Response) -> Vec<usize> {
    let m = r.contacts.len();
    let k = r.contacts.first().map_or(0, |c| c.paired_gap.len());
    let active = move |i: usize, j: usize| {
        let c = &r.contacts[i];
        if c.stiffness.is_some() { c.paired_gap[j] < 0.0 } else { c.force[j] > 0.0 }
    };
    (0..k).flat_map(|j| (0..m).filter(move |&i| active(i, j)).map(move |i| j * m + i)).collect()
}

fn far(a: f64, b: f64) -> bool {
    (a - b).abs() > JUMP_MIN * a.abs().max(b.abs())
}

/// A re-solve on the exact branch, or why not.
pub(super) enum Outcome {
    Followed(Box<Resolved>),
    /// The exact walk does not apply here: the caller follows the discrete branch, saying why.
    Discrete(String),
}

/// The re-solve of `session` (already set to `tuning`) from `c` on the exact branch.
pub(super) fn resolve(session: &mut PeriodicSolver, base: &PeriodicProblem, disc: Discretization, tuning: Tuning, c: &Current<'_>) -> Result<Outcome, Error> {
    if let (true, Some(o)) = (c.tuning == tuning, c.orbit) {
        return Ok(Outcome::Followed(Box::new(on_branch(session, c, o.clone())?)));
    }
    let (param, from, to, neutral) = match knob(&c.tuning, &tuning) {
        Ok(k) => k,
        Err(why) => return Ok(Outcome::Discrete(why.into())),
    };
    let family = neutral.apply(base, disc)?;
    // The current exact orbit: the front end's, or the polish of the current grid orbit.
    let derived;
    let orbit = match c.orbit {
        Some(o) => o,
        None => {
            let here = c.tuning.apply(base, disc)?;
            session.update_problem(here.clone());
            session.set_warm_start(c.active_set);
            let r = session.solve()?;
            session.update_problem(tuning.apply(base, disc)?);
            match polish::polish(&here, &r) {
                Ok(o) => {
                    derived = o;
                    &derived
                }
                Err(e) => return Ok(Outcome::Discrete(format!("no exact orbit at the current values: {e}"))),
            }
        }
    };
    let n = base.model().n();
    if n > MAX_DOFS_DIFFERENCES && orbit.shooting_jacobian(orbit.initial_state(), orbit.times()).is_none() {
        return Ok(Outcome::Discrete(format!(
            "the model has {n} DOFs and its exact orbit has no variational Jacobian here; the finite-difference one costs 2n + events + 1 shooting runs a step, and the re-solves take it up to {MAX_DOFS_DIFFERENCES} DOFs"
        )));
    }
    // A change at the knob's round-off (an FMU host's interpolated input: 1.2625 then
    // 1.2625000000000002) is no step of the walk (it crawled 400 points): the exact orbit stands.
    if (to - from).abs() <= ROUND_OFF * from.abs().max(to.abs()) {
        return Ok(Outcome::Followed(Box::new(on_branch(session, c, orbit.clone())?)));
    }
    let stepped = match exact::step(&family, param, from, to, orbit) {
        Ok(s) => s,
        Err(e) => return Ok(Outcome::Discrete(e.message().to_string())),
    };
    match stepped {
        Stepped::Stopped(why) => Ok(Outcome::Discrete(format!("the exact walk stopped: {why}"))),
        Stepped::Reached(end) => Ok(Outcome::Followed(Box::new(on_branch(session, c, *end)?))),
        Stepped::Fold(at) => Ok(Outcome::Followed(Box::new(jump(session, c, param, at)?))),
    }
}

/// The branch reached the new values with the exact orbit `end`: the grid orbit on it.
fn on_branch(session: &mut PeriodicSolver, c: &Current<'_>, end: PolishedOrbit) -> Result<Resolved, Error> {
    session.set_warm_start(c.active_set);
    let r = session.solve()?;
    let mut exact = r.clone();
    end.write(session.problem(), &mut exact);
    let target = amplitude(&exact);
    let mut response = r;
    if far(amplitude(&response), target) {
        // The grid's orbit of this branch has another active set here: start from the exact one's.
        session.set_warm_start(&active_set_of(&exact));
        response = session.solve()?;
    }
    if far(amplitude(&response), target) {
        // No grid orbit on the branch here (the discrete branch folds before the exact one): the
        // answer is the exact orbit at the instants.
        exact.active_set = active_set_of(&exact);
        exact.warnings.push(format!(
            "the grid LCP has no orbit on the followed branch here (its discrete fold comes first; amplitude {:.6e} vs the exact orbit's {target:.6e}): the series are the exact orbit's at the instants",
            amplitude(&response)
        ));
        session.set_warm_start(&exact.active_set);
        response = exact;
    }
    let stability = exact_stability(&end);
    Ok(Resolved { response, jump: None, not_followed: None, orbit: Some(end), stability, exact: None })
}

/// The branch folded at parameter `at` on the way: the orbit the grid LCP finds without the old
/// branch (cold, then contact-free), polished for the next step.
fn jump(session: &mut PeriodicSolver, c: &Current<'_>, param: Parameter, at: f64) -> Result<Resolved, Error> {
    session.reset_warm_start();
    let mut response = session.solve()?;
    if !far(amplitude(&response), c.amplitude) {
        session.set_warm_start(&[]);
        let free = session.solve()?;
        if far(amplitude(&free), c.amplitude) {
            response = free;
        }
    }
    let mut orbit = polish::polish(session.problem(), &response).ok();
    if !far(amplitude(&response), c.amplitude)
        && let Some(o) = finer_orbit(session.problem(), c.amplitude)
    {
        // The grid's discrete branch outlives the exact one past its fold by O(h^p) (the bds1
        // impact oscillator: 1.1e-3 rad/s at k = 512): the orbit a finer grid finds, exact at the instants.
        let mut exact = response.clone();
        o.write(session.problem(), &mut exact);
        exact.active_set = active_set_of(&exact);
        exact.warnings.push(format!(
            "the grid LCP still has the old branch's orbit here (amplitude {:.6e}; its discrete fold comes later): the series are the exact orbit's at the instants, found on a finer grid",
            amplitude(&response)
        ));
        session.set_warm_start(&exact.active_set);
        (response, orbit) = (exact, Some(o));
    }
    let stability = orbit.as_ref().and_then(exact_stability);
    let mut fold = c.tuning;
    match param {
        Parameter::Frequency | Parameter::Speed { .. } => fold.frequency = at,
        Parameter::ForceScale => fold.force_scale = at,
        Parameter::GapOffset => fold.gap_offset = at,
        // Friction has no exact orbit, so its normal load is never followed here.
        Parameter::NormalForce => {}
    }
    let jump = Jump { fold, from_amplitude: c.amplitude, to_amplitude: amplitude(&response) };
    Ok(Resolved { response, jump: Some(jump), not_followed: None, orbit, stability, exact: None })
}

/// The exact orbit, away from the amplitude `old`, that the grid LCP of `problem` finds cold on 4
/// and 16 times finer grids, polished: the jump's target where the scene's grid still has the
/// orbit of the branch that ended at the exact fold. `None` when none is found.
fn finer_orbit(problem: &PeriodicProblem, old: f64) -> Option<PolishedOrbit> {
    let disc = problem.discretization();
    [4, 16].into_iter().find_map(|f| {
        let mut p = problem.clone();
        p.set_discretization(Discretization { steps: f * disc.steps, ..disc }).ok()?;
        let r = PeriodicSolver::new(p.clone()).solve().ok()?;
        let o = polish::polish(&p, &r).ok()?;
        let mut on_grid = r;
        o.write(&p, &mut on_grid);
        far(amplitude(&on_grid), old).then_some(o)
    })
}
