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
use nalgebra::{DMatrix, DVector};

// The phases' part of the margin: the contacts' signals sampled and refined.
mod margin;

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

/// An orbit's rigid margins: the smallest ([`RigidMargin`]) and each part's own smallest value
/// (a contact's clearance or held force along one phase, an impact's impulse or holding force),
/// keyed by (contact, what, the phase's or event's index). A part's value is smooth in the
/// parameter between the signature's changes: the walk reads a dip below zero between two
/// points from its values at three (continuation/exact/rigid.rs).
#[derive(Clone, Debug)]
pub struct RigidMargins {
    pub least: RigidMargin,
    pub parts: Vec<MarginPart>,
}

/// One part of [`RigidMargins`].
#[derive(Clone, Debug, PartialEq)]
pub struct MarginPart {
    pub contact: usize,
    pub what: &'static str,
    /// The phase's index (a clearance, a stuck force) or the event's (an impulse, a holding force).
    pub at: usize,
    pub value: f64,
}

impl RigidMargins {
    /// Keeps the value as its part's if below it, and as the least if below that.
    fn keep(&mut self, value: f64, (contact, what, at): (usize, &'static str, usize), time: f64, event: Option<usize>) {
        match self.parts.iter_mut().find(|p| p.contact == contact && p.what == what && p.at == at) {
            Some(p) => p.value = p.value.min(value),
            None => self.parts.push(MarginPart { contact, what, at, value }),
        }
        if value < self.least.value {
            self.least = RigidMargin { value, contact, what, time, event };
        }
    }
}

impl PolishedOrbit {
    /// The smallest rigid margin of the orbit ([`RigidMargin`]); `None` without rigid contacts.
    pub fn rigid_margin(&self) -> Option<RigidMargin> {
        self.rigid_margins().map(|m| m.least)
    }

    /// The orbit's rigid margins, the smallest and each part's ([`RigidMargins`]); `None` without rigid contacts.
    pub fn rigid_margins(&self) -> Option<RigidMargins> {
        let model = &self.model;
        if !model.contacts.iter().any(|c| c.is_rigid()) {
            return None;
        }
        // The scales of verify.rs: the largest normal displacement and the largest force met.
        let xs = self.after.iter().flat_map(|y| model.contacts.iter().map(move |c| c.along(|d| y[d]).abs())).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let fs = self.force_scale();
        let least = RigidMargin { value: f64::INFINITY, contact: 0, what: "", time: 0.0, event: None };
        let mut best = RigidMargins { least, parts: Vec::new() };
        for (e, (&p, ev)) in self.impulses.iter().zip(&self.events).enumerate() {
            // A massless contact closes without impulse: its margins are its clearance and force.
            if let EventKind::Impact { stick } = ev.kind
                && !model.contact_is_massless(&model.contacts[ev.contact])
            {
                best.keep(p * model.frequency / fs, (ev.contact, "impulse of the impact", e), self.times[e], Some(e));
                if !stick {
                    // The force that would hold the contact just after a pure impact (≤ 0 for a pure impact).
                    let mut stuck: Vec<usize> = self.phases[e].stuck_contacts().collect();
                    stuck.push(ev.contact);
                    let closed: Vec<usize> = (0..model.contacts.len()).filter(|&i| self.phases[e].closed(i)).collect();
                    if let Some(hold) = Phase::new(model, &stuck, &closed) {
                        let z = hold.stuck_forces(&self.after[e], self.times[e]).into_iter().find(|(k, _)| *k == ev.contact).map_or(0.0, |(_, z)| z);
                        best.keep(-z / fs, (ev.contact, HOLD, e), self.times[e], Some(e));
                    }
                }
            }
        }
        self.phase_margins((xs, fs), &mut best);
        Some(best)
    }
}

impl PolishedOrbit {
    /// The force holding the contact of the sticking impact `e` just after it lands, over the
    /// force scale (signed: negative where the held orbit is not the true one, which lifts off),
    /// or `None` for other events and massless contacts. The test function of a sticking arc's
    /// start grazing: its zero is where the landing turns into a pure impact and a micro-flight.
    pub fn landing_force(&self, e: usize) -> Option<f64> {
        let ev = self.events.get(e)?;
        if ev.kind != (EventKind::Impact { stick: true }) || self.model.contact_is_massless(&self.model.contacts[ev.contact]) {
            return None;
        }
        let hold = self.phases[e].stuck_forces(&self.after[e], self.times[e]).into_iter().find(|(k, _)| *k == ev.contact)?.1;
        Some(hold / self.force_scale())
    }

