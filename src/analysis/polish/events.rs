//! The event sequence of an orbit, read from the LCP's solution: a rigid contact's run of forced
//! instants is an impact followed by a sticking arc and a release (or a pure impact when the run
//! is short); a compliant contact's run of penetrating instants is contact on, then off.
use super::orbit::PolishedOrbit;
use crate::model::Model;
use crate::response::Response;
use nalgebra::DVector;

/// What happens at an event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    /// Plastic impact (e = 0); `stick`: the contact stays closed after it.
    Impact {
        stick: bool,
    },
    /// A stuck rigid contact leaves its obstacle (its force reaches 0).
    Release,
    /// A compliant contact closes / opens (its clearance crosses 0).
    On,
    Off,
}

impl EventKind {
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Impact { .. } => "impact",
            EventKind::Release => "release",
            EventKind::On => "contact_on",
            EventKind::Off => "contact_off",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    pub contact: usize,
    pub kind: EventKind,
    /// Seed time in [0, T).
    pub seed: f64,
}

/// Fewest forced instants in a row read as a sticking arc rather than a pure impact (a pure impact
/// loads one or two instants of a forward-paired scheme).
const STICK_RUN: usize = 4;

/// Cyclic runs [start, end] (inclusive) of `on` over k instants; `None` when every instant is on.
fn runs(on: &[bool]) -> Option<Vec<(usize, usize)>> {
    let k = on.len();
    if on.iter().all(|&b| b) {
        return None;
    }
    let first_off = on.iter().position(|&b| !b).expect("some off");
    let mut out = Vec::new();
    let mut j = 0;
    while j < k {
        let idx = (first_off + j) % k;
        if on[idx] {
            let start = idx;
            let mut len = 0;
            while on[(start + len) % k] {
                len += 1;
            }
            out.push((start, (start + len - 1) % k));
            j += len;
        } else {
            j += 1;
        }
    }
    Some(out)
}

/// The events of `r`, sorted by seed time, and the contacts closed all period long (stuck rigid
/// or closed compliant: they have no event).
pub fn from_response(model: &Model, r: &Response, offsets: &[usize]) -> (Vec<Event>, Vec<usize>) {
    let (k, period) = (r.steps, r.period);
    let h = period / k as f64;
    let mut events = Vec::new();
    let mut always = Vec::new();
    for (i, (c, rc)) in model.contacts.iter().zip(&r.contacts).enumerate() {
        let t = |j: f64| (j * h).rem_euclid(period);
        if c.is_rigid() {
            let big = rc.force.iter().fold(0.0f64, |m, &f| m.max(f));
            let on: Vec<bool> = rc.force.iter().map(|&f| f > 1e-12 * big.max(1e-300)).collect();
            let Some(runs) = runs(&on) else {
                always.push(i);
                continue;
            };
            let s = offsets[i] as f64;
            for (a, b) in runs {
                let len = (b + k - a) % k + 1;
                let stick = len >= STICK_RUN;
                if model.contact_is_massless(c) {
                    // A massless contact's force and clearance are continuous: the closing and the
                    // release are seeded between instants by linear extrapolation of the clearance
                    // before the run and of the force at its end (many contacts of one blade close
                    // and release within one step: equal seeds would leave their order to Newton).
                    let (g, f) = (&rc.gap, &rc.force);
                    let (a1, a2, b1) = ((a + k - 1) % k, (a + k - 2) % k, (b + k - 1) % k);
                    let close = if g[a2] > g[a1] && g[a1] > 0.0 { (g[a1] / (g[a2] - g[a1])).min(1.0) } else { 0.5 };
                    let open = if f[b1] > f[b] && len > 1 { (f[b] / (f[b1] - f[b])).min(1.0) } else { 0.5 };
                    events.push(Event { contact: i, kind: EventKind::Impact { stick: true }, seed: t(a1 as f64 + s + close) });
                    events.push(Event { contact: i, kind: EventKind::Release, seed: t(b as f64 + s + open) });
                    continue;
                }
                // The impulse of step a acts at about t_{a+s} (its paired instant), half a step earlier.
                events.push(Event { contact: i, kind: EventKind::Impact { stick }, seed: t(a as f64 + s - 0.5) });
                if stick {
                    events.push(Event { contact: i, kind: EventKind::Release, seed: t(b as f64 + s) });
                }
            }
        } else {
            let on: Vec<bool> = rc.gap.iter().map(|&g| g < 0.0).collect();
            let Some(runs) = runs(&on) else {
                always.push(i);
                continue;
            };
            // The clearance crosses 0 between the last open and the first closed instant.
            let cross = |j0: usize, j1: usize| {
                let (g0, g1) = (rc.gap[j0], rc.gap[j1]);
                j0 as f64 + (g0 / (g0 - g1)).clamp(0.0, 1.0)
            };
            for (a, b) in runs {
                events.push(Event { contact: i, kind: EventKind::On, seed: t(cross((a + k - 1) % k, a)) });
                events.push(Event { contact: i, kind: EventKind::Off, seed: t(cross(b, (b + 1) % k)) });
            }
        }
    }
    events.sort_by(|a, b| a.seed.total_cmp(&b.seed));
    (events, always)
}

