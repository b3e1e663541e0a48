//! The stick–slip polish: a friction orbit from the LCP refined to round-off (src/formulation.md §9).
//!
//! One Coulomb contact (rigid, or a Jenkins element) on a linear structure with harmonic forcing.
//! Between events the dynamics is linear and flows exactly by the matrix exponential of an
//! augmented system ỹ = [x; v; s₀; cos pΩt, sin pΩt …; 1] (s₀: a Jenkins slider held while stuck):
//! - slip of sign s: M x'' + C x' + K x = F(t) − b·sμN;
//! - rigid stick: bᵀx held, M x'' = P(F − Kx − Cv), P = M⁻¹ − M⁻¹b(bᵀM⁻¹b)⁻¹bᵀM⁻¹ (the reduced
//!   dynamics), holding force f = bᵀM⁻¹(F − Kx − Cv)/(bᵀM⁻¹b);
//! - Jenkins stick: the slider s₀ fixed, f = k_t(bᵀx − s₀).
//!
//! Events: a slip ends at bᵀv = 0 (into stick, or a reversal for rigid Coulomb when the holding
//! force exceeds μN); a stick ends at f = s′μN (release into slip s′). The phase sequence is read
//! from the LCP's stuck flags and force signs; the unknowns are the state at a time t_s inside the
//! longest phase and the event times; the equations are periodicity and one condition per event;
//! Newton with a finite-difference Jacobian, the state seeded by the fixed point of the affine
//! map the LCP's event times give. The result is verified densely (slip keeps its sign, stick
//! holds |f| ≤ μN, a stick onset can hold, a reversal cannot); otherwise the LCP's orbit stays.
//!
//! Stability: the monodromy is the Jacobian's Schur complement, dΦ/dy − dΦ/dt (dg/dt)⁻¹ dg/dy
//! (the event times move with the state). A rigid stick onset projects the state on bᵀv = 0 and
//! the stuck flow keeps it there, so the monodromy has a zero eigenvalue (rank-deficient, the
//! "saltation" of sticking); a Jenkins slider's s₀ is set by the state at the onset, likewise.
//! Zero multipliers are contractions, not a failure: the orbit is stable when the spectral
//! radius of the monodromy is below 1, and they are reported as they are.
use super::PolishFailure;
pub mod multi;
mod newton;
mod settle;
use crate::model::Model;
use crate::periodic::PeriodicProblem;
use crate::response::{EventRecord, Response};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;

/// A phase of the contact, or of a compliant stop among several friction contacts (multi.rs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Slide {
    Stick,
    /// Slip with the sign of the sliding velocity bᵀv (the force is sign·μN).
    Slip(f64),
    /// A compliant unilateral stop open (no force) or closed (its spring pushes back).
    Open,
    Closed,
}

impl Slide {
    fn index(self) -> usize {
        match self {
            Slide::Stick => 0,
            Slide::Slip(s) if s > 0.0 => 1,
            Slide::Slip(_) => 2,
            Slide::Open => 3,
            Slide::Closed => 4,
        }
    }
}

/// The exact flows of the three phases over the augmented state.
#[derive(Clone, Debug)]
struct Flows {
    n: usize,
    dim: usize,
    omega: f64,
    /// The forcing harmonics p ≥ 1 carried as (cos, sin) pairs after s₀.
    harmonics: Vec<u32>,
    b: DVector<f64>,
    slip: f64,
    kt: Option<f64>,
    /// Ã of Stick, Slip(+), Slip(−).
    a: [DMatrix<f64>; 3],
    /// The stuck contact's force as a linear form of ỹ.
    stick_force: DVector<f64>,
    /// M⁻¹b / (bᵀM⁻¹b): the mass-metric projection onto bᵀv = 0 at a rigid stick onset.
    project: DVector<f64>,
}

