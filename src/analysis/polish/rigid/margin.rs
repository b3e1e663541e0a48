//! The search of [`PolishedOrbit::rigid_margin`]: each rigid contact's clearance or held force
//! along every phase. Where the phase has an eigendecomposition the values are its closed-form
//! signals (signals.rs) and the smallest is found by `Signal::minimum`: 17 samples and a
//! bisection of every interval whose bound on the signal's bend lets it go below the lowest value
//! met (certified, to [`TOL`] of the scale). It was 4 samples per radian of the phase's balancing
//! speed (≈ 6 500 a period per contact on the coarse blade, to catch the stiff modes' ringing
//! after a plastic impact) and golden sections: the rigid walk's test functions spent 20.6 of its
//! 105.6 s there (session 29). A phase without an eigendecomposition (Padé flows) is still sampled
//! and its smallest sampled local minima refined by golden section.
//!
//! Only the least margin's search need be bit for bit the same (the walk bisects on it): each
//! closed-form part is first found by `Signal::minimum_stepped` (products where `minimum` makes
//! exponentials; it was 17 % of the coarse rigid walk), and only the parts whose stepped minimum
//! may be the least (within its round-off bound of the least upper bound) are sought again by
//! `minimum`; the others keep the stepped value, within 1e-11 of their scale of it.
use super::super::orbit::PolishedOrbit;
use super::super::signals::{Samples, Signal};
use super::super::verify::{self, Along};
use super::{CLEARANCE, RigidMargins, STUCK};

/// Samples per radian of the phase's fastest rate (its balancing speed, ≥ ω_max), for the sampled
/// phases (and the start of a held arc after its micro-flight). A plastic impact rings the stiff
/// modes: on the coarse blade the tip comes back to the casing 9e-6 s after an impact (one period
/// of its 6e5 rad/s constraint modes), a dip that 200 samples per phase (1.4e-5 s apart there)
/// stepped over, so the walk went on past the second impact.
const PER_RADIAN: f64 = 4.0;
const MIN_SAMPLES: usize = 200;
/// The smallest sampled local minima refined by golden section, per contact and phase.
const REFINED: usize = 4;
/// Golden-section steps of a refinement.
const GOLDEN: usize = 40;
/// The closed-form minimum's accuracy over the scale: below the located events' sensitivity
/// (a margin's slope is ≳ 1e-4 per rad/s near its zero, so ≤ 1e-11 rad/s) and near round-off.
const TOL: f64 = 1e-15;

/// One contact's margin sought along one sampled phase: its samples (from index `from`), scale and what.
struct Sought {
    e: usize,
    contact: usize,
    what: &'static str,
    scale: f64,
    from: usize,
    values: Vec<f64>,
}

