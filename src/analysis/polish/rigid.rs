//! How far an exact orbit with rigid contacts is from leaving its event signature: the signed
//! margin the continuation bisects on (src/analysis/continuation/exact). The quantities are the
//! admissibility checks of [`super::verify`], each over its scale, signed so that a negative
//! margin means the signature no longer holds: a free rigid contact's clearance (a new impact,
//! a grazing), a stuck contact's force (a release inside the sticking arc), an impact's impulse
//! (an impact fading to a touch) and the force that would hold a pure impact's contact (the
//! impact starts to stick).
use super::events::EventKind;
use super::orbit::PolishedOrbit;
use super::phase::Phase;
use super::verify::minimum;

/// A margin of a rigid-contact orbit: its value (over the clearance or force scale), the contact
/// and what is measured, for the branch point's detail.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidMargin {
    pub value: f64,
    pub contact: usize,
    pub what: &'static str,
    /// Where: the time of the smallest value between events, or the event's index.
    pub time: f64,
    pub event: Option<usize>,
}

/// [`RigidMargin::what`] of a free contact's clearance (a new impact where it touches zero).
pub const CLEARANCE: &str = "clearance of the free contact";
/// [`RigidMargin::what`] of a stuck contact's force (a release inside the arc where it touches zero).
pub const STUCK: &str = "force of the stuck contact";
/// [`RigidMargin::what`] of the force that would hold a pure impact's contact (it starts to stick
/// where that force reaches zero).
pub const HOLD: &str = "force that would hold the contact after its impact";

impl PolishedOrbit {
    /// The smallest rigid margin of the orbit ([`RigidMargin`]); `None` without rigid contacts.
    pub fn rigid_margin(&self) -> Option<RigidMargin> {
        let model = &self.model;
        if !model.contacts.iter().any(|c| c.is_rigid()) {
            return None;
        }
        // The scales of verify.rs: the largest normal displacement and the largest force met.
        let xs = self.after.iter().flat_map(|y| model.contacts.iter().map(move |c| c.along(|d| y[d]).abs())).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let loads: f64 = model.forces.iter().map(|f| f.term.amplitude.abs()).sum();
        let fs = self.impulses.iter().fold(loads, |m, p| m.max(p.abs() * model.frequency)).max(f64::MIN_POSITIVE);
        let mut best = RigidMargin { value: f64::INFINITY, contact: 0, what: "", time: 0.0, event: None };
        let mut keep = |value: f64, contact: usize, what: &'static str, time: f64, event: Option<usize>| {
            if value < best.value {
                best = RigidMargin { value, contact, what, time, event };
            }
        };
        for (e, (&p, ev)) in self.impulses.iter().zip(&self.events).enumerate() {
            // A massless contact closes without impulse: its margins are its clearance and force.
            if let EventKind::Impact { stick } = ev.kind
                && !model.contact_is_massless(&model.contacts[ev.contact])
            {
                keep(p * model.frequency / fs, ev.contact, "impulse of the impact", self.times[e], Some(e));
                if !stick {
                    // The force that would hold the contact just after a pure impact (≤ 0 for a pure impact).
                    let mut stuck: Vec<usize> = self.phases[e].stuck_contacts().collect();
                    stuck.push(ev.contact);
                    let closed: Vec<usize> = (0..model.contacts.len()).filter(|&i| self.phases[e].closed(i)).collect();
                    if let Some(hold) = Phase::new(model, &stuck, &closed) {
                        let z = hold.stuck_forces(&self.after[e], self.times[e]).into_iter().find(|(k, _)| *k == ev.contact).map_or(0.0, |(_, z)| z);
                        keep(-z / fs, ev.contact, HOLD, self.times[e], Some(e));
                    }
                }
            }
        }
        let ne = self.events.len().max(1);
        for e in 0..ne {
            let (a, b) = (self.times[e], if e + 1 < self.events.len() { self.times[e + 1] } else { self.times[0] + self.period });
            let ph = &self.phases[e];
            let y0 = &self.after[e];
            let stuck: Vec<usize> = ph.stuck_contacts().collect();
            for i in (0..model.contacts.len()).filter(|&i| model.contacts[i].is_rigid()) {
                if stuck.contains(&i) {
                    let (v, t) = minimum(a, b, &|t| ph.stuck_forces(&ph.flow(a, y0, t), t).into_iter().find(|(k, _)| *k == i).map_or(0.0, |(_, z)| z));
                    keep(v / fs, i, STUCK, t, None);
                } else {
                    let (v, t) = minimum(a, b, &|t| self.clearance(i, &ph.flow(a, y0, t), t));
                    keep(v / xs, i, CLEARANCE, t, None);
                }
            }
        }
        Some(best)
    }
}
