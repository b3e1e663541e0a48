//! Is the polished orbit admissible? Between events: the clearance of every free rigid contact
//! ≥ 0, the force of every stuck one ≥ 0, a closed compliant contact penetrating and an open one
//! not. Each function is sampled densely on every phase and minimised around each sampled local
//! minimum (golden section), so that a dip between samples is found too. At the events:
//! impulses ≥ 0, and a pure impact may not call for sticking (the force that would hold the
//! contact just after it must not be compressive).
use super::PolishFailure;
use super::events::{Event, EventKind};
use super::orbit::PolishedOrbit;
use super::phase::{Harmonics, Phase, Transient};
use super::signals::{Samples, Signal};
use nalgebra::DVector;
use num_complex::Complex64 as C;

/// Samples per phase before the local refinement.
const SAMPLES: usize = 200;
/// Relative tolerance of the sign checks (of the clearance scale, of the force scale).
const TOL: f64 = 1e-9;

/// The smallest value of `f` over [a, b]: at the dense samples `ts` (values `vs`), then by
/// golden section around each sampled local minimum.
pub(super) fn minimum(ts: &[f64], vs: &[f64], f: &dyn Fn(f64) -> f64) -> (f64, f64) {
    let mut best = (vs[0], ts[0]);
    for i in 0..ts.len() {
        if vs[i] < best.0 {
            best = (vs[i], ts[i]);
        }
        if i > 0 && i + 1 < ts.len() && vs[i] <= vs[i - 1] && vs[i] <= vs[i + 1] {
            let (t, v) = golden(ts[i - 1], ts[i + 1], 60, f);
            if v < best.0 {
                best = (v, t);
            }
        }
    }
    best
}

/// The minimum of a unimodal `f` on [lo, hi] by `iterations` golden-section steps, one new value
/// per step (the other interior point is the last step's; Press et al., "Numerical Recipes",
/// §10.2): (time, value) at the final bracket's middle.
pub(super) fn golden(mut lo: f64, mut hi: f64, iterations: usize, f: &dyn Fn(f64) -> f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iterations {
        if fc < fd {
            (hi, d, fd) = (d, c, fc);
            c = hi - g * (hi - lo);
            fc = f(c);
        } else {
            (lo, c, fc) = (c, d, fd);
            d = lo + g * (hi - lo);
            fd = f(d);
        }
    }
    let t = 0.5 * (lo + hi);
    (t, f(t))
}

/// Where an orbit dips through a contact between events: the contact, the time of its lowest
/// value, whether it is closed there (stuck or on), and the events around.
#[derive(Clone, Copy, Debug)]
pub(super) struct Dip {
    pub contact: usize,
    pub time: f64,
    pub closed: bool,
    start: f64,
    end: f64,
}

impl Dip {
    /// Half the width of the run seeded around the dip: 1e-3 T, within 0.4 of the room to the
    /// events around it (of the phase and of `events`).
    pub fn half_width(&self, period: f64, events: &[Event]) -> f64 {
        let room =
            events.iter().map(|e| (e.seed - self.time).rem_euclid(period).min((self.time - e.seed).rem_euclid(period))).fold(self.time - self.start, f64::min);
        (1e-3 * period).min(0.4 * room.min(self.end - self.time)).max(1e-9 * period)
    }
}

/// [`check`], and where it fails between events, the dip ([`Dip`]).
pub(super) fn check_dip(o: &PolishedOrbit) -> Result<(), (PolishFailure, Option<Dip>)> {
    let mut dip = None;
    check_with(o, &mut |d| dip = Some(d)).map_err(|e| (e, dip))
}

pub(super) fn check(o: &PolishedOrbit) -> Result<(), PolishFailure> {
    check_with(o, &mut |_| {})
}

fn what_sign(o: &PolishedOrbit, e: usize, i: usize) -> bool {
    o.phases[e].stuck_contacts().any(|k| k == i) || o.phases[e].closed(i)
}

