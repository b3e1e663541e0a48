//! The shooting equations of an event sequence, their Newton solve, the monodromy, and the
//! polished orbit's values at any time.
use super::PolishFailure;
use super::events::{self, Event, EventKind};
use super::phase::{self, Phase};
use crate::model::Model;
use crate::periodic::{OutputMap, PeriodicProblem};
use crate::response::{EventRecord, Response};
use nalgebra::{DMatrix, DVector};

const MAX_ITERATIONS: usize = 40;

/// One period flowed: the state back at event 0, the event conditions, the state after each
/// event and each event's impulse.
struct Shot {
    end: DVector<f64>,
    conditions: Vec<f64>,
    after: Vec<DVector<f64>>,
    impulses: Vec<f64>,
}

/// A polished orbit's definition, from which [`PolishedOrbit::rebuild`] makes it again (the FMU
/// keeps it in a serialized FMU state).
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitParts {
    pub events: Vec<Event>,
    pub always: Vec<usize>,
    pub y0: Vec<f64>,
}

/// A periodic orbit made of exact linear phases between events.
#[derive(Clone, Debug)]
pub struct PolishedOrbit {
    pub(super) model: Model,
    pub(super) period: f64,
    pub(super) events: Vec<Event>,
    /// Contacts closed all period long (no event).
    pub(super) always: Vec<usize>,
    /// Event times, increasing, times[0] ∈ [0, T) (a single 0 when there is no event).
    pub(super) times: Vec<f64>,
    /// The phase after each event (phases[e] runs from times[e] to times[e+1]).
    pub(super) phases: Vec<Phase>,
    /// Full state [x; v] just after event 0.
    pub(super) y0: DVector<f64>,
    /// State just after each event, and the impulse of each (0 but at impacts).
    pub(super) after: Vec<DVector<f64>>,
    pub(super) impulses: Vec<f64>,
    pub(super) gaps: Vec<phase::Harmonics>,
    pub(super) iterations: usize,
    pub(super) residual: f64,
    pub(super) correction: f64,
    /// Made at its first use where the saltations are the identity (the phases' product: a
    /// sweep's point never asks for it), else by [`Self::finish`].
    monodromy: std::sync::OnceLock<DMatrix<f64>>,
}

impl PolishedOrbit {
    pub(super) fn solve(model: &Model, evs: Vec<Event>, always: &[usize]) -> Result<Self, PolishFailure> {
        let clock = std::time::Instant::now();
        let mut o = Self::new(model, evs, always)?;
        super::profile("building the phases", clock);
        o.newton()?;
        Ok(o)
    }

    /// The orbit of [`Self::parts`] again, for `model` (the model it was polished on): the
    /// phases are rebuilt and one period is flowed, without Newton.
    pub fn rebuild(model: &Model, parts: &OrbitParts) -> Result<Self, PolishFailure> {
        let fail = |w: &str| PolishFailure(format!("the stored polished orbit does not fit this model: {w}"));
        let (m, n) = (model.contacts.len(), model.n());
        if parts.y0.len() != 2 * n || parts.events.iter().map(|e| e.contact).chain(parts.always.iter().copied()).any(|i| i >= m) {
            return Err(fail("its state or a contact index is out of range"));
        }
        let mut o = Self::new(model, parts.events.clone(), &parts.always)?;
        o.y0 = DVector::from_column_slice(&parts.y0);
        if !o.ordered(&DVector::from_iterator(2 * n + o.events.len(), o.y0.iter().copied().chain(o.times.iter().copied().take(o.events.len())))) {
            return Err(fail("its event times are not increasing within one period"));
        }
        o.finish().map_err(|e| fail(&e.0))?;
        Ok(o)
    }

    /// What [`Self::rebuild`] needs: the events with their converged times (as `seed`), the
    /// contacts closed all period long, and the state just after event 0.
    pub fn parts(&self) -> OrbitParts {
        let events = self.events.iter().zip(&self.times).map(|(e, &t)| Event { seed: t, ..*e }).collect();
        OrbitParts { events, always: self.always.clone(), y0: self.y0.iter().copied().collect() }
    }

    pub(super) fn new(model: &Model, evs: Vec<Event>, always: &[usize]) -> Result<Self, PolishFailure> {
        Self::reusing(model, evs, always, &[])
    }

