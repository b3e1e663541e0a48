//! The search of [`PolishedOrbit::rigid_margin`]: each rigid contact's clearance or held force
//! sampled along every phase and refined by golden section around its smallest sampled local
//! minima. Where the phase has an eigendecomposition the values are its closed-form signals
//! (signals.rs: O(n_a + harmonics) per value, the exponentials of a sample shared by the
//! contacts; it was a 2n-state flow per sample and per golden step, and a held force a dense
//! product per sample and per contact: 2.3 s per evaluation on the real blade), and a local
//! minimum is refined only where the bound on the signal's bend lets it go below the smallest
//! value found (a skipped refinement could not have changed the margin).
use super::super::orbit::PolishedOrbit;
use super::super::phase::Phase;
use super::super::signals::Signal;
use super::super::verify::{self, Along};
use super::{CLEARANCE, RigidMargin, STUCK};
use nalgebra::DVector;

/// Samples per radian of the phase's fastest rate (its balancing speed, ≥ ω_max). A plastic
/// impact rings the stiff modes: on the coarse blade the tip comes back to the casing 9e-6 s
/// after an impact (one period of its 6e5 rad/s constraint modes), a dip that 200 samples per
/// phase (1.4e-5 s apart there) stepped over, so the walk went on past the second impact.
const PER_RADIAN: f64 = 4.0;
const MIN_SAMPLES: usize = 200;
/// The smallest sampled local minima refined by golden section, per contact and phase.
const REFINED: usize = 4;
/// Golden-section steps of a refinement.
const GOLDEN: usize = 40;

/// How one phase's values are had: its signals in closed form, or (a phase without an accepted
/// eigendecomposition: Padé flows) its sampled states, a refinement flowing from the sample before.
enum Values<'a> {
    Closed(Vec<Signal>),
    Flowed(&'a Phase, Vec<DVector<f64>>),
}

/// One contact's margin sought along one phase: its samples (from index `from`), scale and what.
struct Sought {
    e: usize,
    contact: usize,
    what: &'static str,
    scale: f64,
    from: usize,
    values: Vec<f64>,
}

/// A sampled local minimum to refine, and the lowest value its bracket may hold (over the scale).
struct Candidate {
    sought: usize,
    index: usize,
    lower: f64,
}

impl PolishedOrbit {
    /// The phases' margins (see the module) into `best`, with the clearance and force scales.
    pub(super) fn phase_margins(&self, (xs, fs): (f64, f64), best: &mut RigidMargin) {
        let model = &self.model;
        let ne = self.events.len().max(1);
        let (mut phases, mut sought) = (Vec::with_capacity(ne), Vec::new());
        for e in 0..ne {
            let (a, b) = (self.times[e], if e + 1 < self.events.len() { self.times[e + 1] } else { self.times[0] + self.period });
            let ph = &self.phases[e];
            let count = (((b - a) * ph.speed_hint().max(model.frequency) * PER_RADIAN).ceil() as usize).max(MIN_SAMPLES);
            let h = (b - a) / count as f64;
            let ts: Vec<f64> = (0..=count).map(|j| a + h * j as f64).collect();
            let stuck: Vec<usize> = ph.stuck_contacts().collect();
            let first = sought.len();
            for i in (0..model.contacts.len()).filter(|&i| model.contacts[i].is_rigid()) {
                if stuck.contains(&i) {
                    // A landing whose holding force is just negative but rising: its lift-off
                    // (the orbit's distance from the true one), and the arc after the micro-flight.
                    let lift = self.lift_off(e, i);
                    let from = lift.map_or(0, |(_, flight)| ts.iter().position(|&t| t >= a + flight).unwrap_or(ts.len()));
                    if let Some((height, _)) = lift {
                        best.keep(-height / xs, i, STUCK, a, None);
                    }
                    if ts.len() - from >= 3 {
                        sought.push(Sought { e, contact: i, what: STUCK, scale: fs, from, values: Vec::new() });
                    }
                } else {
                    sought.push(Sought { e, contact: i, what: CLEARANCE, scale: xs, from: 0, values: Vec::new() });
                }
            }
            let values = match ph.transient(a, &self.after[e]) {
                Some(transient) => {
                    let along = Along::new(self, e, &transient);
                    let signals: Vec<Signal> = sought[first..].iter().map(|s| along.signal(self, s.contact, 1.0)).collect();
                    for (s, vs) in sought[first..].iter_mut().zip(Signal::values(&signals, &ts)) {
                        s.values = vs;
                    }
                    Values::Closed(signals)
                }
                None => {
                    let states = ph.samples(a, &self.after[e], h, ts.len());
                    let forces: Vec<Vec<(usize, f64)>> =
                        if stuck.is_empty() { vec![] } else { states.iter().zip(&ts).map(|(y, &t)| ph.stuck_forces(y, t)).collect() };
                    for s in &mut sought[first..] {
                        s.values = match stuck.iter().position(|&k| k == s.contact) {
                            Some(k) => forces.iter().map(|z| z[k].1).collect(),
                            None => states.iter().zip(&ts).map(|(y, &t)| self.clearance(s.contact, y, t)).collect(),
                        };
                    }
                    Values::Flowed(ph, states)
                }
            };
            phases.push((ts, h, first, values));
        }
        // The smallest sample of each, and its smallest local minima to refine.
        let mut candidates = Vec::new();
        for (k, s) in sought.iter().enumerate() {
            let (ts, h, first, values) = &phases[s.e];
            let vs = &s.values[s.from..];
            let (v, t) = vs.iter().zip(&ts[s.from..]).fold((f64::INFINITY, 0.0), |m, (&v, &t)| if v < m.0 { (v, t) } else { m });
            best.keep(v / s.scale, s.contact, s.what, t, None);
            let mut minima: Vec<usize> = (1..vs.len().saturating_sub(1)).filter(|&i| vs[i] <= vs[i - 1] && vs[i] <= vs[i + 1]).collect();
            minima.sort_by(|&x, &y| vs[x].total_cmp(&vs[y]));
            for &i in minima.iter().take(REFINED) {
                let index = s.from + i;
                // Between samples h apart a signal with |s''| ≤ M is above the lower sample − M h²/8.
                let lower = match values {
                    Values::Closed(signals) => (vs[i] - signals[k - first].bend((ts[index - 1], ts[index + 1]), None) * h * h / 8.0) / s.scale,
                    Values::Flowed(..) => f64::NEG_INFINITY,
                };
                candidates.push(Candidate { sought: k, index, lower });
            }
        }
        candidates.sort_by(|x, y| x.lower.total_cmp(&y.lower));
        for c in candidates {
            let s = &sought[c.sought];
            let (ts, _, first, values) = &phases[s.e];
            if c.lower >= best.value {
                break;
            }
            let (t0, t1) = (ts[c.index - 1], ts[c.index + 1]);
            let (t, v) = match values {
                Values::Closed(signals) => verify::golden(t0, t1, GOLDEN, &|t| signals[c.sought - first].value(t)),
                Values::Flowed(ph, states) => {
                    let stuck = s.what == STUCK;
                    let at = |t: f64| {
                        let y = ph.flow(t0, &states[c.index - 1], t);
                        if stuck {
                            ph.stuck_forces(&y, t).into_iter().find(|(k, _)| *k == s.contact).map_or(0.0, |(_, z)| z)
                        } else {
                            self.clearance(s.contact, &y, t)
                        }
                    };
                    verify::golden(t0, t1, GOLDEN, &at)
                }
            };
            best.keep(v / s.scale, s.contact, s.what, t, None);
        }
    }
}