fn check_with(o: &PolishedOrbit, on_dip: &mut dyn FnMut(Dip)) -> Result<(), PolishFailure> {
    let model = &o.model;
    let ne = o.events.len().max(1);
    // Scales: the largest normal displacement of a contact and the largest force met.
    let xs = o.after.iter().flat_map(|y| model.contacts.iter().map(move |c| c.along(|d| y[d]).abs())).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let fs = o.force_scale();
    for (e, &p) in o.impulses.iter().enumerate() {
        if p < -TOL * fs / model.frequency {
            return Err(PolishFailure(format!("the impact of contact[{}] at t = {:.6} would pull (impulse {p:.3e})", o.events[e].contact, o.times[e])));
        }
    }
    for e in 0..ne {
        let (a, b) = (o.times[e], if e + 1 < o.events.len() { o.times[e + 1] } else { o.times[0] + o.period });
        let lowest = match o.phases[e].transient(a, &o.after[e]) {
            Some(transient) => closed_form(o, e, &transient, (a, b), (xs, fs)),
            None => sampled(o, e, (a, b), (xs, fs)),
        };
        for (i, v, t, what) in lowest {
            if v < -TOL {
                on_dip(Dip { contact: i, time: t, closed: what_sign(o, e, i), start: a, end: b });
                return Err(PolishFailure(format!(
                    "contact[{i}]: the {what} is negative ({:.3e} relative) at t = {:.6} between the events at {a:.6} and {b:.6}: the LCP's event sequence is not admissible for the exact orbit",
                    v,
                    t.rem_euclid(o.period)
                )));
            }
        }
    }
    // A pure impact must not call for sticking: the force that would hold the contact is ≤ 0.
    for (e, ev) in o.events.iter().enumerate() {
        if ev.kind == (EventKind::Impact { stick: false }) {
            let mut stuck: Vec<usize> = o.phases[e].stuck_contacts().collect();
            stuck.push(ev.contact);
            let closed: Vec<usize> = (0..model.contacts.len()).filter(|&i| o.phases[e].closed(i)).collect();
            let Some(hold) = Phase::new(model, &stuck, &closed) else { continue };
            let y: &DVector<f64> = &o.after[e];
            let z = hold.stuck_forces(y, o.times[e]).into_iter().find(|(k, _)| *k == ev.contact).map_or(0.0, |(_, z)| z);
            if z > TOL * fs {
                return Err(PolishFailure(format!(
                    "contact[{}]: after the impact at t = {:.6} the contact would stick (holding force {z:.3e} > 0), but the LCP showed no sticking arc; refine steps",
                    ev.contact,
                    o.times[e].rem_euclid(o.period)
                )));
            }
        }
    }
    Ok(())
}

/// Each contact's smallest value over phase `e` on [a, b] of what [`check`] signs (the held force
/// of a stuck contact, the clearance of a free rigid one, the signed clearance of a compliant
/// one), over its scale (`xs` clearances, `fs` forces): (contact, value, time, what).
type Lowest = Vec<(usize, f64, f64, &'static str)>;

/// What is signed for contact `i` in phase `e`, and its sign (−1: a closed compliant contact's penetration).
fn what(o: &PolishedOrbit, e: usize, i: usize) -> (&'static str, f64) {
    if o.phases[e].stuck_contacts().any(|k| k == i) {
        ("force", 1.0)
    } else if o.model.contacts[i].is_rigid() {
        ("clearance", 1.0)
    } else if o.phases[e].closed(i) {
        ("penetration of the closed compliant contact", -1.0)
    } else {
        ("clearance of the open compliant contact", 1.0)
    }
}

/// [`Lowest`] from the signals in closed form (signals.rs): the phase's transient from its start
/// state and its particular solution, each contact's row on them.
fn closed_form(o: &PolishedOrbit, e: usize, transient: &Transient, (a, b): (f64, f64), (xs, fs): (f64, f64)) -> Lowest {
    let along = Along::new(o, e, transient);
    let mut parts = Vec::new();
    for i in 0..o.model.contacts.len() {
        let (what, sign) = what(o, e, i);
        let scale = if along.stuck.contains(&i) { fs } else { xs };
        parts.push((i, along.signal(o, i, sign), scale, what));
    }
    let rates = parts.iter().flat_map(|(_, s, _, _)| s.rates()).collect::<Vec<f64>>();
    let samples = Samples::new(a, &transient.lambda, (a, b), rates.into_iter());
    parts
        .into_iter()
        .map(|(i, signal, scale, what)| {
            let (v, t) = signal.lowest(&samples, -TOL * scale);
            (i, v / scale, t, what)
        })
        .collect()
}

/// A phase's signals in closed form (signals.rs): its transient from its start state, its stuck
/// contacts, and its particular solution (the full one and its stuck forces) where it has stuck
/// contacts (a clearance needs only its row's).
pub(super) struct Along<'a> {
    e: usize,
    a: f64,
    transient: &'a Transient,
    pub stuck: Vec<usize>,
    part: Harmonics,
    held: Harmonics,
}