    /// Event `e` is contact `c`'s sticking impact and the force holding c just after it is
    /// negative while rising: the true orbit lifts off there and lands again at once (a
    /// micro-flight). With a, j the free clearance's acceleration and jerk after the impact
    /// (a > 0, j < 0), its clearance ½aτ² + ⅙jτ³ comes back to zero at τ = −3a/j, having risen
    /// to (2/3)a³/j² at τ = −2a/j (Taylor at the impact): that height is the distance between the
    /// orbit held from the landing and the true one, the margin where the held force alone would
    /// read the landing force. On the coarse rigid blade at 2217.54 rad/s the landing force
    /// crosses zero at −6.2e-5 of the force scale per rad/s while rising at 29 force scales per
    /// period: a flight of 3e-9 s and a height below 1e-17 m, which no event condition resolves.
    /// (height, flight); `None` otherwise (then the landing force itself is the margin).
    fn lift_off(&self, e: usize, c: usize) -> Option<(f64, f64)> {
        let ev = self.events.get(e)?;
        if ev.contact != c || ev.kind != (EventKind::Impact { stick: true }) || self.model.contact_is_massless(&self.model.contacts[c]) {
            return None;
        }
        let ph = &self.phases[e];
        let (t0, y0) = (self.times[e], &self.after[e]);
        let hold = ph.stuck_forces(y0, t0).into_iter().find(|(k, _)| *k == c)?.1;
        if hold >= 0.0 {
            return None;
        }
        let stuck: Vec<usize> = ph.stuck_contacts().filter(|&i| i != c).collect();
        let closed: Vec<usize> = (0..self.model.contacts.len()).filter(|&i| i != c && ph.closed(i)).collect();
        let ne = self.events.len();
        let before = &self.phases[(e + ne - 1) % ne];
        let built;
        let free = if before.is_for(&stuck, &closed) {
            before
        } else {
            built = Phase::new(&self.model, &stuck, &closed)?;
            &built
        };
        let accel = |y: &DVector<f64>, t: f64| {
            let acc = free.acceleration(y, t);
            self.gap(c, t, 2) - self.model.contacts[c].along(|d| acc[d])
        };
        let a = accel(y0, t0);
        let h = 1e-8 * self.period;
        let j = (accel(&free.flow(t0, y0, t0 + h), t0 + h) - a) / h;
        (a > 0.0 && j < 0.0).then(|| (2.0 / 3.0 * a.powi(3) / (j * j), -3.0 * a / j))
    }

