//! The exact orbit as a function of its unknowns, for the continuation of its branch
//! (src/analysis/continuation/exact): the shooting residual at a given state and event times
//! (the polish's own equations), the orbit at a solution, its monodromy as the product of the
//! phases' exponentials, the contacts' interior extrema that announce a grazing, and the
//! amplitudes over the period.
use super::PolishFailure;
use super::events::{Event, EventKind};
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

    /// [`Self::shooting_residual`] and its Jacobian in (y0, times), from one flow of the period:
    /// the variational equations of ẏ = A y + b(t) between events, ∂y(t₁)/∂y(t₀) = e^{A(t₁−t₀)},
    /// ∂y(t₁)/∂t₀ = −e^{A(t₁−t₀)} f(t₀, y(t₀)), ∂y(t₁)/∂t₁ = f(t₁, y(t₁)) (f the phase's vector
    /// field; Hairer, Nørsett & Wanner I, §I.14), chained through the events with identity
    /// saltation (compliant switches, see [`Self::flow_product`]). `None` with a stuck contact
    /// or an impact or release event, or where [`Self::shooting_residual`] gives none.
    pub fn shooting_jacobian(&self, y0: &[f64], times: &[f64]) -> Option<(DVector<f64>, DMatrix<f64>)> {
        let compliant = self.events.iter().all(|e| matches!(e.kind, EventKind::On | EventKind::Off));
        if !compliant || !self.phases.iter().all(|p| p.all_free()) {
            return None;
        }
        let (n, ne) = (self.model.n(), self.events.len());
        let n2 = 2 * n;
        let tau: &[f64] = if ne == 0 { &[] } else { times };
        if tau.windows(2).any(|w| w[0] >= w[1]) || tau.last().is_some_and(|&l| l >= tau[0] + self.period) {
            return None;
        }
        let start = DVector::from_column_slice(y0);
        let mut res = DVector::zeros(n2 + ne);
        let mut jac = DMatrix::zeros(n2 + ne, n2 + ne);
        let mut y = start.clone();
        let mut dy = DMatrix::identity(n2, n2 + ne);
        let field = |e: usize, y: &DVector<f64>, t: f64| {
            let mut f = DVector::zeros(n2);
            f.rows_mut(0, n).copy_from(&y.rows(n, n));
            f.rows_mut(n, n).copy_from(&self.phases[e].acceleration(y, t));
            f
        };
        for e in 0..ne.max(1) {
            let (t0, t1) = if ne == 0 { (0.0, self.period) } else { (tau[e], if e + 1 < ne { tau[e + 1] } else { tau[0] + self.period }) };
            let ex = self.phases[e].exp(t1 - t0);
            let ym = self.phases[e].flow_with(&ex, t0, &y, t1);
            dy = &ex * dy;
            if ne > 0 {
                let next = (e + 1) % ne;
                let (f0, f1) = (&ex * field(e, &y, t0), field(e, &ym, t1));
                for r in 0..n2 {
                    dy[(r, n2 + e)] -= f0[r];
                    dy[(r, n2 + next)] += f1[r];
                }
                let c = self.events[next].contact;
                res[n2 + next] = self.clearance(c, &ym, t1);
                for col in 0..n2 + ne {
                    jac[(n2 + next, col)] = -self.model.contacts[c].along(|d| dy[(d, col)]);
                }
                jac[(n2 + next, n2 + next)] += self.gap(c, t1, 1);
            }
            y = ym;
        }
        res.rows_mut(0, n2).copy_from(&(&y - &start));
        jac.view_mut((0, 0), (n2, n2 + ne)).copy_from(&(dy - DMatrix::identity(n2, n2 + ne)));
        res.iter().all(|v| v.is_finite()).then_some((res, jac))
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

    /// The states at the samples, each flowed from the one before in its phase (short flows).
    fn sampled_states(&self, samples: &[(f64, usize)]) -> Vec<DVector<f64>> {
        let mut out: Vec<DVector<f64>> = Vec::with_capacity(samples.len());
        for (j, &(t, e)) in samples.iter().enumerate() {
            let y = match j.checked_sub(1).map(|i| (samples[i], &out[i])) {
                Some(((s, f), prev)) if f == e => self.phases[e].flow(s, prev, t),
                _ => self.phases[e].flow(self.times[e], &self.after[e], t),
            };
            out.push(y);
        }
        out
    }

    /// The state at `t` (in [τ_0, τ_0 + T), as [`Self::locate`] gives it) flowed from the last
    /// sample at or before it, which is in its phase (each phase's start is a sample).
    fn state_near(&self, samples: &[(f64, usize)], states: &[DVector<f64>], t: f64) -> DVector<f64> {
        let j = samples.partition_point(|s| s.0 <= t).saturating_sub(1);
        let (s, e) = samples[j];
        self.phases[e].flow(s, &states[j], t)
    }

    /// Each compliant contact's smallest local minimum of its signed clearance between its own
    /// events ([`Touch`]): on samples of the whole period (cyclic), refined by golden section.
    /// A contact's own events, where its signed clearance comes down to 0 from both sides, are
    /// not minima.
    pub fn touches(&self) -> Vec<Touch> {
        let samples = self.samples();
        let states = self.sampled_states(&samples);
        let len = samples.len();
        let mut out = Vec::new();
        for (i, c) in self.model.contacts.iter().enumerate() {
            if c.is_rigid() {
                continue;
            }
            let sign = |e: usize| if self.phases[e].closed(i) { -1.0 } else { 1.0 };
            let f = |t: f64| {
                let (e, tt) = self.locate(t);
                sign(e) * self.clearance(i, &self.state_near(&samples, &states, tt), tt)
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
        user_value(map, dof, &self.y0, 0, n)?;
        let samples = self.samples();
        let states = self.sampled_states(&samples);
        let x = |t: f64| {
            let (_, tt) = self.locate(t);
            user_value(map, dof, &self.state_near(&samples, &states, tt), 0, n).unwrap_or(0.0)
        };
        let xs: Vec<f64> = states.iter().map(|y| user_value(map, dof, y, 0, n).unwrap_or(0.0)).collect();
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
