//! Several friction contacts in the stick–slip polish (src/formulation.md §9, issue 25).
//!
//! A mode is one phase per contact (stick, slip ±): 3^m of them, each built when first met.
//! In a mode the slipping contacts apply ∓μN_i along b_i, the stuck Jenkins elements
//! k_t(b_iᵀx − s_i), and the stuck rigid contacts B_S hold B_Sᵀv = 0 with the reactions
//! f_S = (B_SᵀM⁻¹B_S)⁻¹B_SᵀM⁻¹ H ỹ (H ỹ: every other force), so that
//! M x'' = H ỹ − B_S f_S (the constrained dynamics, Lagrange multipliers eliminated).
//! The augmented state is [x; v; s_1 … s_m; cos pΩt, sin pΩt …; 1] (s_i: the Jenkins sliders).
//! The events of all contacts merge in time order; each changes one contact's phase. The
//! phase sequence comes from the LCP's per-contact stuck flags and force signs (as read; rigid
//! stick runs of ≤ 2 instants taken for reversals), else from an event-driven march of the exact
//! flows; Newton on the state and the event times; contacts stuck all period are pinned at the
//! LCP's slider constants (their orbit is unique only up to those, §9). Compliant unilateral
//! stops ([`stops`]) are further entries of a mode, after the friction contacts: one event list,
//! one Newton, one monodromy for both.
use super::super::PolishFailure;
use super::Slide;
use crate::model::Model;
use crate::response::EventRecord;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;
use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

pub type Mode = Vec<Slide>;

fn fail<T>(w: impl std::fmt::Display) -> Result<T, PolishFailure> {
    Err(PolishFailure(format!("stick–slip polish ({w}); the LCP's orbit is kept")))
}

/// One mode's flow matrix and each contact's friction force as a linear form of ỹ.
#[derive(Debug)]
struct ModeFlow {
    a: DMatrix<f64>,
    force: Vec<DVector<f64>>,
}

/// The exact flows of every mode, built on demand.
#[derive(Clone, Debug)]
pub struct MultiFlows {
    n: usize,
    dim: usize,
    omega: f64,
    harmonics: Vec<u32>,
    b: Vec<DVector<f64>>,
    slip: Vec<f64>,
    kt: Vec<Option<f64>>,
    /// The compliant stops, mode entries `b.len()..`.
    stops: Vec<stops::Stop>,
    minv: DMatrix<f64>,
    /// G ỹ = F(t) − Kx − Cv.
    g: DMatrix<f64>,
    cache: Rc<RefCell<HashMap<Vec<usize>, Rc<ModeFlow>>>>,
}

fn key(mode: &[Slide]) -> Vec<usize> {
    mode.iter().map(|s| s.index()).collect()
}

impl MultiFlows {
    pub fn new(model: &Model) -> Result<Self, PolishFailure> {
        let n = model.n();
        // ỹ = (x, v, each contact's slider, cos/sin of each harmonic, 1).
        let Some(super::ForcedStructure { minv, g, harmonics, dim }) = super::forced_structure(model, model.frictions.len()) else {
            return fail("the mass matrix is singular");
        };
        let b = model
            .frictions
            .iter()
            .map(|fr| {
                let mut b = DVector::zeros(n);
                fr.row.iter().for_each(|&(d, c)| b[d] += c);
                b
            })
            .collect();
        Ok(MultiFlows {
            n,
            dim,
            omega: model.frequency,
            harmonics,
            b,
            slip: model.frictions.iter().map(|f| f.slip_force()).collect(),
            kt: model.frictions.iter().map(|f| f.stiffness).collect(),
            stops: stops::Stop::from_model(model)?,
            minv,
            g,
            cache: Rc::default(),
        })
    }

    /// The friction contacts (the first entries of a mode).
    pub fn contacts(&self) -> usize {
        self.b.len()
    }

    /// The entries of a mode: friction contacts, then stops.
    pub fn elements(&self) -> usize {
        self.b.len() + self.stops.len()
    }