    /// The flight after event `e` (a plastic impact of a rigid contact c, after which c's clearance
    /// and its rate are zero) if c were left free there: the first time Δ ∈ (0, `horizon`] at which
    /// c's clearance on the flow with c free comes back to zero from above, or `None`. Where the
    /// force holding c after the impact is just negative (a sticking arc's start grazing) the
    /// clearance is ½aΔ² + ⅙jΔ³ + (1/24)sΔ⁴ (a, j, s its acceleration, jerk and snap, Taylor at
    /// the impact), whose return Δ ≈ −3a/j grows like √(12a/|s|) where j ≈ 0: found here on the
    /// exact flow, not from the expansion (its terms cancel to round-off at small Δ). Samples at
    /// Δ doubling from 1e-12 of the period up to a quarter of the phase's fastest period, then
    /// four samples per radian of it, the crossing refined by bisection.
    pub fn free_return(&self, e: usize, horizon: f64) -> Option<f64> {
        let c = self.events.get(e)?.contact;
        let ph = &self.phases[e];
        let stuck: Vec<usize> = ph.stuck_contacts().filter(|&i| i != c).collect();
        let closed: Vec<usize> = (0..self.model.contacts.len()).filter(|&i| i != c && ph.closed(i)).collect();
        let free = Phase::new(&self.model, &stuck, &closed)?;
        let (t0, y0) = (self.times[e], &self.after[e]);
        let g = |d: f64| self.clearance(c, &free.flow(t0, y0, t0 + d), t0 + d);
        let fast = 0.25 / free.speed_hint().max(self.model.frequency);
        let mut steps = Vec::new();
        let mut d = 1e-12 * self.period;
        while d < fast.min(horizon) {
            steps.push(d);
            d *= 2.0;
        }
        let mut d = fast;
        while d <= horizon {
            steps.push(d);
            d += fast;
        }
        // Above the clearance's round-off (the state's scale times 1e-13) counts as open.
        let floor = 1e-13 * self.model.contacts[c].along(|i| y0[i]).abs().max(f64::MIN_POSITIVE);
        let mut open: Option<f64> = None;
        for &d in &steps {
            let v = g(d);
            match open {
                None if v > floor => open = Some(d),
                Some(a) if v < 0.0 => {
                    let (mut lo, mut hi) = (a, d);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if g(mid) > 0.0 { lo = mid } else { hi = mid }
                    }
                    return Some(0.5 * (lo + hi));
                }
                Some(_) if v > 0.0 => open = Some(d),
                _ => {}
            }
        }
        None
    }
}

/// One period flowed with its first-order variation: the state after event 0's return, the
/// event conditions, and their derivatives by the columns (y0, τ_0 as phase 0's start,
/// τ_1 … τ_{ne−1}, the return time of event 0) (2n + ne + 1 columns).
pub(super) struct Variation {
    pub end: DVector<f64>,
    pub conditions: DVector<f64>,
    pub d_end: DMatrix<f64>,
    pub d_conditions: DMatrix<f64>,
}

/// A period's [`Variation`] kept with what it was flowed from (state, event times, return):
/// a shooting Jacobian's, for the monodromy of the orbit placed at the same unknowns.
pub struct KeptVariation {
    pub(super) start: DVector<f64>,
    pub(super) tau: Vec<f64>,
    pub(super) ret: f64,
    pub(super) v: Variation,
}

/// A plastic impact's velocity reset (src/formulation.md §5 in one instant) on the contacts `set`
/// (the stuck ones and the impacting one): v⁺ = v⁻ − W (B v⁻ − ġ_set(t)), W = M⁻¹Bᵀ(BM⁻¹Bᵀ)⁻¹,
/// the impulses (BM⁻¹Bᵀ)⁻¹(B v⁻ − ġ). (B, M⁻¹Bᵀ, (BM⁻¹Bᵀ)⁻¹); `None` with a singular M or BM⁻¹Bᵀ.
pub(super) type Reset = (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>);

impl PolishedOrbit {
    /// The derivative of the one-period shoot's end state by its start state at fixed event times
    /// `tau` (the map is affine): the phases' transitions ([`Phase::transition_times`]) chained
    /// through the linear part of each plastic impact's velocity reset, dv⁺ = (I − W B) dv⁻
    /// (src/formulation.md §5; [`Self::variation`]'s state columns).
    pub(super) fn state_map(&self, tau: &[f64]) -> Option<DMatrix<f64>> {
        let (n, ne) = (self.model.n(), self.events.len());
        if ne > 0 && self.massive_reducible() {
            let spans: Vec<f64> = (0..ne).map(|e| if e + 1 < ne { tau[e + 1] - tau[e] } else { tau[0] + self.period - tau[e] }).collect();
            let map = self.massive_transition(&spans);
            return map.iter().all(|v| v.is_finite()).then_some(map);
        }
        let mut dy = DMatrix::identity(2 * n, 2 * n);
        for e in 0..ne.max(1) {
            let ph = &self.phases[e];
            let span = if ne == 0 {
                self.period
            } else if e + 1 < ne {
                tau[e + 1] - tau[e]
            } else {
                tau[0] + self.period - tau[e]
            };
            dy = ph.transition_times(&ph.exp(span), &dy);
            let Some(ev) = self.events.get((e + 1) % ne.max(1)) else { break };
            if matches!(ev.kind, EventKind::Impact { .. }) && !self.model.contact_is_massless(&self.model.contacts[ev.contact]) {
                let mut set: Vec<usize> = ph.stuck_contacts().collect();
                if !set.contains(&ev.contact) {
                    set.push(ev.contact);
                }
                let (b, m_inv_bt, s_inv) = self.reset(&set)?;
                let dv = dy.rows(n, n).into_owned();
                let jump = m_inv_bt * (s_inv * (&b * &dv));
                dy.rows_mut(n, n).copy_from(&(dv - jump));
            }
        }
        dy.iter().all(|v| v.is_finite()).then_some(dy)
    }

