//! The exact orbit as a function of its unknowns, for the continuation of its branch
//! (src/analysis/continuation/exact): the shooting residual at a given state and event times
//! (the polish's own equations), the orbit at a solution, its monodromy as the product of the
//! phases' exponentials, the contacts' interior extrema that announce a grazing, and the
//! amplitudes over the period.
use super::PolishFailure;
use super::events::Event;
use super::orbit::{PolishedOrbit, user_value};
use crate::model::Model;
use crate::periodic::OutputMap;
use nalgebra::{DMatrix, DVector};

/// Where a compliant contact's clearance comes closest to switching inside a phase: the signed
/// clearance (clearance in an open phase, penetration in a closed one) at its smallest interior
/// local minimum; negative when the orbit has crossed the contact's surface between events.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touch {
    /// The phase (after event `phase`) and the contact.
    pub phase: usize,
    pub contact: usize,
    /// The signed clearance [length] and its time.
    pub value: f64,
    pub time: f64,
    /// The contact is closed in this phase (a touch would open it).
    pub closed: bool,
}

/// Samples per phase and radian of the phase's fastest motion, and the least per phase.
const SAMPLES_PER_RADIAN: f64 = 2.0;
const MIN_SAMPLES: usize = 24;

impl PolishedOrbit {
    /// The orbit of the event signature `events` (their seeds unused) and the contacts closed all
    /// period long on `model`, not solved: for [`Self::shooting_residual`] and [`Self::at`].
    pub fn unsolved(model: &Model, events: Vec<Event>, always: &[usize]) -> Result<Self, PolishFailure> {
        Self::new(model, events, always)
    }

    /// The shooting residual [y(τ_0 + T) − y0; event conditions] from the state `y0` just after
    /// event 0 and the event times `times` (one 0 without events); `None` when the times are not
    /// increasing within one period or a flow fails.
    pub fn shooting_residual(&self, y0: &[f64], times: &[f64]) -> Option<DVector<f64>> {
        let ne = self.events.len();
        let tau: &[f64] = if ne == 0 { &[] } else { times };
        if tau.windows(2).any(|w| w[0] >= w[1]) || tau.last().is_some_and(|&l| l >= tau[0] + self.period) {
            return None;
        }
        let u = DVector::from_iterator(y0.len() + tau.len(), y0.iter().chain(tau).copied());
        self.residual_of(&u)
    }

    /// This orbit at the solution (`y0`, `times`) of [`Self::shooting_residual`]: the states after
    /// the events and the monodromy; `residual` is the solution's, for the record.
    pub fn at(mut self, y0: &[f64], times: &[f64], residual: f64) -> Result<Self, PolishFailure> {
        self.y0 = DVector::from_column_slice(y0);
        if !self.events.is_empty() {
            self.times = times.to_vec();
        }
        self.residual = residual;
        self.correction = residual;
        self.finish()?;
        Ok(self)
    }

    /// The event signature (times as seeds), the contacts closed all period long, the event
    /// times and the state just after event 0.
    pub fn events(&self) -> &[Event] {
        &self.events
    }
    pub fn always_closed(&self) -> &[usize] {
        &self.always
    }
    pub fn times(&self) -> &[f64] {
        &self.times
    }
    pub fn initial_state(&self) -> &[f64] {
        self.y0.as_slice()
    }

    /// The monodromy from just after event 0 round the period as the product of the phases'
    /// exponentials: exact when every phase is free (compliant contacts), because a compliant
    /// contact's force is continuous at its switch (zero at clearance 0), so its saltation matrix
    /// S = I + (f⁺ − f⁻)∇hᵀ/(∇h·f⁻) is the identity (Leine & Nijmeijer, "Dynamics and
    /// Bifurcations of Non-Smooth Mechanical Systems", §7.1). `None` with a stuck contact or an
    /// impact (its velocity reset is not the identity: the relocated one-period map then).
    pub(super) fn flow_product(&self) -> Option<DMatrix<f64>> {
        if !self.phases.iter().all(|p| p.all_free()) || self.events.iter().any(|e| matches!(e.kind, super::EventKind::Impact { .. })) {
            return None;
        }
        let n2 = 2 * self.model.n();
        let ne = self.events.len();
        let mut m = DMatrix::identity(n2, n2);
        for e in 0..ne.max(1) {
            let span = if ne == 0 { self.period } else { self.end_of(e) - self.times[e] };
            m = self.phases[e].exp(span) * m;
        }
        Some(m)
    }

    /// The time phase `e` ends (the next event's, event 0's a period later).
    fn end_of(&self, e: usize) -> f64 {
        if e + 1 < self.events.len() { self.times[e + 1] } else { self.times[0] + self.period }
    }

