//! The event-fitted polish: the LCP's orbit refined to round-off.
//!
//! Between events the dynamics is linear with harmonic forcing and has an exact flow
//! ([`phase`]). The event sequence (impacts, sticking arcs and releases, compliant contact on and
//! off) is read from the LCP's solution ([`events`]); the unknowns are the state just after the
//! first event and the event times; the equations are periodicity and one condition per event
//! (clearance 0 at an impact or a compliant switch, force 0 at a release). Impacts are plastic
//! (e = 0), as in the LCP. Newton (finite-difference Jacobian) is seeded by the LCP's event
//! times, the state by the periodic fixed point of the affine map those times give. The result
//! is verified (clearance ≥ 0 of free rigid contacts and force ≥ 0 of stuck ones between the
//! events, checked densely and at every local minimum; impulses ≥ 0; a pure impact may not call
//! for sticking). Where the grid's sequence is not the orbit's, the phases it missed are put back
//! where the orbit dips, else a finer grid's sequence is taken ([`repair`]); failing that, the
//! LCP's orbit is kept, with a warning that says why.
mod continued;
mod detect;
mod eigen_flow;
pub mod events;
mod forces;
pub mod friction;
mod massive;
mod orbit;
mod phase;
mod repair;
mod rigid;
mod signals;
mod verify;

pub use continued::{KeptVariation, Touch};
pub use detect::{PhaseBank, follow_detected, follow_detected_with};
pub use events::{Event, EventKind};
pub use orbit::{OrbitParts, PolishedOrbit, user_value};
pub use repair::Polished;
pub use rigid::{CLEARANCE, HOLD, MarginPart, RigidMargin, RigidMargins, STUCK};

use crate::model::Model;
use crate::periodic::PeriodicProblem;
use crate::response::{EventRecord, PolishSummary, Response};
use std::time::Instant;

/// Why the polish could not give an orbit; the LCP's orbit is kept.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct PolishFailure(pub String);

/// Polishes the orbit of `r` (solved from `problem`).
pub fn polish(problem: &PeriodicProblem, r: &Response) -> Result<PolishedOrbit, PolishFailure> {
    polish_noted(problem, r).map(|p| p.orbit)
}

/// [`polish`], and how the event sequence was had when the grid's did not hold as read
/// (phases put back, a finer grid's: [`repair`]).
pub fn polish_noted(problem: &PeriodicProblem, r: &Response) -> Result<Polished, PolishFailure> {
    let model = problem.model();
    let damped: Vec<usize> =
        model.massless_dofs().into_iter().filter(|&d| (0..model.n()).any(|j| model.structure.damping.as_ref().is_some_and(|c| c.get(d, j) != 0.0))).collect();
    if !damped.is_empty() {
        return Err(PolishFailure(format!(
            "DOFs {damped:?} are massless but damped: the polish condenses massless DOFs statically (src/formulation.md §4.1 gives them no damping); the LCP's orbit is kept"
        )));
    }
    if problem.period_multiple() != 1 {
        return Err(PolishFailure(format!(
            "the orbit spans period_multiple = {} forcing periods; the polish fits events over one period T only",
            problem.period_multiple()
        )));
    }
    if !model.frictions.is_empty() {
        return Err(PolishFailure("friction contacts are fitted by the stick–slip polish (`polish::apply`), not as contact events: continuation on the exact orbit does not take friction".into()));
    }
    if !model.rubbing.is_empty() {
        return Err(PolishFailure("the polish does not fit rubbing contacts yet (their force leaves the normal): the LCP's orbit is kept".into()));
    }
    if r.contacts.len() != model.contacts.len() {
        return Err(PolishFailure("the result has no contact outputs ([output] contacts = false): the event sequence cannot be read".into()));
    }
    repair::polish_grid(problem, r)
}