impl<'a> Along<'a> {
    pub fn new(o: &PolishedOrbit, e: usize, transient: &'a Transient) -> Self {
        let ph = &o.phases[e];
        let stuck: Vec<usize> = ph.stuck_contacts().collect();
        let part = if stuck.is_empty() { vec![] } else { ph.particular() };
        let held = if stuck.is_empty() { vec![] } else { ph.stuck_force_particular(&part) };
        Along { e, a: o.times[e], transient, stuck, part, held }
    }

    /// Contact `i`'s held force if it is stuck, else sign·(gap(t) − B_i x(t)).
    pub fn signal(&self, o: &PolishedOrbit, i: usize, sign: f64) -> Signal {
        let (ph, c, w, n) = (&o.phases[self.e], &o.model.contacts[i], o.model.frequency, o.model.n());
        let (rho, harmonics) = if let Some(s) = self.stuck.iter().position(|&k| k == i) {
            (ph.stuck_force_gradient().row(s).transpose(), self.held.iter().map(|(p, z)| (*p as f64 * w, z[s])).collect::<Vec<_>>())
        } else {
            let mut rho = DVector::zeros(2 * n);
            c.row.iter().for_each(|&(d, cd)| rho[d] = -sign * cd);
            let mut h: Vec<(f64, C)> = o.gaps[i].iter().map(|(p, g)| (*p as f64 * w, g[0] * sign)).collect();
            if self.stuck.is_empty() {
                h.extend(ph.particular_along(&c.row).into_iter().map(|(p, x)| (p as f64 * w, -x * sign)));
            } else {
                h.extend(self.part.iter().map(|(p, y)| (*p as f64 * w, -c.along(|d| y[d]) * sign)));
            }
            (rho, h)
        };
        Signal::new(self.a, self.transient.lambda.clone(), self.transient.coefficients(&rho), harmonics)
    }
}

/// [`Lowest`] by [`SAMPLES`] flows over the phase and a golden section around each sampled local
/// minimum (a phase without an eigendecomposition: its flows are Padé's).
fn sampled(o: &PolishedOrbit, e: usize, (a, b): (f64, f64), (xs, fs): (f64, f64)) -> Lowest {
    let ph: &Phase = &o.phases[e];
    let y0 = &o.after[e];
    let state = |t: f64| ph.flow(a, y0, t);
    // The samples' states once for every contact: one exponential, then a product per sample.
    let ts: Vec<f64> = (0..=SAMPLES).map(|j| a + (b - a) * j as f64 / SAMPLES as f64).collect();
    let step = ph.exp((b - a) / SAMPLES as f64);
    let mut ys = vec![ph.flow(a, y0, a)];
    for w in ts.windows(2) {
        let next = ph.flow_with(&step, w[0], ys.last().expect("one"), w[1]);
        ys.push(next);
    }
    let forces: Vec<Vec<(usize, f64)>> = ys.iter().zip(&ts).map(|(y, &t)| ph.stuck_forces(y, t)).collect();
    let stuck: Vec<usize> = ph.stuck_contacts().collect();
    let mut out = Vec::new();
    for i in 0..o.model.contacts.len() {
        let (what, sign) = what(o, e, i);
        let (v, t) = if let Some(s) = stuck.iter().position(|&k| k == i) {
            let vs: Vec<f64> = forces.iter().map(|z| z[s].1).collect();
            let (v, t) = minimum(&ts, &vs, &|t| ph.stuck_forces(&state(t), t)[s].1);
            (v / fs, t)
        } else {
            let vs: Vec<f64> = ys.iter().zip(&ts).map(|(y, &t)| sign * o.clearance(i, y, t)).collect();
            let (v, t) = minimum(&ts, &vs, &|t| sign * o.clearance(i, &state(t), t));
            (v / xs, t)
        };
        out.push((i, v, t, what));
    }
    out
}

impl PolishedOrbit {
    /// The force scale of the sign checks ([`super::verify`], [`Self::rigid_margin`]): the largest
    /// load, impulse × ω, or stuck contact's force at the events. The held forces count because a
    /// casing-driven blade has no load, and its rigid contacts on massless DOFs no impulse: without
    /// them the scale was f64::MIN_POSITIVE and a −2e-12 N round-off read as −1e296.
    pub fn force_scale(&self) -> f64 {
        let loads: f64 = self.model.forces.iter().map(|f| f.term.amplitude.abs()).sum();
        let held =
            self.after.iter().zip(&self.times).zip(&self.phases).flat_map(|((y, &t), ph)| ph.stuck_forces(y, t)).fold(0.0f64, |m, (_, z)| m.max(z.abs()));
        self.impulses.iter().fold(loads.max(held), |m, p| m.max(p.abs() * self.model.frequency)).max(f64::MIN_POSITIVE)
    }
}