    /// [`Self::new`], taking from `reuse` the phases whose contact sets it already holds.
    pub(super) fn reusing(model: &Model, evs: Vec<Event>, always: &[usize], reuse: &[Phase]) -> Result<Self, PolishFailure> {
        Self::with_phases(model, evs, always, |stuck, closed| match reuse.iter().find(|p| p.is_for(stuck, closed)) {
            Some(p) => Some(p.clone()),
            None => Phase::new(model, stuck, closed),
        })
    }

    /// [`Self::new`] with each phase (its stuck and closed contacts) made by `make`.
    pub(super) fn with_phases(
        model: &Model,
        evs: Vec<Event>,
        always: &[usize],
        mut make: impl FnMut(&[usize], &[usize]) -> Option<Phase>,
    ) -> Result<Self, PolishFailure> {
        let sets = events::phase_sets(model, &evs, always);
        let mut phases = Vec::new();
        let empty = vec![always.to_vec()];
        for set in if evs.is_empty() { &empty } else { &sets } {
            let stuck: Vec<usize> = set.iter().copied().filter(|&i| model.contacts[i].is_rigid()).collect();
            let closed: Vec<usize> = set.iter().copied().filter(|&i| !model.contacts[i].is_rigid()).collect();
            phases
                .push(make(&stuck, &closed).ok_or_else(|| PolishFailure("a phase's operator is singular at a forcing harmonic (undamped resonance)".into()))?);
        }
        // Stuck rows must stay orthonormal (phase.rs): contacts on disjoint DOFs.
        let mut dofs: Vec<usize> = model.contacts.iter().flat_map(|c| c.row.iter().map(|e| e.0)).collect();
        dofs.sort_unstable();
        if dofs.windows(2).any(|w| w[0] == w[1]) {
            return Err(PolishFailure("two contacts act on the same DOF".into()));
        }
        let gaps = (0..model.contacts.len()).map(|i| phase::gap_harmonics(model, i)).collect();
        let times = if evs.is_empty() { vec![0.0] } else { evs.iter().map(|e| e.seed).collect() };
        let n = model.n();
        Ok(PolishedOrbit {
            always: always.to_vec(),
            model: model.clone(),
            period: model.period(),
            events: evs,
            times,
            phases,
            y0: DVector::zeros(2 * n),
            after: vec![],
            impulses: vec![],
            gaps,
            iterations: 0,
            residual: f64::INFINITY,
            correction: f64::INFINITY,
            monodromy: std::sync::OnceLock::new(),
        })
    }

    /// Takes the eigendecompositions and force gradients of `other`'s phases for the phases of
    /// the same matrices (they do not depend on the frequency: one decomposition per contact set
    /// for a whole sweep).
    pub fn share_modes(&mut self, other: &PolishedOrbit) {
        for ph in &mut self.phases {
            if let Some(o) = other.phases.iter().find(|o| o.same_matrix(ph)) {
                ph.share_modes(o);
            }
        }
    }

    pub(super) fn gap(&self, i: usize, t: f64, order: u32) -> f64 {
        let w = self.model.frequency;
        self.gaps[i]
            .iter()
            .map(|(p, a)| (a[0] * num_complex::Complex64::from_polar(1.0, *p as f64 * w * t) * num_complex::Complex64::new(0.0, *p as f64 * w).powu(order)).re)
            .sum()
    }

    /// Clearance of contact `i` in state `y` at `t`: gap(t) − B_i x.
    pub(super) fn clearance(&self, i: usize, y: &DVector<f64>, t: f64) -> f64 {
        self.gap(i, t, 0) - self.model.contacts[i].along(|d| y[d])
    }

