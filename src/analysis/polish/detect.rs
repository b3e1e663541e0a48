//! The exact orbit of compliant contacts by shooting with switch detection, for `sweep --exact`'s
//! next point: the unknown is the state at t = 0 (the same forcing phase at every ω, so the two
//! previous orbits give a secant predictor); one period is flowed exactly phase by phase, each
//! contact switching where its clearance changes sign (found on steps of a fraction of the
//! phase's fastest period, then by the Illinois method to round-off), so the event signature is
//! the flow's own and may change from one iteration (or point) to the next. A compliant switch
//! has identity saltation (continuous force), so the derivative of the state at T by the state at
//! 0 is the product of the phases' exponentials, as in validation/exact_flow.py's Newton shooting.
//! At convergence the orbit is the polish's ([`PolishedOrbit`] on the detected signature) and is
//! verified as the polish's is.
use super::events::{self, Event, EventKind};
use super::phase::Phase;
use super::{PolishFailure, PolishedOrbit, verify};
use crate::model::Model;
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

// The switch search on a phase's grid without a flow per step.
mod grid;
use grid::Grid;
// The phases kept across a sweep's points.
mod bank;
pub use bank::PhaseBank;

/// Switch-search steps per radian of a phase's fastest motion (its balancing speed, ≥ ω_max):
/// a sign change between steps is bracketed; a dip between two steps is left to the check.
const STEPS_PER_RADIAN: f64 = 2.0;
/// Newton iterations before the walk falls back to the signature-following polish.
const MAX_ITERATIONS: usize = 10;

/// Phases by closed set at one ω: `prev`'s re-tuned where it has the set (only the particular
/// solution depends on ω), else made and given `prev`'s eigendecomposition of the same matrix.
struct Flows<'a> {
    model: &'a Model,
    prev: &'a PolishedOrbit,
    /// The sets met at earlier points.
    bank: &'a PhaseBank,
    /// Whether `model` is `prev`'s at another frequency (the same structure and contacts).
    retune: bool,
    /// Whether `model` is the bank's system at another frequency.
    same_as_bank: bool,
    phases: Vec<Phase>,
    /// Each phase's switch-search grid.
    grids: Vec<Grid>,
    /// Each contact's gap harmonics (the grids' periodic parts).
    gaps: Vec<super::phase::Harmonics>,
    /// Phases made anew (not re-tuned), for the profile (a CPU tally per phase read /proc twice
    /// per phase: ~0.2 s of the sweep's walk).
    made: usize,
}

impl Flows<'_> {
    fn phase(&mut self, closed: &[usize]) -> Result<usize, PolishFailure> {
        if let Some(k) = self.phases.iter().position(|p| p.is_for(&[], closed)) {
            return Ok(k);
        }
        let banked = self.bank.find(self.same_as_bank, closed);
        let old = self.prev.phases.iter().find(|o| self.retune && o.is_for(&[], closed)).or(banked.map(|(p, _)| p));
        let p = match old {
            Some(o) => o.retuned(self.model),
            None => Phase::new(self.model, &[], closed).map(|mut p| {
                self.made += 1;
                if let Some(o) = self.prev.phases.iter().find(|o| o.same_matrix(&p)) {
                    p.share_modes(o);
                }
                p
            }),
        };
        let p = p.ok_or_else(|| PolishFailure("a phase's operator is singular at a forcing harmonic".into()))?;
        let h = 1.0 / (STEPS_PER_RADIAN * p.speed_hint().max(self.model.frequency));
        let fixed = match banked {
            Some((_, f)) if f.h == h => Arc::clone(f),
            _ => Arc::new(grid::Fixed::new(self.model, &p, h)),
        };
        self.grids.push(Grid::new(self.model, &p, fixed, &self.gaps));
        self.phases.push(p);
        Ok(self.phases.len() - 1)
    }
}

/// One period flowed from t = 0: the state at T, the switches (contact, kind, time, state there),
/// the contacts closed at 0, and the phases flowed with their spans (for the exponentials'
/// product over the period, made only for the shots whose Jacobian Newton takes: [`Shot::product`]).
struct Shot {
    end: DVector<f64>,
    switches: Vec<(Event, DVector<f64>)>,
    closed_at_start: Vec<usize>,
    spans: Vec<(usize, f64)>,
    last_phase: usize,
}

impl Shot {
    /// Π e^{A τ} over the shot's phases (massive free state), last phase leftmost.
    fn product(&self, phases: &[Phase]) -> DMatrix<f64> {
        let mut out: Option<DMatrix<f64>> = None;
        for &(k, tau) in &self.spans {
            let e = phases[k].exp(tau);
            out = Some(out.map_or_else(|| e.clone(), |p| &e * p));
        }
        out.expect("one phase at least")
    }

