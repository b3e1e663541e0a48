//! Changes of the event signature at a grazing: a contact's clearance touching zero between its
//! events adds a pair of events there (contact on/off around the touch of an open contact,
//! off/on inside a closed one; release/impact inside a rigid contact's sticking arc whose force
//! touches zero); a phase shrinking to nothing between two events of one contact removes the pair.
use super::family::{Family, Signature};
use crate::analysis::polish::{Event, EventKind, PolishedOrbit, Touch};

/// The signature of `orbit` with a pair of events (`first`, `second`) `delta` (fraction of the
/// period) apart around the touch: the new unknowns' guess (at λ/ρ `wl`) and the pair's indices
/// in the new time order.
pub(super) fn insert(
    fam: &Family,
    orbit: &PolishedOrbit,
    touch: &Touch,
    (first, second): (EventKind, EventKind),
    delta: f64,
    wl: f64,
) -> (Signature, Vec<f64>, (usize, usize)) {
    let t = orbit.period();
    let mut list: Vec<(f64, Event)> = orbit.events().iter().zip(orbit.times()).map(|(e, &s)| (s / t, *e)).collect();
    let base = list.first().map_or(touch.time / t - 0.5 * delta, |l| l.0);
    let wrap = |s: f64| base + (s - base).rem_euclid(1.0);
    let a = wrap(touch.time / t - 0.5 * delta);
    let b = wrap(touch.time / t + 0.5 * delta);
    list.push((a, Event { contact: touch.contact, kind: first, seed: 0.0 }));
    list.push((b, Event { contact: touch.contact, kind: second, seed: 0.0 }));
    list.sort_by(|x, y| x.0.total_cmp(&y.0));
    let ia = list.iter().position(|l| l.0 == a && l.1.kind == first && l.1.contact == touch.contact).expect("inserted");
    let ib = list.iter().position(|l| l.0 == b && l.1.kind == second && l.1.contact == touch.contact).expect("inserted");
    let always: Vec<usize> = orbit.always_closed().iter().copied().filter(|&c| c != touch.contact).collect();
    let sig = Signature { events: list.iter().map(|l| l.1).collect(), always };
    (sig, guess(fam, orbit, &list, wl), (ia, ib))
}

/// The signature of `orbit` without the events `phase` and `phase + 1` (cyclic) of one contact,
/// whose phase between them shrinks to nothing; the new unknowns' guess at λ/ρ `wl`. `None`
/// when the two events are not one contact's.
pub(super) fn remove(fam: &Family, orbit: &PolishedOrbit, phase: usize, wl: f64) -> Option<(Signature, Vec<f64>)> {
    let t = orbit.period();
    let ne = orbit.events().len();
    let (a, b) = (phase, (phase + 1) % ne);
    let (ea, eb) = (orbit.events()[a], orbit.events()[b]);
    if ea.contact != eb.contact || a == b {
        return None;
    }
    let list: Vec<(f64, Event)> =
        orbit.events().iter().zip(orbit.times()).enumerate().filter(|(i, _)| *i != a && *i != b).map(|(_, (e, &s))| (s / t, *e)).collect();
    let mut always = orbit.always_closed().to_vec();
    // The vanishing phase was open (off → on, release → impact): without events the contact is closed all along.
    if matches!(ea.kind, EventKind::Off | EventKind::Release) && !list.iter().any(|l| l.1.contact == ea.contact) {
        always.push(ea.contact);
        always.sort_unstable();
    }
    let sig = Signature { events: list.iter().map(|l| l.1).collect(), always };
    Some((sig, guess(fam, orbit, &list, wl)))
}

/// Unknowns for the time-ordered `list` (fractions of the period): the state at the first
/// event's time (at t = 0 without events; the state is continuous across compliant switches).
pub(super) fn guess(fam: &Family, orbit: &PolishedOrbit, list: &[(f64, Event)], wl: f64) -> Vec<f64> {
    let t = orbit.period();
    let t0 = list.first().map_or(0.0, |l| l.0 * t);
    let mut w = fam.scaled(orbit.state(t0).as_slice());
    w.extend(list.iter().map(|l| l.0));
    w.push(wl);
    w
}