    /// The constrained rows of `mode`: the closed rigid stops' normals, then the stuck rigid
    /// contacts' directions, each kept if independent of those before (a friction direction in
    /// the span of closed stops: the stop carries the reaction, the friction force is 0). As
    /// columns B, W = (BᵀM⁻¹B)⁻¹BᵀM⁻¹, and each column's mode entry.
    fn constraint(&self, mode: &[Slide]) -> Option<(DMatrix<f64>, DMatrix<f64>, Vec<usize>)> {
        let nb = self.b.len();
        let stops = (0..self.stops.len()).filter(|&j| mode[nb + j] == Slide::Closed && self.stops[j].rigid()).map(|j| (nb + j, &self.stops[j].normal));
        let stuck = (0..nb).filter(|&i| mode[i] == Slide::Stick && self.kt[i].is_none()).map(|i| (i, &self.b[i]));
        let mut basis = Vec::new();
        let kept: Vec<(usize, &DVector<f64>)> = stops.chain(stuck).filter(|(_, col)| stops::extend_basis(&mut basis, col)).collect();
        if kept.is_empty() {
            return None;
        }
        let bs = DMatrix::from_fn(self.n, kept.len(), |r, c| kept[c].1[r]);
        let mb = &self.minv * &bs;
        let w = (bs.transpose() * &mb).try_inverse()? * mb.transpose();
        Some((bs, w, kept.iter().map(|k| k.0).collect()))
    }

    fn mode(&self, mode: &[Slide]) -> Rc<ModeFlow> {
        if let Some(f) = self.cache.borrow().get(&key(mode)) {
            return f.clone();
        }
        let (n, dim, is0, ione) = (self.n, self.dim, 2 * self.n, self.dim - 1);
        let mut h = self.g.clone();
        let mut force = vec![DVector::zeros(dim); mode.len()];
        for (i, &phase) in mode.iter().enumerate() {
            if i >= self.b.len() {
                if phase == Slide::Closed {
                    force[i] = self.stops[i - self.b.len()].close(&mut h, ione);
                }
                continue;
            }
            let b = &self.b[i];
            match (phase, self.kt[i]) {
                (Slide::Slip(s), _) => {
                    let mut col = h.column_mut(ione);
                    col -= b * (s * self.slip[i]);
                    force[i][ione] = s * self.slip[i];
                }
                (Slide::Stick, Some(kt)) => {
                    let mut x = h.view_mut((0, 0), (n, n));
                    x -= b * b.transpose() * kt;
                    let mut col = h.column_mut(is0 + i);
                    col += b * kt;
                    force[i].rows_mut(0, n).copy_from(&(b * kt));
                    force[i][is0 + i] = -kt;
                }
                (Slide::Stick, None) | (Slide::Open | Slide::Closed, _) => {}
            }
        }
        let mut acc = h.clone();
        if let Some((bs, w, rows)) = self.constraint(mode) {
            // M x'' = H ỹ − B f: a stop's f is its compressive force λ (along −c).
            let reactions = &w * &h;
            acc -= &bs * &reactions;
            for (r, &i) in rows.iter().enumerate() {
                force[i] = reactions.row(r).transpose();
            }
        }
        let mut a = DMatrix::zeros(dim, dim);
        a.view_mut((0, n), (n, n)).fill_with_identity();
        a.view_mut((n, 0), (n, dim)).copy_from(&(&self.minv * acc));
        let ih = is0 + self.b.len();
        for (j, &q) in self.harmonics.iter().enumerate() {
            let w = q as f64 * self.omega;
            a[(ih + 2 * j, ih + 1 + 2 * j)] = -w;
            a[(ih + 1 + 2 * j, ih + 2 * j)] = w;
        }
        let f = Rc::new(ModeFlow { a, force });
        self.cache.borrow_mut().insert(key(mode), f.clone());
        f
    }

    pub fn flow(&self, mode: &[Slide], y: &DVector<f64>, tau: f64) -> DVector<f64> {
        (&self.mode(mode).a * tau).exp() * y
    }

