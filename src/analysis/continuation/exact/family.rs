//! The exact orbits of one event signature as the parameter varies: unknowns, residual,
//! Jacobian, corrector and tangent, and the solved point (its orbit, multipliers and touches).
//!
//! Unknowns w = (y0/y_s, θ, λ/ρ): the state just after event 0 over a state scale, the event
//! times as fractions of the period (τ_e = θ_e·T(λ)), the parameter over its range. Equations:
//! the polish's shooting residual (periodicity over y_s, and an event condition per event: the
//! clearance 0 at a compliant switch), as COCO's `hspo` (Dankowicz & Schilder, "Recipes for
//! Continuation", ch. 19) with a fixed segment signature.
use super::super::{Parameter, floquet};
use super::metric::Metric;
use super::modes::{Modes, SignatureKey};
use super::profile::{Stage, timed};
use crate::analysis::polish::{Event, EventKind, KeptVariation, PolishedOrbit, RigidMargins, Touch};
use crate::model::{Compliance, Model};
use nalgebra::{DMatrix, DVector, Dyn, LU};
use num_complex::Complex64;
use std::rc::Rc;

mod failure;
pub(super) use failure::Failure;

/// The event signature: the events in time order (their seeds unused) and the contacts closed
/// all period long.
#[derive(Clone, Debug)]
pub(super) struct Signature {
    pub events: Vec<Event>,
    pub always: Vec<usize>,
}

/// Newton has converged when its correction (scaled unknowns) is below [`CONVERGED`]: the
/// iterate after it is then exact to O(correction²).
const CONVERGED: f64 = 1e-10;
/// Or when its corrections have stopped contracting (Θ = ‖Δw_k‖/‖Δw_k−1‖ ≥ 1, which a slowly
/// converging Newton never shows) below [`ATTAINABLE`] with a defect below [`NOISE_DEFECT`]:
/// the residual's round-off then dominates, and ‖Δw‖ is the accuracy Newton can
/// attain (Deuflhard, "Newton Methods for Nonlinear Problems", 2004, §2.1.2: termination at
/// the level of the residual's precision). On the coarse blade that noise is all in the
/// velocity rows of the contact DOFs (‖F‖ 1e-10 to 8e-10 of the state scale, the displacement
/// and event rows at 1e-15): the stiff contact modes' exponentials (ω_c/ω ≈ 270) carry
/// ε‖A h‖ into the velocities; their corrections then hover at 1e-10 to 4e-9 and never reach
/// a fixed 1e-11 defect, so every corrector near the grazing at 2254 rad/s spent its 12
/// iterations and halved the step.
const ATTAINABLE: f64 = 1e-8;
const NOISE_DEFECT: f64 = 1e-9;
const MAX_ITERATIONS: usize = 12;
/// Chord iterations go on while each correction is at most this fraction of the one before.
const CHORD_CONTRACTION: f64 = 0.25;
/// A search's trial ([`Family::correct_trial`]) has stalled when its fresh-Jacobian corrections
/// stop decreasing: from the [`STALL_FROM`]th on, one no smaller than the one two before and above
/// [`STALL_FLOOR`]. On the coarse rigid walk the landing searches' trials near a singular orbit
/// (2398.88 rad/s) hovered at 1e-6 to 1e-3 for all 12 iterations, chord and fresh runs alike (2.9 s
/// of 23 s); no trial that converged meets the test there, so the walk is the same bit for bit. The
/// walk's steps are not tested: there a stall then recovers (validation/RECORD.md, session 36).
const STALL_FROM: usize = 5;
const STALL_FLOOR: f64 = 1e-5;
/// Central-difference step of the Jacobian (unknowns are O(1)).
const DIFF: f64 = 1e-7;