    /// Plastic impact of contact `i` at `t`, the contacts `stuck` staying on their obstacles:
    /// v⁺ = v⁻ − M⁻¹Bᵀ P with B v⁺ = ġ (src/formulation.md §5's forward increment, in one instant).
    pub(super) fn impact(&self, i: usize, stuck: &[usize], y: &DVector<f64>, t: f64) -> Option<(DVector<f64>, f64)> {
        let n = self.model.n();
        if self.model.contact_is_massless(&self.model.contacts[i]) {
            // A rigid contact on a massless DOF closes without impulse (no mass to stop): the DOF
            // follows the obstacle from here, the massive state is continuous.
            return Some((y.clone(), 0.0));
        }
        let mut set: Vec<usize> = stuck.to_vec();
        if !set.contains(&i) {
            set.push(i);
        }
        let (b, m_inv_bt, s_inv) = self.reset(&set)?;
        let v = y.rows(n, n).into_owned();
        let rhs = &b * &v - DVector::from_fn(set.len(), |r, _| self.gap(set[r], t, 1));
        let p = s_inv * rhs;
        let mut out = y.clone();
        let dv = m_inv_bt * &p;
        for d in 0..n {
            out[n + d] -= dv[d];
        }
        let k = set.iter().position(|&c| c == i).expect("pushed");
        Some((out, p[k]))
    }

    /// One period from `y0` with event times `tau`: the state after the last event (back at
    /// event 0), the event conditions, the states after each event and the impulses.
    fn shoot(&self, y0: &DVector<f64>, tau: &[f64]) -> Option<Shot> {
        self.shoot_to(y0, tau, tau[0] + self.period)
    }

    /// [`Self::shoot`] with event 0 coming back at `ret` instead of tau[0] + T.
    fn shoot_to(&self, y0: &DVector<f64>, tau: &[f64], ret: f64) -> Option<Shot> {
        let ne = self.events.len();
        if ne == 0 {
            let end = self.phases[0].flow(0.0, y0, self.period);
            return Some(Shot { end, conditions: vec![], after: vec![y0.clone()], impulses: vec![0.0] });
        }
        let (mut g, mut after, mut imp) = (vec![0.0; ne], vec![y0.clone(); ne], vec![0.0; ne]);
        let mut y = y0.clone();
        for e in 0..ne {
            let (t0, t1) = (tau[e], if e + 1 < ne { tau[e + 1] } else { ret });
            let ph = &self.phases[e];
            let ym = ph.flow(t0, &y, t1);
            let next = (e + 1) % ne;
            let ev = self.events[next];
            g[next] = match ev.kind {
                EventKind::Release => ph.stuck_forces(&ym, t1).into_iter().find(|(c, _)| *c == ev.contact)?.1,
                _ => self.clearance(ev.contact, &ym, t1),
            };
            y = match ev.kind {
                EventKind::Impact { .. } => {
                    let stuck: Vec<usize> = ph.stuck_contacts().collect();
                    let (yp, p) = self.impact(ev.contact, &stuck, &ym, t1)?;
                    imp[next] = p;
                    yp
                }
                _ => ym,
            };
            after[next] = y.clone();
        }
        Some(Shot { end: y, conditions: g, after, impulses: imp })
    }

    pub(super) fn residual_of(&self, u: &DVector<f64>) -> Option<DVector<f64>> {
        let n2 = 2 * self.model.n();
        let y0 = u.rows(0, n2).into_owned();
        let tau: Vec<f64> = u.iter().skip(n2).copied().collect();
        let tau = if tau.is_empty() { vec![0.0] } else { tau };
        let Shot { end: y, conditions: g, .. } = self.shoot(&y0, &tau)?;
        let mut r = DVector::zeros(u.len());
        r.rows_mut(0, n2).copy_from(&(y - y0));
        for (i, v) in g.iter().enumerate() {
            r[n2 + i] = *v;
        }
        Some(r)
    }

    fn jacobian(&self, u: &DVector<f64>, scale: &DVector<f64>) -> Option<DMatrix<f64>> {
        let len = u.len();
        // One variational flow of the period (continued.rs) instead of 2(2n + ne) flows: 380 of
        // 52 phases each on the real blade's massless boundary, 344 of 34 on its Craig–Bampton model.
        let n2 = 2 * self.model.n();
        if let Some((_, j)) = self.shooting_jacobian(&u.as_slice()[..n2], &u.as_slice()[n2..]) {
            return Some(j);
        }
        let mut j = DMatrix::zeros(len, len);
        for c in 0..len {
            let h = 1e-7 * scale[c];
            let (mut up, mut dn) = (u.clone(), u.clone());
            up[c] += h;
            dn[c] -= h;
            let col = (self.residual_of(&up)? - self.residual_of(&dn)?) / (2.0 * h);
            j.set_column(c, &col);
        }
        Some(j)
    }