    pub fn step_map(&self, mode: &[Slide], tau: f64) -> DMatrix<f64> {
        (&self.mode(mode).a * tau).exp()
    }

    pub fn velocity(&self, i: usize, y: &DVector<f64>) -> f64 {
        self.b[i].dot(&y.rows(self.n, self.n))
    }

    /// Contact `i`'s friction force in `mode` at state `y`.
    pub fn force(&self, mode: &[Slide], i: usize, y: &DVector<f64>) -> f64 {
        self.mode(mode).force[i].dot(y)
    }

    pub fn augment(&self, t: f64, xv: &[f64]) -> DVector<f64> {
        let mut y = DVector::zeros(self.dim);
        y.rows_mut(0, xv.len()).copy_from_slice(xv);
        let ih = 2 * self.n + self.contacts();
        for (j, &p) in self.harmonics.iter().enumerate() {
            let th = p as f64 * self.omega * t;
            y[ih + 2 * j] = th.cos();
            y[ih + 1 + 2 * j] = th.sin();
        }
        y[self.dim - 1] = 1.0;
        y
    }

    /// The event function of contact `i` leaving its phase in `mode` for `to` (0 at the event).
    fn event(&self, mode: &[Slide], i: usize, to: Slide, y: &DVector<f64>) -> f64 {
        match (mode[i], to) {
            // A rigid stop opens where its force vanishes.
            (Slide::Closed, _) if self.stops[i - self.b.len()].rigid() => self.force(mode, i, y),
            (Slide::Open | Slide::Closed, _) => self.stops[i - self.b.len()].penetration(y),
            (Slide::Slip(_), _) => self.velocity(i, y),
            (Slide::Stick, Slide::Slip(s)) => self.force(mode, i, y) - s * self.slip[i],
            (Slide::Stick, _) => f64::NAN,
        }
    }

    /// The state entering `after` from `before` (contact `i` changed): a rigid stick projects v
    /// onto the new stuck set's B_Sᵀv = 0 (mass metric), a Jenkins stick places its slider where
    /// the spring carries the slip force.
    pub fn enter(&self, before: &[Slide], after: &[Slide], i: usize, mut y: DVector<f64>) -> DVector<f64> {
        // A rigid stop's plastic impact (e = 0, as the LCP): v projected onto the new constraint.
        if i >= self.b.len() && after[i] == Slide::Closed && self.stops[i - self.b.len()].rigid() {
            return self.project(after, y);
        }
        if let (Slide::Slip(s), Slide::Stick) = (before[i], after[i]) {
            match self.kt[i] {
                None => y = self.project(after, y),
                Some(kt) => y[2 * self.n + i] = self.b[i].dot(&y.rows(0, self.n)) - s * self.slip[i] / kt,
            }
        }
        y
    }

    /// `y` with v moved onto the stuck rigid contacts' B_Sᵀv = 0 of `mode` (mass metric).
    pub fn project(&self, mode: &[Slide], mut y: DVector<f64>) -> DVector<f64> {
        if let Some((bs, w, _)) = self.constraint(mode) {
            let dv = w.transpose() * (bs.transpose() * y.rows(self.n, self.n));
            let mut vv = y.rows_mut(self.n, self.n);
            vv -= dv;
        }
        y
    }

    /// The phase contact `i` takes when its phase in `mode` ends at state `y`.
    pub fn next(&self, mode: &[Slide], i: usize, y: &DVector<f64>) -> Slide {
        match mode[i] {
            Slide::Open => Slide::Closed,
            Slide::Closed => Slide::Open,
            Slide::Stick => Slide::Slip(self.force(mode, i, y).signum()),
            Slide::Slip(_) if self.kt[i].is_some() => Slide::Stick,
            Slide::Slip(_) => {
                // Rigid at bᵀv = 0: stick if the holding force is within μN, else slip its way.
                let mut stuck = mode.to_vec();
                stuck[i] = Slide::Stick;
                let held = self.force(&stuck, i, &self.enter(mode, &stuck, i, y.clone()));
                if held.abs() <= self.slip[i] { Slide::Stick } else { Slide::Slip(held.signum()) }
            }
        }
    }