impl Flows {
    fn new(model: &Model) -> Result<Self, PolishFailure> {
        let fail = |w: &str| PolishFailure(format!("stick–slip polish: {w}; the LCP's orbit is kept"));
        let n = model.n();
        let fr = &model.frictions[0];
        let mut b = DVector::zeros(n);
        fr.row.iter().for_each(|&(d, c)| b[d] += c);
        // ỹ = (x, v, the slider s0, cos/sin of each harmonic, 1).
        let ForcedStructure { minv, g, harmonics, dim } = forced_structure(model, 1).ok_or_else(|| fail("the mass matrix is singular"))?;
        let (is0, ione) = (2 * n, dim - 1);
        let mb = &minv * &b;
        let med = b.dot(&mb);
        let kt = fr.stiffness;
        let slip = fr.slip_force();
        let p = &minv - &mb * mb.transpose() / med;
        let build = |phase: Slide| {
            let mut a = DMatrix::zeros(dim, dim);
            a.view_mut((0, n), (n, n)).fill_with_identity();
            let acc = match (phase, kt) {
                (Slide::Stick, None) => &p * &g,
                _ => &minv * &g,
            };
            a.view_mut((n, 0), (n, dim)).copy_from(&acc);
            for i in 0..n {
                match (phase, kt) {
                    (Slide::Slip(s), _) => a[(n + i, ione)] -= mb[i] * s * slip,
                    (Slide::Stick, Some(kt)) => {
                        for j in 0..n {
                            a[(n + i, j)] -= mb[i] * kt * b[j];
                        }
                        a[(n + i, is0)] += mb[i] * kt;
                    }
                    (Slide::Stick, None) | (Slide::Open | Slide::Closed, _) => {}
                }
            }
            for (h, &q) in harmonics.iter().enumerate() {
                let w = q as f64 * model.frequency;
                a[(is0 + 1 + 2 * h, is0 + 2 + 2 * h)] = -w;
                a[(is0 + 2 + 2 * h, is0 + 1 + 2 * h)] = w;
            }
            a
        };
        let stick_force = match kt {
            Some(kt) => {
                let mut f = DVector::zeros(dim);
                f.rows_mut(0, n).copy_from(&(&b * kt));
                f[is0] = -kt;
                f
            }
            None => g.transpose() * &mb / med,
        };
        let a = [build(Slide::Stick), build(Slide::Slip(1.0)), build(Slide::Slip(-1.0))];
        Ok(Flows { n, dim, omega: model.frequency, harmonics, b, slip, kt, a, stick_force, project: mb / med })
    }

    fn flow(&self, phase: Slide, y: &DVector<f64>, tau: f64) -> DVector<f64> {
        (&self.a[phase.index()] * tau).exp() * y
    }

    fn velocity(&self, y: &DVector<f64>) -> f64 {
        self.b.dot(&y.rows(self.n, self.n))
    }

    /// The friction force of `phase` in state `y`.
    fn force(&self, phase: Slide, y: &DVector<f64>) -> f64 {
        match phase {
            Slide::Stick => self.stick_force.dot(y),
            Slide::Slip(s) => s * self.slip,
            Slide::Open | Slide::Closed => 0.0,
        }
    }

    /// The augmented state at `t` with the structure's state `xv` (and s₀ if given).
    fn augment(&self, t: f64, xv: &[f64]) -> DVector<f64> {
        let mut y = DVector::zeros(self.dim);
        y.rows_mut(0, xv.len()).copy_from_slice(xv);
        for (h, &p) in self.harmonics.iter().enumerate() {
            let th = p as f64 * self.omega * t;
            y[2 * self.n + 1 + 2 * h] = th.cos();
            y[2 * self.n + 2 + 2 * h] = th.sin();
        }
        y[self.dim - 1] = 1.0;
        y
    }

    /// The event function ending `from` into `to` (0 at the event).
    fn event(&self, from: Slide, to: Slide, y: &DVector<f64>) -> f64 {
        match (from, to) {
            (Slide::Slip(_), _) => self.velocity(y),
            (Slide::Stick, Slide::Slip(s)) => self.stick_force.dot(y) - s * self.slip,
            _ => unreachable!("phases alternate between stick and slip"),
        }
    }

    /// The state entering `to` from `from`: a rigid stick projects onto bᵀv = 0, a Jenkins stick
    /// places the slider where the spring carries the slip force.
    fn enter(&self, from: Slide, to: Slide, mut y: DVector<f64>) -> DVector<f64> {
        if let (Slide::Slip(s), Slide::Stick) = (from, to) {
            match self.kt {
                None => {
                    let v = self.velocity(&y);
                    let mut vv = y.rows_mut(self.n, self.n);
                    vv -= &self.project * v;
                }
                Some(kt) => y[2 * self.n] = self.b.dot(&y.rows(0, self.n)) - s * self.slip / kt,
            }
        }
        y
    }
}