    pub(super) fn reset(&self, set: &[usize]) -> Option<Reset> {
        let n = self.model.n();
        // The phases' M is the model's (phase.rs): its inverse made once for them all.
        let m_inv = self.phases[0].mass_inverse()?;
        let b = DMatrix::from_fn(set.len(), n, |r, d| self.model.contacts[set[r]].row.iter().find(|e| e.0 == d).map_or(0.0, |e| e.1));
        let m_inv_bt = m_inv * b.transpose();
        let s_inv = (&b * &m_inv_bt).try_inverse()?;
        Some((b, m_inv_bt, s_inv))
    }

    /// [`Self::shoot_to`] with its variation (the variational equations of ẏ = A y + b(t) between
    /// events, Hairer, Nørsett & Wanner I, §I.14: ∂y(t₁)/∂y(t₀) = Φ, ∂y(t₁)/∂t₀ = −Φ f(t₀, y(t₀)),
    /// ∂y(t₁)/∂t₁ = f(t₁, y(t₁)), Φ the phase's transition, which drops the stuck and massless
    /// DOFs; chained through each event's state map: the identity at compliant switches,
    /// releases and massless closings, the affine velocity reset of [`Self::reset`] at a plastic
    /// impact, whose time dependence enters through ġ(t)). With the event times left free this is
    /// the saltation product of Leine & Nijmeijer, "Dynamics and Bifurcations of Non-Smooth
    /// Mechanical Systems", §7.1. `None` where a flow or a reset fails.
    pub(super) fn variation(&self, y0: &DVector<f64>, tau: &[f64], ret: f64) -> Option<Variation> {
        let (n, ne) = (self.model.n(), self.events.len());
        // Massless DOFs: carried in the massive state (massive.rs), d = 40 rows on the real blade.
        if ne > 0 && self.massive_reducible() {
            return self.massive_variation(y0, tau, ret);
        }
        let (n2, cols) = (2 * n, 2 * n + ne + 1);
        let field = |e: usize, y: &DVector<f64>, t: f64| self.vector_field(e, y, t);
        let mut y = y0.clone();
        let mut dy = DMatrix::identity(n2, cols);
        let (mut g, mut dg) = (DVector::zeros(ne), DMatrix::zeros(ne, cols));
        for e in 0..ne.max(1) {
            let ph = &self.phases[e];
            let (t0, t1) = if ne == 0 { (0.0, self.period) } else { (tau[e], if e + 1 < ne { tau[e + 1] } else { ret }) };
            let ex = ph.exp(t1 - t0);
            let ym = ph.flow_with(&ex, t0, &y, t1);
            dy = ph.transition_times(&ex, &dy);
            if ne == 0 {
                y = ym;
                break;
            }
            let (next, end_col) = ((e + 1) % ne, if e + 1 < ne { n2 + e + 1 } else { n2 + ne });
            let f0 = ph.transition_times(&ex, &DMatrix::from_column_slice(n2, 1, field(e, &y, t0).as_slice())).column(0).into_owned();
            let f1 = field(e, &ym, t1);
            for r in 0..n2 {
                dy[(r, n2 + e)] -= f0[r];
                dy[(r, end_col)] += f1[r];
            }
            let ev = self.events[next];
            let c = ev.contact;
            if ev.kind == EventKind::Release {
                // The held force z(y, t) is affine in y: its y-gradient is the phase's
                // (`stuck_force_gradient`).
                let row = ph.stuck_contacts().position(|k| k == c)?;
                let (z, rate) = self.held_force(e, c, &ym, t1)?;
                g[next] = z;
                dg.row_mut(next).copy_from(&(ph.stuck_force_gradient().row(row) * &dy));
                dg[(next, end_col)] += rate;
            } else {
                g[next] = self.clearance(c, &ym, t1);
                for col in 0..cols {
                    dg[(next, col)] = -self.model.contacts[c].along(|d| dy[(d, col)]);
                }
                dg[(next, end_col)] += self.gap(c, t1, 1);
            }
            y = match ev.kind {
                EventKind::Impact { .. } if !self.model.contact_is_massless(&self.model.contacts[c]) => {
                    let mut set: Vec<usize> = ph.stuck_contacts().collect();
                    if !set.contains(&c) {
                        set.push(c);
                    }
                    let (b, m_inv_bt, s_inv) = self.reset(&set)?;
                    // v⁺ = v⁻ − W (B v⁻ − ġ(t)): dv⁺ = (I − W B) dv⁻ + W g̈(t) dt.
                    let w = m_inv_bt * s_inv;
                    let dv = dy.rows(n, n).into_owned();
                    let jump = &w * (&b * &dv);
                    dy.rows_mut(n, n).copy_from(&(dv - jump));
                    let gdd = DVector::from_iterator(set.len(), set.iter().map(|&k| self.gap(k, t1, 2)));
                    let wg = &w * gdd;
                    for r in 0..n {
                        dy[(n + r, end_col)] += wg[r];
                    }
                    let v = ym.rows(n, n).into_owned();
                    let gd = DVector::from_iterator(set.len(), set.iter().map(|&k| self.gap(k, t1, 1)));
                    let mut out = ym;
                    let v_new = &v - &w * (&b * &v - gd);
                    out.rows_mut(n, n).copy_from(&v_new);
                    out
                }
                _ => ym,
            };
        }
        let all = y.iter().chain(g.iter()).chain(dy.iter()).chain(dg.iter()).all(|v| v.is_finite());
        all.then_some(Variation { end: y, conditions: g, d_end: dy, d_conditions: dg })
    }