    /// Whether contact `i`'s phase in `mode` has ended by state `y`.
    pub fn ended(&self, mode: &[Slide], i: usize, y: &DVector<f64>) -> bool {
        match mode[i] {
            Slide::Slip(s) => s * self.velocity(i, y) < 0.0,
            Slide::Stick => self.force(mode, i, y).abs() > self.slip[i],
            // A rigid stop resting at its gap (v = 0, friction holding) is not hit again.
            Slide::Open if self.stops[i - self.b.len()].rigid() => {
                let stop = &self.stops[i - self.b.len()];
                stop.penetration(y) > 0.0 && stop.normal.dot(&y.rows(self.n, self.n)) > 0.0
            }
            Slide::Open => self.stops[i - self.b.len()].penetration(y) > 0.0,
            Slide::Closed if self.stops[i - self.b.len()].rigid() => self.force(mode, i, y) < 0.0,
            Slide::Closed => self.stops[i - self.b.len()].penetration(y) < 0.0,
        }
    }
}

/// The polished orbit with several friction contacts.
#[derive(Clone, Debug)]
pub struct MultiOrbit {
    flows: MultiFlows,
    period: f64,
    start: f64,
    /// The mode at `start`, then (contact, its phase after) per event.
    first: Mode,
    events: Vec<(usize, Slide)>,
    /// Event times in (start, start + T).
    pub times: Vec<f64>,
    /// The mode and augmented state at `start` and just after each event.
    modes: Vec<Mode>,
    states: Vec<DVector<f64>>,
    /// The Jenkins sliders among the unknowns (stuck at `start`).
    sliders: Vec<usize>,
    /// Pinned slider constants of the contacts stuck all period: (contact, constant).
    pins: Vec<(usize, f64)>,
    pub iterations: usize,
    pub residual: f64,
    pub correction: f64,
    monodromy: DMatrix<f64>,
}

impl MultiOrbit {
    pub fn new(flows: MultiFlows, period: f64, start: f64, first: Mode, events: Vec<(usize, Slide)>, times: Vec<f64>, constants: &[f64]) -> Self {
        let sliders: Vec<usize> = (0..first.len()).filter(|&i| first[i] == Slide::Stick && flows.kt[i].is_some()).collect();
        let pins = (0..first.len()).filter(|&i| first[i] == Slide::Stick && !events.iter().any(|e| e.0 == i)).map(|i| (i, constants[i])).collect();
        let first = flows.pin_to_stops(first);
        let mut modes = vec![first.clone()];
        for &(i, to) in &events {
            let mut next = modes[modes.len() - 1].clone();
            next[i] = to;
            modes.push(flows.pin_to_stops(next));
        }
        MultiOrbit {
            flows,
            period,
            start,
            first,
            events,
            times,
            modes,
            states: vec![],
            sliders,
            pins,
            iterations: 0,
            residual: f64::INFINITY,
            correction: f64::INFINITY,
            monodromy: DMatrix::zeros(0, 0),
        }
    }

    fn nr(&self) -> usize {
        2 * self.flows.n + self.sliders.len()
    }

    fn state_at_start(&self, u: &DVector<f64>) -> DVector<f64> {
        let n2 = 2 * self.flows.n;
        let mut y = self.flows.augment(self.start, u.rows(0, n2).as_slice());
        for (k, &i) in self.sliders.iter().enumerate() {
            y[n2 + i] = u[n2 + k];
        }
        y
    }