/// Prints a stage's wall time, and the thread's CPU time so far (Linux: /proc/thread-self/schedstat,
/// the figure to read on a loaded machine), under `PERIODIC_CONTACT_PROFILE` (as the LCP's shooting does).
pub fn profile(stage: &str, since: Instant) {
    if std::env::var_os("PERIODIC_CONTACT_PROFILE").is_some() {
        eprintln!("polish profile: {stage} {:.3} s wall (thread CPU so far {:.3} s)", since.elapsed().as_secs_f64(), thread_cpu().unwrap_or(f64::NAN));
    }
}

/// The calling thread's CPU time [s] (Linux), for the profile.
pub(super) fn thread_cpu() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}

/// The exact orbit of `model` (the model of `prev` at another frequency) on `prev`'s event
/// signature: Newton from `prev`'s event times scaled to the new period (the state from the
/// affine one-period map's fixed point there), verified as [`polish`]'s orbit is. The phases'
/// eigendecompositions are `prev`'s ([`PolishedOrbit`]'s phases depend on ω only through the
/// forcing). For a sweep's next point (`sweep --exact`).
pub fn follow(model: &Model, prev: &PolishedOrbit) -> Result<PolishedOrbit, PolishFailure> {
    let parts = prev.parts();
    let scale = model.period() / prev.period();
    let events = parts.events.into_iter().map(|e| Event { seed: e.seed * scale, ..e }).collect();
    settle(model, prev, events, &parts.always).map_err(|(e, _)| e)
}

/// Newton on the signature `events` (seeded) from `prev`'s decompositions, then the check; on a
/// failed check also the unverified orbit and where it dips through a contact.
fn settle(model: &Model, prev: &PolishedOrbit, events: Vec<Event>, always: &[usize]) -> Result<PolishedOrbit, (PolishFailure, Option<verify::Dip>)> {
    let mut orbit = PolishedOrbit::new(model, events, always).map_err(|e| (e, None))?;
    orbit.share_modes(prev);
    orbit.newton().map_err(|e| (e, None))?;
    verify::check_dip(&orbit)?;
    Ok(orbit)
}

/// Shortest spans of one contact tried removed when [`follow_across`] looks for the next signature.
const VANISHING: usize = 2;

/// [`follow`], and where `prev`'s signature no longer holds, the neighbouring signatures it
/// predicts (`sweep --exact` across signature changes; the real blade's changes every ~0.75 rad/s):
/// where Newton converges but the orbit dips through a contact, that contact switched twice around
/// the dip (a grazing crossed: a new arc or gap); where Newton fails, one of the [`VANISHING`]
/// shortest arcs or gaps of one contact removed (it shrank to nothing, or two arcs merged), then
/// once more switched around a dip. The first admissible orbit is taken; else `follow`'s failure.
pub fn follow_across(model: &Model, prev: &PolishedOrbit) -> Result<PolishedOrbit, PolishFailure> {
    let parts = prev.parts();
    let period = model.period();
    let events: Vec<Event> = parts.events.iter().map(|e| Event { seed: e.seed * period / prev.period(), ..*e }).collect();
    let first = match settle(model, prev, events.clone(), &parts.always) {
        Ok(orbit) => return Ok(orbit),
        Err(e) => e,
    };
    let around = |(evs, always): (Vec<Event>, Vec<usize>), dip: &verify::Dip| {
        let (evs, always) = events::with_run(model, &evs, &always, (dip.contact, dip.time, dip.closed), dip.half_width(period, &evs));
        (events::normalised(evs, period), always)
    };
    let mut tries: Vec<(Vec<Event>, Vec<usize>)> = Vec::new();
    if let Some(dip) = &first.1 {
        tries.push(around((events.clone(), parts.always.clone()), dip));
    }
    tries.extend(
        events::without_shortest(&events::normalised(events, period), &parts.always, period, VANISHING)
            .into_iter()
            .map(|(e, a)| (events::normalised(e, period), a)),
    );
    for (evs, always) in tries {
        match settle(model, prev, evs.clone(), &always) {
            Ok(orbit) => return Ok(orbit),
            Err((_, Some(dip))) => {
                let (evs, always) = around((evs, always), &dip);
                if let Ok(orbit) = settle(model, prev, evs, &always) {
                    return Ok(orbit);
                }
            }
            Err(_) => {}
        }
    }
    Err(first.0)
}