/// The polished stick–slip orbit.
#[derive(Clone, Debug)]
pub struct StickSlipOrbit {
    flows: Flows,
    period: f64,
    start: f64,
    /// Phase from `start`, then the phase after each event.
    first: Slide,
    slides: Vec<Slide>,
    /// Event times in (start, start + T), increasing.
    pub times: Vec<f64>,
    /// The augmented state at `start` and just after each event.
    states: Vec<DVector<f64>>,
    /// Number of state unknowns (2n, + s₀ when a Jenkins contact is stuck at `start`).
    nr: usize,
    pub iterations: usize,
    pub residual: f64,
    pub correction: f64,
    monodromy: DMatrix<f64>,
}

impl StickSlipOrbit {
    fn new(flows: Flows, period: f64, start: f64, first: Slide, slides: Vec<Slide>, times: Vec<f64>) -> Self {
        let nr = 2 * flows.n + usize::from(first == Slide::Stick && flows.kt.is_some());
        StickSlipOrbit {
            flows,
            period,
            start,
            first,
            slides,
            times,
            states: vec![],
            nr,
            iterations: 0,
            residual: f64::INFINITY,
            correction: f64::INFINITY,
            monodromy: DMatrix::zeros(0, 0),
        }
    }

    fn slide_before(&self, e: usize) -> Slide {
        if e == 0 { self.first } else { self.slides[e - 1] }
    }

    /// Flows one period from the unknowns `u` = [state; times]: the residual (periodicity, then
    /// the event conditions) and the states after each event.
    fn shoot(&self, u: &DVector<f64>) -> (DVector<f64>, Vec<DVector<f64>>) {
        let (nr, m) = (self.nr, self.slides.len());
        let mut y = self.flows.augment(self.start, u.rows(0, nr).as_slice());
        let mut states = vec![y.clone()];
        let mut res = DVector::zeros(nr + m);
        let mut t = self.start;
        for e in 0..m {
            let (from, to) = (self.slide_before(e), self.slides[e]);
            y = self.flows.flow(from, &y, u[nr + e] - t);
            res[nr + e] = self.flows.event(from, to, &y);
            y = self.flows.enter(from, to, y);
            t = u[nr + e];
            states.push(y.clone());
        }
        y = self.flows.flow(self.slides.last().copied().unwrap_or(self.first), &y, self.start + self.period - t);
        for i in 0..nr {
            res[i] = y[i] - u[i];
        }
        (res, states)
    }

    fn unknowns(&self, state: &[f64]) -> DVector<f64> {
        DVector::from_iterator(self.nr + self.times.len(), state.iter().copied().chain(self.times.iter().copied()))
    }

    /// The unknowns at the seeded times with the state at the periodic fixed point of the
    /// (affine) one-period map those times give.
    fn seed(&self) -> Result<DVector<f64>, PolishFailure> {
        let nr = self.nr;
        let mut u = self.unknowns(&vec![0.0; nr]);
        let c0 = self.shoot(&u).0.rows(0, nr).into_owned();
        let mut a = DMatrix::zeros(nr, nr);
        for i in 0..nr {
            let mut ui = u.clone();
            ui[i] = 1.0;
            a.set_column(i, &(self.shoot(&ui).0.rows(0, nr) - &c0));
        }
        // (Φ − I)u + c0 = 0 with a = Φ − I (the residual's linear part).
        let x = a.lu().solve(&(-&c0)).ok_or_else(|| {
            PolishFailure("stick–slip polish: the one-period map at the LCP's event times has a multiplier 1; the LCP's orbit is kept".into())
        })?;
        u.rows_mut(0, nr).copy_from(&x);
        Ok(u)
    }