    /// The contacts closed all period (closed at 0, never switched).
    fn always_closed(&self) -> Vec<usize> {
        self.closed_at_start.iter().copied().filter(|i| !self.switches.iter().any(|(e, _)| e.contact == *i)).collect()
    }
}

/// The orbit of `model` (a sweep's next ω) from the predicted state `start` at t = 0, by Newton
/// shooting with switch detection (see the module); `prev` lends its phases' decompositions.
/// Only for models whose contacts are all compliant (identity saltation, no stuck DOFs).
pub fn follow_detected(model: &Model, prev: &PolishedOrbit, start: &[f64]) -> Result<PolishedOrbit, PolishFailure> {
    follow_detected_with(model, prev, start, &mut PhaseBank::default())
}

/// [`follow_detected`] with the phases of the sets met at earlier points (`bank`, which keeps
/// this point's too).
pub fn follow_detected_with(model: &Model, prev: &PolishedOrbit, start: &[f64], bank: &mut PhaseBank) -> Result<PolishedOrbit, PolishFailure> {
    if model.contacts.iter().any(|c| c.is_rigid()) || !model.frictions.is_empty() || !model.rubbing.is_empty() {
        return Err(PolishFailure("switch-detecting shooting: only for compliant contacts".into()));
    }
    let gaps = (0..model.contacts.len()).map(|i| super::phase::gap_harmonics(model, i)).collect();
    let retune = same_system(model, &prev.model);
    // The bank's system compared once per point (M, C, K: 3 n² comparisons), not per phase.
    let same_as_bank = bank.is_for(model);
    let mut flows = Flows { model, prev, bank, retune, same_as_bank, phases: Vec::new(), grids: Vec::new(), gaps, made: 0 };
    let out = newton(&mut flows, start);
    let phases = std::mem::take(&mut flows.phases);
    let kept = phases.into_iter().zip(flows.grids.iter().map(|g| Arc::clone(&g.fixed))).collect();
    bank.keep(model, kept);
    out
}

/// The Newton shooting of [`follow_detected`] on `flows`.
fn newton(flows: &mut Flows, start: &[f64]) -> Result<PolishedOrbit, PolishFailure> {
    let (model, prev) = (flows.model, flows.prev);
    let fail = |w: &str| PolishFailure(format!("switch-detecting shooting: {w}"));
    let carrier = PolishedOrbit::new(model, vec![], &[])?;
    let clock = std::time::Instant::now();
    let n2 = 2 * model.n();
    let w = carrier.weights().rows(0, n2).into_owned();
    let mut y = DVector::from_column_slice(start);
    let size = y.component_mul(&w).amax().max(1e-300);
    let floor = 1e-10 * size;
    let mut shot = shoot(&carrier, flows, &y)?;
    let mut r = &shot.end - &y;
    let mut iterations = 0;
    // The last Jacobian's factors: a correction below round-off by this chord ends Newton without
    // a new Jacobian and a confirming shot (the chord's step is the exact one's to O(‖Δy‖) relative).
    let mut chord: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> = None;
    let correction = loop {
        if let Some(du) = chord.as_ref().and_then(|lu| lu.solve(&(-&r))).filter(|du| du.component_mul(&w).amax() < 1e-12 * size) {
            break du.rows(0, model.n()).amax();
        }
        if iterations == MAX_ITERATIONS {
            // Near a grazing the flow's derivative is not Lipschitz and Newton may stall short
            // of round-off: the polish's Newton on the detected signature, its times as seeds.
            let why = format!("no convergence in {MAX_ITERATIONS} iterations (residual {:.2e})", r.component_mul(&w).amax());
            return settle_detected(model, prev, flows, shot).map_err(|e| fail(&format!("{why}; on its signature: {e}")));
        }
        // d y(T) / d y(0) = L_last (Π e^{A τ}) R: every phase shares the free basis (no stuck
        // contact), so R L_j = I between phases (phase.rs's `transition`).
        let m = flows.phases[shot.last_phase].transition(&shot.product(&flows.phases));
        let jac = m - DMatrix::identity(n2, n2);
        let lu = jac.lu();
        let du = lu.solve(&(-&r)).ok_or_else(|| fail("the monodromy has a multiplier 1"))?;
        chord = Some(lu);
        let before = r.component_mul(&w).amax();
        let mut lambda = 1.0;
        let (next, next_shot, rn) = loop {
            let cand = &y + &du * lambda;
            if let Ok(s) = shoot(&carrier, flows, &cand) {
                let rc = &s.end - &cand;
                let merit = rc.component_mul(&w).amax();
                if merit < before || merit < floor {
                    break (cand, s, rc);
                }
            }
            lambda *= 0.5;
            if lambda < 1e-3 {
                return Err(fail("Newton stalled"));
            }
        };
        iterations += 1;
        let correction = du.rows(0, model.n()).amax() * lambda;
        let step = (&du * lambda).component_mul(&w).amax();
        let stagnant = rn.component_mul(&w).amax() < floor && rn.component_mul(&w).amax() > 0.5 * before;
        (y, shot, r) = (next, next_shot, rn);
        if step < 1e-12 * size || stagnant {
            break correction;
        }
    };
    let residual = r.component_mul(&w).amax();
    super::profile(&format!("switch detection: {iterations} iterations, {} phases, {} made anew", flows.phases.len(), flows.made), clock);
    let orbit = assemble(model, prev, flows, shot, (iterations, residual, correction))?;
    super::profile("the orbit on the detected signature", clock);
    verify::check(&orbit)?;
    super::profile("admissibility check", clock);
    Ok(orbit)
}