    /// Row weights that put the residual in length units: 1 on displacements and clearances,
    /// 1/ω_d on the velocity of DOF d (ω_d = max(√(K_dd/M_dd), ω)), 1/K_dd on a release's force.
    /// In raw units the velocity of a stiff DOF (a Craig–Bampton constraint mode, a closed
    /// contact spring: ω_d ≈ 6e5 rad/s on the coarse blade) outweighs every clearance, and the
    /// line search then refuses Newton steps that are right (the coarse blade's stall).
    pub(super) fn weights(&self) -> DVector<f64> {
        let (n, s) = (self.model.n(), &self.model.structure);
        let rate = |d: usize| (s.stiffness.get(d, d) / s.mass.get(d, d)).abs().sqrt().max(self.model.frequency);
        let ne = self.events.len();
        DVector::from_fn(2 * n + ne, |i, _| match i {
            i if i < n => 1.0,
            i if i < 2 * n => 1.0 / rate(i - n),
            i => {
                let e = self.events[i - 2 * n];
                // n_iᵀ K n_i: the stiffness along the contact's normal.
                let c = &self.model.contacts[e.contact];
                let k = c.along(|a| c.along(|b| s.stiffness.get(a, b))).abs();
                if e.kind == EventKind::Release && k > 0.0 { 1.0 / k } else { 1.0 }
            }
        })
    }

    pub(super) fn ordered(&self, u: &DVector<f64>) -> bool {
        let n2 = 2 * self.model.n();
        let tau: Vec<f64> = u.iter().skip(n2).copied().collect();
        tau.windows(2).all(|w| w[0] < w[1]) && tau.last().is_none_or(|&l| l < tau[0] + self.period)
    }