/// `events` (sorted by seed in [0, T)) rotated so that event 0 is the one farthest from both
/// its neighbours, the events before it a period later: the polish lets events of different
/// contacts pass each other but keeps event 0 first (its state is the unknown), and on the real
/// blade the first seed is one of five tips closing within one step.
pub fn isolated_first(mut events: Vec<Event>, period: f64) -> Vec<Event> {
    let ne = events.len();
    if ne < 3 {
        return events;
    }
    let room = |e: usize| {
        let (prev, next) = (events[(e + ne - 1) % ne].seed, events[(e + 1) % ne].seed);
        let s = events[e].seed;
        (s - prev).rem_euclid(period).min((next - s).rem_euclid(period))
    };
    let best = (0..ne).fold(0, |b, e| if room(e) > room(b) { e } else { b });
    events.rotate_left(best);
    for e in events.iter_mut().skip(ne - best) {
        e.seed += period;
    }
    events
}

/// `events` without the contact runs shorter than `span` [s] whose switches have zero force (a
/// rigid contact on a massless DOF, a compliant one): a near-grazing that the LCP's orbit touches
/// for a step or two and the exact orbit may clear (the real blade's tip 14 at k = 2048 only,
/// clearance 1e-9 m beside it). The polish's admissibility check says whether it does.
pub fn without_short_runs(model: &Model, events: &[Event], span: f64, period: f64) -> Vec<Event> {
    let ne = events.len();
    let mut drop = vec![false; ne];
    for (a, e) in events.iter().enumerate() {
        let c = &model.contacts[e.contact];
        let opens = matches!(e.kind, EventKind::On) || (matches!(e.kind, EventKind::Impact { stick: true }) && model.contact_is_massless(c));
        let Some(b) = (1..ne).map(|s| (a + s) % ne).find(|&b| events[b].contact == e.contact) else { continue };
        if opens && matches!(events[b].kind, EventKind::Off | EventKind::Release) && (events[b].seed - e.seed).rem_euclid(period) < span {
            drop[a] = true;
            drop[b] = true;
        }
    }
    events.iter().zip(&drop).filter(|(_, d)| !**d).map(|(e, _)| *e).collect()
}

/// `events` in [0, T), sorted, event 0 the most isolated ([`isolated_first`]).
pub fn normalised(mut events: Vec<Event>, period: f64) -> Vec<Event> {
    events.iter_mut().for_each(|e| e.seed = e.seed.rem_euclid(period));
    events.sort_by(|a, b| a.seed.total_cmp(&b.seed));
    isolated_first(events, period)
}

/// The signatures of `events` (with `always`) in which one contact's shortest runs vanish: for
/// each of the `count` shortest spans between two consecutive events of the same contact (an arc
/// or a gap that shrank toward nothing as the parameter moved), the events without those two;
/// a contact whose only gap vanishes is then closed all period.
pub fn without_shortest(events: &[Event], always: &[usize], period: f64, count: usize) -> Vec<(Vec<Event>, Vec<usize>)> {
    let ne = events.len();
    let mut spans: Vec<(f64, usize, usize)> = Vec::new();
    for (a, e) in events.iter().enumerate() {
        if let Some(b) = (1..ne).map(|s| (a + s) % ne).find(|&b| events[b].contact == e.contact) {
            spans.push(((events[b].seed - e.seed).rem_euclid(period), a, b));
        }
    }
    spans.sort_by(|x, y| x.0.total_cmp(&y.0));
    spans
        .into_iter()
        .take(count)
        .map(|(_, a, b)| {
            let kept: Vec<Event> = events.iter().enumerate().filter(|(k, _)| *k != a && *k != b).map(|(_, e)| *e).collect();
            let mut always = always.to_vec();
            if !kept.iter().any(|e| e.contact == events[a].contact) && !after(events[a].kind) {
                always.push(events[a].contact);
                always.sort_unstable();
            }
            (kept, always)
        })
        .collect()
}