/// Whether `a` and `b` differ at most in frequency (the same M, C, K and contacts).
fn same_system(a: &Model, b: &Model) -> bool {
    let (s, t) = (&a.structure, &b.structure);
    s.mass == t.mass && s.stiffness == t.stiffness && s.damping == t.damping && a.contacts == b.contacts
}

/// The polish's Newton on the signature of `shot` (its switch times as seeds), then the check.
fn settle_detected(model: &Model, prev: &PolishedOrbit, flows: &Flows, shot: Shot) -> Result<PolishedOrbit, PolishFailure> {
    let always = shot.always_closed();
    let evs = events::isolated_first(shot.switches.iter().map(|(e, _)| *e).collect(), model.period());
    let mut orbit = PolishedOrbit::reusing(model, evs, &always, &flows.phases)?;
    orbit.share_modes(prev);
    orbit.newton()?;
    verify::check(&orbit)?;
    Ok(orbit)
}

/// The polish's orbit on the detected signature at the converged state.
fn assemble(
    model: &Model,
    prev: &PolishedOrbit,
    flows: &Flows,
    shot: Shot,
    (iterations, residual, correction): (usize, f64, f64),
) -> Result<PolishedOrbit, PolishFailure> {
    let period = model.period();
    let always = shot.always_closed();
    let mut orbit = if shot.switches.is_empty() {
        let mut o = PolishedOrbit::reusing(model, vec![], &always, &flows.phases)?;
        o.y0 = shot.end;
        o
    } else {
        let evs: Vec<Event> = shot.switches.iter().map(|(e, _)| *e).collect();
        let evs = events::isolated_first(evs, period);
        // isolated_first shifts only the events before event 0 (by a period).
        let first = shot.switches.iter().position(|(e, _)| *e == evs[0]).unwrap_or(0);
        let mut o = PolishedOrbit::reusing(model, evs, &always, &flows.phases)?;
        o.y0 = shot.switches[first].1.clone();
        o
    };
    orbit.share_modes(prev);
    orbit.finish()?;
    orbit.iterations = iterations;
    orbit.residual = residual;
    orbit.correction = correction;
    Ok(orbit)
}

/// One period from `y0` at t = 0 with switch detection ([`Shot`]): each phase searched on its
/// grid of steps of 1/([`STEPS_PER_RADIAN`]·its fastest rate) from its start ([`grid::first_switch`]).
fn shoot(carrier: &PolishedOrbit, flows: &mut Flows, y0: &DVector<f64>) -> Result<Shot, PolishFailure> {
    let model = flows.model;
    let period = model.period();
    let m = model.contacts.len();
    let mut closed: Vec<usize> = (0..m).filter(|&i| carrier.clearance(i, y0, 0.0) < 0.0).collect();
    let closed_at_start = closed.clone();
    let (mut a, mut ya) = (0.0, y0.clone());
    let mut switches = Vec::new();
    let mut spans = Vec::new();
    let mut k = flows.phase(&closed)?;
    loop {
        let found = grid::first_switch(model, &flows.phases[k], &flows.grids[k], &closed, (a, &ya), period);
        let Some((i, ts, ys)) = found else {
            spans.push((k, period - a));
            let end = flows.phases[k].flow(a, &ya, period);
            return Ok(Shot { end, switches, closed_at_start, spans, last_phase: k });
        };
        spans.push((k, ts - a));
        let kind = if closed.contains(&i) { EventKind::Off } else { EventKind::On };
        if kind == EventKind::On {
            closed.push(i);
            closed.sort_unstable();
        } else {
            closed.retain(|&c| c != i);
        }
        switches.push((Event { contact: i, kind, seed: ts }, ys.clone()));
        (a, ya) = (ts, ys);
        k = flows.phase(&closed)?;
        if switches.len() > 64 * m.max(1) {
            return Err(PolishFailure("switch-detecting shooting: chattering (too many switches in one period)".into()));
        }
    }
}
