//! Changes of the event signature of an orbit with rigid contacts (impacts with e = 0, sticking
//! arcs, releases): located on the exact orbit, and the branch past them started there.
//!
//! A change shows as the orbit's rigid margin ([`PolishedOrbit::rigid_margin`]) crossing zero
//! (a free contact's clearance touching zero: a new impact; a stuck contact's force touching
//! zero: a release inside the arc, or a sticking impact landing where it is zero; an impulse
//! fading to zero; a pure impact starting to stick), or as a phase between two events of one
//! rigid contact shrinking to nothing (a sticking arc, a flight between two impacts or from a
//! release to an impact vanishing). The change is located by bisection on the arc of the old
//! signature (to the bracket of the exact walk), and recorded as a grazing. The new signature
//! differs by an event or a phase of zero length, so the orbit is the same there: the branch
//! goes on from it on the exact orbit. Where that fails (and for the changes not listed), the
//! branch is started from the grid LCP's orbit, polished, a short way past the change
//! ([`RESEED`] of the range, growing until the polish accepts the grid's signature): the
//! stretch between is not traced, and the grazing's detail says so.
//!
//! [`PolishedOrbit::rigid_margin`]: crate::analysis::polish::PolishedOrbit::rigid_margin
use super::family::{Node, Signature, lambda_axis};
use super::locate::{Test, locate};
use super::{BRACKET, EventKind, NEW_PAIR, Walk, signature};
use crate::analysis::polish::{self, Event, EventKind as Switch, Touch};
use crate::periodic::{PeriodicProblem, PeriodicSolver};
use crate::time::Discretization;

mod diagnose;
mod dip;
mod held;
mod landing;
mod stall;
mod touch;
mod trace;
pub(super) use dip::Behind;
use touch::touch_point;
use trace::trace;

/// Margins above −this are admissible (the relative tolerance of the polish's own checks).
const TOL: f64 = 1e-9;
/// The trial steps that orient a restarted branch (scaled unknowns), in turn: past an impact
/// added at a grazing on the coarse blade the next impact (the stiff modes ringing) comes
/// 0.003 rad/s further, closer than 1e-3 reaches.
const TRIAL: [f64; 3] = [1e-3, 1e-4, 1e-5];
/// How far past a change the grid LCP is asked for the new signature (fractions of ρ), in turn.
const RESEED: [f64; 6] = [1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1];
/// The grid is refined this many times over when its orbit's events cannot be polished (an LCP
/// arc a few instants long near the change), for models of at most [`REFINE_DOFS`] DOFs.
const REFINE: usize = 4;
const REFINE_DOFS: usize = 64;

/// The length (fraction of the period) of a phase started at a grazing ([`Walk::open_phase`]),
/// in turn until its first point is admissible.
const START_PHASE: [f64; 3] = [NEW_PAIR, 0.1 * NEW_PAIR, 0.01 * NEW_PAIR];

/// How far past a sticking arc's grazing start (fractions of ρ) the flight after its landing is
/// first sought, in turn ([`Walk::unmerge`]).
const UNMERGE: [f64; 5] = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2];

/// The flight (fraction of the period) below which a re-impact's condition is divided by the
/// flight²: after a plastic impact the contact's clearance and its rate are zero, so the
/// clearance at the re-impact Δ later is ½aΔ² + ⅙jΔ³ (a, j its acceleration and jerk after the
/// impact; Δ ≈ −3a/j), whose root at Δ = 0 is double. The condition itself turns tangent in its
/// time as Δ → 0 (the coarse blade at 2215.5 rad/s: Δ = 2.5e-6 and the corrector stalls);
/// over Δ² it is ½a + ⅙jΔ (Taylor at the impact), regular through the merge.
const REIMPACT_REF: f64 = 1e-4;

/// The factor 1 + (Δ_ref/Δ)² of a re-impact's condition after a flight Δ (fraction of the period).
pub(super) fn reimpact_factor(flight: f64) -> f64 {
    1.0 + (REIMPACT_REF / flight).powi(2)
}

/// d/dΔ of [`reimpact_factor`].
pub(super) fn reimpact_factor_rate(flight: f64) -> f64 {
    -2.0 * REIMPACT_REF * REIMPACT_REF / flight.powi(3)
}

