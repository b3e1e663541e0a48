//! Changes of the event signature at a grazing: a contact's clearance touching zero between its
//! events adds a pair of events there (contact on/off around the touch of an open contact,
//! off/on inside a closed one; release/impact inside a rigid contact's sticking arc whose force
//! touches zero); a phase shrinking to nothing between two events of one contact removes the pair.
//! Not a change: events of different contacts with identity state maps passing each other.
use super::family::{Family, Signature};
use crate::analysis::polish::{Event, EventKind, PolishedOrbit, Touch};
use crate::model::Model;

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

/// The signature of `orbit` without the event `phase` and its [`partner`] (one contact's),
/// whose phase between them shrinks to nothing; the new unknowns' guess at λ/ρ `wl`. `None`
/// without a partner.
pub(super) fn remove(fam: &Family, orbit: &PolishedOrbit, phase: usize, wl: f64) -> Option<(Signature, Vec<f64>)> {
    let t = orbit.period();
    let (a, b) = (phase, partner(fam.base(), orbit.events(), phase)?);
    let ea = orbit.events()[a];
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

/// Whether an event of contact `c` leaves the state as it is (identity saltation): a compliant
/// switch (the force is zero at clearance 0), or a rigid contact on a massless DOF closing or
/// releasing (no mass to stop, zero force at both; src/analysis/polish/continued.rs).
fn identity_map(model: &Model, c: usize) -> bool {
    let contact = &model.contacts[c];
    !contact.is_rigid() || model.contact_is_massless(contact)
}

/// The signature after events of different contacts, both with identity state maps, have passed
/// each other in the unknowns `w` (times out of order): the events re-sorted by their times,
/// event 0 kept first (its state is the unknown), and the new order (old index of each new
/// event). Two such events may cross without a change of topology: at the crossing both orders
/// give the same orbit and, the maps being the identity, the same flow derivative (the phase
/// between them has zero length). `None` when nothing passed, or when an event whose map is not
/// the identity (a plastic impact on a DOF with mass) or two events of one contact did: there a
/// crossing is a change of the orbit's topology.
pub(super) fn passed(fam: &Family, model: &Model, w: &[f64]) -> Option<(Signature, Vec<usize>)> {
    let ne = fam.ne();
    if ne < 3 {
        return None;
    }
    let theta = &w[w.len() - 1 - ne..w.len() - 1];
    let events = &fam.sig.events;
    let mut any = false;
    for a in 0..ne {
        for b in a + 1..ne {
            let d = theta[b] - theta[a];
            if d > 0.0 && d < 1.0 {
                continue;
            }
            if events[a].contact == events[b].contact || !identity_map(model, events[a].contact) || !identity_map(model, events[b].contact) {
                return None;
            }
            any = true;
        }
    }
    if !any {
        return None;
    }
    let mut order: Vec<usize> = (0..ne).collect();
    let psi = |e: usize| theta[0] + (theta[e] - theta[0]).rem_euclid(1.0);
    order[1..].sort_by(|&a, &b| psi(a).total_cmp(&psi(b)));
    let sig = Signature { events: order.iter().map(|&e| events[e]).collect(), always: fam.sig.always.clone() };
    Some((sig, order))
}

/// `v` (unknowns or a tangent: state, event times, λ) with its event components in the new
/// `order` of [`passed`]; with `wrap`, each time moved by whole periods into
/// [θ_0, θ_0 + 1) (unknowns; a tangent's components are rates and keep their values).
pub(super) fn reorder(v: &[f64], order: &[usize], wrap: bool) -> Vec<f64> {
    let ne = order.len();
    let n2 = v.len() - 1 - ne;
    let mut out = v.to_vec();
    for (x, &e) in order.iter().enumerate() {
        let t = v[n2 + e];
        out[n2 + x] = if wrap { v[n2] + (t - v[n2]).rem_euclid(1.0) } else { t };
    }
    out
}

/// The predictor `pred` from the unknowns `here` (both in the family's order) with the order of
/// each close pair of adjacent events that may pass each other toggled (their times exchanged):
/// a pair whose gap shrinks along the step and whose crossing lies within that change of the
/// predicted gap, so that the corrector may land on either side of it (with event 0, its state
/// unknown then starts from the other event's time). `None` when there is no such pair.
pub(super) fn toggled(fam: &Family, model: &Model, here: &[f64], pred: &[f64]) -> Option<Vec<f64>> {
    let ne = fam.ne();
    let n2 = pred.len() - 1 - ne;
    let events = &fam.sig.events;
    let mut out = pred.to_vec();
    let mut any = false;
    for e in 0..ne {
        let b = (e + 1) % ne;
        if events[e].contact == events[b].contact || !identity_map(model, events[e].contact) || !identity_map(model, events[b].contact) {
            continue;
        }
        // The pair (last, 0) across the period's end: event 0 a period later.
        let wrap = if b == 0 { 1.0 } else { 0.0 };
        let gap = here[n2 + b] + wrap - here[n2 + e];
        let predicted = pred[n2 + b] + wrap - pred[n2 + e];
        if predicted < gap && predicted.abs() < gap - predicted {
            out[n2 + e] = pred[n2 + b] + wrap;
            out[n2 + b] = pred[n2 + e] - wrap;
            any = true;
        }
    }
    any.then_some(out)
}

/// The event that ends contact `events[e].contact`'s phase begun by event `e`: the next event
/// when it is that contact's; for a rigid contact on a massless DOF, its next event whatever
/// lies between (other contacts' events inside its phase: the real blade at 2278.9746626 rad/s,
/// contact 13's held arc vanishing with contact 15's landing in it, which the adjacent test
/// missed and the corrector stalled on). `None` otherwise.
pub(super) fn partner(model: &Model, events: &[Event], e: usize) -> Option<usize> {
    let ne = events.len();
    let c = events.get(e)?.contact;
    let b = (e + 1) % ne;
    if ne < 2 || b == e {
        return None;
    }
    if events[b].contact == c {
        return Some(b);
    }
    let contact = &model.contacts[c];
    if !(contact.is_rigid() && model.contact_is_massless(contact)) {
        return None;
    }
    (1..ne).map(|k| (e + k) % ne).find(|&f| events[f].contact == c)
}

/// The phase begun by event `e` of the unknowns `w` when it lies between two events of one
/// contact (the pair a grazing adds or removes, [`partner`]): (its end's event, its length as a
/// fraction of the period), else `None`.
pub(super) fn pair_phase(fam: &Family, w: &[f64], e: usize) -> Option<(usize, f64)> {
    let ne = fam.ne();
    let n2 = w.len() - 1 - ne;
    let b = partner(fam.base(), &fam.sig.events, e)?;
    Some((b, w[n2 + b] - w[n2 + e] + if b <= e { 1.0 } else { 0.0 }))
}

/// Phases between two events of one contact that shrink along the tangent `along` at the
/// unknowns `w`: (phase, length, rate of shrinking per unit arclength).
pub(super) fn shrinking(fam: &Family, w: &[f64], along: &[f64]) -> Vec<(usize, f64, f64)> {
    let ne = fam.ne();
    let n2 = w.len() - 1 - ne;
    (0..ne)
        .filter_map(|e| {
            let (b, len) = pair_phase(fam, w, e)?;
            let rate = along[n2 + e] - along[n2 + b];
            (rate > 0.0).then_some((e, len, rate))
        })
        .collect()
}

/// Whether a phase between two events of one contact has a negative length in the unknowns
/// `w`: the corrector went past its vanishing onto the formal continuation of the signature
/// (a massless point's held arc is √ long in λ there, so that continuation turns back in λ:
/// the real blade's false fold at 2298.19 rad/s), which is no orbit.
pub(super) fn reversed(fam: &Family, w: &[f64]) -> bool {
    (0..fam.ne()).any(|e| pair_phase(fam, w, e).is_some_and(|(_, len)| len <= 0.0))
}

/// Whether a phase between two events of one contact collapsed in the corrector: below
/// [`super::VANISH`] at the corrected `w` and under a tenth of its length in the predictor `pred`.
/// Both events at one instant solve the equations wherever the orbit without them crosses the
/// clearance (a phase of zero length is no phase), a set that meets the branch at its grazing:
/// a long step's corrector landed there past the grazing (random family seeds 101, 108, 111,
/// 126: the closed phase 1e-2 → 1e-16 of the period in one step, the walk then stopped on the
/// penetrating orbit), where the steps that land on a vanishing phase by quarters reach it.
pub(super) fn collapsed(fam: &Family, pred: &[f64], w: &[f64]) -> bool {
    (0..fam.ne()).any(|e| pair_phase(fam, w, e).zip(pair_phase(fam, pred, e)).is_some_and(|((_, len), (_, was))| len < super::VANISH && len < 0.1 * was))
}

/// How many contacts have a different number of events in `a` and `b`.
pub(super) fn contacts_changed(a: &[Event], b: &[Event]) -> usize {
    let count = |events: &[Event], c: usize| events.iter().filter(|e| e.contact == c).count();
    let contacts = a.iter().chain(b).map(|e| e.contact + 1).max().unwrap_or(0);
    (0..contacts).filter(|&c| count(a, c) != count(b, c)).count()
}
