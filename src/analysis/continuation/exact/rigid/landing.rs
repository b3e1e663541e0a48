//! Where a sticking impact's landing force crosses zero (a sticking arc's start grazing: the
//! landing turns into a pure impact and a micro-flight), located on that force itself. The
//! rigid margin lets the held orbit go on while its micro-flight's height is below 1e-9 of the
//! clearance scale (polish's `lift_off`), so a bisection on the margin's sign finds where the
//! flight becomes visible (the impact oscillator: 8.1e-6 before the closed form's change), not
//! the change of topology.
use super::super::family::{Family, Node, Signature, lambda_axis};
use super::super::{BRACKET, EventKind, Walk, profile, signature};
use super::trace::trace;
use super::{TOL, margin};
use crate::analysis::polish;
use crate::analysis::polish::Event;

/// A landing force this small (of the force scale) is its zero: the corrector's round-off.
const ZERO: f64 = 1e-13;
/// Secant or Illinois steps at most.
const STEPS: usize = 40;
/// A secant step without a bracket goes at most this many times the last step's length.
const REACH: f64 = 8.0;
/// A merge's zero farther ahead than this (of ρ) is not this merge's: the held orbit traced that
/// far passes other contacts' changes unchecked (the coarse rigid blade from 2340.02 rad/s: a zero
/// at 2365.31, 24 changes skipped). `merge`'s own search ahead reaches 1e-2 too.
const AHEAD: f64 = 1e-2;
/// A trial whose corrector fails is moved halfway back towards the point it starts from, at most
/// this many times (2^-16 of the step).
const HALVINGS: usize = 16;

/// The event `e` of `n`'s orbit is a sticking impact whose holding force is negative at its
/// landing, and the margin is that landing's lift-off: `Some(e)`.
pub(in super::super) fn lifted(n: &Node) -> Option<usize> {
    let m = n.rigid_margin()?;
    if m.what != polish::STUCK || m.event.is_some() {
        return None;
    }
    let e = super::landing(n, m.contact, m.time)?;
    (n.orbit.landing_force(e)? < 0.0).then_some(e)
}

/// The zero of the force holding the contact of the family's sticking impact `e` just after its
/// landing, on the orbits of the family's signature corrected at λ fixed (from the unknowns
/// `from`): secant steps on λ from `la` and `lb`, Illinois once the zero is bracketed (Dowell &
/// Jarratt 1971), to [`BRACKET`] of the range or a force below [`ZERO`]. The node there, its
/// tangent along λ's `sense`, and the force's rate per unit λ (its sign: the side where the
/// landing holds). `None` where the corrector fails or no zero is found.
pub(in super::super) fn landing_zero(fam: &Family, from: &[f64], e: usize, (la, lb): (f64, f64), sense: f64) -> Option<(Node, f64)> {
    let start = profile::newton_clock();
    let out = landing_zero_in(fam, from, e, (la, lb), sense);
    profile::search_done("landing", la, out.as_ref().map(|z| z.0.lambda(fam.rho)), start);
    out
}