/// The contact-free periodic orbit of `model` (every contact open all period, not checked
/// against the obstacles): `sweep --exact`'s linear curve, `prev`'s decomposition reused.
pub fn linear(model: &Model, prev: Option<&PolishedOrbit>) -> Result<PolishedOrbit, PolishFailure> {
    let mut orbit = PolishedOrbit::new(model, vec![], &[])?;
    if let Some(p) = prev {
        orbit.share_modes(p);
    }
    orbit.newton()?;
    Ok(orbit)
}

/// Polishes `r` in place: on success its series are the polished orbit's at the same instants,
/// `polish` lists the events and `accuracy` says the orbit is exact to the Newton residual, and
/// the orbit is returned (its interpolant for the front ends); on failure the LCP's orbit stays,
/// with a warning and `polish.status = "fallback"`.
pub fn apply(problem: &PeriodicProblem, r: &mut Response) -> Option<PolishedOrbit> {
    let t0 = Instant::now();
    // Several friction contacts, or friction with compliant stops: one mode per contact and stop.
    let model = problem.model();
    if model.frictions.len() > 1 || (!model.frictions.is_empty() && !model.contacts.is_empty()) {
        match friction::multi::polish(problem, r) {
            Ok(orbit) => {
                friction::multi::write(&orbit, problem, r);
                let how = "stick–slip orbit of friction contacts and compliant stops (exact flows between their merged events)";
                record(r, how, orbit.event_records(), (orbit.iterations, orbit.residual, orbit.correction), t0);
            }
            Err(e) => fall_back(r, e, t0),
        }
        return None;
    }
    if !problem.model().frictions.is_empty() {
        // The stick–slip orbit writes the samples; the front ends interpolate those.
        match friction::polish(problem, r) {
            Ok(orbit) => {
                friction::write(&orbit, problem, r);
                let how = "stick–slip orbit (exact flows between stick, slip and reversal events)";
                record(r, how, orbit.event_records(), (orbit.iterations, orbit.residual, orbit.correction), t0);
            }
            Err(e) => fall_back(r, e, t0),
        }
        return None;
    }
    match polish_noted(problem, r) {
        Ok(Polished { orbit, note }) => {
            if !note.is_empty() {
                r.warnings.push(format!("polish: {note}"));
            }
            let clock = Instant::now();
            orbit.write(problem, r);
            profile("writing the series", clock);
            record(r, "event-fitted exact orbit", orbit.event_records(), (orbit.iterations(), orbit.residual(), orbit.correction()), t0);
            Some(orbit)
        }
        Err(e) => {
            fall_back(r, e, t0);
            None
        }
    }
}

/// The polished orbit's summary and its accuracy: the last Newton correction (round-off level).
fn record(r: &mut Response, how: &str, events: Vec<EventRecord>, (iterations, residual, correction): (usize, f64, f64), t0: Instant) {
    let scale = r.displacement.values().map(|x| Response::peak_to_peak(x)).fold(0.0, f64::max);
    let e = correction.max(f64::EPSILON * scale);
    r.accuracy.estimate = Some(e);
    r.accuracy.relative = (scale > 0.0).then(|| e / scale);
    r.accuracy.method = format!(
        "polish: {how} ({} events), Newton converged in {iterations} iterations; the estimate is the last Newton correction (round-off level)",
        events.len()
    );
    r.polish = Some(PolishSummary { status: "polished".into(), reason: String::new(), events, iterations, residual, time_s: t0.elapsed().as_secs_f64() });
}

fn fall_back(r: &mut Response, e: PolishFailure, t0: Instant) {
    r.warnings.push(format!("polish: fell back to the LCP's orbit: {e}"));
    r.polish = Some(PolishSummary {
        status: "fallback".into(),
        reason: e.0,
        events: Vec::<EventRecord>::new(),
        iterations: 0,
        residual: 0.0,
        time_s: t0.elapsed().as_secs_f64(),
    });
}
