//! Changes of the event signature of an orbit with rigid contacts (impacts with e = 0, sticking
//! arcs, releases): located on the exact orbit, then the new signature asked of the grid LCP.
//!
//! A change shows as the orbit's rigid margin ([`PolishedOrbit::rigid_margin`]) crossing zero
//! (a free contact's clearance touching zero: a new impact; a stuck contact's force touching
//! zero: a release inside the arc; an impulse fading to zero; a pure impact starting to stick),
//! or as a phase between two events of one rigid contact shrinking to nothing (a sticking arc
//! or a flight between two impacts vanishing). The change is located by bisection on the arc of
//! the old signature (to the bracket of the exact walk), and recorded as a grazing. The branch
//! beyond it is started from the grid LCP's orbit, polished, a short way past the change
//! ([`RESEED`] of the range, growing until the polish accepts the grid's signature): the
//! stretch between is not traced, and the grazing's detail says so.
use super::family::Node;
use super::{EventKind, Walk, bisect};
use crate::analysis::polish;
use crate::periodic::{PeriodicProblem, PeriodicSolver};

/// Margins above −this are admissible (the relative tolerance of the polish's own checks).
const TOL: f64 = 1e-9;
/// How far past a change the grid LCP is asked for the new signature (fractions of ρ), in turn.
const RESEED: [f64; 4] = [1e-4, 1e-3, 1e-2, 3e-2];

/// The node's rigid margin; +∞ without rigid contacts.
pub(super) fn margin(n: &Node) -> f64 {
    n.orbit.rigid_margin().map_or(f64::INFINITY, |m| m.value)
}

impl Walk<'_> {
    /// Whether the event `e`'s contact is rigid (its vanishing phase is this module's).
    pub(super) fn rigid_event(&self, e: usize) -> bool {
        self.problem.model().contacts[self.fam.sig.events[e].contact].is_rigid()
    }

    /// `next` breaks the signature that holds at `here`: the change located between them, the
    /// multiplier events before it recorded, and the first point of the branch past it.
    pub(super) fn rigid_crossing(&mut self, here: &Node, next: &Node, to: f64) -> Option<Node> {
        let (lo, _) = bisect(&self.fam, here, next, &|n| margin(n) >= -TOL, false)?;
        for (kind, node, detail) in self.events_between(here, &lo) {
            self.push(&node, Some(kind), detail);
        }
        let m = lo.orbit.rigid_margin()?;
        let what = format!("contact {}: the {} reaches zero", m.contact, m.what);
        self.reseed(&lo, &what, to)
    }

    /// A phase between two events of one rigid contact has vanished at `here` (phase `e`).
    pub(super) fn rigid_vanish(&mut self, here: &Node, e: usize, to: f64) -> Option<Node> {
        let ev = self.fam.sig.events[e];
        let what = format!(
            "contact {}: its {} phase vanishes",
            ev.contact,
            if matches!(ev.kind, polish::EventKind::Impact { stick: true }) { "sticking" } else { "free" }
        );
        self.reseed(here, &what, to)
    }

    /// The corrector stalls at `here` with the smallest step on an orbit with rigid contacts:
    /// events merging (a flight between two impacts shrinking as the second impact fades, a pure
    /// impact starting to stick), where the old signature's Jacobian turns singular. `None`
    /// without rigid contacts.
    pub(super) fn rigid_stall(&mut self, here: &Node, to: f64) -> Option<Node> {
        let m = here.orbit.rigid_margin()?;
        let what = format!("the events merge (the corrector stalls; the smallest margin: contact {}'s {}, {:.1e})", m.contact, m.what, m.value);
        self.reseed(here, &what, to)
    }

    /// Records the grazing at `at` and starts the branch past it from the grid LCP's orbit,
    /// polished, at λ a short way further along the branch's direction (not beyond `to`).
    fn reseed(&mut self, at: &Node, what: &str, to: f64) -> Option<Node> {
        let rho = self.fam.rho;
        let lambda = at.lambda(rho);
        let sense = at.tangent[at.tangent.len() - 1].signum();
        let sense = if sense == 0.0 { (to - lambda).signum() } else { sense };
        let before = self.fam.ne();
        for f in RESEED {
            let mut l = lambda + sense * f * rho;
            if (l - to) * (to - lambda).signum() > 0.0 && (to - lambda) * sense > 0.0 {
                l = to;
            }
            let Some(orbit) = grid_orbit(self.problem, self.fam.param, l) else { continue };
            let sig = super::family::Signature { events: orbit.events().to_vec(), always: orbit.always_closed().to_vec() };
            let old = std::mem::replace(&mut self.fam.sig, sig);
            let d = self.fam.dim();
            let e_l: Vec<f64> = (0..d).map(|i| if i + 1 == d { 1.0 } else { 0.0 }).collect();
            let prev: Vec<f64> = e_l.iter().map(|x| x * sense).collect();
            let node = self.fam.correct(&self.fam.pack(&orbit, l), &e_l, l / rho).and_then(|w| self.fam.node(w, &prev));
            match node {
                Some(n) if margin(&n) >= -TOL => {
                    let detail = format!(
                        "{what}; events per period {before} -> {} (the new signature from the grid LCP at λ = {l}, the branch between not traced)",
                        self.fam.ne()
                    );
                    self.push(at, Some(EventKind::Grazing), detail);
                    return Some(n);
                }
                _ => self.fam.sig = old,
            }
        }
        None
    }
}

/// The polished orbit of the grid LCP's solve at λ, or `None`.
fn grid_orbit(problem: &PeriodicProblem, param: super::Parameter, lambda: f64) -> Option<polish::PolishedOrbit> {
    let mut p = problem.clone();
    param.apply(&mut p, lambda).ok()?;
    let r = PeriodicSolver::new(p.clone()).solve().ok()?;
    polish::polish(&p, &r).ok()
}