    pub(super) fn newton(&mut self) -> Result<(), PolishFailure> {
        let n2 = 2 * self.model.n();
        let ne = self.events.len();
        let fail = |w: &str| PolishFailure(w.to_string());
        // Seed: the fixed point of the affine one-period map at the seeded times.
        // The map is affine in the state at fixed times: its offset from one shoot, its
        // derivative from the chained transitions (`state_map`; were 2n more shoots: 139 flows of
        // the period on the real blade, 80 % of its Newton).
        let clock = std::time::Instant::now();
        let zero = DVector::zeros(n2);
        let c = self.shoot(&zero, &self.times).ok_or_else(|| fail("the seeded event sequence cannot be flowed"))?.end;
        let phi = self.state_map(&self.times).ok_or_else(|| fail("the seeded flow failed"))?;
        let y0 = (DMatrix::identity(n2, n2) - &phi).lu().solve(&c).ok_or_else(|| fail("the seeded one-period map has a multiplier 1"))?;
        super::profile("Newton's seed", clock);
        let mut u = DVector::zeros(n2 + ne);
        u.rows_mut(0, n2).copy_from(&y0);
        for (i, &t) in self.times.iter().take(ne).enumerate() {
            u[n2 + i] = t;
        }
        let ys = y0.amax().max(1e-300);
        let scale = DVector::from_fn(n2 + ne, |i, _| if i < n2 { ys } else { self.period });
        let mut w = self.weights();
        // The merit: the max norm of the residual in length units (see `weights`; a max norm,
        // so the same whatever the events' order).
        let size = y0.component_mul(&w.rows(0, n2)).amax().max(1e-300);
        // Below this the residual is round-off of the flows (ε·‖Â τ‖ of the exponentials).
        let floor = 1e-10 * size;
        let merit = |r: &DVector<f64>, w: &DVector<f64>| r.component_mul(w).amax();
        let mut r = self.residual_of(&u).ok_or_else(|| fail("the seeded event sequence cannot be flowed"))?;
        let mut converged = false;
        for it in 0..MAX_ITERATIONS {
            let jac = self.jacobian(&u, &scale).ok_or_else(|| fail("the Jacobian could not be formed"))?;
            let du = jac.lu().solve(&(-&r)).ok_or_else(|| fail("the shooting Jacobian is singular (a grazing or degenerate event sequence)"))?;
            let mut lambda = 1.0;
            let before = merit(&r, &w);
            let (next, rn) = loop {
                let cand = &u + &du * lambda;
                if self.ordered(&cand)
                    && let Some(rc) = self.residual_of(&cand)
                    && (merit(&rc, &w) < before || merit(&rc, &w) < floor)
                {
                    break (cand, rc);
                }
                // Events of different contacts that passed each other: the same step in their new order.
                if !self.ordered(&cand)
                    && let Some((orbit, cand)) = self.reordered(&cand)
                    && orbit.ordered(&cand)
                    && let Some(rc) = orbit.residual_of(&cand)
                    && (merit(&rc, &orbit.weights()) < before || merit(&rc, &orbit.weights()) < floor)
                {
                    self.events = orbit.events;
                    self.phases = orbit.phases;
                    w = self.weights();
                    break (cand, rc);
                }
                lambda *= 0.5;
                if lambda < 1e-4 {
                    return Err(fail("Newton stalled: the LCP's event sequence does not lead to an exact orbit (events merge or reorder)"));
                }
            };
            let step = du.iter().enumerate().map(|(i, v)| (v * lambda).abs() / scale[i]).fold(0.0, f64::max);
            self.correction = du.rows(0, self.model.n()).amax() * lambda;
            // Converged: a negligible step, or the residual at round-off and no longer halving.
            let stagnant = merit(&rn, &w) < floor && merit(&rn, &w) > 0.5 * before;
            u = next;
            r = rn;
            self.iterations = it + 1;
            if step < 1e-14 || (step < 1e-11 && merit(&r, &w) < 1e-12 * size) || stagnant {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(fail(&format!("Newton did not converge in {MAX_ITERATIONS} iterations (residual {:.2e})", merit(&r, &w))));
        }
        self.residual = merit(&r, &w);
        // Times into [0, T): a shift by whole periods changes nothing.
        let shift = (u[n2.min(u.len() - 1)] / self.period).floor() * self.period;
        self.y0 = u.rows(0, n2).into_owned();
        if ne > 0 {
            self.times = u.iter().skip(n2).map(|t| t - shift).collect();
        }
        let clock = std::time::Instant::now();
        let done = self.finish();
        super::profile("the monodromy", clock);
        done
    }

    /// The states after the events, the impulses and the monodromy of the orbit at y0 and times.
    pub(super) fn finish(&mut self) -> Result<(), PolishFailure> {
        self.finish_kept(None)
    }

    /// [`Self::finish`], the monodromy from `kept` where it was flowed from this orbit's unknowns.
    pub(super) fn finish_kept(&mut self, kept: Option<super::rigid::KeptVariation>) -> Result<(), PolishFailure> {
        self.finish_states()?;
        if !self.identity_saltation() {
            let fail = |w: &str| PolishFailure(w.to_string());
            let m =
                self.event_monodromy(kept).ok_or_else(|| fail("the monodromy could not be formed (an event condition is singular in its time: grazing)"))?;
            self.monodromy = m.into();
        }
        Ok(())
    }

    /// [`Self::finish`] without the monodromy: the states after the events and the impulses.
    pub(super) fn finish_states(&mut self) -> Result<(), PolishFailure> {
        let shot = self.shoot(&self.y0, &self.times).ok_or_else(|| PolishFailure("the converged orbit cannot be flowed".to_string()))?;
        self.after = shot.after;
        self.impulses = shot.impulses;
        self.monodromy = std::sync::OnceLock::new();
        Ok(())
    }

    /// Newton iterations, final residual (max norm of periodicity and event conditions) and the
    /// last displacement correction.
    pub fn iterations(&self) -> usize {
        self.iterations
    }
    pub fn residual(&self) -> f64 {
        self.residual
    }
    pub fn correction(&self) -> f64 {
        self.correction
    }

    /// The monodromy matrix (2n×2n, state [x; v]): the derivative of the one-period map at the
    /// fixed time [`Self::section_time`] (just after the first event), the events relocated
    /// (the phases' exponentials and the events' saltation: [`Self::flow_product`], else the
    /// variational flow of `rigid.rs`). Its eigenvalues are the orbit's Floquet
    /// multipliers (a plastic impact adds zeros).
    pub fn monodromy(&self) -> &DMatrix<f64> {
        // An orbit made without it (`at_states`) forms it here, as `finish` would have.
        let made = || if self.identity_saltation() { self.flow_product() } else { self.event_monodromy(None) };
        self.monodromy.get_or_init(|| made().expect("the monodromy (an event condition singular in its time: grazing)"))
    }

    /// The period T [s].
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The section's time: the first event's (0 without events).
    pub fn section_time(&self) -> f64 {
        self.times[0]
    }

    /// Events with their times in [0, T) and impulses.
    pub fn event_records(&self) -> Vec<EventRecord> {
        self.events
            .iter()
            .zip(&self.times)
            .zip(&self.impulses)
            .map(|((e, &t), &p)| EventRecord { time: t.rem_euclid(self.period), contact: e.contact, kind: e.kind.name().into(), impulse: p })
            .collect()
    }

    /// The phase index and its start time for time `t` (any real).
    pub(super) fn locate(&self, t: f64) -> (usize, f64) {
        let t0 = self.times[0];
        let tt = t0 + (t - t0).rem_euclid(self.period);
        let e = self.times.iter().rposition(|&s| s <= tt).unwrap_or(0);
        (e, tt)
    }

    /// Full state [x; v] at `t`.
    pub fn state(&self, t: f64) -> DVector<f64> {
        let (e, tt) = self.locate(t);
        self.phases[e].flow(self.times[e], &self.after[e], tt)
    }

    /// Displacement and velocity of user DOF `dof` at `t` (through the reduction's output map
    /// when there is one); `None` for a DOF the map does not hold.
    pub fn user_state(&self, map: Option<&OutputMap>, dof: usize, t: f64) -> Option<(f64, f64)> {
        let y = self.state(t);
        let n = self.model.n();
        Some((user_value(map, dof, &y, 0, n)?, user_value(map, dof, &y, n, n)?))
    }

    /// Clearance of contact `i` at `t` (negative: a compliant contact's penetration).
    pub fn clearance_at(&self, i: usize, t: f64) -> f64 {
        let (_, tt) = self.locate(t);
        self.clearance(i, &self.state(tt), tt)
    }

    /// Time derivative of contact `i`'s clearance at `t`: gap'(t) − B_i v.
    pub fn clearance_rate(&self, i: usize, t: f64) -> f64 {
        let (_, tt) = self.locate(t);
        let y = self.state(tt);
        self.gap(i, tt, 1) - self.model.contacts[i].along(|d| y[self.model.n() + d])
    }

    /// Acceleration of every DOF at `t` (between events).
    pub fn acceleration(&self, t: f64) -> DVector<f64> {
        let (e, tt) = self.locate(t);
        self.phases[e].acceleration(&self.state(tt), tt)
    }

    /// Compressive force of contact `i` at `t`: a stuck rigid contact's force, a closed compliant
    /// contact's stiffness times penetration, else 0 (impulses are in [`Self::event_records`]).
    pub fn contact_force(&self, i: usize, t: f64) -> f64 {
        let (e, tt) = self.locate(t);
        let y = self.state(tt);
        match self.model.contacts[i].compliance {
            crate::model::Compliance::Compliant { stiffness } => stiffness * (-self.clearance(i, &y, tt)).max(0.0),
            crate::model::Compliance::Rigid => self.phases[e].stuck_forces(&y, tt).into_iter().find(|(c, _)| *c == i).map_or(0.0, |(_, z)| z),
        }
    }

    /// Every contact's [`Self::contact_force`] at `t`, from one state (and one e^{ipωt} per
    /// gap harmonic p for all contacts; the stuck forces only in a phase with stuck contacts).
    pub fn contact_forces(&self, t: f64) -> Vec<f64> {
        let (e, tt) = self.locate(t);
        let y = self.state(tt);
        let w = self.model.frequency;
        let mut turns: Vec<(u32, num_complex::Complex64)> = Vec::new();
        let mut out: Vec<f64> = (0..self.model.contacts.len())
            .map(|i| match self.model.contacts[i].compliance {
                crate::model::Compliance::Compliant { stiffness } => {
                    let gap: f64 = self.gaps[i]
                        .iter()
                        .map(|(p, a)| {
                            let turn = match turns.iter().find(|(q, _)| q == p) {
                                Some(&(_, z)) => z,
                                None => {
                                    let z = num_complex::Complex64::from_polar(1.0, *p as f64 * w * tt);
                                    turns.push((*p, z));
                                    z
                                }
                            };
                            (a[0] * turn).re
                        })
                        .sum();
                    stiffness * (self.model.contacts[i].along(|d| y[d]) - gap).max(0.0)
                }
                crate::model::Compliance::Rigid => 0.0,
            })
            .collect();
        if self.phases[e].stuck_contacts().next().is_some() {
            for (i, z) in self.phases[e].stuck_forces(&y, tt) {
                out[i] = z;
            }
        }
        out
    }

    /// Replaces `r`'s series by this orbit's at the same instants t_j: displacement, velocity and
    /// acceleration outputs, clearances, and forces (rigid: impulse per step divided by h,
    /// as the LCP reports them; compliant: the force at t_j).
    pub fn write(&self, problem: &PeriodicProblem, r: &mut Response) {
        let n = self.model.n();
        let h = r.period / r.steps as f64;
        let states: Vec<DVector<f64>> = r.time.iter().map(|&t| self.state(t)).collect();
        let accs: Vec<DVector<f64>> = if r.acceleration.is_empty() { vec![] } else { r.time.iter().map(|&t| self.acceleration(t)).collect() };
        write_kinematics(r, problem.output_map(), &states, &accs, n);
        let rigid = self.model.contacts.iter().any(|c| c.is_rigid());
        let forces = if rigid { self.all_phase_forces() } else { vec![] };
        let integrals: Vec<Vec<f64>> = if rigid { r.time.iter().map(|&t| self.force_integrals(&forces, t, t + h)).collect() } else { vec![] };
        for (i, rc) in r.contacts.iter_mut().enumerate() {
            for (j, &t) in r.time.iter().enumerate() {
                rc.gap[j] = self.clearance(i, &states[j], t);
                rc.force[j] = match self.model.contacts[i].compliance {
                    crate::model::Compliance::Rigid => integrals[j][i] / h,
                    crate::model::Compliance::Compliant { stiffness } => stiffness * (-rc.gap[j]).max(0.0),
                };
            }
            let s = problem.pairing_at(i).offset();
            let k = rc.gap.len();
            rc.paired_gap = (0..k).map(|j| rc.gap[(j + s) % k]).collect();
        }
    }
}

/// Overwrites `r`'s displacement, velocity and acceleration series, output by output, with the
/// states (x, ẋ) and accelerations of an exact orbit at `r`'s instants.
pub(super) fn write_kinematics(r: &mut Response, map: Option<&OutputMap>, states: &[DVector<f64>], accs: &[DVector<f64>], n: usize) {
    let label = |key: &str, v: &DVector<f64>, off: usize| user_value(map, key.parse().unwrap_or(usize::MAX), v, off, n).unwrap_or(f64::NAN);
    for (key, series) in r.displacement.iter_mut() {
        series.iter_mut().zip(states).for_each(|(x, y)| *x = label(key, y, 0));
    }
    for (key, series) in r.velocity.iter_mut() {
        series.iter_mut().zip(states).for_each(|(x, y)| *x = label(key, y, n));
    }
    for (key, series) in r.acceleration.iter_mut() {
        series.iter_mut().zip(accs).for_each(|(x, a)| *x = label(key, a, 0));
    }
}

/// User DOF `dof`'s value in the model vector `v` from offset `off` (displacements at 0,
/// velocities at n of an n-DOF model): the output map's row, or the model DOF itself without a map.
pub fn user_value(map: Option<&OutputMap>, dof: usize, v: &DVector<f64>, off: usize, n: usize) -> Option<f64> {
    match map {
        Some(map) => map.rows.get(&dof).map(|row| row.iter().map(|&(d, c)| c * v[off + d]).sum()),
        None => (dof < n).then(|| v[off + dof]),
    }
}

/// Two orbits are equal when their definitions are ([`PolishedOrbit::parts`]) on the same period.
impl PartialEq for PolishedOrbit {
    fn eq(&self, other: &Self) -> bool {
        self.period == other.period && self.parts() == other.parts()
    }
}