    /// Seeds the state by the periodic fixed point of the (affine) one-period map at the seeded
    /// times, then Newton on state and times (src/analysis/polish/friction/newton.rs).
    fn converge(&mut self) -> Result<(), PolishFailure> {
        let fail = |w: newton::NewtonFailure| PolishFailure(format!("stick–slip polish: {w}; the LCP's orbit is kept"));
        let newton = newton::Newton::run(&*self, self.seed()?).map_err(fail)?;
        let (nr, u) = (self.nr, &newton.u);
        (self.iterations, self.correction) = (newton.iterations, newton.correction);
        let (r, states) = self.shoot(u);
        self.residual = r.amax();
        self.times = u.rows(nr, self.times.len()).iter().copied().collect();
        self.states = states;
        self.monodromy = event_condensed_monodromy(&newton::Shooting::jacobian(&*self, u, &r), nr, self.times.len());
        Ok(())
    }

    /// The dense check of the contact law along the converged orbit.
    fn verify(&self) -> Result<(), PolishFailure> {
        let fail = |w: String| Err(PolishFailure(format!("stick–slip polish: the fitted orbit breaks the friction law: {w}; the LCP's orbit is kept")));
        let fl = &self.flows;
        let ends: Vec<f64> = std::iter::once(self.start).chain(self.times.iter().copied()).chain(std::iter::once(self.start + self.period)).collect();
        if ends.windows(2).any(|w| !(w[1] > w[0])) {
            return fail("event times out of order (a phase of negative length)".into());
        }
        let vscale = (0..64).map(|i| fl.velocity(&self.at(self.start + i as f64 * self.period / 64.0).1).abs()).fold(f64::MIN_POSITIVE, f64::max);
        let (vtol, ftol) = (1e-9 * vscale, 1e-9 * fl.slip.max(f64::MIN_POSITIVE));
        for (e, y0) in self.states.iter().enumerate() {
            let phase = if e == 0 { self.first } else { self.slides[e - 1] };
            let len = ends[e + 1] - ends[e];
            // Densely over a phase that fills the period (no event pins the orbit down).
            let samples = if self.times.is_empty() { 4096 } else { 64 };
            for i in 1..samples {
                let y = fl.flow(phase, y0, len * i as f64 / samples as f64);
                match phase {
                    Slide::Slip(s) if s * fl.velocity(&y) < -vtol => {
                        return fail(format!("slip {s:+} reverses inside its phase at t = {:.6}", ends[e] + len * i as f64 / samples as f64));
                    }
                    Slide::Stick if fl.force(phase, &y).abs() > fl.slip + ftol => {
                        return fail(format!("a stuck force exceeds μN at t = {:.6}", ends[e] + len * i as f64 / samples as f64));
                    }
                    _ => {}
                }
            }
        }
        // A rigid onset of sticking must hold; a reversal must not.
        if fl.kt.is_none() {
            for (e, y) in self.states.iter().enumerate().skip(1) {
                let held = fl.stick_force.dot(y);
                match (self.slide_before(e - 1), self.slides[e - 1]) {
                    (Slide::Slip(_), Slide::Stick) if held.abs() > fl.slip + ftol => {
                        return fail(format!("sticking at t = {:.6} needs {held:.6e} > μN", self.times[e - 1]));
                    }
                    (Slide::Slip(_), Slide::Slip(s)) if s * held < fl.slip - ftol => {
                        return fail(format!("a reversal at t = {:.6} could stick (holding force {held:.6e})", self.times[e - 1]));
                    }
                    _ => {}
                }
            }
        }
        Ok(())
    }

    /// The phase and augmented state at `t` (any real).
    fn at(&self, t: f64) -> (Slide, DVector<f64>) {
        let tt = self.start + (t - self.start).rem_euclid(self.period);
        let e = self.times.partition_point(|&s| s <= tt);
        let (phase, t0) = if e == 0 { (self.first, self.start) } else { (self.slides[e - 1], self.times[e - 1]) };
        (phase, self.flows.flow(phase, &self.states[e], tt - t0))
    }

    /// The structure's state [x; v] at `t`.
    pub fn state(&self, t: f64) -> DVector<f64> {
        self.at(t).1.rows(0, 2 * self.flows.n).into_owned()
    }

    /// Friction force, sliding velocity bᵀv (the slider's for a Jenkins element: 0 while stuck),
    /// sliding displacement bᵀx and stuck flag at `t`.
    pub fn contact(&self, t: f64) -> (f64, f64, f64, bool) {
        let (phase, y) = self.at(t);
        let fl = &self.flows;
        let v = if phase == Slide::Stick { 0.0 } else { fl.velocity(&y) };
        (fl.force(phase, &y), v, fl.b.dot(&y.rows(0, fl.n)), phase == Slide::Stick)
    }

