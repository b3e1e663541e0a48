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
use nalgebra::DVector;

/// Samples per radian of the phase's fastest rate (its balancing speed, ≥ ω_max). A plastic
/// impact rings the stiff modes: on the coarse blade the tip comes back to the casing 9e-6 s
/// after an impact (one period of its 6e5 rad/s constraint modes), a dip that 200 samples per
/// phase (1.4e-5 s apart there) stepped over, so the walk went on past the second impact.
const PER_RADIAN: f64 = 4.0;
const MIN_SAMPLES: usize = 200;
/// The smallest sampled local minima refined by golden section, per contact and phase.
const REFINED: usize = 4;

/// The phase's states from `a` (state `y0`) to `b`, equally spaced at [`PER_RADIAN`] of its
/// fastest rate: one exponential, then a matrix-vector product per sample.
fn sample(ph: &Phase, a: f64, b: f64, y0: &DVector<f64>, omega: f64) -> Vec<(f64, DVector<f64>)> {
    let count = (((b - a) * ph.speed_hint().max(omega) * PER_RADIAN).ceil() as usize).max(MIN_SAMPLES);
    let h = (b - a) / count as f64;
    let step = ph.exp(h);
    let mut out = Vec::with_capacity(count + 1);
    let mut y = y0.clone();
    for j in 0..=count {
        let t = a + h * j as f64;
        let next = if j < count { Some(ph.flow_with(&step, t, &y, t + h)) } else { None };
        out.push((t, y));
        match next {
            Some(n) => y = n,
            None => break,
        }
    }
    out
}

/// The smallest value of `f(y, t)` over the sampled phase, and where: the [`REFINED`] smallest
/// sampled local minima refined by golden section, each from its neighbouring sample's state.
fn smallest(ph: &Phase, samples: &[(f64, DVector<f64>)], f: &dyn Fn(&DVector<f64>, f64) -> f64) -> (f64, f64) {
    let vs: Vec<f64> = samples.iter().map(|(t, y)| f(y, *t)).collect();
    let mut best = vs.iter().zip(samples).map(|(&v, s)| (v, s.0)).fold((f64::INFINITY, 0.0), |m, x| if x.0 < m.0 { x } else { m });
    let mut minima: Vec<usize> = (1..vs.len().saturating_sub(1)).filter(|&i| vs[i] <= vs[i - 1] && vs[i] <= vs[i + 1]).collect();
    minima.sort_by(|&x, &y| vs[x].total_cmp(&vs[y]));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for &i in minima.iter().take(REFINED) {
        let (t0, y0) = (samples[i - 1].0, &samples[i - 1].1);
        let at = |t: f64| f(&ph.flow(t0, y0, t), t);
        let (mut lo, mut hi) = (t0, samples[i + 1].0);
        for _ in 0..40 {
            let (c, d) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if at(c) < at(d) { hi = d } else { lo = c }
        }
        let t = 0.5 * (lo + hi);
        let v = at(t);
        if v < best.0 {
            best = (v, t);
        }
    }
    best
}

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
        let fs = self.force_scale();
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
            let samples = sample(ph, a, b, &self.after[e], model.frequency);
            let stuck: Vec<usize> = ph.stuck_contacts().collect();
            for i in (0..model.contacts.len()).filter(|&i| model.contacts[i].is_rigid()) {
                if stuck.contains(&i) {
                    let (v, t) = smallest(ph, &samples, &|y, t| ph.stuck_forces(y, t).into_iter().find(|(k, _)| *k == i).map_or(0.0, |(_, z)| z));
                    keep(v / fs, i, STUCK, t, None);
                } else {
                    let (v, t) = smallest(ph, &samples, &|y, t| self.clearance(i, y, t));
                    keep(v / xs, i, CLEARANCE, t, None);
                }
            }
        }
        Some(best)
    }
}