pub(super) struct Family {
    base: Model,
    pub param: Parameter,
    pub rho: f64,
    pub ys: f64,
    pub sig: Signature,
    n2: usize,
    /// The state's weights ([`state_weights`]): unknown i is y_i·weight_i/y_s.
    weight: Vec<f64>,
    /// The arclength's metric ([`Metric`]).
    pub metric: Metric,
    /// Each contact's nᵀKn (1 where not positive): a release's force over it is a displacement.
    normal_stiffness: Vec<f64>,
    /// The corrector's last solution and its Jacobian, for the point's tangent.
    last_jacobian: std::cell::RefCell<Option<(Vec<f64>, DMatrix<f64>)>>,
    /// The Jacobian of the last point solved, for the next corrector's chord iterations.
    chord: std::cell::RefCell<Option<Chord>>,
    /// The orbits whose phases the builds share.
    modes: std::cell::RefCell<Modes>,
    /// The flight (its phase) whose re-impact time alone kept the last corrector from
    /// converging ([`Self::unresolved_flight`]).
    unresolved: std::cell::Cell<Option<usize>>,
}

type ChordKey = (SignatureKey, f64);

struct Chord {
    key: ChordKey,
    jacobian: DMatrix<f64>,
}

/// A solved point with its unit tangent (oriented along the branch), orbit, multipliers and the
/// contacts' touches.
#[derive(Clone, Debug)]
pub(super) struct Node {
    pub w: Vec<f64>,
    pub tangent: Vec<f64>,
    pub orbit: PolishedOrbit,
    /// The Floquet multipliers (empty: not computed, [`Family::orbit_node`]).
    pub mu: Vec<Complex64>,
    pub touches: Vec<Touch>,
    /// The outputs' amplitudes when surveyed with the touches (empty: not yet).
    pub amplitude: Vec<f64>,
    /// The orbit's rigid margin, made at its first use (a sampled period; asked for again at steps' ends).
    pub(super) margin: std::cell::OnceCell<Option<RigidMargins>>,
}

impl Node {
    pub fn lambda(&self, rho: f64) -> f64 {
        self.w[self.w.len() - 1] * rho
    }
    /// The smallest signed clearance between a contact's events (negative: not admissible).
    pub fn worst_touch(&self) -> Option<&Touch> {
        self.touches.iter().min_by(|a, b| a.value.total_cmp(&b.value))
    }
}

/// The unit vector along λ, the last of `d` unknowns (the normal of a corrector at λ fixed).
pub(super) fn lambda_axis(d: usize) -> Vec<f64> {
    (0..d).map(|i| if i + 1 == d { 1.0 } else { 0.0 }).collect()
}

impl Family {
    pub fn new(base: &Model, param: Parameter, rho: f64, ys: f64, sig: Signature) -> Family {
        let weight = state_weights(base);
        let metric = Metric::new(base, &weight);
        Family {
            base: base.clone(),
            param,
            rho,
            ys,
            sig,
            n2: 2 * base.n(),
            weight,
            metric,
            normal_stiffness: base
                .contacts
                .iter()
                .map(|c| c.along(|a| c.along(|b| base.structure.stiffness.get(a, b))).abs())
                .map(|k| if k > 0.0 { k } else { 1.0 })
                .collect(),
            last_jacobian: Default::default(),
            chord: Default::default(),
            modes: Default::default(),
            unresolved: Default::default(),
        }
    }

    /// The largest weighted state component of `y`: the state scale y_s of an orbit.
    pub fn scale_of(&self, y: &[f64]) -> f64 {
        y.iter().zip(&self.weight).fold(0.0f64, |m, (y, w)| m.max((y * w).abs())).max(1e-300)
    }

    /// The state's unknowns y_i·weight_i/y_s.
    pub fn scaled(&self, y: &[f64]) -> Vec<f64> {
        y.iter().zip(&self.weight).map(|(y, w)| y * w / self.ys).collect()
    }