/// A closed-form part's stepped search, kept in the order its margin is kept: its signal, its
/// samples (index), scale and key, the stepped minimum (value, time) and its round-off bound.
struct Stepped {
    signal: Signal,
    samples: usize,
    scale: f64,
    key: (usize, &'static str, usize),
    found: (f64, f64),
    error: f64,
}

/// A margin kept during the phases' pass: a lift-off's height (value, key, time) or a closed-form
/// part ([`Stepped`], by index).
enum Kept {
    Height(f64, (usize, &'static str, usize), f64),
    Part(usize),
}

/// The stepped searches' tolerance beyond their round-off bound (of the part's scale).
const STEPPED_SLACK: f64 = 1e-11;

/// A sampled local minimum to refine.
struct Candidate {
    sought: usize,
    index: usize,
}

impl PolishedOrbit {
    /// The phases' margins (see the module) into `best`, with the clearance and force scales.
    pub(super) fn phase_margins(&self, (xs, fs): (f64, f64), best: &mut RigidMargins) {
        let model = &self.model;
        let ne = self.events.len().max(1);
        let (mut phases, mut sought) = (Vec::with_capacity(ne), Vec::new());
        let (mut kept, mut stepped, mut all_samples) = (Vec::new(), Vec::new(), Vec::new());
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
                        kept.push(Kept::Height(-height / xs, (i, STUCK, e), a));
                    }
                    if ts.len() - from >= 3 {
                        sought.push(Sought { e, contact: i, what: STUCK, scale: fs, from, values: Vec::new() });
                    }
                } else {
                    sought.push(Sought { e, contact: i, what: CLEARANCE, scale: xs, from: 0, values: Vec::new() });
                }
            }
            if let Some(transient) = ph.transient(a, &self.after[e]) {
                let along = Along::new(self, e, &transient);
                let parts: Vec<(Sought, Signal)> = sought
                    .drain(first..)
                    .map(|s| {
                        let signal = along.signal(self, s.contact, 1.0);
                        (s, signal)
                    })
                    .collect();
                // One set of samples per span, with every rate of its parts (the same values each part's own would hold).
                let base = all_samples.len();
                let mut spans: Vec<usize> = parts.iter().map(|(s, _)| s.from).collect();
                spans.sort_unstable();
                spans.dedup();
                for &from in &spans {
                    let rates: Vec<f64> = parts.iter().filter(|(s, _)| s.from == from).flat_map(|(_, g)| g.rates()).collect();
                    all_samples.push(Samples::new(a, &transient.lambda, (ts[from], ts[ts.len() - 1]), rates.into_iter()));
                }
                for (s, signal) in parts {
                    let index = base + spans.iter().position(|&f| f == s.from).expect("a span per part");
                    let samples = &all_samples[index];
                    let found = signal.minimum_stepped(samples, TOL * s.scale);
                    let error = signal.stepped_error(samples) + STEPPED_SLACK * s.scale;
                    kept.push(Kept::Part(stepped.len()));
                    stepped.push(Stepped { signal, samples: index, scale: s.scale, key: (s.contact, s.what, s.e), found, error });
                }
                phases.push(None);
                continue;
            }
            let states = ph.samples(a, &self.after[e], h, ts.len());
            let forces: Vec<Vec<(usize, f64)>> = if stuck.is_empty() { vec![] } else { states.iter().zip(&ts).map(|(y, &t)| ph.stuck_forces(y, t)).collect() };
            for s in &mut sought[first..] {
                s.values = match stuck.iter().position(|&k| k == s.contact) {
                    Some(k) => forces.iter().map(|z| z[k].1).collect(),
                    None => states.iter().zip(&ts).map(|(y, &t)| self.clearance(s.contact, y, t)).collect(),
                };
            }
            phases.push(Some((ts, ph, states)));
        }
        self.replay(best, &kept, &stepped, &all_samples);
        // The smallest sample of each, and its smallest local minima to refine.
        let mut candidates = Vec::new();
        for (k, s) in sought.iter().enumerate() {
            let Some((ts, ..)) = &phases[s.e] else { continue };
            let vs = &s.values[s.from..];
            let (v, t) = vs.iter().zip(&ts[s.from..]).fold((f64::INFINITY, 0.0), |m, (&v, &t)| if v < m.0 { (v, t) } else { m });
            best.keep(v / s.scale, (s.contact, s.what, s.e), t, None);
            let mut minima: Vec<usize> = (1..vs.len().saturating_sub(1)).filter(|&i| vs[i] <= vs[i - 1] && vs[i] <= vs[i + 1]).collect();
            minima.sort_by(|&x, &y| vs[x].total_cmp(&vs[y]));
            candidates.extend(minima.iter().take(REFINED).map(|&i| Candidate { sought: k, index: s.from + i }));
        }
        for c in candidates {
            let s = &sought[c.sought];
            let Some((ts, ph, states)) = &phases[s.e] else { continue };
            let t0 = ts[c.index - 1];
            let stuck = s.what == STUCK;
            let at = |t: f64| {
                let y = ph.flow(t0, &states[c.index - 1], t);
                if stuck { ph.stuck_forces(&y, t).into_iter().find(|(k, _)| *k == s.contact).map_or(0.0, |(_, z)| z) } else { self.clearance(s.contact, &y, t) }
            };
            let (t, v) = verify::golden(t0, ts[c.index + 1], GOLDEN, &at);
            best.keep(v / s.scale, (s.contact, s.what, s.e), t, None);
        }
    }

    /// The phases' heights and closed-form parts into `best` in the order they were met: a part
    /// whose stepped minimum less its bound lies above the least upper bound of all (the events'
    /// margins, the heights, each stepped minimum plus its bound) is not the least and keeps its
    /// stepped value; the others are sought by `Signal::minimum`, as before the stepped search.
    fn replay(&self, best: &mut RigidMargins, kept: &[Kept], stepped: &[Stepped], samples: &[Samples]) {
        let heights = kept.iter().filter_map(|k| if let Kept::Height(v, ..) = k { Some(*v) } else { None });
        let upper = stepped.iter().map(|p| (p.found.0 + TOL * p.scale + p.error) / p.scale).chain(heights).fold(best.least.value, f64::min);
        for k in kept {
            match *k {
                Kept::Height(v, key, t) => best.keep(v, key, t, None),
                Kept::Part(i) => {
                    let p = &stepped[i];
                    let (v, t) =
                        if (p.found.0 - TOL * p.scale - p.error) / p.scale > upper { p.found } else { p.signal.minimum(&samples[p.samples], TOL * p.scale) };
                    best.keep(v / p.scale, p.key, t, None);
                }
            }
        }
    }
}
