//! The exact orbit as a function of its unknowns, for the continuation of its branch
//! (src/analysis/continuation/exact): the shooting residual at a given state and event times
//! (the polish's own equations), the orbit at a solution, its monodromy as the product of the
//! phases' exponentials, the contacts' interior extrema that announce a grazing, and the
//! amplitudes over the period.
use super::PolishFailure;
use super::events::{Event, EventKind};
use super::orbit::{PolishedOrbit, user_value};
use super::phase::Phase;
pub use super::rigid::KeptVariation;
use crate::model::Model;
use crate::periodic::OutputMap;
use nalgebra::{DMatrix, DVector};

// The outputs' samples in closed form, for the amplitudes.
mod outputs;

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
    /// period long on `model`, not solved: for [`Self::shooting_residual`] and [`Self::at`]. Each
    /// phase whose contact sets one of `bank`'s orbits holds is re-tuned
    /// from it ([`Phase::retuned`]: the loads and particular solution made at `model`'s ω, the
    /// ω-independent rest shared, the same values as made anew) rather than made: the exact
    /// walk's orbit at each λ made ~50 phases of dense n × n products, 70 % of its time on the
    /// real blade. A bank orbit whose structure or contacts' rows and compliances differ from
    /// `model`'s lends nothing.
    pub fn unsolved_retuning(model: &Model, events: Vec<Event>, always: &[usize], bank: &[&PolishedOrbit]) -> Result<Self, PolishFailure> {
        let same = |o: &PolishedOrbit| {
            let (s, t) = (&model.structure, &o.model.structure);
            s.mass == t.mass
                && s.stiffness == t.stiffness
                && s.damping == t.damping
                && model.contacts.len() == o.model.contacts.len()
                && model.contacts.iter().zip(&o.model.contacts).all(|(a, b)| a.row == b.row && a.compliance == b.compliance)
        };
        // Checked only where a bank orbit has the phase sought, once each: the exact walk's bank
        // grows by an orbit per signature met, and checking all of them was 5 % of the rigid blade's walk.
        let mut fits: Vec<Option<bool>> = vec![None; bank.len()];
        // Phases of one contact set are the same phase: made once per build, the others its copies
        // (the same function of the same bank and model, so the same bits).
        let mut made: Vec<Phase> = Vec::new();
        Self::with_phases(model, events, always, |stuck, closed| {
            if let Some(p) = made.iter().find(|p| p.is_for(stuck, closed)) {
                return Some(p.clone());
            }
            let phase = bank
                .iter()
                .zip(&mut fits)
                .find_map(|(o, fit)| o.phases.iter().find(|p| p.is_for(stuck, closed)).filter(|_| *fit.get_or_insert_with(|| same(o))))
                .map_or_else(|| Phase::new(model, stuck, closed), |p| p.retuned(model))?;
            made.push(phase.clone());
            Some(phase)
        })
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

    /// [`Self::shooting_residual`] and its Jacobian in (y0, times), from one flow of the period
    /// and its variation ([`Self::variation`] in rigid.rs: exact flows between events, each
    /// event's state map, plastic impacts' velocity resets included; event 0's time enters as
    /// phase 0's start and as its return a period later). `None` when the times are not
    /// increasing within one period, or where a flow or a reset fails.
    pub fn shooting_jacobian(&self, y0: &[f64], times: &[f64]) -> Option<(DVector<f64>, DMatrix<f64>)> {
        self.shooting_jacobian_kept(y0, times).map(|(r, j, _)| (r, j))
    }

    /// [`Self::shooting_jacobian`] with its period's variation, for [`Self::at_kept`] at the same unknowns.
    pub fn shooting_jacobian_kept(&self, y0: &[f64], times: &[f64]) -> Option<(DVector<f64>, DMatrix<f64>, KeptVariation)> {
        let (n2, ne) = (2 * self.model.n(), self.events.len());
        let tau: &[f64] = if ne == 0 { &[0.0] } else { times };
        if tau.windows(2).any(|w| w[0] >= w[1]) || (ne > 0 && tau[ne - 1] >= tau[0] + self.period) {
            return None;
        }
        let start = DVector::from_column_slice(y0);
        let v = self.variation(&start, tau, tau[0] + self.period)?;
        let mut res = DVector::zeros(n2 + ne);
        res.rows_mut(0, n2).copy_from(&(&v.end - &start));
        res.rows_mut(n2, ne).copy_from(&v.conditions);
        let mut jac = DMatrix::zeros(n2 + ne, n2 + ne);
        jac.view_mut((0, 0), (n2, n2 + ne)).copy_from(&v.d_end.columns(0, n2 + ne));
        jac.view_mut((n2, 0), (ne, n2 + ne)).copy_from(&v.d_conditions.columns(0, n2 + ne));
        for r in 0..n2 {
            jac[(r, r)] -= 1.0;
        }
        if ne > 0 {
            // τ_0 is also event 0's return time.
            let back = v.d_end.column(n2 + ne).into_owned();
            let cond = v.d_conditions.column(n2 + ne).into_owned();
            for r in 0..n2 {
                jac[(r, n2)] += back[r];
            }
            for r in 0..ne {
                jac[(n2 + r, n2)] += cond[r];
            }
        }
        let ret = tau[0] + self.period;
        Some((res, jac, KeptVariation { start, tau: tau.to_vec(), ret, v }))
    }

    /// This orbit at the solution (`y0`, `times`) of [`Self::shooting_residual`]: the states after
    /// the events and the monodromy; `residual` is the solution's, for the record.
    pub fn at(self, y0: &[f64], times: &[f64], residual: f64) -> Result<Self, PolishFailure> {
        self.at_kept(y0, times, residual, None)
    }

    /// [`Self::at`], its monodromy from `kept` (a Jacobian's variation) where that was flowed from
    /// these unknowns: a point's Jacobian and monodromy flowed the same period twice.
    pub fn at_kept(self, y0: &[f64], times: &[f64], residual: f64, kept: Option<KeptVariation>) -> Result<Self, PolishFailure> {
        let mut o = self.placed(y0, times, residual);
        o.finish_kept(kept)?;
        Ok(o)
    }

    /// [`Self::at`] without the monodromy, made where [`Self::monodromy`] asks for it: a
    /// located event's trial orbit is read for its margin or a force alone.
    pub fn at_states(self, y0: &[f64], times: &[f64], residual: f64) -> Result<Self, PolishFailure> {
        let mut o = self.placed(y0, times, residual);
        o.finish_states()?;
        Ok(o)
    }

    fn placed(mut self, y0: &[f64], times: &[f64], residual: f64) -> Self {
        self.y0 = DVector::from_column_slice(y0);
        if !self.events.is_empty() {
            self.times = times.to_vec();
        }
        self.residual = residual;
        self.correction = residual;
        self
    }

    /// The state `y` at `t` as the phase before event 0 carries it (the last one: the shooting
    /// residual's return state, event 0's map being the identity where events pass each other):
    /// its stuck DOFs on their obstacles, its massless DOFs condensed from the massive ones (the
    /// phase's flow over no time). A massless DOF's velocity jumps where its rigid contact
    /// closes (the mass's when free, the obstacle's when stuck), so this state changes with the
    /// contacts closed before event 0.
    pub fn section_state(&self, y: &[f64], t: f64) -> Vec<f64> {
        let before = self.phases.last().expect("one phase at least");
        before.flow(t, &DVector::from_column_slice(y), t).as_slice().to_vec()
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
        if !self.identity_saltation() {
            return None;
        }
        let n2 = 2 * self.model.n();
        let ne = self.events.len();
        if ne > 0 && self.massive_reducible() {
            let spans: Vec<f64> = (0..ne).map(|e| self.end_of(e) - self.times[e]).collect();
            return Some(self.massive_transition(&spans));
        }
        let mut m = DMatrix::identity(n2, n2);
        for e in 0..ne.max(1) {
            let span = if ne == 0 { self.period } else { self.end_of(e) - self.times[e] };
            m = self.phases[e].transition(&self.phases[e].exp(span)) * m;
        }
        Some(m)
    }

    /// Every event's saltation matrix is the identity: compliant switches (see
    /// [`Self::flow_product`]), and rigid contacts on massless DOFs closing and releasing. Such a
    /// contact's force is zero at both (clearance 0 when it closes, force 0 when it releases), so
    /// the condensed massless DOFs are the same either side and the massive vector field is
    /// continuous. An impact on a massive DOF resets velocities (not the identity).
    pub(super) fn identity_saltation(&self) -> bool {
        let massless = |i: usize| self.model.contact_is_massless(&self.model.contacts[i]);
        let events = self.events.iter().all(|e| match e.kind {
            EventKind::On | EventKind::Off => true,
            EventKind::Impact { .. } | EventKind::Release => massless(e.contact),
        });
        events && self.phases.iter().all(|p| p.stuck_contacts().all(massless))
    }

    /// The time phase `e` ends (the next event's, event 0's a period later).
    fn end_of(&self, e: usize) -> f64 {
        if e + 1 < self.events.len() { self.times[e + 1] } else { self.times[0] + self.period }
    }

    /// The period sampled phase by phase, each phase's samples equally spaced from its start
    /// ([`super::phase::Phase::samples`]: one exponential e^{Ah} per phase, then a
    /// matrix-vector product per sample), with each phase's state at its end (before the next
    /// event), so that every interval between samples lies in one phase.
    fn sampled(&self) -> Sampled {
        let ne = self.events.len();
        let mut out = Sampled { samples: Vec::new(), states: Vec::new(), ends: Vec::new() };
        for e in 0..ne.max(1) {
            let (a, b, h, count) = self.sample_grid(e);
            let states = self.phases[e].samples(a, &self.after[e], h, count);
            out.samples.extend((0..count).map(|j| (a + h * j as f64, e)));
            // The phase's end flowed from its last sample, as the last interval is.
            out.ends.push(self.phases[e].flow(a + h * (count - 1) as f64, &states[count - 1], b));
            out.states.extend(states);
        }
        out
    }

    /// Phase `e`'s samples for [`Self::sampled`]: its start and end, the step and the count.
    fn sample_grid(&self, e: usize) -> (f64, f64, f64, usize) {
        let (a, b) = (self.times[e], self.end_of(e));
        let count = (((b - a) * self.phases[e].speed_hint().max(self.model.frequency) * SAMPLES_PER_RADIAN).ceil() as usize).max(MIN_SAMPLES);
        (a, b, (b - a) / count as f64, count)
    }

    /// Each compliant contact's smallest local minimum of its signed clearance between its own
    /// events ([`Touch`]). On the sampled period (cyclic): each interval between samples where
    /// the slope turns from negative to non-negative holds a minimum; its cubic Hermite estimate
    /// (values and slopes at both ends) ranks it, and those within [`REFINE_BAND`] of the
    /// contact's range of the best estimate are refined by Newton on the slope ([`refine`]).
    /// A contact's own events, where its signed clearance comes down to 0 from both sides, are
    /// not minima: each interval is taken in its phase up to the phase's end (left limit).
    pub fn touches(&self) -> Vec<Touch> {
        if !self.has_touches() {
            return Vec::new();
        }
        self.touches_in(&self.sampled())
    }

    /// Whether a contact may have a touch: a compliant one (a rigid contact's margins are
    /// `rigid_margin`'s). Without one no state need be sampled for them.
    fn has_touches(&self) -> bool {
        self.model.contacts.iter().any(|c| !c.is_rigid())
    }

    /// [`Self::touches`] and [`Self::amplitudes`] from one sampling of the period (a branch
    /// point's: the sampling was most of the exact walk's time, and each point took two).
    pub fn touches_and_amplitudes(&self, map: Option<&OutputMap>, dofs: &[usize]) -> (Vec<Touch>, Vec<Option<f64>>) {
        // Without touches the amplitudes come in closed form (the sampled states were a fifth of the rigid blade's walk).
        if !self.has_touches() {
            return (Vec::new(), self.amplitudes(map, dofs));
        }
        let sampled = self.sampled();
        (self.touches_in(&sampled), self.amplitudes_in(&sampled, map, dofs))
    }

    fn touches_in(&self, sampled: &Sampled) -> Vec<Touch> {
        let mut out = Vec::new();
        for (i, c) in self.model.contacts.iter().enumerate() {
            if c.is_rigid() {
                continue;
            }
            let n = self.model.n();
            let sign = |e: usize| if self.phases[e].closed(i) { -1.0 } else { 1.0 };
            // Signed clearance, its slope and curvature in state `y` at `t` of phase `e`.
            let jet = |e: usize, y: &DVector<f64>, t: f64, curvature: bool| {
                let s = sign(e);
                let value = s * self.clearance(i, y, t);
                let slope = s * (self.gap(i, t, 1) - c.along(|d| y[n + d]));
                let bend = if curvature {
                    let a = self.phases[e].acceleration(y, t);
                    s * (self.gap(i, t, 2) - c.along(|d| a[d]))
                } else {
                    0.0
                };
                (value, slope, bend)
            };
            let own = |j: usize| {
                let (t, e) = sampled.samples[j];
                !self.events.is_empty() && t == self.times[e] && self.events[e].contact == i
            };
            let best = sampled.smallest(self, &|e, y, t| jet(e, y, t, false), &|e, y, t| jet(e, y, t, true), &own, false);
            out.extend(best.map(|(value, time)| {
                let (e, tt) = self.locate(time);
                Touch { phase: e, contact: i, value, time: tt, closed: self.phases[e].closed(i) }
            }));
        }
        out
    }

    /// The fraction of the period each contact is closed (compliant) or stuck (rigid): the
    /// phases' exact durations.
    pub fn contact_fractions(&self) -> Vec<f64> {
        let m = self.model.contacts.len();
        let mut out = vec![0.0; m];
        for e in 0..self.events.len().max(1) {
            let span = if self.events.is_empty() { self.period } else { self.end_of(e) - self.times[e] };
            let ph = &self.phases[e];
            for (i, share) in out.iter_mut().enumerate() {
                if ph.closed(i) || ph.stuck_contacts().any(|k| k == i) {
                    *share += span / self.period;
                }
            }
        }
        out
    }

    /// Each contact's largest force at `samples` equally spaced instants of the period (impulses
    /// not counted: [`Self::event_records`] has them).
    pub fn max_forces(&self, samples: usize) -> Vec<f64> {
        let mut out = vec![0.0f64; self.model.contacts.len()];
        for j in 0..samples {
            let t = self.times[0] + self.period * j as f64 / samples as f64;
            for (m, f) in out.iter_mut().zip(self.contact_forces(t)) {
                *m = m.max(f);
            }
        }
        out
    }

    /// Peak-to-peak / 2 of user DOF `dof`'s displacement over the period (through the output
    /// map when there is one): its extrema located as [`Self::touches`] locates minima.
    pub fn amplitude(&self, map: Option<&OutputMap>, dof: usize) -> Option<f64> {
        self.amplitudes(map, &[dof])[0]
    }

    /// [`Self::amplitude`] of each of `dofs`, from one sampling of the period.
    pub fn amplitudes(&self, map: Option<&OutputMap>, dofs: &[usize]) -> Vec<Option<f64>> {
        if let Some(out) = self.output_amplitudes(map, dofs) {
            return out;
        }
        self.amplitudes_in(&self.sampled(), map, dofs)
    }

    fn amplitudes_in(&self, sampled: &Sampled, map: Option<&OutputMap>, dofs: &[usize]) -> Vec<Option<f64>> {
        let n = self.model.n();
        let one = |dof: usize| {
            user_value(map, dof, &self.y0, 0, n)?;
            let jet = |e: usize, y: &DVector<f64>, t: f64, sign: f64, curvature: bool| {
                let value = user_value(map, dof, y, 0, n).unwrap_or(0.0);
                let slope = user_value(map, dof, y, n, n).unwrap_or(0.0);
                let bend = if curvature { user_value(map, dof, &self.phases[e].acceleration(y, t), 0, n).unwrap_or(0.0) } else { 0.0 };
                (sign * value, sign * slope, sign * bend)
            };
            let lo = sampled.smallest(self, &|e, y, t| jet(e, y, t, 1.0, false), &|e, y, t| jet(e, y, t, 1.0, true), &|_| false, true)?.0;
            let hi = -sampled.smallest(self, &|e, y, t| jet(e, y, t, -1.0, false), &|e, y, t| jet(e, y, t, -1.0, true), &|_| false, true)?.0;
            Some(0.5 * (hi - lo))
        };
        dofs.iter().map(|&d| one(d)).collect()
    }
}