    /// Half the peak-to-peak of DOF `dof` over the period: the extreme samples of 4096, each
    /// refined by golden section on the exact flow (to round-off).
    pub fn amplitude(&self, dof: usize) -> f64 {
        let ns = 4096;
        let h = self.period / ns as f64;
        let x = |t: f64| self.state(t)[dof];
        let samples: Vec<f64> = (0..ns).map(|i| x(i as f64 * h)).collect();
        let refine = |sign: f64| {
            let i = (0..ns).max_by(|&a, &b| (sign * samples[a]).total_cmp(&(sign * samples[b]))).unwrap_or(0);
            let (mut lo, mut hi) = ((i as f64 - 1.0) * h, (i as f64 + 1.0) * h);
            let g = 0.5 * (5f64.sqrt() - 1.0);
            for _ in 0..80 {
                let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
                if sign * x(a) > sign * x(b) { hi = b } else { lo = a }
            }
            x(0.5 * (lo + hi))
        };
        0.5 * (refine(1.0) - refine(-1.0))
    }

    /// Floquet multipliers of the orbit (eigenvalues of the monodromy; zeros from sticking).
    pub fn multipliers(&self) -> Vec<C> {
        self.monodromy.complex_eigenvalues().iter().copied().collect()
    }

    /// The fraction of the period the contact sticks.
    pub fn stuck_fraction(&self) -> f64 {
        let ends: Vec<f64> = std::iter::once(self.start).chain(self.times.iter().copied()).chain(std::iter::once(self.start + self.period)).collect();
        let phases = std::iter::once(self.first).chain(self.slides.iter().copied());
        phases.zip(ends.windows(2)).filter(|(p, _)| *p == Slide::Stick).map(|(_, w)| w[1] - w[0]).sum::<f64>() / self.period
    }

    pub fn event_records(&self) -> Vec<EventRecord> {
        (0..self.times.len())
            .map(|e| {
                let kind = match (self.slide_before(e), self.slides[e]) {
                    (Slide::Stick, _) => "slip",
                    (_, Slide::Stick) => "stick",
                    _ => "reversal",
                };
                EventRecord { time: self.times[e].rem_euclid(self.period), contact: 0, kind: kind.into(), impulse: 0.0 }
            })
            .collect()
    }
}

impl newton::Shooting for StickSlipOrbit {
    fn residual(&self, u: &DVector<f64>) -> DVector<f64> {
        self.shoot(u).0
    }

    fn scale(&self, c: usize) -> f64 {
        if c < self.nr { 1.0 } else { self.period }
    }
}

/// The phases at the LCP's instants (instant j describes (t_{j−1}, t_j] under bds1), merged into
/// circular runs: (phase, first instant).
fn runs(stuck: &[bool], force: &[f64]) -> Vec<(Slide, usize)> {
    let k = stuck.len();
    let slide = |j: usize| if stuck[j] { Slide::Stick } else { Slide::Slip(force[j].signum()) };
    let mut runs: Vec<(Slide, usize)> = (0..k).filter(|&j| slide(j) != slide((j + k - 1) % k)).map(|j| (slide(j), j)).collect();
    runs.sort_by_key(|r| r.1);
    runs
}