    /// The sample times of the period, phase by phase (each phase's start included, its end not):
    /// (time, phase).
    fn samples(&self) -> Vec<(f64, usize)> {
        let ne = self.events.len();
        let mut out = Vec::new();
        for e in 0..ne.max(1) {
            let (a, b) = (self.times[e], if ne == 0 { self.times[0] + self.period } else { self.end_of(e) });
            let count = (((b - a) * self.phases[e].speed_hint().max(self.model.frequency) * SAMPLES_PER_RADIAN).ceil() as usize).max(MIN_SAMPLES);
            out.extend((0..count).map(|j| (a + (b - a) * j as f64 / count as f64, e)));
        }
        out
    }

    /// Each compliant contact's smallest local minimum of its signed clearance between its own
    /// events ([`Touch`]): on samples of the whole period (cyclic), refined by golden section.
    /// A contact's own events, where its signed clearance comes down to 0 from both sides, are
    /// not minima.
    pub fn touches(&self) -> Vec<Touch> {
        let samples = self.samples();
        let states: Vec<DVector<f64>> = samples.iter().map(|&(t, e)| self.phases[e].flow(self.times[e], &self.after[e], t)).collect();
        let len = samples.len();
        let mut out = Vec::new();
        for (i, c) in self.model.contacts.iter().enumerate() {
            if c.is_rigid() {
                continue;
            }
            let sign = |e: usize| if self.phases[e].closed(i) { -1.0 } else { 1.0 };
            let f = |t: f64| {
                let (e, tt) = self.locate(t);
                sign(e) * self.clearance(i, &self.state(tt), tt)
            };
            let v: Vec<f64> = samples.iter().zip(&states).map(|(&(t, e), y)| sign(e) * self.clearance(i, y, t)).collect();
            let own = |j: usize| {
                let (t, e) = samples[j];
                !self.events.is_empty() && t == self.times[e] && self.events[e].contact == i
            };
            let mut best: Option<Touch> = None;
            for j in 0..len {
                let (l, r) = ((j + len - 1) % len, (j + 1) % len);
                if own(j) || v[j] > v[l] || v[j] > v[r] {
                    continue;
                }
                let t = samples[j].0;
                let (tl, tr) = (t - (t - samples[l].0).rem_euclid(self.period), t + (samples[r].0 - t).rem_euclid(self.period));
                let (time, value) = golden(tl, tr, &f);
                if best.is_none_or(|b| value < b.value) {
                    let (e, tt) = self.locate(time);
                    best = Some(Touch { phase: e, contact: i, value, time: tt, closed: self.phases[e].closed(i) });
                }
            }
            out.extend(best);
        }
        out
    }

    /// Peak-to-peak / 2 of user DOF `dof`'s displacement over the period (through the output
    /// map when there is one): samples, each extremum refined by golden section.
    pub fn amplitude(&self, map: Option<&OutputMap>, dof: usize) -> Option<f64> {
        let n = self.model.n();
        let x = |t: f64| user_value(map, dof, &self.state(t), 0, n).unwrap_or(0.0);
        user_value(map, dof, &self.y0, 0, n)?;
        let samples = self.samples();
        let xs: Vec<f64> = samples.iter().map(|&(t, _)| x(t)).collect();
        let len = xs.len();
        let (mut hi, mut lo) = (f64::MIN, f64::MAX);
        for j in 0..len {
            let (l, r) = ((j + len - 1) % len, (j + 1) % len);
            let t = samples[j].0;
            let (tl, tr) = (t - (t - samples[l].0).rem_euclid(self.period), t + (samples[r].0 - t).rem_euclid(self.period));
            hi = hi.max(xs[j]);
            lo = lo.min(xs[j]);
            if xs[j] >= xs[l] && xs[j] >= xs[r] {
                hi = hi.max(-golden(tl, tr, &|t| -x(t)).1);
            }
            if xs[j] <= xs[l] && xs[j] <= xs[r] {
                lo = lo.min(golden(tl, tr, &x).1);
            }
        }
        Some(0.5 * (hi - lo))
    }
}

/// The minimum of `f` on [lo, hi] by golden section: (its time, its value).
fn golden(mut lo: f64, mut hi: f64, f: &dyn Fn(f64) -> f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..80 {
        if hi - lo <= 1e-13 * (1.0 + hi.abs()) {
            break;
        }
        if fc < fd {
            hi = d;
            d = c;
            fd = fc;
            c = hi - g * (hi - lo);
            fc = f(c);
        } else {
            lo = c;
            c = d;
            fc = fd;
            d = lo + g * (hi - lo);
            fd = f(d);
        }
    }
    let t = 0.5 * (lo + hi);
    (t, f(t))
}