/// A recorded point's rigid margin and events per period on the trace (`PC_TRACE_UNMERGE`):
/// an inadmissible orbit walked on shows there.
pub(super) fn trace_point(n: &Node, lambda: f64) {
    // The margin samples the whole period (≈ 8 % of the real blade's walk): only when traced.
    if !trace::tracing() {
        return;
    }
    trace(format_args!(
        "point: λ {lambda:.10}: {} events, margin {:?}",
        n.orbit.events().len(),
        n.rigid_margin().map(|m| (m.contact, m.what, m.value, m.time / n.orbit.period()))
    ));
}

impl Node {
    /// The orbit's rigid margin ([`polish::PolishedOrbit::rigid_margin`]), made once per point:
    /// a step's and a bisection's ends asked for it again (a sampled period each).
    pub fn rigid_margin(&self) -> Option<polish::RigidMargin> {
        self.margins().map(|m| m.least.clone())
    }

    /// The orbit's rigid margins, the least and each part's, made once per point.
    pub fn margins(&self) -> Option<&polish::RigidMargins> {
        self.margin.get_or_init(|| self.orbit.rigid_margins()).as_ref()
    }
}

/// The node's rigid margin; +∞ without rigid contacts.
pub(super) fn margin(n: &Node) -> f64 {
    n.rigid_margin().map_or(f64::INFINITY, |m| m.value)
}