fn landing_zero_in(fam: &Family, from: &[f64], e: usize, (la, lb): (f64, f64), sense: f64) -> Option<(Node, f64)> {
    let (rho, d) = (fam.rho, fam.dim());
    let e_l = lambda_axis(d);
    let at = |w0: &[f64], lambda: f64| -> Option<(Vec<f64>, f64)> {
        let mut g = w0.to_vec();
        g[d - 1] = lambda / rho;
        let w = profile::caller("landing", (lambda / rho - w0[d - 1]).abs(), || fam.correct_trial(&g, &e_l, lambda / rho)).ok()?;
        let n = fam.trial_node(w, &e_l)?;
        let h = n.orbit.landing_force(e)?;
        trace(format_args!("landing zero: λ {lambda:.13}, force {h:e} of the scale"));
        Some((n.w, h))
    };
    // A trial λ too far from its start for the corrector (the coarse rigid blade at 2398.27 rad/s:
    // the first trial 0.075 rad/s on, the zero 6e-7 rad/s on) is moved halfway back, in turn.
    let toward = |w0: &[f64], l0: f64, mut l: f64| -> Option<(f64, f64, Vec<f64>)> {
        for _ in 0..=HALVINGS {
            if let Some((w, h)) = at(w0, l) {
                return Some((l, h, w));
            }
            l = 0.5 * (l0 + l);
        }
        None
    };
    let (wa, ha) = at(from, la)?;
    let b = toward(&wa, la, lb)?;
    let (lb, hb) = (b.0, b.1);
    let (mut a, mut b) = ((la, ha, wa), b);
    let rate = (hb - ha) / (lb - la);
    for _ in 0..STEPS {
        if b.1.abs() < ZERO || (a.0 - b.0).abs() <= BRACKET * rho {
            break;
        }
        let bracketed = a.1 * b.1 < 0.0;
        let mut l = b.0 - b.1 * (b.0 - a.0) / (b.1 - a.1);
        if !l.is_finite() {
            return None;
        }
        if !bracketed {
            let span = REACH * (b.0 - a.0).abs();
            l = l.clamp(b.0 - span, b.0 + span);
        }
        let (l, h, w) = toward(&b.2, b.0, l)?;
        if bracketed && h * b.1 > 0.0 {
            // Illinois: the end kept has its value halved.
            b = (l, h, w);
            a.1 *= 0.5;
        } else {
            a = std::mem::replace(&mut b, (l, h, w));
        }
    }
    if b.1.abs() >= ZERO && (a.0 - b.0).abs() > BRACKET * rho {
        return None;
    }
    // The side where the landing holds (h ≥ 0), when bracketed, unless the last is the zero to
    // round-off: the other end may be a whole secant step back (3.4e-6 rad/s on the coarse rigid
    // blade at 2216.26), which put the located grazing where the step path led (validation/RECORD.md).
    let best = if a.1 * b.1 < 0.0 && b.1 < 0.0 && b.1.abs() >= ZERO { a } else { b };
    let rate = if rate.is_finite() && rate != 0.0 { rate } else { -sense };
    let prev: Vec<f64> = e_l.iter().map(|x| x * sense).collect();
    Some((fam.node(best.2, &prev)?, rate))
}