/// A signal's value, slope and curvature at a state and time of a phase.
type Jet<'a> = &'a dyn Fn(usize, &DVector<f64>, f64) -> (f64, f64, f64);

/// Minima whose Hermite estimate lies within this fraction of the signal's sampled range of the
/// best estimate are refined: the cubic Hermite error at 1/[`SAMPLES_PER_RADIAN`] radian of the
/// fastest motion is (ωh)⁴/384 ≈ 1.6e-4 of that motion's amplitude (Burden & Faires §3.4), so the
/// true smallest minimum is among them.
const REFINE_BAND: f64 = 1e-2;

/// The sampled period ([`PolishedOrbit::sampled`]).
struct Sampled {
    /// (time, phase) of each sample, and its state.
    samples: Vec<(f64, usize)>,
    states: Vec<DVector<f64>>,
    /// Each phase's state at its end, flowed in the phase (before the next event).
    ends: Vec<DVector<f64>>,
}

impl Sampled {
    /// The smallest value of a signal over the period, and its time: the smallest interior
    /// minimum between samples (refined), a kink at a phase start where the slope jumps from
    /// negative to non-negative (an impact elsewhere) unless `own` says the sample is the
    /// signal's own event, and the samples themselves when `samples_count`. `quick` gives value
    /// and slope, `full` also the curvature (for Newton).
    fn smallest(&self, orbit: &PolishedOrbit, quick: Jet, full: Jet, own: &dyn Fn(usize) -> bool, samples_count: bool) -> Option<(f64, f64)> {
        // Value and slope once per sample and per phase end (each is an interval's start and the
        // interval before's end, and a phase's end also feeds the kink test after it).
        let at: Vec<(f64, f64)> = self.samples.iter().zip(&self.states).map(|(&(t, e), y)| quick(e, y, t)).map(|(v, d, _)| (v, d)).collect();
        let at_end: Vec<(f64, f64)> = self.ends.iter().enumerate().map(|(e, y)| quick(e, y, orbit.end_of(e))).map(|(v, d, _)| (v, d)).collect();
        let len = self.samples.len();
        let phases = at_end.len();
        let mut best: Option<(f64, f64)> = None;
        let keep = |best: &mut Option<(f64, f64)>, v: f64, t: f64| {
            if best.is_none_or(|b| v < b.0) {
                *best = Some((v, t));
            }
        };
        let (mut vmin, mut vmax) = (f64::MAX, f64::MIN);
        // Per interval: (Hermite estimate, its place in [0, 1], start sample, end time).
        let mut candidates: Vec<(f64, f64, usize, f64)> = Vec::new();
        for j in 0..len {
            let (t0, e) = self.samples[j];
            let (v0, d0) = at[j];
            let (t1, (v1, d1)) = match self.samples.get(j + 1) {
                Some(&(t1, f)) if f == e => (t1, at[j + 1]),
                _ => (orbit.end_of(e), at_end[e]),
            };
            vmin = vmin.min(v0).min(v1);
            vmax = vmax.max(v0).max(v1);
            // A sample counts when asked, or as a kink at a phase start (slope − before, + after).
            let kink = (j == 0 || self.samples[j - 1].1 != e) && d0 >= 0.0 && !own(j) && at_end[(e + phases - 1) % phases].1 < 0.0;
            if samples_count || kink {
                keep(&mut best, v0, t0);
            }
            if d0 < 0.0 && d1 >= 0.0 {
                let (s, estimate) = hermite_min(v0, d0, v1, d1, t1 - t0);
                candidates.push((estimate, s, j, t1));
            }
        }
        let band = REFINE_BAND * (vmax - vmin);
        let floor = candidates.iter().map(|c| c.0).fold(f64::MAX, f64::min);
        for &(estimate, s, j, t1) in &candidates {
            if estimate > floor + band || best.is_some_and(|b| estimate > b.0 + band) {
                continue;
            }
            let (t0, e) = self.samples[j];
            let (t, v) = refine(t0, t1, t0 + s * (t1 - t0), &|t| full(e, &orbit.phases[e].flow(t0, &self.states[j], t), t));
            keep(&mut best, v, t);
        }
        best
    }
}