    /// The scale of residual row r (the state's weight over y_s; an event's clearance as a
    /// displacement, a release's force over the stiffness along its contact's normal as one, as
    /// the polish weighs it). A release's force in newtons read 1e-5 after a converged Newton on
    /// the coarse rigid blade (its stiff modes' round-off), far above the defect's noise, so a
    /// corrector stalled at the noise was never accepted (the grazing at 2329.96 rad/s).
    fn row_scale(&self, r: usize) -> f64 {
        let release = r >= self.n2 && self.sig.events.get(r - self.n2).is_some_and(|e| e.kind == EventKind::Release);
        let force = if release { self.normal_stiffness[self.sig.events[r - self.n2].contact] } else { 1.0 };
        (if r < self.n2 { self.weight[r] } else { self.weight[0] }) / self.ys / force
    }

    /// The scene's model at λ.
    pub fn model_at(&self, lambda: f64) -> Model {
        let mut m = self.base.clone();
        match self.param {
            Parameter::Frequency => m.frequency = lambda,
            Parameter::Speed { lobes } => m.frequency = f64::from(lobes) * lambda,
            Parameter::ForceScale => m.forces.iter_mut().for_each(|f| f.term.amplitude *= lambda),
            Parameter::GapOffset => m.contacts.iter_mut().for_each(|c| c.gap += lambda),
            Parameter::NormalForce => m.frictions.iter_mut().for_each(|f| f.normal_force = lambda),
        }
        m
    }

    /// The scene's model (at its own λ).
    pub fn base(&self) -> &Model {
        &self.base
    }
    pub fn ne(&self) -> usize {
        self.sig.events.len()
    }
    pub fn dim(&self) -> usize {
        self.n2 + self.ne() + 1
    }

    /// The unknowns of `orbit` at λ.
    pub fn pack(&self, orbit: &PolishedOrbit, lambda: f64) -> Vec<f64> {
        let t = orbit.period();
        let mut w = self.scaled(orbit.initial_state());
        if self.ne() > 0 {
            w.extend(orbit.times().iter().map(|s| s / t));
        }
        w.push(lambda / self.rho);
        w
    }

    fn orbit(&self, lambda: f64) -> Option<Rc<PolishedOrbit>> {
        if !lambda.is_finite() {
            return None;
        }
        timed(Stage::Build, || self.build(lambda))
    }

    fn build(&self, lambda: f64) -> Option<Rc<PolishedOrbit>> {
        let (mut modes, key) = (self.modes.borrow_mut(), self.signature_key());
        if let Some(orbit) = modes.again(&key, &self.sig.events, &self.sig.always, lambda) {
            return Some(orbit);
        }
        let orbit = Rc::new(modes.build(key, &self.model_at(lambda), self.sig.events.clone(), &self.sig.always)?);
        modes.remember(self.sig.events.clone(), &self.sig.always, lambda, &orbit);
        Some(orbit)
    }

    fn unpack(&self, w: &[f64], period: f64) -> (Vec<f64>, Vec<f64>) {
        let y: Vec<f64> = w[..self.n2].iter().zip(&self.weight).map(|(v, s)| v * self.ys / s).collect();
        let times: Vec<f64> = if self.ne() == 0 { vec![0.0] } else { w[self.n2..self.n2 + self.ne()].iter().map(|s| s * period).collect() };
        (y, times)
    }

    /// Whether the event times of `w` increase within one period (the shooting residual's domain).
    fn ordered(&self, w: &[f64], period: f64) -> bool {
        let (_, tau) = self.unpack(w, period);
        self.ne() == 0 || (tau.windows(2).all(|p| p[0] < p[1]) && tau[self.ne() - 1] < tau[0] + period)
    }