impl Walk<'_> {
    /// A pure impact and the sticking impact after it merge at `here` (the corrector stalls on
    /// the flight between them) while the merged orbit (signature `list`, its sticking impact
    /// `k`) is still held at its landing by a negative force, its micro-flight below resolution:
    /// the merge is where that force crosses zero, ahead along the walk (the impact oscillator:
    /// the stall 8.1e-6 before the closed form's change). The branch goes on there on the merged
    /// orbit, the grazing recorded. `None` where the force holds already or no zero is found.
    pub(in super::super) fn held_merge(&mut self, here: &Node, list: &[(f64, Event)], k: usize, what: &str) -> Option<Node> {
        let (rho, lambda) = (self.fam.rho, here.lambda(self.fam.rho));
        let sense = here.tangent[here.tangent.len() - 1].signum();
        let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: here.orbit.always_closed().to_vec() };
        let guess = signature::guess(&self.fam, &here.orbit, list, here.w[here.w.len() - 1]);
        let before = self.fam.ne();
        let old = std::mem::replace(&mut self.fam.sig, sig);
        let d = self.fam.dim();
        let e_l = lambda_axis(d);
        let held = profile::caller("held", f64::NAN, || self.fam.correct(&guess, &e_l, lambda / rho)).ok().and_then(|w| self.fam.node_with(w, &e_l, false));
        let zero = held
            .filter(|n| n.orbit.landing_force(k).is_some_and(|h| h < 0.0))
            .and_then(|n| landing_zero(&self.fam, &n.w, k, (lambda, lambda + sense * 1e-4 * rho), sense))
            .map(|z| z.0)
            .filter(|z| margin(z) >= -TOL && (z.lambda(rho) - lambda) * sense >= -BRACKET * rho && (z.lambda(rho) - lambda).abs() <= AHEAD * rho);
        match zero {
            Some(z) => {
                let detail = format!(
                    "{what}; events per period {before} -> {} (located on the orbit without the impact, where its landing force crosses zero)",
                    self.fam.ne()
                );
                self.push(&z, Some(EventKind::Grazing), detail);
                Some(z)
            }
            None => {
                self.fam.sig = old;
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::landing_zero;
    use crate::analysis::continuation::Parameter;
    use crate::analysis::continuation::exact::family::tests::forced_with_rigid_stop;
    use crate::analysis::continuation::exact::family::{Family, Signature, lambda_axis};
    use crate::analysis::polish::{self, EventKind};
    use crate::model::{Matrix, Structure};
    use crate::periodic::{PeriodicProblem, PeriodicSolver};

    /// The sticking oscillator of tests/rigid_branch.rs: m x'' + 0.1 x' + x = cos Ωt, x ≤ 0.5 (a
    /// rigid stop, plastic impacts), bds1 with 512 steps.
    fn sticking_oscillator(omega: f64) -> PeriodicProblem {
        let structure =
            Structure { mass: Matrix::from_rows(&[vec![1.0]]), stiffness: Matrix::from_rows(&[vec![1.0]]), damping: Some(Matrix::from_rows(&[vec![0.1]])) };
        forced_with_rigid_stop(structure, 0, 0.5, 512, omega)
    }

    /// The force holding the sticking oscillator at its landing crosses zero where its merged orbit
    /// (one sticking impact, then the release) and the orbit with a pure impact and a flight before
    /// the sticking one meet: at the closed form's change of regime, Ω = 0.6384152319 (src/exact/rigid.rs,
    /// by bisection on its regime in tests/rigid_branch.rs). Sought from Ω = 0.63 with the first
    /// trial far out, where the corrector fails (the coarse rigid blade at 2398.27 rad/s: a trial
    /// 0.075 rad/s on, the zero 6e-7 rad/s on, so the merge fell back to another contact's change
    /// and the walk turned back; validation/RECORD.md): the trial is moved back until it converges.
    #[test]
    fn the_landing_force_zero_is_found_past_a_trial_the_corrector_cannot_reach() {
        let p = sticking_oscillator(0.7);
        let r = PeriodicSolver::new(p.clone()).solve().expect("the grid solve at Ω = 0.7");
        let orbit = polish::polish(&p, &r).expect("the polish at Ω = 0.7");
        let e = orbit.events().iter().position(|x| x.kind == (EventKind::Impact { stick: true })).expect("a sticking impact at Ω = 0.7");
        let sig = Signature { events: orbit.events().to_vec(), always: orbit.always_closed().to_vec() };
        let mut fam = Family::new(p.model(), Parameter::Frequency, 1.0, 1.0, sig);
        fam.ys = fam.scale_of(orbit.initial_state());
        let w = fam.correct(&fam.pack(&orbit, 0.7), &lambda_axis(fam.dim()), 0.7).expect("closed at Ω = 0.7");
        let closed_form = 0.638_415_231_9;
        for far in [0.66, 2.0, 6.0] {
            let (z, rate) = landing_zero(&fam, &w, e, (0.63, far), 1.0).unwrap_or_else(|| panic!("no zero with the first trial at Ω = {far}"));
            let at = z.lambda(1.0);
            eprintln!("first trial at Ω = {far}: the landing force's zero at {at:.10} (closed form {closed_form}), its first secant's rate {rate:e}");
            assert!((at - closed_form).abs() < 1e-6, "the zero at Ω = {at}, the closed form's change at {closed_form}");
        }
    }
}