/// `events` with contact `i` switched twice around `t`, at t ∓ `half`: closed (a rigid contact
/// stuck, a compliant one on) where it was free, free where it was closed (`closed`) — a grazing
/// that the orbit now crosses. `always` loses `i` when it held it.
pub fn with_run(model: &Model, events: &[Event], always: &[usize], (i, t, closed): (usize, f64, bool), half: f64) -> (Vec<Event>, Vec<usize>) {
    let rigid = model.contacts[i].is_rigid();
    let (first, second) = match (rigid, closed) {
        (true, false) => (EventKind::Impact { stick: true }, EventKind::Release),
        (true, true) => (EventKind::Release, EventKind::Impact { stick: true }),
        (false, false) => (EventKind::On, EventKind::Off),
        (false, true) => (EventKind::Off, EventKind::On),
    };
    let mut out = events.to_vec();
    out.push(Event { contact: i, kind: first, seed: t - half });
    out.push(Event { contact: i, kind: second, seed: t + half });
    (out, always.iter().copied().filter(|&k| k != i).collect())
}

/// The contacts closed (stuck rigid, closed compliant) in the phase after each event: each
/// contact is closed after its own last event of the sequence before wrapping around.
pub fn phase_sets(model: &Model, events: &[Event], always: &[usize]) -> Vec<Vec<usize>> {
    let m = model.contacts.len();
    let mut closed = vec![false; m];
    for &i in always {
        closed[i] = true;
    }
    // The state before event 0 is the state after each contact's last event.
    for e in events {
        closed[e.contact] = after(e.kind);
    }
    let mut out = Vec::with_capacity(events.len());
    for e in events {
        closed[e.contact] = after(e.kind);
        out.push((0..m).filter(|&i| closed[i]).collect());
    }
    out
}

fn after(kind: EventKind) -> bool {
    match kind {
        EventKind::Impact { stick } => stick,
        EventKind::Release | EventKind::Off => false,
        EventKind::On => true,
    }
}

/// Events of different contacts passing each other in the polish's Newton (orbit.rs).
impl PolishedOrbit {
    /// Whether events `a` and `b` may pass each other in Newton: two contacts whose switches
    /// have identity saltation (the contact force is zero there: compliant contacts and rigid
    /// ones on massless DOFs), so that the orbit is continuous in their times through the swap.
    /// The real blade's 17 tips close and release within one step of each other, in an order the
    /// LCP's grid cannot tell.
    pub(super) fn may_pass(&self, a: &Event, b: &Event) -> bool {
        let smooth = |e: &Event| {
            let c = &self.model.contacts[e.contact];
            !c.is_rigid() || self.model.contact_is_massless(c)
        };
        a.contact != b.contact && smooth(a) && smooth(b)
    }

    /// The orbit with the events of the unknowns `u` sorted by their times, and `u` in that
    /// order, when only events that [`Self::may_pass`] have passed each other and event 0 stays
    /// first within one period; the phases of unchanged contact sets are reused.
    pub(super) fn reordered(&self, u: &DVector<f64>) -> Option<(Self, DVector<f64>)> {
        let n2 = 2 * self.model.n();
        let ne = self.events.len();
        let tau: Vec<f64> = u.iter().skip(n2).copied().collect();
        if ne < 3 || tau[1..].iter().any(|&t| t <= tau[0] || t >= tau[0] + self.period) {
            return None;
        }
        let mut order: Vec<usize> = (0..ne).collect();
        order[1..].sort_by(|&a, &b| tau[a].total_cmp(&tau[b]));
        for (x, &a) in order.iter().enumerate() {
            if order[x + 1..].iter().any(|&b| b < a && !self.may_pass(&self.events[a], &self.events[b])) {
                return None;
            }
        }
        let events: Vec<Event> = order.iter().map(|&e| Event { seed: tau[e], ..self.events[e] }).collect();
        let orbit = Self::reusing(&self.model, events, &self.always, &self.phases).ok()?;
        let mut v = u.clone();
        for (x, &e) in order.iter().enumerate() {
            v[n2 + x] = tau[e];
        }
        Some((orbit, v))
    }
}