/// The minimum of the cubic Hermite interpolant on [0, h] with values v0, v1 and slopes
/// d0 < 0 ≤ d1 at its ends (its slope's root by bisection): (its place in [0, 1], its value).
fn hermite_min(v0: f64, d0: f64, v1: f64, d1: f64, h: f64) -> (f64, f64) {
    // p(s) = v0 + b s + c s² + d s³ on s ∈ [0, 1].
    let (b, c, d) = (h * d0, 3.0 * (v1 - v0) - h * (2.0 * d0 + d1), 2.0 * (v0 - v1) + h * (d0 + d1));
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..50 {
        let s = 0.5 * (lo + hi);
        if b + 2.0 * c * s + 3.0 * d * s * s < 0.0 {
            lo = s;
        } else {
            hi = s;
        }
    }
    let s = 0.5 * (lo + hi);
    (s, v0 + s * (b + s * (c + s * d)))
}

/// The minimum of a signal on [lo, hi], whose slope is negative at lo and non-negative at hi:
/// Newton on the slope from `start` (the Hermite estimate's place), a bisection step where
/// Newton leaves the bracket or the curvature is not positive. (time, value).
fn refine(mut lo: f64, mut hi: f64, start: f64, jet: &dyn Fn(f64) -> (f64, f64, f64)) -> (f64, f64) {
    let (mut t, mut last) = (start, jet(start));
    for _ in 0..60 {
        let (_, slope, bend) = last;
        if slope < 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let newton = t - slope / bend;
        let next = if bend > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        let done = (next - t).abs() <= 1e-13 * (1.0 + t.abs()) || hi - lo <= 1e-13 * (1.0 + hi.abs());
        t = next;
        last = jet(t);
        if done {
            break;
        }
    }
    (t, last.0)
}