    fn residual_with(&self, orbit: &PolishedOrbit, w: &[f64]) -> Option<DVector<f64>> {
        let (y, times) = self.unpack(w, orbit.period());
        let mut r = timed(Stage::Residual, || orbit.shooting_residual(&y, &times))?;
        r.iter_mut().enumerate().for_each(|(i, v)| *v *= self.row_scale(i));
        for (row, e, p, wrap) in self.reimpacts() {
            r[row] *= super::rigid::reimpact_factor(w[e] + wrap - w[p]);
        }
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    /// The re-impacts of the signature: (residual row, unknown of its time, unknown of the pure
    /// impact of the same rigid contact just before it, 1 when the flight wraps the period),
    /// whose condition is desingularised ([`super::rigid::reimpact_factor`]).
    fn reimpacts(&self) -> Vec<(usize, usize, usize, f64)> {
        let ev = &self.sig.events;
        let ne = ev.len();
        (0..ne)
            .filter(|&e| {
                let p = ev[(e + ne - 1) % ne];
                ne >= 2
                    && p.kind == EventKind::Impact { stick: false }
                    && matches!(ev[e].kind, EventKind::Impact { .. })
                    && p.contact == ev[e].contact
                    && !self.base.contact_is_massless(&self.base.contacts[p.contact])
            })
            .map(|e| (self.n2 + e, self.n2 + e, self.n2 + (e + ne - 1) % ne, if e == 0 { 1.0 } else { 0.0 }))
            .collect()
    }

    /// `w` with its state the one the signature's last phase carries at θ_0
    /// ([`PolishedOrbit::section_state`]): for a predictor whose events passed event 0.
    pub fn sectioned(&self, w: &[f64]) -> Option<Vec<f64>> {
        let orbit = self.orbit(w[w.len() - 1] * self.rho)?;
        let (y, times) = self.unpack(w, orbit.period());
        let mut out = self.scaled(&orbit.section_state(&y, times[0]));
        out.extend_from_slice(&w[self.n2..]);
        Some(out)
    }

    pub fn residual(&self, w: &[f64]) -> Option<DVector<f64>> {
        self.residual_with(&*self.orbit(w[w.len() - 1] * self.rho)?, w)
    }

    /// [∂F/∂w]: the state and time columns from the variational flow of one period
    /// ([`PolishedOrbit::shooting_jacobian`]; ∂τ_e/∂θ_e = T), the λ column by central differences
    /// on orbits rebuilt at λ ± h·ρ. By central differences throughout where the variational flow
    /// does not apply.
    pub fn jacobian(&self, w: &[f64]) -> Option<DMatrix<f64>> {
        self.jacobian_at(&*self.orbit(w[w.len() - 1] * self.rho)?, w)
    }

    /// [`Self::jacobian`] with the orbit at w's λ already built.
    fn jacobian_at(&self, here: &PolishedOrbit, w: &[f64]) -> Option<DMatrix<f64>> {
        self.jacobian_kept(here, w).map(|(j, _)| j)
    }

    /// [`Self::jacobian_at`] and its period's variation (for the monodromy of the orbit at w).
    fn jacobian_kept(&self, here: &PolishedOrbit, w: &[f64]) -> Option<(DMatrix<f64>, Option<KeptVariation>)> {
        let d = self.dim();
        let (y, times) = self.unpack(w, here.period());
        let mut j = DMatrix::zeros(d - 1, d);
        if let Some((_, dr, kept)) = timed(Stage::Variational, || here.shooting_jacobian_kept(&y, &times)) {
            for c in 0..d - 1 {
                let scale = if c < self.n2 { self.ys / self.weight[c] } else { here.period() };
                j.set_column(c, &(dr.column(c) * scale));
            }
            for r in 0..d - 1 {
                j.row_mut(r).scale_mut(self.row_scale(r));
            }
            // A re-impact's condition over its flight² (rigid.rs): F̃ = s(Δ)·F, dF̃ = s·dF + F·s'(Δ)·dΔ.
            let reimpacts = self.reimpacts();
            if !reimpacts.is_empty() {
                let f = self.residual_with(here, w)?;
                for (row, e, p, wrap) in reimpacts {
                    let flight = w[e] + wrap - w[p];
                    let (s, ds) = (super::rigid::reimpact_factor(flight), super::rigid::reimpact_factor_rate(flight));
                    let unscaled = f[row] / s;
                    j.row_mut(row).scale_mut(s);
                    j[(row, e)] += unscaled * ds;
                    j[(row, p)] -= unscaled * ds;
                }
            }
            let (mut up, mut dn) = (w.to_vec(), w.to_vec());
            up[d - 1] += DIFF;
            dn[d - 1] -= DIFF;
            let col = timed(Stage::LambdaColumn, || Some((self.residual(&up)? - self.residual(&dn)?) / (2.0 * DIFF)))?;
            j.set_column(d - 1, &col);
            return Some((j, Some(kept)));
        }
        for c in 0..d - 1 {
            let (mut up, mut dn) = (w.to_vec(), w.to_vec());
            up[c] += DIFF;
            dn[c] -= DIFF;
            let col = (self.residual_with(here, &up)? - self.residual_with(here, &dn)?) / (2.0 * DIFF);
            j.set_column(c, &col);
        }
        let (mut up, mut dn) = (w.to_vec(), w.to_vec());
        up[d - 1] += DIFF;
        dn[d - 1] -= DIFF;
        let col =
            (self.residual_with(&*self.orbit(up[d - 1] * self.rho)?, &up)? - self.residual_with(&*self.orbit(dn[d - 1] * self.rho)?, &dn)?) / (2.0 * DIFF);
        j.set_column(d - 1, &col);
        Some((j, None))
    }

    /// Newton on F(w) = 0, normal·w = target, from `pred`. Chord iterations first, with the
    /// Jacobian of the last point solved ([`Self::node_with`]) while they contract by
    /// [`CHORD_CONTRACTION`] or better; fresh Jacobians (Newton) from the first that does not.
    /// One Jacobian costs the variational flow and two orbits rebuilt at λ ± h, a chord
    /// iteration one residual: on the coarse blade a step's Jacobians were most of its cost.
    pub fn correct(&self, pred: &[f64], normal: &[f64], target: f64) -> Result<Vec<f64>, Failure> {
        self.correct_with(pred, normal, target, false)
    }

    /// [`Self::correct`] for a search's trial, which its caller moves when it fails: failing
    /// too where the corrections stall ([`Failure::Stalled`]).
    pub fn correct_trial(&self, pred: &[f64], normal: &[f64], target: f64) -> Result<Vec<f64>, Failure> {
        self.correct_with(pred, normal, target, true)
    }

    fn correct_with(&self, pred: &[f64], normal: &[f64], target: f64, stall: bool) -> Result<Vec<f64>, Failure> {
        let chord = self.chord.borrow().as_ref().filter(|c| c.key == self.key()).map(|c| c.jacobian.clone());
        if chord.is_some()
            && let Ok(w) = timed(Stage::Chord, || self.newton(pred, normal, target, chord, stall))
        {
            return Ok(w);
        }
        timed(Stage::Newton, || self.newton(pred, normal, target, None, stall))
    }

    /// The flight (its phase, from a pure impact to a re-impact of one contact with mass) whose
    /// re-impact time alone kept the last corrector from converging: its last correction the
    /// largest and every other one below [`ATTAINABLE`]. Over a flight Δ the clearance is
    /// O(jΔ³), so a short one's re-impact time is set by round-off (the coarse rigid blade at
    /// 2338.39 rad/s: contact 2's flight 1.8e-6 of the period, its time wandering by 1e-7 to
    /// 8e-6 each iteration while the state had converged).
    pub fn unresolved_flight(&self) -> Option<usize> {
        self.unresolved.get()
    }

    /// The flight whose re-impact time is the only unconverged component of the correction `dw`.
    fn unresolved_in(&self, dw: &DVector<f64>) -> Option<usize> {
        let worst = dw.iamax();
        let rest = dw.iter().enumerate().filter(|(i, _)| *i != worst).fold(0.0f64, |m, (_, v)| m.max(v.abs()));
        let (_, _, p, _) = self.reimpacts().into_iter().find(|r| r.1 == worst)?;
        (rest < ATTAINABLE).then_some(p - self.n2)
    }

    fn newton(&self, pred: &[f64], normal: &[f64], target: f64, chord: Option<DMatrix<f64>>, stall: bool) -> Result<Vec<f64>, Failure> {
        let fresh = chord.is_none();
        let mut corrections = Vec::new();
        let start = super::profile::newton_clock();
        let out = self.newton_with(pred, normal, target, (chord, stall), &mut corrections);
        super::profile::newton_call(fresh, &out, &corrections, start);
        out
    }

    fn newton_with(
        &self,
        pred: &[f64],
        normal: &[f64],
        target: f64,
        (mut chord, stall): (Option<DMatrix<f64>>, bool),
        corrections: &mut Vec<(f64, bool)>,
    ) -> Result<Vec<f64>, Failure> {
        let d = self.dim();
        let mut w = pred.to_vec();
        let mut last = f64::INFINITY;
        // The corrections of the iterations with fresh Jacobians, for the stall test.
        let mut newton_steps: Vec<f64> = Vec::new();
        self.unresolved.set(None);
        // The chord's bordered matrix is the same at every chord iteration: factorised once.
        let mut chord_lu: Option<LU<f64, Dyn, Dyn>> = None;
        let bordered = |jac: &DMatrix<f64>| {
            let mut a = DMatrix::zeros(d, d);
            a.view_mut((0, 0), (d - 1, d)).copy_from(jac);
            for c in 0..d {
                a[(d - 1, c)] = normal[c];
            }
            a.lu()
        };
        for iteration in 1..=MAX_ITERATIONS {
            let lambda = w[d - 1] * self.rho;
            let here = self.orbit(lambda).ok_or(Failure::Build { iteration, lambda })?;
            let f = self
                .residual_with(&here, &w)
                .ok_or_else(|| if self.ordered(&w, here.period()) { Failure::Residual { iteration } } else { Failure::Unordered { iteration } })?;
            let fresh = chord.is_none();
            let (jac, lu) = match &chord {
                Some(j) => (None, &*chord_lu.get_or_insert_with(|| bordered(j))),
                None => {
                    let jac = self.jacobian_at(&here, &w).ok_or(Failure::Jacobian { iteration })?;
                    let lu = bordered(&jac);
                    (Some(jac), &*chord_lu.insert(lu))
                }
            };
            let mut rhs = DVector::zeros(d);
            rhs.rows_mut(0, d - 1).copy_from(&(-&f));
            rhs[d - 1] = target - normal.iter().zip(&w).map(|(n, x)| n * x).sum::<f64>();
            let dw = lu.solve(&rhs).ok_or(Failure::Singular { iteration })?;
            self.unresolved.set(self.unresolved_in(&dw));
            w.iter_mut().zip(dw.iter()).for_each(|(x, s)| *x += s);
            let step = dw.amax();
            corrections.push((step, fresh));
            if !step.is_finite() || step > 1.0 {
                return Err(Failure::Diverged { iteration, correction: step });
            }
            // A chord step is exact to Θ/(1 − Θ) of itself: CONVERGED holds it below 1e-10/3.
            if step < CONVERGED || (step < ATTAINABLE && step >= last && f.amax() < NOISE_DEFECT) {
                if let Some(jac) = jac {
                    // The Jacobian of the last iterate, ‖Δw‖ away: the tangent's.
                    self.last_jacobian.replace(Some((w.clone(), jac)));
                }
                self.unresolved.set(None);
                return Ok(w);
            }
            if stall && fresh {
                newton_steps.push(step);
                let k = newton_steps.len();
                if k >= STALL_FROM && step >= newton_steps[k - 3] && step >= STALL_FLOOR {
                    return Err(Failure::Stalled { iteration, correction: step });
                }
            }
            if !fresh && step > CHORD_CONTRACTION * last && step >= ATTAINABLE {
                chord = None;
            }
            if chord.is_none() {
                chord_lu = None;
            }
            last = step;
        }
        Err(Failure::Exhausted { correction: last })
    }

    /// What a Jacobian depends on besides w: the signature and the state scale.
    fn key(&self) -> ChordKey {
        (self.signature_key(), self.ys)
    }

    fn signature_key(&self) -> SignatureKey {
        (self.sig.events.iter().map(|e| (e.contact, e.kind)).collect(), self.sig.always.clone())
    }

    /// The unit tangent of the branch at w: [J; (G·prev)ᵀ] t = e_last, oriented along `prev` in
    /// the arclength's metric G, as the walk's steps are. Oriented in the unknowns' own product, a
    /// point located between two steps (a grazing's, a fold's) could get the reverse of the walk's
    /// sense where the stiff components, which the metric leaves out, turn: a fold recorded with λ
    /// still increasing (the coarse rigid blade at 2481.59 and five more, validation/RECORD.md).
    pub fn tangent(&self, jac: &DMatrix<f64>, prev: &[f64]) -> Option<Vec<f64>> {
        let d = self.dim();
        let border = self.metric.lower(prev);
        let mut a = DMatrix::zeros(d, d);
        a.view_mut((0, 0), (d - 1, d)).copy_from(jac);
        for c in 0..d {
            a[(d - 1, c)] = border[c];
        }
        let mut e = DVector::zeros(d);
        e[d - 1] = 1.0;
        let t = a.lu().solve(&e)?;
        let norm = t.norm();
        (norm.is_finite() && norm > 0.0).then(|| t.iter().map(|x| x / norm).collect())
    }

    /// The point at the solution `w`: its tangent (oriented along `prev`), orbit, multipliers and
    /// touches (none unless `touches`: a bisection for a multiplier event does not need them).
    pub fn node(&self, w: Vec<f64>, prev: &[f64]) -> Option<Node> {
        self.node_with(w, prev, true)
    }

    pub fn node_with(&self, w: Vec<f64>, prev: &[f64], touches: bool) -> Option<Node> {
        timed(Stage::Node, || self.solved(w, prev, touches))
    }

    /// The orbit at the solution `w` and its touches (when `touches`), without the tangent (`prev`
    /// stands for it) nor the multipliers: a bisection's trial point for a test of the orbit
    /// alone. The tangent's Jacobian and the monodromy's Schur form were two thirds of a trial.
    pub fn orbit_node(&self, w: Vec<f64>, prev: &[f64], touches: bool) -> Option<Node> {
        timed(Stage::Node, || {
            let orbit = self.exact_orbit(Rc::unwrap_or_clone(self.orbit(w[w.len() - 1] * self.rho)?), &w, false)?;
            let touches = if touches { orbit.touches() } else { Vec::new() };
            Some(Node { w, tangent: prev.to_vec(), orbit, mu: Vec::new(), touches, amplitude: Vec::new(), margin: Default::default() })
        })
    }

    /// The orbit at the solution `w` (its events' states and impulses) from `orbit`, the one built
    /// at w's λ, its defect recorded; its monodromy made now when `monodromy`, else where asked.
    fn exact_orbit(&self, orbit: PolishedOrbit, w: &[f64], monodromy: bool) -> Option<PolishedOrbit> {
        self.exact_orbit_kept(orbit, w, monodromy, None)
    }

    /// [`Self::exact_orbit`], its monodromy from `kept` (the variation of a Jacobian at w).
    fn exact_orbit_kept(&self, orbit: PolishedOrbit, w: &[f64], monodromy: bool, kept: Option<KeptVariation>) -> Option<PolishedOrbit> {
        let (y, times) = self.unpack(w, orbit.period());
        let defect = self.residual_with(&orbit, w)?.amax() * self.ys;
        if monodromy { orbit.at_kept(&y, &times, defect, kept).ok() } else { orbit.at_states(&y, &times, defect).ok() }
    }

    /// [`Self::node_with`] without the multipliers (nor touches): a secant's trial point whose
    /// orbit alone is read (a landing force), the next corrector's chord set as a point sets it,
    /// so that the iterates are a point's bit for bit. The trials' monodromies and their Schur
    /// forms were a tenth of the coarse rigid walk.
    pub fn trial_node(&self, w: Vec<f64>, prev: &[f64]) -> Option<Node> {
        timed(Stage::Node, || self.solved_as(w, prev, false, false))
    }

    fn solved(&self, w: Vec<f64>, prev: &[f64], touches: bool) -> Option<Node> {
        self.solved_as(w, prev, touches, true)
    }

    fn solved_as(&self, w: Vec<f64>, prev: &[f64], touches: bool, multipliers: bool) -> Option<Node> {
        // One orbit built at w's λ for the Jacobian and the point (two builds before).
        let here = self.orbit(w[w.len() - 1] * self.rho)?;
        let (jac, kept) = match self.last_jacobian.take() {
            Some((at, j)) if at == w => (j, None),
            _ => self.jacobian_kept(&here, &w)?,
        };
        let tangent = self.tangent(&jac, prev)?;
        if std::env::var_os("PC_TRACE_FOLD").is_some() && prev.iter().zip(&tangent).map(|(p, x)| p * x).sum::<f64>() < 0.0 {
            let l = w[w.len() - 1] * self.rho;
            eprintln!(
                "fold trace: at λ {l:.10} the metric orients the tangent against the unknowns' product (its λ component {:e})",
                tangent[tangent.len() - 1]
            );
        }
        self.chord.replace(Some(Chord { key: self.key(), jacobian: jac }));
        let orbit = self.exact_orbit_kept(Rc::unwrap_or_clone(here), &w, multipliers, kept)?;
        if !multipliers {
            return Some(Node { w, tangent, orbit, mu: Vec::new(), touches: Vec::new(), amplitude: Vec::new(), margin: Default::default() });
        }
        let mu = floquet::multipliers(orbit.monodromy());
        // No multipliers (the Schur iteration did not converge): no point, the step is shortened.
        if mu.iter().any(|m| !m.is_finite()) {
            return None;
        }
        let touches = if touches { orbit.touches() } else { Vec::new() };
        Some(Node { w, tangent, orbit, mu, touches, amplitude: Vec::new(), margin: Default::default() })
    }
}

/// The weights of the state (q, v) in the unknowns, so that a unit of each is a like share of the
/// orbit's energy: displacements times the forcing frequency ω, velocities times ω/max(ω_i, ω)
/// with ω_i = √((K_ii + Σ k_c b_ci²)/M_ii) the DOF's own frequency, its compliant contacts
/// closed (an estimate of its stiffest mode: the energy norm's ½(kq² + mv²) weighs a velocity
/// error of a mode of frequency ω_i as a displacement error v/ω_i). Unweighted, the coarse
/// blade's contact DOFs' velocities (ω_c/ω ≈ 270) carried the corrector's round-off (1e-10 of
/// the scale, the displacement rows at 1e-15) and turned the branch's tangent in their fast
/// phase, where their energy is nil.
fn state_weights(model: &Model) -> Vec<f64> {
    let (n, omega) = (model.n(), model.frequency.abs().max(1e-300));
    let mut k: Vec<f64> = (0..n).map(|i| model.structure.stiffness.get(i, i)).collect();
    for c in &model.contacts {
        if let Compliance::Compliant { stiffness } = c.compliance {
            c.row.iter().for_each(|&(d, b)| k[d] += stiffness * b * b);
        }
    }
    let own = |i: usize| (k[i] / model.structure.mass.get(i, i)).sqrt();
    let velocity = |i: usize| {
        let w = own(i);
        if w.is_finite() && w > omega { omega / w } else { 1.0 }
    };
    (0..n).map(|_| omega).chain((0..n).map(velocity)).collect()
}

#[cfg(test)]
pub(crate) mod tests;
