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
use super::family::{Node, Signature};
use super::{EventKind, Walk, bisect};
use crate::analysis::polish::{self, Event};
use crate::periodic::{PeriodicProblem, PeriodicSolver};
use crate::time::Discretization;

/// Margins above −this are admissible (the relative tolerance of the polish's own checks).
const TOL: f64 = 1e-9;
/// The trial step that orients a restarted branch (scaled unknowns).
const TRIAL: f64 = 1e-3;
/// How far past a change the grid LCP is asked for the new signature (fractions of ρ), in turn.
const RESEED: [f64; 6] = [1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1];
/// The grid is refined this many times over when its orbit's events cannot be polished (an LCP
/// arc a few instants long near the change), for models of at most [`REFINE_DOFS`] DOFs.
const REFINE: usize = 4;
const REFINE_DOFS: usize = 64;

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
        // Where the bisection's corrector fails (close to a singular event), from the bracket itself.
        let (lo, hi) = bisect(&self.fam, here, next, &|n| margin(n) >= -TOL, false).unwrap_or_else(|| (here.clone(), next.clone()));
        for (kind, node, detail) in self.events_between(here, &lo) {
            self.push(&node, Some(kind), detail);
        }
        let m = hi.orbit.rigid_margin()?;
        let what = format!("contact {}: the {} reaches zero", m.contact, m.what);
        // A new pure impact where the clearance touches zero; an impact whose impulse fades, removed.
        let t = lo.orbit.period();
        let mut list: Vec<(f64, Event)> = lo.orbit.events().iter().zip(lo.orbit.times()).map(|(e, &s)| (s / t, *e)).collect();
        let changed = match (m.what, m.event) {
            (polish::CLEARANCE, _) => {
                let base = list.first().map_or(0.0, |l| l.0);
                let at = base + (m.time / t - base).rem_euclid(1.0);
                list.push((at, Event { contact: m.contact, kind: polish::EventKind::Impact { stick: false }, seed: 0.0 }));
                list.sort_by(|x, y| x.0.total_cmp(&y.0));
                true
            }
            ("impulse of the impact", Some(e)) if lo.orbit.events()[e].kind == (polish::EventKind::Impact { stick: false }) => {
                list.remove(e);
                true
            }
            _ => false,
        };
        if changed && let Some(n) = self.restart(&lo, list, &what) {
            return Some(n);
        }
        self.reseed(&lo, &what, to)
    }

    /// The branch of the signature `list` (events at fractions of the period) through the orbit
    /// of `at` (a zero-velocity impact added or removed leaves the orbit as it is): corrected at
    /// λ fixed, oriented towards the side where the orbit is admissible (λ's sense first).
    fn restart(&mut self, at: &Node, list: Vec<(f64, Event)>, what: &str) -> Option<Node> {
        let rho = self.fam.rho;
        let lambda = at.lambda(rho);
        let t = at.orbit.period();
        let t0 = list.first().map_or(0.0, |l| l.0 * t);
        let mut guess: Vec<f64> = at.orbit.state(t0).iter().map(|y| y / self.fam.ys).collect();
        guess.extend(list.iter().map(|l| l.0));
        guess.push(lambda / rho);
        let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: at.orbit.always_closed().to_vec() };
        let before = self.fam.ne();
        let old = std::mem::replace(&mut self.fam.sig, sig);
        let d = self.fam.dim();
        let e_l: Vec<f64> = (0..d).map(|i| if i + 1 == d { 1.0 } else { 0.0 }).collect();
        let sense = at.tangent[at.tangent.len() - 1].signum();
        let found = self.fam.correct(&guess, &e_l, lambda / rho).and_then(|w| {
            [sense, -sense].into_iter().find_map(|s| {
                let prev: Vec<f64> = e_l.iter().map(|x| x * s).collect();
                let n = self.fam.node(w.clone(), &prev)?;
                // A short step along the tangent must stay admissible.
                let pred: Vec<f64> = n.w.iter().zip(&n.tangent).map(|(w, t)| w + TRIAL * t).collect();
                let target: f64 = n.tangent.iter().zip(&pred).map(|(t, p)| t * p).sum();
                let trial = self.fam.correct(&pred, &n.tangent, target).and_then(|w| self.fam.node_with(w, &n.tangent, false))?;
                (margin(&trial) >= -TOL).then_some(n)
            })
        });
        match found {
            Some(n) => {
                let detail = format!("{what}; events per period {before} -> {}", self.fam.ne());
                self.push(at, Some(EventKind::Grazing), detail);
                Some(n)
            }
            None => {
                self.fam.sig = old;
                None
            }
        }
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
            let sig = Signature { events: orbit.events().to_vec(), always: orbit.always_closed().to_vec() };
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

/// The polished orbit of the grid LCP's solve at λ (on a [`REFINE`] times finer grid when the
/// scene's cannot be polished), or `None`.
fn grid_orbit(problem: &PeriodicProblem, param: super::Parameter, lambda: f64) -> Option<polish::PolishedOrbit> {
    let mut p = problem.clone();
    param.apply(&mut p, lambda).ok()?;
    let solve = |p: &PeriodicProblem| PeriodicSolver::new(p.clone()).solve().ok().and_then(|r| polish::polish(p, &r).ok());
    if let Some(o) = solve(&p) {
        return Some(o);
    }
    if p.model().n() > REFINE_DOFS {
        return None;
    }
    let disc = p.discretization();
    p.set_discretization(Discretization { steps: REFINE * disc.steps, ..disc }).ok()?;
    solve(&p)
}