    /// Stuck contact `c`'s force in phase `e`, state `y`, at `t`, and its explicit t-derivative by
    /// central differences (the variation's release condition).
    pub(super) fn held_force(&self, e: usize, c: usize, y: &DVector<f64>, t: f64) -> Option<(f64, f64)> {
        let z = |t: f64| self.phases[e].stuck_forces(y, t).into_iter().find(|(k, _)| *k == c).map(|(_, z)| z);
        let h = 1e-7 * self.period;
        Some((z(t)?, (z(t + h)? - z(t - h)?) / (2.0 * h)))
    }

    /// ẏ = [v; a] of phase `e` in state `y` at `t` (the variation's time columns).
    pub(super) fn vector_field(&self, e: usize, y: &DVector<f64>, t: f64) -> DVector<f64> {
        let n = self.model.n();
        let mut f = DVector::zeros(2 * n);
        f.rows_mut(0, n).copy_from(&y.rows(n, n));
        f.rows_mut(n, n).copy_from(&self.phases[e].acceleration(y, t));
        f
    }

    /// The monodromy of a solved orbit with events whose state maps are not the identity: the
    /// derivative of the one-period map at the fixed time s = times[0], z ↦ y(s + T), its events
    /// relocated (with w = (τ_1 … τ_{ne−1}, event 0's return) and G(z, w) = 0 the event
    /// conditions: dy/dz = Y_z − Y_w G_w⁻¹ G_z) from [`Self::variation`]. `None` where G_w is
    /// singular (an event condition tangent in its time: a grazing).
    pub(super) fn event_monodromy(&self, kept: Option<KeptVariation>) -> Option<DMatrix<f64>> {
        let (n2, ne) = (2 * self.model.n(), self.events.len());
        let (s, t) = (self.times[0], self.period);
        let bits = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        let v = match kept {
            // The Jacobian's variation from the same unknowns: the one flowed here, bit for bit.
            Some(k) if bits(k.start.as_slice(), self.y0.as_slice()) && bits(&k.tau, &self.times) && k.ret.to_bits() == (s + t).to_bits() => k.v,
            _ => self.variation(&self.y0, &self.times, s + t)?,
        };
        if ne == 0 {
            return Some(v.d_end.columns(0, n2).into_owned());
        }
        // Past the return, phase 0 runs on to s + T: a flow of zero length (its projection) whose
        // start moves with the return time.
        let ph = &self.phases[0];
        let proj = ph.transition(&ph.exp(0.0));
        let mut f = DVector::zeros(n2);
        let n = n2 / 2;
        f.rows_mut(0, n).copy_from(&v.end.rows(n, n));
        f.rows_mut(n, n).copy_from(&ph.acceleration(&v.end, s + t));
        let y_z = &proj * v.d_end.columns(0, n2);
        let mut y_w = &proj * v.d_end.columns(n2 + 1, ne);
        let back = &proj * f;
        for r in 0..n2 {
            y_w[(r, ne - 1)] -= back[r];
        }
        let g_z = v.d_conditions.columns(0, n2).into_owned();
        let g_w = v.d_conditions.columns(n2 + 1, ne).into_owned();
        let m = y_z - y_w * g_w.lu().solve(&g_z)?;
        m.iter().all(|x| x.is_finite()).then_some(m)
    }
}