impl Walk<'_> {
    /// Whether the event `e`'s contact is rigid (its vanishing phase is this module's).
    pub(super) fn rigid_event(&self, e: usize) -> bool {
        self.problem.model().contacts[self.fam.sig.events[e].contact].is_rigid()
    }

    /// `next` breaks the signature that holds at `here`: the change located between them, the
    /// multiplier events before it recorded, and the first point of the branch past it.
    /// `None` where the bisection fails and `retry` (the caller shortens its step): the bracket's
    /// start is no location (the real blade's 2299.5250 and 2286.4071 rad/s: step points, validation/RECORD.md).
    pub(super) fn rigid_crossing(&mut self, here: &Node, next: &Node, to: f64, retry: bool) -> Option<Node> {
        // Where the bisection's corrector fails (close to a singular event), from the bracket itself.
        let (lo, hi) = match locate(&self.fam, here, next, Test::Value(&|n| margin(n) + TOL), false) {
            Some(bracket) => bracket,
            None if retry => return None,
            None => (here.clone(), next.clone()),
        };
        for (kind, node, detail) in self.events_between(here, &lo) {
            self.push(&node, Some(kind), detail);
        }
        let m = hi.rigid_margin()?;
        let what = format!("contact {}: the {} reaches zero", m.contact, m.what);
        // A new pure impact where the clearance touches zero; an impact whose impulse fades, removed.
        let t = lo.orbit.period();
        let mut list = timed(&lo.orbit);
        let land = if m.what == polish::STUCK { landing(&lo, m.contact, m.time) } else { None };
        let massless = self.problem.model().contact_is_massless(&self.problem.model().contacts[m.contact]);
        let changed = match (m.what, m.event) {
            // A massless contact point's clearance touches zero: it closes without impulse and is
            // held, then released, a held arc of zero length there (the orbit is the same) that
            // grows on the exact orbit.
            (polish::CLEARANCE, _) if massless => {
                let touch = Touch { phase: 0, contact: m.contact, value: 0.0, time: m.time, closed: false };
                let kinds = (Switch::Impact { stick: true }, Switch::Release);
                let (sig, guess, pair) = signature::insert(&self.fam, &lo.orbit, &touch, kinds, NEW_PAIR, lo.w[lo.w.len() - 1]);
                if let Some(n) = self.start_phase(&lo, sig, &guess, pair, &what) {
                    return Some(n);
                }
                false
            }
            (polish::CLEARANCE, _) => {
                let base = list.first().map_or(0.0, |l| l.0);
                let at = base + (m.time / t - base).rem_euclid(1.0);
                list.push((at, Event { contact: m.contact, kind: Switch::Impact { stick: false }, seed: 0.0 }));
                list.sort_by(|x, y| x.0.total_cmp(&y.0));
                true
            }
            ("impulse of the impact", Some(e)) if lo.orbit.events()[e].kind == (Switch::Impact { stick: false }) => {
                list.remove(e);
                // Located on the orbit without the impact, regular where the impacting one is singular.
                let rho = self.fam.rho;
                if let Some(n) = self.fade((here.lambda(rho), next.lambda(rho)), &lo, list.clone(), &what, ("the impact", None)) {
                    return Some(n);
                }
                true
            }
            // A pure impact starts to stick: a sticking arc of zero length after it, ending in a
            // release (the orbit is the same), grows on the exact orbit.
            (polish::HOLD, Some(e)) => {
                list[e].1.kind = Switch::Impact { stick: true };
                list.insert(e + 1, (list[e].0 + NEW_PAIR, Event { contact: m.contact, kind: Switch::Release, seed: 0.0 }));
                if let Some(n) = self.begin_phase(&lo, &list, (e, e + 1), &what) {
                    return Some(n);
                }
                false
            }
            // A stuck contact's force touches zero inside its arc: a flight of zero length there,
            // from a release to a sticking impact (of zero impulse), grows on the exact orbit.
            (polish::STUCK, None) if land.is_some() => {
                let e = land.expect("guarded");
                let (rho, l0) = (self.fam.rho, lo.lambda(self.fam.rho));
                let sense = (next.lambda(rho) - here.lambda(rho)).signum();
                // The held orbit went on while its micro-flight was below resolution: the change
                // is where the landing force crosses zero, back towards `here` (or just behind).
                let back = if (here.lambda(rho) - l0).abs() > 1e-9 * rho { here.lambda(rho) } else { l0 - sense * 1e-4 * rho };
                // Not ahead of `lo`: the secant may run on to the next zero (2351.59 → 2354.03 rad/s, validation/RECORD.md).
                let zero = landing::landing_zero(&self.fam, &lo.w, e, (l0, back), sense).map(|z| z.0).filter(|z| (z.lambda(rho) - l0) * sense <= BRACKET * rho);
                if let Some(n) = self.unmerge(&lo, zero.as_ref(), e, sense, &what) {
                    return Some(n);
                }
                // The force touches zero where the sticking impact lands: the impact turns pure,
                // and a flight of zero length leads to the sticking impact.
                list[e].1.kind = Switch::Impact { stick: false };
                list.insert(e + 1, (list[e].0 + NEW_PAIR, Event { contact: m.contact, kind: Switch::Impact { stick: true }, seed: 0.0 }));
                if let Some(n) = self.begin_phase(&lo, &list, (e, e + 1), &what) {
                    return Some(n);
                }
                false
            }
            (polish::STUCK, None) => {
                let touch = Touch { phase: 0, contact: m.contact, value: 0.0, time: m.time, closed: true };
                let (sig, guess, pair) =
                    signature::insert(&self.fam, &lo.orbit, &touch, (Switch::Release, Switch::Impact { stick: true }), NEW_PAIR, lo.w[lo.w.len() - 1]);
                if let Some(n) = self.start_phase(&lo, sig, &guess, pair, &what) {
                    return Some(n);
                }
                false
            }
            _ => false,
        };
        if changed {
            let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: lo.orbit.always_closed().to_vec() };
            let guess = signature::guess(&self.fam, &lo.orbit, &list, lo.w[lo.w.len() - 1]);
            if let Some(n) = self.restart(&lo, sig, guess, &what) {
                return Some(n);
            }
        }
        self.reseed(&lo, &what, to)
    }

    /// The force holding the contact of the sticking impact `e` reaches zero where it lands at
    /// `lo` (the sticking arc's start grazes): past it (λ's `sense`) the impact is pure and the
    /// contact flies until its clearance comes back to zero, where it sticks. The flight grows
    /// like −3a/j, or like √(12a/|s|) where the clearance's jerk j at the landing is nil (a, s its
    /// acceleration and snap; rigid.rs of polish), so a first flight of fixed length (1e-5 of
    /// the period) lies a distance ∝ Δ² away in λ that the linear start misses, and a shorter
    /// one (1e-7 … 1e-8) has a clearance ½aΔ² below its round-off. Started instead at λ fixed a
    /// short way past `lo` ([`UNMERGE`] of ρ in turn): the old signature's orbit there (no longer
    /// admissible), its flight from the exact free flow's return
    /// ([`polish::PolishedOrbit::free_return`]), the new signature corrected at that λ.
    /// The grazing is recorded at `zero` (the landing force's zero, [`landing::landing_zero`]), in
    /// λ's order among the points of the held orbit walked past it, or at `lo` without it.
    fn unmerge(&mut self, lo: &Node, zero: Option<&Node>, e: usize, sense: f64, what: &str) -> Option<Node> {
        let (rho, d) = (self.fam.rho, self.fam.dim());
        let e_l = lambda_axis(d);
        let before = self.fam.ne();
        for f in UNMERGE {
            let l = lo.lambda(rho) + sense * f * rho;
            let mut g = lo.w.clone();
            g[d - 1] = l / rho;
            let Some(merged) =
                super::profile::caller("unmerge", f, || self.fam.correct(&g, &e_l, l / rho)).ok().and_then(|w| self.fam.node_with(w, &e_l, false))
            else {
                continue;
            };
            let (o, t) = (&merged.orbit, merged.orbit.period());
            let ne = o.times().len();
            let arc = if e + 1 < ne { o.times()[e + 1] - o.times()[e] } else { o.times()[0] + t - o.times()[e] };
            let flight = o.free_return(e, arc);
            trace(format_args!("unmerge: λ {l:.10} ({f:e} of ρ): flight {:?} of the period", flight.map(|x| x / t)));
            let Some(flight) = flight else { continue };
            let mut list = timed(o);
            let base = list[0].0;
            list[e].1.kind = Switch::Impact { stick: false };
            let at = list[e].0 + flight / t;
            list.push((if at >= base + 1.0 { at - 1.0 } else { at }, Event { contact: list[e].1.contact, kind: Switch::Impact { stick: true }, seed: 0.0 }));
            list.sort_by(|x, y| x.0.total_cmp(&y.0));
            let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: o.always_closed().to_vec() };
            let guess = signature::guess(&self.fam, o, &list, l / rho);
            let old = std::mem::replace(&mut self.fam.sig, sig);
            // One more unknown (the new event's time): λ is the last.
            let mut e_l1 = vec![0.0; guess.len()];
            e_l1[guess.len() - 1] = 1.0;
            let prev1: Vec<f64> = e_l1.iter().map(|x| x * sense).collect();
            let first = super::profile::caller("unmerge", f, || self.fam.correct(&guess, &e_l1, l / rho)).ok().and_then(|w| self.fam.node(w, &prev1));
            trace(format_args!("unmerge: corrected {}, margin {:?}", first.is_some(), first.as_ref().map(margin)));
            match first {
                Some(n) if margin(&n) >= -TOL => {
                    let held = zero.map_or(String::new(), |_| format!("; the landing force crosses zero here, the held orbit traced on to λ = {:.10} (its micro-flight below 1e-9 of the clearance scale)", lo.lambda(rho)));
                    let detail = format!(
                        "{what}{held}; events per period {before} -> {} (the flight after the landing started at λ = {l:.10}, {:.2e} of the period, from the free flow's return)",
                        self.fam.ne(),
                        flight / t
                    );
                    self.push_in_order(zero.unwrap_or(lo), EventKind::Grazing, detail, sense);
                    self.multipliers_across(lo, &n);
                    return Some(n);
                }
                _ => self.fam.sig = old,
            }
        }
        None
    }

    /// Records the event `kind` at `node`, before the last points that lie past it along λ's
    /// `sense` (walked on past the change before it was seen).
    fn push_in_order(&mut self, node: &Node, kind: EventKind, detail: String, sense: f64) {
        self.push(node, Some(kind), detail);
        let Some(p) = self.points.pop() else { return };
        let mut i = self.points.len();
        while i > 0 && self.points[i - 1].event.is_none() && (self.points[i - 1].parameter - p.parameter) * sense > 0.0 {
            i -= 1;
        }
        self.points.insert(i, p);
    }

    /// [`Self::start_phase`] for the time-ordered `list` (fractions of the period) of the orbit at `at`.
    fn begin_phase(&mut self, at: &Node, list: &[(f64, Event)], pair: (usize, usize), what: &str) -> Option<Node> {
        let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: at.orbit.always_closed().to_vec() };
        let guess = signature::guess(&self.fam, &at.orbit, list, at.w[at.w.len() - 1]);
        self.start_phase(at, sig, &guess, pair, what)
    }

    /// The branch of signature `sig` (unknowns `guess`) whose phase between the events `pair`
    /// begins at `at`, where it has zero length: its first point, the grazing recorded at `at`.
    fn start_phase(&mut self, at: &Node, sig: Signature, guess: &[f64], pair: (usize, usize), what: &str) -> Option<Node> {
        let before = self.fam.ne();
        // The first point lies where the phase is `len` long, which may be far in λ (a flight
        // growing slowly): the k = 1024 blade's contact 16 at 2287.578 rad/s, its 1e-5 flight
        // 0.37 rad/s on, past contact 2's grazing (margin −2.5e-5), and the walk went on blind on
        // that inadmissible branch to 2279.79. A shorter phase starts closer to the grazing.
        let mut first = None;
        for len in START_PHASE {
            let old = self.fam.sig.clone();
            let Some(n) = self.open_phase(sig.clone(), guess, pair, len) else { continue };
            trace(format_args!(
                "start phase {len:e}: first point λ {:.10} (the grazing at {:.10}), margin {:?}",
                n.lambda(self.fam.rho),
                at.lambda(self.fam.rho),
                n.rigid_margin().map(|m| (m.contact, m.what, m.value, m.time / n.orbit.period()))
            ));
            if margin(&n) >= -TOL {
                first = Some(n);
                break;
            }
            self.fam.sig = old;
        }
        let first = first?;
        let detail = format!("{what}; events per period {before} -> {} (the new phase started on the exact orbit)", self.fam.ne());
        self.push(at, Some(EventKind::Grazing), detail);
        self.multipliers_across(at, &first);
        Some(first)
    }

    /// An impact's impulse fades between `here` (positive) and `next` (negative): the grazing where
    /// it vanishes is the point where the orbit without it (signature `list`, events at fractions
    /// of the period as on `near`) touches the stop (Nordmark 1991: both orbits coincide there).
    /// Located by bisection in λ on that orbit, corrected at λ fixed (regular, unlike the impacting
    /// orbit whose impact velocity vanishes there), on the sign of its rigid margin between λ(here)
    /// and λ(next); the branch goes on towards the side where that margin is ≥ 0, which reverses λ
    /// when the impacting orbit and the admissible contact-free one lie on the same side (the
    /// unstable impacting orbit from a fold ending at the grazing). `None` without a sign change.
    /// With `own` (a merge of that contact's phase searched ahead), a change of another contact's
    /// margin is refused: it is the next change, not this one ([`touch_point`]).
    fn fade(&mut self, (la, lb): (f64, f64), near: &Node, list: Vec<(f64, Event)>, what: &str, (without, own): (&str, Option<usize>)) -> Option<Node> {
        let guess = signature::guess(&self.fam, &near.orbit, &list, 0.0);
        let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: near.orbit.always_closed().to_vec() };
        let before = self.fam.ne();
        let old = std::mem::replace(&mut self.fam.sig, sig);
        let located = touch_point(&mut self.fam, &guess, (la, lb), own);
        match located {
            Some(n) => {
                let detail = format!("{what}; events per period {before} -> {} (located on the orbit without {without})", self.fam.ne());
                self.push(&n, Some(EventKind::Grazing), detail);
                Some(n)
            }
            None => {
                self.fam.sig = old;
                None
            }
        }
    }

    /// The branch of the signature `sig` (unknowns `guess`) through the orbit of `at` (a
    /// zero-velocity impact added or removed, a vanished sticking arc or flight, leaves the orbit
    /// as it is): corrected at λ fixed, oriented towards the side where the orbit is admissible
    /// (λ's sense first).
    fn restart(&mut self, at: &Node, sig: Signature, guess: Vec<f64>, what: &str) -> Option<Node> {
        let rho = self.fam.rho;
        let lambda = at.lambda(rho);
        let before = self.fam.ne();
        let old = std::mem::replace(&mut self.fam.sig, sig);
        let d = self.fam.dim();
        let e_l = lambda_axis(d);
        let sense = at.tangent[at.tangent.len() - 1].signum();
        let corrected = super::profile::caller("restart", f64::NAN, || self.fam.correct(&guess, &e_l, lambda / rho)).ok();
        trace(format_args!(
            "restart at λ {lambda:.10}: {before} -> {} events, corrected at λ fixed: {}, margin there {:?}",
            self.fam.ne(),
            corrected.is_some(),
            corrected.as_ref().and_then(|w| self.fam.node_with(w.clone(), &e_l, false)).and_then(|n| n.rigid_margin().map(|m| (
                m.contact,
                m.what,
                m.value,
                m.event,
                m.time / n.orbit.period()
            )))
        ));
        let found = corrected.and_then(|w| {
            [sense, -sense].into_iter().find_map(|s| {
                let prev: Vec<f64> = e_l.iter().map(|x| x * s).collect();
                let n = self.fam.node(w.clone(), &prev)?;
                // A short step along the tangent must stay admissible.
                let admissible = TRIAL.iter().any(|step| {
                    let pred: Vec<f64> = n.w.iter().zip(&n.tangent).map(|(w, t)| w + step * t).collect();
                    let target: f64 = n.tangent.iter().zip(&pred).map(|(t, p)| t * p).sum();
                    let trial = super::profile::caller("restart", f64::NAN, || self.fam.correct(&pred, &n.tangent, target))
                        .ok()
                        .and_then(|w| self.fam.node_with(w, &n.tangent, false));
                    trace(format_args!(
                        "restart: sense {s}, trial {step:e}: λ {:?}, margin {:?}",
                        trial.as_ref().map(|t| t.lambda(rho)),
                        trial.as_ref().and_then(|t| t.rigid_margin().map(|m| (m.contact, m.what, m.value, m.event)))
                    ));
                    trial.is_some_and(|t| margin(&t) >= -TOL)
                });
                admissible.then_some(n)
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

    /// A phase between two events of one rigid contact has vanished at `here` (phase `e`): a
    /// sticking arc (the impact goes on as a pure one) or a flight from a release to a sticking
    /// impact (the contact stays stuck) is removed on the exact orbit; other phases restart from
    /// the grid LCP.
    pub(super) fn rigid_vanish(&mut self, here: &Node, e: usize, to: f64) -> Option<Node> {
        let ev = self.fam.sig.events[e];
        let what = format!("contact {}: its {} phase vanishes", ev.contact, if ev.kind == (Switch::Impact { stick: true }) { "sticking" } else { "free" });
        if let Some(n) = self.merge(here, e, &what) {
            return Some(n);
        }
        self.reseed(here, &what, to)
    }

    /// The branch past `here` without its phase `e` (between two events of one rigid contact,
    /// about to vanish), on the exact orbit; `None` for other phases or where that fails.
    pub(super) fn merge(&mut self, here: &Node, e: usize, what: &str) -> Option<Node> {
        let ne = self.fam.ne();
        let (ev, next) = (self.fam.sig.events[e], self.fam.sig.events[signature::partner(self.fam.base(), &self.fam.sig.events, e)?]);
        let wl = here.w[here.w.len() - 1];
        let mut list = timed(&here.orbit);
        let (rho, lambda) = (self.fam.rho, here.lambda(self.fam.rho));
        let sense = here.tangent[here.tangent.len() - 1].signum();
        let massless = self.problem.model().contact_is_massless(&self.problem.model().contacts[ev.contact]);
        let (sig, guess) = match (ev.kind, next.kind) {
            // A massless point's held arc vanishing: the free clearance's minimum touches zero (the
            // arc is where it would be negative, √ long in λ), so the point flies free past it:
            // closing and release removed, the orbit the same there (the inverse of
            // `rigid_crossing`'s massless arm). A pure impact has no meaning without mass.
            (Switch::Impact { stick: true }, Switch::Release) if massless => return self.merge_held_arc(here, e, what),
            // Located on the orbit with a pure impact, where the force that would hold its contact
            // touches zero, a short way ahead; else that orbit's branch from here.
            (Switch::Impact { stick: true }, Switch::Release) => {
                list[e].1.kind = Switch::Impact { stick: false };
                list.remove((e + 1) % ne);
                if let Some(n) = [1e-5, 1e-4, 1e-3]
                    .into_iter()
                    .find_map(|f| self.fade((lambda, lambda + sense * f * rho), here, list.clone(), what, ("the sticking arc", Some(ev.contact))))
                {
                    return Some(n);
                }
                let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: here.orbit.always_closed().to_vec() };
                (sig, signature::guess(&self.fam, &here.orbit, &list, wl))
            }
            (Switch::Release, Switch::Impact { stick: true }) => {
                let removed = signature::remove(&self.fam, &here.orbit, e, wl);
                trace::merge(here, &list, (e, ne), ev.contact, removed.is_some());
                removed?
            }
            // A pure impact and the sticking impact after it merge: located on the orbit without
            // the pure impact, where the force at its landing touches zero, a short way ahead;
            // else that orbit's branch from here (the coarse blade at 2215.5 rad/s: the flight
            // between them 2.5e-6 of the period when the corrector stalls, and no zero ahead).
            (Switch::Impact { stick: false }, Switch::Impact { stick: true }) => {
                list.remove(e);
                // The merged orbit held by a negative landing force: the merge is that force's
                // zero ahead (the coarse blade at 2316.83 rad/s: 2316.95), not where its
                // micro-flight becomes visible (2322.33, the force still −4.1e-4 there).
                if let Some(n) = self.held_merge(here, &list, if e + 1 < ne { e } else { 0 }, what) {
                    return Some(n);
                }
                // The flight vanishes where the merged orbit's force at its landing touches zero:
                // ahead by the flight over its rate of shrinking (the coarse blade at 2226.26 rad/s,
                // ρ = 30: a flight of 6.5e-7 of the period, the zero 0.03–0.3 rad/s ahead).
                let n2 = here.w.len() - 1 - ne;
                let b = (e + 1) % ne;
                let len = here.w[n2 + b] - here.w[n2 + e] + if b == 0 { 1.0 } else { 0.0 };
                let rate = here.tangent[n2 + e] - here.tangent[n2 + b];
                let ahead = if rate > 0.0 { (len / rate * here.tangent[here.tangent.len() - 1]).abs() } else { 0.0 };
                let mut reach = vec![1e-5, 1e-4, 1e-3, 1.5 * ahead, 3.0 * ahead, 1e-2];
                reach.retain(|f| *f > 0.0 && *f <= 1e-2);
                reach.sort_by(f64::total_cmp);
                if let Some(n) =
                    reach.into_iter().find_map(|f| self.fade((lambda, lambda + sense * f * rho), here, list.clone(), what, ("the impact", Some(ev.contact))))
                {
                    return Some(n);
                }
                let sig = Signature { events: list.iter().map(|l| l.1).collect(), always: here.orbit.always_closed().to_vec() };
                (sig, signature::guess(&self.fam, &here.orbit, &list, wl))
            }
            _ => return None,
        };
        self.restart(here, sig, guess, what)
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
            let Some(orbit) = grid_orbit(self.problem, self.fam.param, l) else {
                trace(format_args!("reseed: no grid orbit polished at λ {l}"));
                continue;
            };
            // A grazing changes one contact's phases; more (11 -> 0 events at 2397.64) is another branch.
            if signature::contacts_changed(orbit.events(), &self.fam.sig.events) > 1 {
                trace(format_args!("reseed at λ {l}: the grid orbit changes several contacts' phases (another branch): refused"));
                continue;
            }
            let sig = Signature { events: orbit.events().to_vec(), always: orbit.always_closed().to_vec() };
            let old = std::mem::replace(&mut self.fam.sig, sig);
            let d = self.fam.dim();
            let e_l = lambda_axis(d);
            let prev: Vec<f64> = e_l.iter().map(|x| x * sense).collect();
            let node =
                super::profile::caller("reseed", f, || self.fam.correct(&self.fam.pack(&orbit, l), &e_l, l / rho)).ok().and_then(|w| self.fam.node(w, &prev));
            trace(format_args!(
                "reseed at λ {l}: {} events, corrected {}, margin {:?}",
                self.fam.ne(),
                node.is_some(),
                node.as_ref().and_then(|n| n.rigid_margin().map(|m| (m.contact, m.what, m.value)))
            ));
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

/// The orbit's events with their times as fractions of the period.
pub(super) fn timed(orbit: &polish::PolishedOrbit) -> Vec<(f64, Event)> {
    let t = orbit.period();
    orbit.events().iter().zip(orbit.times()).map(|(e, &s)| (s / t, *e)).collect()
}

/// The sticking impact of contact `c` that lands at `time` (within 1e-9 of the period) on `n`'s orbit.
fn landing(n: &Node, c: usize, time: f64) -> Option<usize> {
    let t = n.orbit.period();
    let near = |s: f64| ((s - time) / t + 0.5).rem_euclid(1.0) - 0.5;
    n.orbit.events().iter().zip(n.orbit.times()).position(|(e, &s)| e.contact == c && e.kind == (Switch::Impact { stick: true }) && near(s).abs() < 1e-9)
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