    /// The residual (periodicity, the event conditions, the pins) and the states after each event.
    fn shoot(&self, u: &DVector<f64>) -> (DVector<f64>, Vec<DVector<f64>>) {
        let (nr, m, n2) = (self.nr(), self.events.len(), 2 * self.flows.n);
        let fl = &self.flows;
        let mut y = self.state_at_start(u);
        let y0 = y.clone();
        let mut states = vec![y.clone()];
        let mut res = DVector::zeros(nr + m + 2 * self.pins.len());
        let mut t = self.start;
        for e in 0..m {
            let (i, to) = self.events[e];
            y = fl.flow(&self.modes[e], &y, u[nr + e] - t);
            res[nr + e] = fl.event(&self.modes[e], i, to, &y);
            y = fl.enter(&self.modes[e], &self.modes[e + 1], i, y);
            t = u[nr + e];
            states.push(y.clone());
        }
        y = fl.flow(&self.modes[m], &y, self.start + self.period - t);
        for r in 0..n2 {
            res[r] = y[r] - u[r];
        }
        for (k, &i) in self.sliders.iter().enumerate() {
            res[n2 + k] = y[n2 + i] - u[n2 + k];
        }
        for (p, &(i, c)) in self.pins.iter().enumerate() {
            let (x, v) = (fl.b[i].dot(&y0.rows(0, fl.n)), fl.velocity(i, &y0));
            res[nr + m + 2 * p] = match fl.kt[i] {
                Some(_) => y0[n2 + i] - c,
                None => x - c,
            };
            res[nr + m + 2 * p + 1] = if fl.kt[i].is_some() { 0.0 } else { v };
        }
        (res, states)
    }

    /// The unknowns at the seeded times, the state at the fixed point of the (affine) one-period
    /// map those times give (one Newton step with the times held).
    pub fn seeded(&self) -> Result<DVector<f64>, PolishFailure> {
        let nr = self.nr();
        let mut u = DVector::from_iterator(nr + self.times.len(), std::iter::repeat_n(0.0, nr).chain(self.times.iter().copied()));
        let r0 = self.shoot(&u).0;
        let j = super::newton::Shooting::jacobian(self, &u, &r0);
        // The periodicity and pin rows on the state columns (the event rows need the times).
        let m = self.times.len();
        let rows: Vec<usize> = (0..nr).chain(nr + m..r0.len()).collect();
        let a = DMatrix::from_fn(rows.len(), nr, |r, c| j[(rows[r], c)]);
        let r0 = DVector::from_fn(rows.len(), |r, _| r0[rows[r]]);
        let Some(du) = super::newton::solve_step(&a, &r0) else { return fail("the one-period map at the seeded events has a multiplier 1") };
        let mut x = u.rows_mut(0, nr);
        x += du;
        Ok(u)
    }

    /// The seeded start: (time, mode, augmented state).
    pub fn seed(&self) -> Option<(f64, Mode, DVector<f64>)> {
        self.seeded().ok().map(|u| (self.start, self.first.clone(), self.state_at_start(&u)))
    }

    /// Newton on the state and the event times from the seed (src/analysis/polish/friction/newton.rs).
    pub fn converge(&mut self) -> Result<(), PolishFailure> {
        let newton = match super::newton::Newton::run(&*self, self.seeded()?) {
            Ok(n) => n,
            Err(e) => return fail(e),
        };
        let (nr, u) = (self.nr(), &newton.u);
        (self.iterations, self.correction) = (newton.iterations, newton.correction);
        let (r, states) = self.shoot(u);
        self.residual = r.amax();
        self.times = u.rows(nr, self.times.len()).iter().copied().collect();
        self.states = states;
        self.monodromy = super::event_condensed_monodromy(&super::newton::Shooting::jacobian(&*self, u, &r), nr, self.times.len());
        Ok(())
    }