/// Fits the stick–slip orbit of the one friction contact of `problem` to the LCP's result `r`.
pub fn polish(problem: &PeriodicProblem, r: &Response) -> Result<StickSlipOrbit, PolishFailure> {
    let model = problem.model();
    let fail = |w: &str| Err(PolishFailure(format!("stick–slip polish: {w}; the LCP's orbit is kept")));
    if model.frictions.len() != 1 || !model.contacts.is_empty() {
        return fail("this version fits one friction contact without unilateral contacts");
    }
    let Some(fr) = r.friction.first() else { return fail("the result has no friction output") };
    let flows = Flows::new(model)?;
    let (k, h, period) = (fr.stuck.len(), r.period / fr.stuck.len() as f64, r.period);
    if flows.slip == 0.0 {
        // No slip force: the free structure's linear orbit (the law holds at either velocity sign).
        let mut orbit = StickSlipOrbit::new(flows.clone(), period, 0.0, Slide::Slip(1.0), vec![], vec![]);
        orbit.converge()?;
        return Ok(orbit);
    }
    let all = runs(&fr.stuck, &fr.force);
    // The slider's constant of an orbit stuck all period: the LCP's mean of bᵀx (rigid) or of
    // the slider bᵀx − f/k_t (Jenkins).
    let constant = fr.displacement.iter().zip(&fr.force).map(|(u, f)| u - flows.kt.map_or(0.0, |kt| f / kt)).sum::<f64>() / k as f64;
    if all.is_empty() {
        // No event in the LCP: stuck (or slipping one way) all period.
        let phase = if fr.stuck[0] { Slide::Stick } else { Slide::Slip(fr.force[0].signum()) };
        let orbit = StickSlipOrbit::new(flows.clone(), period, 0.0, phase, vec![], vec![]);
        return settle::fit(orbit, constant).or_else(|e| settle::marched(&flows, period, None, constant).ok_or(e)?);
    }
    // Candidate topologies: as read, and (rigid Coulomb) with stick runs of one or two instants
    // taken for reversals, the LCP's trace of a continuous motion through v = 0.
    let merged: Vec<(Slide, usize)> = {
        let len = |i: usize| (all[(i + 1) % all.len()].1 + k - all[i].1) % k;
        let kept: Vec<(Slide, usize)> = all.iter().enumerate().filter(|&(i, r)| !(r.0 == Slide::Stick && len(i) <= 2)).map(|(_, r)| *r).collect();
        let mut out: Vec<(Slide, usize)> = Vec::new();
        for r in kept {
            if out.last().is_none_or(|l| l.0 != r.0) {
                out.push(r);
            }
        }
        if out.len() > 1 && out[0].0 == out[out.len() - 1].0 {
            out.remove(0);
        }
        out
    };
    let mut candidates = vec![all.clone()];
    if flows.kt.is_none() && merged.len() >= 2 && merged != all {
        candidates.push(merged);
    }
    let mut last = PolishFailure(String::new());
    let mut seeded = None;
    for runs in candidates {
        let nrun = runs.len();
        let len = |i: usize| (runs[(i + 1) % nrun].1 + k - runs[i].1) % k;
        let longest = (0..nrun).max_by_key(|&i| len(i)).unwrap_or(0);
        // Run i starts at t_{first − 1}; the origin sits in the middle of the longest run.
        let begin = |i: usize| (runs[i].1 as f64 - 1.0) * h;
        let start = begin(longest) + 0.5 * len(longest) as f64 * h;
        let order: Vec<usize> = (1..=nrun).map(|i| (longest + i) % nrun).collect();
        let times = order.iter().map(|&i| start + (begin(i) - start).rem_euclid(period)).collect();
        let slides = order.iter().map(|&i| runs[i].0).collect();
        let orbit = StickSlipOrbit::new(flows.clone(), period, start, runs[longest].0, slides, times);
        if seeded.is_none() {
            seeded = orbit.seed().ok().map(|u| (start, orbit.first, flows.augment(start, u.rows(0, orbit.nr).as_slice())));
        }
        match settle::fit(orbit, constant) {
            Ok(o) => return Ok(o),
            Err(e) => last = e,
        }
    }
    // The LCP's phases fit no exact orbit. Its short slips may be the trace of an orbit stuck
    // all period (holding force near μN); else march the exact flows from the seeded state.
    let stuck = StickSlipOrbit::new(flows.clone(), period, 0.0, Slide::Stick, vec![], vec![]);
    settle::fit(stuck, constant).or_else(|_| settle::marched(&flows, period, seeded, constant).unwrap_or(Err(last)))
}

/// The structure's dense M⁻¹ and its forced dynamics G ỹ = F(t) − Kx − Cv (n × dim) on an
/// augmented state ỹ = (x, v, `extra` friction unknowns, cos and sin of each forcing harmonic, 1),
/// shared by the one- and several-contact polish. `None` when M is singular.
pub(super) struct ForcedStructure {
    pub minv: DMatrix<f64>,
    pub g: DMatrix<f64>,
    pub harmonics: Vec<u32>,
    pub dim: usize,
}