impl PolishedOrbit {
    /// The one-period map at the section time s = times[0] by event-driven simulation: from the
    /// state `z` just after event 0 at s, each phase is flowed to the root of its next event's
    /// condition (the clearance at an impact or a compliant switch, the held force at a release;
    /// secant iteration from the orbit's own event time, to 1e-15 of the period), the event's
    /// state map applied, and the last phase flowed on to s + T. The reference for the
    /// [`Self::monodromy`] (its differences); `None` where a root is not found.
    pub fn return_map(&self, z: &[f64]) -> Option<DVector<f64>> {
        let ne = self.events.len();
        let (s, t) = (self.times[0], self.period);
        let mut y = DVector::from_column_slice(z);
        if ne == 0 {
            return Some(self.phases[0].flow(s, &y, s + t));
        }
        let mut start = s;
        for e in 0..ne {
            let ph = &self.phases[e];
            let next = (e + 1) % ne;
            let ev = self.events[next];
            let condition = |at: f64| {
                let ym = ph.flow(start, &y, at);
                match ev.kind {
                    EventKind::Release => ph.stuck_forces(&ym, at).into_iter().find(|(k, _)| *k == ev.contact).map_or(f64::NAN, |(_, z)| z),
                    _ => self.clearance(ev.contact, &ym, at),
                }
            };
            let nominal = if e + 1 < ne { self.times[e + 1] } else { s + t };
            let (mut a, mut b) = (nominal, nominal + 1e-6 * t);
            let (mut ga, mut gb) = (condition(a), condition(b));
            for _ in 0..60 {
                if gb == ga || (b - a).abs() < 1e-15 * t {
                    break;
                }
                let c = b - gb * (b - a) / (gb - ga);
                (a, ga) = (b, gb);
                b = c;
                gb = condition(b);
            }
            // 1e-11 T: the eigen flows' round-off leaves the secant's last two iterates ~1e-12 T apart
            // on the stiff coarse blade (conditions of 1e-17 m either side of the root).
            if !gb.is_finite() || (b - a).abs() > 1e-11 * t {
                return None;
            }
            let ym = ph.flow(start, &y, b);
            y = match ev.kind {
                EventKind::Impact { .. } => self.impact(ev.contact, &ph.stuck_contacts().collect::<Vec<_>>(), &ym, b)?.0,
                _ => ym,
            };
            start = b;
        }
        Some(self.phases[0].flow(start, &y, s + t))
    }
}