    /// The least and greatest friction force of contact `i` over 1024 points of the period.
    fn force_range(&self, i: usize) -> (f64, f64) {
        let f: Vec<f64> = (0..1024).map(|k| self.contact(i, self.start + k as f64 * self.period / 1024.0).0).collect();
        (f.iter().copied().fold(f64::INFINITY, f64::min), f.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    }

    /// Moves each pinned slider constant, by the constant force shift per unit constant (§9),
    /// so that its contact's holding force stays within ±μN; returns whether any moved.
    pub fn shift_pins(&mut self) -> Result<bool, PolishFailure> {
        let mut moved = false;
        for p in 0..self.pins.len() {
            let (i, c) = self.pins[p];
            let ((lo, hi), slip) = (self.force_range(i), self.flows.slip[i]);
            if hi - lo >= 2.0 * slip {
                return fail(format_args!("contact {i} stuck all period needs a holding force spanning {:.6e} > 2μN", hi - lo));
            }
            let shift = if hi > slip {
                slip - hi
            } else if lo < -slip {
                -slip - lo
            } else {
                continue;
            };
            let mut probe = self.clone();
            probe.pins[p].1 = c + 1.0;
            probe.converge()?;
            let per_unit = probe.force_range(i).0 - lo;
            if per_unit != 0.0 {
                self.pins[p].1 = c + shift / per_unit;
                self.converge()?;
                moved = true;
            }
        }
        Ok(moved)
    }

    fn ends(&self) -> Vec<f64> {
        std::iter::once(self.start).chain(self.times.iter().copied()).chain(std::iter::once(self.start + self.period)).collect()
    }

    /// The dense check of every contact's law along the converged orbit.
    pub fn verify(&self) -> Result<(), PolishFailure> {
        let fl = &self.flows;
        let ends = self.ends();
        if ends.windows(2).any(|w| !(w[1] > w[0])) {
            return fail("the fitted orbit's event times are out of order");
        }
        let vscale = (0..64)
            .flat_map(|k| {
                let y = self.at(self.start + k as f64 * self.period / 64.0).1;
                (0..fl.contacts()).map(move |i| (i, y.clone()))
            })
            .map(|(i, y)| fl.velocity(i, &y).abs())
            .fold(f64::MIN_POSITIVE, f64::max);
        let vtol = 1e-9 * vscale;
        // A stop's clearance is checked against the largest |x| or gap.
        let xscale = (0..64).map(|k| self.state(self.start + k as f64 * self.period / 64.0).rows(0, fl.n).amax()).fold(0.0, f64::max);
        let ptol = 1e-9 * fl.stops.iter().fold(xscale, |m, s| m.max(s.gap.abs())).max(f64::MIN_POSITIVE);
        // A rigid stop's force against the structure's largest force term at that scale.
        let ltol = 1e-9 * (1.0 + fl.g.amax() * xscale.max(1.0));
        let samples = if self.times.is_empty() { 4096 } else { 64 };
        for (e, y0) in self.states.iter().enumerate() {
            let (mode, len) = (&self.modes[e], ends[e + 1] - ends[e]);
            for k in 1..samples {
                let t = len * k as f64 / samples as f64;
                let y = fl.flow(mode, y0, t);
                for (i, &phase) in mode.iter().enumerate() {
                    let ftol = 1e-9 * fl.slip.get(i).copied().unwrap_or(0.0).max(f64::MIN_POSITIVE);
                    match phase {
                        Slide::Closed if fl.stops[i - fl.contacts()].rigid() && fl.force(mode, i, &y) < -ltol => {
                            return fail(format_args!("the fitted orbit's rigid stop {} pulls at t = {:.6}", i - fl.contacts(), ends[e] + t));
                        }
                        Slide::Open | Slide::Closed if fl.stops[i - fl.contacts()].breaks(phase, &y, ptol) => {
                            return fail(format_args!(
                                "the fitted orbit's stop {} is {phase:?} against its clearance at t = {:.6}",
                                i - fl.contacts(),
                                ends[e] + t
                            ));
                        }
                        Slide::Slip(s) if s * fl.velocity(i, &y) < -vtol => {
                            return fail(format_args!("the fitted orbit's contact {i} reverses inside a slip at t = {:.6}", ends[e] + t));
                        }
                        Slide::Stick if fl.force(mode, i, &y).abs() > fl.slip[i] + ftol => {
                            return fail(format_args!("the fitted orbit's contact {i} needs more than μN to stay stuck at t = {:.6}", ends[e] + t));
                        }
                        _ => {}
                    }
                }
            }
        }
        // A rigid onset of sticking must hold; a reversal must not.
        for (e, &(i, to)) in self.events.iter().enumerate() {
            let (before, y) = (&self.modes[e], &self.states[e + 1]);
            if i >= fl.contacts() || fl.kt[i].is_some() || before[i] == Slide::Stick {
                continue;
            }
            let mut stuck = before.clone();
            stuck[i] = Slide::Stick;
            let held = fl.force(&stuck, i, y);
            let ftol = 1e-9 * fl.slip[i];
            match to {
                Slide::Stick if held.abs() > fl.slip[i] + ftol => {
                    return fail(format_args!("contact {i} sticks at t = {:.6} with a holding force {held:.6e} > μN", self.times[e]));
                }
                Slide::Slip(s) if s * held < fl.slip[i] - ftol => return fail(format_args!("contact {i}'s reversal at t = {:.6} could stick", self.times[e])),
                _ => {}
            }
        }
        Ok(())
    }

    /// The mode and augmented state at `t` (any real).
    fn at(&self, t: f64) -> (&Mode, DVector<f64>) {
        let tt = self.start + (t - self.start).rem_euclid(self.period);
        let e = self.times.partition_point(|&s| s <= tt);
        let t0 = if e == 0 { self.start } else { self.times[e - 1] };
        (&self.modes[e], self.flows.flow(&self.modes[e], &self.states[e], tt - t0))
    }

    /// The structure's state [x; v] at `t`.
    pub fn state(&self, t: f64) -> DVector<f64> {
        self.at(t).1.rows(0, 2 * self.flows.n).into_owned()
    }

    /// Contact `i`'s force, sliding velocity (0 while stuck), sliding displacement bᵀx and stuck flag.
    pub fn contact(&self, i: usize, t: f64) -> (f64, f64, f64, bool) {
        let (mode, y) = self.at(t);
        let fl = &self.flows;
        let stuck = mode[i] == Slide::Stick;
        (fl.force(mode, i, &y), if stuck { 0.0 } else { fl.velocity(i, &y) }, fl.b[i].dot(&y.rows(0, fl.n)), stuck)
    }

    /// The fraction of the period contact `i` sticks.
    pub fn stuck_fraction(&self, i: usize) -> f64 {
        self.modes.iter().zip(self.ends().windows(2)).filter(|(m, _)| m[i] == Slide::Stick).map(|(_, w)| w[1] - w[0]).sum::<f64>() / self.period
    }

    /// Energy dissipated per period by contact `i`: μN Σ |Δ(bᵀx)| over its slips.
    pub fn dissipated_energy(&self, i: usize) -> f64 {
        let ends = self.ends();
        let slips = self.modes.iter().zip(ends.windows(2)).filter(|(m, _)| m[i] != Slide::Stick);
        slips.map(|(_, w)| self.flows.slip[i] * (self.contact(i, w[1]).2 - self.contact(i, w[0]).2).abs()).sum()
    }

    pub fn multipliers(&self) -> Vec<C> {
        self.monodromy.complex_eigenvalues().iter().copied().collect()
    }

    pub fn event_records(&self) -> Vec<EventRecord> {
        (0..self.events.len())
            .map(|e| {
                let (i, to) = self.events[e];
                let contact = if i < self.flows.contacts() { i } else { i - self.flows.contacts() };
                let kind = match (self.modes[e][i], to) {
                    (_, Slide::Closed) => "contact_on",
                    (_, Slide::Open) => "contact_off",
                    (Slide::Stick, _) => "slip",
                    (_, Slide::Stick) => "stick",
                    _ => "reversal",
                };
                EventRecord { time: self.times[e].rem_euclid(self.period), contact, kind: kind.into(), impulse: 0.0 }
            })
            .collect()
    }
}

impl super::newton::Shooting for MultiOrbit {
    fn residual(&self, u: &DVector<f64>) -> DVector<f64> {
        self.shoot(u).0
    }

    fn scale(&self, c: usize) -> f64 {
        if c < self.nr() { 1.0 } else { self.period }
    }
}

pub mod stops;
mod topology;
pub use topology::{polish, write};