pub(super) fn forced_structure(model: &Model, extra: usize) -> Option<ForcedStructure> {
    let n = model.n();
    let s = &model.structure;
    let minv = super::phase::dense(&s.mass, n).try_inverse()?;
    let c = s.damping.as_ref().map_or_else(|| DMatrix::zeros(n, n), |d| super::phase::dense(d, n));
    let k = super::phase::dense(&s.stiffness, n);
    let mut harmonics: Vec<u32> = model.forces.iter().map(|f| f.term.harmonic).filter(|&p| p > 0).collect();
    harmonics.sort_unstable();
    harmonics.dedup();
    let dim = 2 * n + extra + 2 * harmonics.len() + 1;
    let (ih, ione) = (2 * n + extra, dim - 1);
    let mut g = DMatrix::zeros(n, dim);
    g.view_mut((0, 0), (n, n)).copy_from(&(-&k));
    g.view_mut((0, n), (n, n)).copy_from(&(-&c));
    for f in &model.forces {
        let amp = C::from_polar(f.term.amplitude, f.term.phase);
        match harmonics.iter().position(|&p| p == f.term.harmonic) {
            // Re(a e^{iθ}) = Re a cos θ − Im a sin θ.
            Some(h) => {
                g[(f.dof, ih + 2 * h)] += amp.re;
                g[(f.dof, ih + 1 + 2 * h)] -= amp.im;
            }
            None => g[(f.dof, ione)] += amp.re,
        }
    }
    Some(ForcedStructure { minv, g, harmonics, dim })
}

/// The monodromy of a shooting Jacobian [[Φ − I, J_xt], [J_tx, J_tt]] over the state and `m`
/// event times: the event times eliminated (Schur complement), Φ − J_xt J_tt⁻¹ J_tx.
pub(super) fn event_condensed_monodromy(j: &DMatrix<f64>, nr: usize, m: usize) -> DMatrix<f64> {
    let phi = j.view((0, 0), (nr, nr)) + DMatrix::identity(nr, nr);
    // No events: the monodromy is the flow's (and a 0 × 0 LU would not solve).
    let schur = if m > 0 { j.view((nr, nr), (m, m)).into_owned().lu().solve(&j.view((nr, 0), (m, nr)).into_owned()) } else { None };
    match schur {
        Some(s) => phi - j.view((0, nr), (nr, m)) * s,
        None => phi,
    }
}

/// Replaces `r`'s kinematic series by an exact orbit's at the same instants: `at(t)` gives the
/// augmented state's rate and the state (x, v, …) there.
pub(super) fn write_flow_kinematics(r: &mut Response, problem: &PeriodicProblem, n: usize, at: impl Fn(f64) -> (DVector<f64>, DVector<f64>)) {
    let (accs, states): (Vec<DVector<f64>>, Vec<DVector<f64>>) =
        r.time.iter().map(|&t| at(t)).map(|(rate, y)| (rate.rows(n, n).into_owned(), y.rows(0, 2 * n).into_owned())).unzip();
    super::orbit::write_kinematics(r, problem.output_map(), &states, &accs, n);
}

/// Replaces `r`'s series by the orbit's at the same instants, and its friction outputs (the
/// slip velocity is the exact bᵀẋ(t_j), the energy ∮ f v dt = μN Σ |Δ(bᵀx)| over the slips).
pub fn write(orbit: &StickSlipOrbit, problem: &PeriodicProblem, r: &mut Response) {
    write_flow_kinematics(r, problem, orbit.flows.n, |t| {
        let (p, y) = orbit.at(t);
        (&orbit.flows.a[p.index()] * &y, y)
    });
    if let Some(f) = r.friction.first_mut() {
        for (j, &t) in r.time.iter().enumerate() {
            (f.force[j], f.slip_velocity[j], f.displacement[j], f.stuck[j]) = orbit.contact(t);
        }
        let fl = &orbit.flows;
        let ends: Vec<f64> = std::iter::once(orbit.start).chain(orbit.times.iter().copied()).chain(std::iter::once(orbit.start + orbit.period)).collect();
        let phases = std::iter::once(orbit.first).chain(orbit.slides.iter().copied());
        f.dissipated_energy =
            phases.zip(ends.windows(2)).filter(|(p, _)| *p != Slide::Stick).map(|(_, w)| fl.slip * (orbit.contact(w[1]).2 - orbit.contact(w[0]).2).abs()).sum();
    }
}
