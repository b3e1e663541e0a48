//! Where a sticking impact's landing force crosses zero (a sticking arc's start grazing: the
//! landing turns into a pure impact and a micro-flight), located on that force itself. The
//! rigid margin lets the held orbit go on while its micro-flight's height is below 1e-9 of the
//! clearance scale (polish's `lift_off`), so a bisection on the margin's sign finds where the
//! flight becomes visible (the impact oscillator: 8.1e-6 before the closed form's change), not
//! the change of topology.
use super::super::family::{Family, Node, Signature, lambda_axis};
use super::super::{BRACKET, EventKind, Walk, signature};
use super::{TOL, margin};
use crate::analysis::polish;
use crate::analysis::polish::Event;

/// A landing force this small (of the force scale) is its zero: the corrector's round-off.
const ZERO: f64 = 1e-13;
/// Secant or Illinois steps at most.
const STEPS: usize = 40;
/// A secant step without a bracket goes at most this many times the last step's length.
const REACH: f64 = 8.0;

/// The event `e` of `n`'s orbit is a sticking impact whose holding force is negative at its
/// landing, and the margin is that landing's lift-off: `Some(e)`.
pub(in super::super) fn lifted(n: &Node) -> Option<usize> {
    let m = n.orbit.rigid_margin()?;
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
    let (rho, d) = (fam.rho, fam.dim());
    let e_l = lambda_axis(d);
    let at = |w0: &[f64], lambda: f64| -> Option<(Vec<f64>, f64)> {
        let mut g = w0.to_vec();
        g[d - 1] = lambda / rho;
        let w = fam.correct(&g, &e_l, lambda / rho)?;
        let n = fam.node_with(w, &e_l, false)?;
        let h = n.orbit.landing_force(e)?;
        Some((n.w, h))
    };
    let (wa, ha) = at(from, la)?;
    let (wb, hb) = at(&wa, lb)?;
    let (mut a, mut b) = ((la, ha, wa), (lb, hb, wb));
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
        let (w, h) = at(&b.2, l)?;
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
    // The side where the landing holds (h ≥ 0), when bracketed.
    let best = if a.1 * b.1 < 0.0 && b.1 < 0.0 { a } else { b };
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
        let held = self.fam.correct(&guess, &e_l, lambda / rho).and_then(|w| self.fam.node_with(w, &e_l, false));
        let zero = held
            .filter(|n| n.orbit.landing_force(k).is_some_and(|h| h < 0.0))
            .and_then(|n| landing_zero(&self.fam, &n.w, k, (lambda, lambda + sense * 1e-4 * rho), sense))
            .map(|z| z.0)
            .filter(|z| margin(z) >= -TOL && (z.lambda(rho) - lambda) * sense >= -BRACKET * rho);
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
