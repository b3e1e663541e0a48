//! Continuation of the exact orbit (issue 24): branches that do not depend on the grid.
//!
//! The grid LCP and the polish give the first orbit and its event signature; from there the branch is continued
//! on the exact hybrid orbit ([`family`]: state and event times, exact flows between events, pseudo-arclength in
//! the parameter; Keller 1977). Stability: the multipliers of the exact monodromy (the phases' exponentials,
//! identity saltation at compliant switches). Events between two points are located by bisection on the arc to
//! 1e-12 of the scaled unknowns: fold (the tangent's parameter component), period doubling (det(I + M)),
//! Neimark–Sacker (complex multipliers outside the unit circle), grazing (the signature changes). A grazing is
//! met from either side: a contact's clearance touching zero between its events (located where the touch's sign
//! flips; a pair of events is inserted there and the new branch starts with its phase 1e-5 of the period long),
//! or a phase between two events of one contact shrinking below 1e-6 of the period (steps land on it by quarters;
//! the pair is removed and the branch goes on in the same direction of the parameter). Rigid contacts (plastic
//! impacts, sticking arcs, releases; the monodromy is the relocated one-period map, rank-deficient at an impact):
//! their signature changes are located on the exact orbit and the branch goes on from there, from the grid LCP
//! only where that fails ([`rigid`]).
mod approach;
mod family;
mod locate;
mod metric;
mod modes;
mod pairs;
mod profile;
mod rigid;
mod signature;
mod start;
mod steps;

use super::{BranchPoint, ContinuationSettings, EventKind, Parameter, Source, floquet};
use crate::analysis::polish::{self, EventKind as Switch, PolishedOrbit};
use crate::error::Error;
use crate::periodic::PeriodicProblem;
use family::{Family, Node, Signature, lambda_axis};
use locate::{Test, locate};
pub(super) use start::{Started, start};
use steps::StepTrace;

/// A phase shorter than this (fraction of the period) and shrinking has vanished: a grazing.
const VANISH: f64 = 1e-6;
/// Below this step a corrector failing on a flight's re-impact time alone ([`Family::unresolved_flight`]):
/// the flight is below resolution, merged, not crawled at (coarse rigid blade, 2338.39 rad/s; validation/RECORD.md).
const UNRESOLVED_STEP: f64 = 1e-4;
/// Above this step a rigid change or a multiplier event whose bisection fails (a trial's corrector
/// failed in the bracket) is stepped at again shorter, not placed at the step's start (rigid) or
/// recorded unlocated at its end (fold, period doubling, Neimark–Sacker).
const UNLOCATED_STEP: f64 = 1e-4;
/// The phase of a pair of events just inserted at a grazing (fraction of the period).
const NEW_PAIR: f64 = 1e-5;
/// Bisection stops when the bracket is this short (scaled unknowns).
const BRACKET: f64 = 1e-12;
/// A bracket this short is located even where the corrector fails on its midpoint: the
/// corrector's corrections stall at 1e-10 to 4e-9 on the coarse blade (family.rs, ATTAINABLE).
const NEWTON_NOISE: f64 = 1e-8;
/// Successive tangents at a larger angle than arccos(this) mean a step too long.
const MIN_COS: f64 = 0.9;
/// A corrected point farther than this × the step from the predictor is on another part of the
/// branch: the corrector jumped (the coarse blade: from the upper branch at 2655.19 rad/s onto the
/// near-parallel middle branch at 2605.14, tangents still at cos 0.93, so the walk turned back
/// with no fold). On this part the distance is ≈ ½·step·angle ≤ 0.23·step (angle ≤
/// arccos(MIN_COS)); the 19 jumps of one whole run were 0.68 to 11.5 steps away (Allgower & Georg
/// 1990, §6.1: the corrector's distance to the predictor bounds the step).
const MAX_DRIFT: f64 = 0.5;
/// A touch counts as a crossing below −this × the state scale (round-off of the flows).
const TOUCH_TOL: f64 = 1e-10;
/// The step's growth after a point: each change of signature restarts it at `initial_step`, and the
/// real blade's walk (a grazing every ≈ 17 points) spent most points growing back; over 1150 → 1145
/// rad/s ×1.5 took 146 points and 94.0 s CPU, ×2 103 and 75.6 s, ×3 83 and 78.1 s; but ×2's walk down
/// lost the period doubling at 1141.60 (a trial failed in its wider bracket): ×1.5 kept (validation/RECORD.md).
const GROWTH: f64 = 1.5;
/// The step's growth after a change of signature whose first step failed and was cut short, up to the
/// controller's step before the change: after a grazing that inserts a pair (its phase 1e-5 of the
/// period, opening as √σ) the real blade's first step was cut from `initial_step` to 7.8e-6 by eight
/// failed correctors and grew back ×1.5 over ≈ 25 points, its predictor error falling as the phase
/// opened. Not after a change whose first step holds (the coarse rigid walk): growing faster there
/// lost events (session 31's restart at the last step; session 32's ×3, validation/RECORD.md).
const REGROWTH: f64 = 3.0;
/// The regrowth keeps the next corrector within this × the step of its predictor, from the last
/// one's distance (½·κ·step² on an arc of curvature κ: linear in the step; Allgower & Georg 1990,
/// §6.1): the tangent turns by ≈ 2·this, within [`MIN_COS`]'s 0.45 rad.
const STRAIGHT: f64 = 0.1;

/// One exact walk: its points, why it stopped, and whether it reached `to`.
pub(super) struct Walked {
    pub points: Vec<BranchPoint>,
    pub stop: String,
    pub reached: bool,
    /// The branch left the range through `from` (turned back): nothing left to do.
    pub turned_back: bool,
    /// Where it stopped short (not at the point limit): the last point's exact orbit.
    pub stopped: Option<PolishedOrbit>,
}

struct Walk<'a> {
    problem: &'a PeriodicProblem,
    fam: Family,
    points: Vec<BranchPoint>,
    /// A front end's step ([`step`]): stop at the first fold, where its branch ends.
    stop_at_fold: bool,
    /// The fold the walk stopped at (its λ), when `stop_at_fold`.
    fold: Option<f64>,
    /// The exact orbit where the walk reached `to`.
    end: Option<PolishedOrbit>,
    /// How many of `points` went to the progress callback.
    reported: usize,
    /// The last corrector's distance from its predictor over the step (metric): ½·κ·step on an arc.
    drift: f64,
    /// The point before the current one, for a rigid margin's dip within a step ([`rigid::Behind`]).
    behind: Option<rigid::Behind>,
    /// [`Walked::stopped`].
    stopped: Option<PolishedOrbit>,
}

/// The scenes the exact walk takes: orbits of one forcing period.
fn check(problem: &PeriodicProblem) -> Result<(), Error> {
    if problem.period_multiple() != 1 {
        return Err(Error::input("the exact continuation follows orbits of one forcing period (period_multiple = 1)"));
    }
    Ok(())
}

/// The branch of the exact orbit from the orbit the session's solve and the polish find at
/// λ = `from`, towards `to`. An error when no exact orbit can be had at `from`.
pub(super) fn walk(
    problem: &PeriodicProblem,
    param: Parameter,
    from: f64,
    to: f64,
    settings: &ContinuationSettings,
    on_point: &dyn Fn(&BranchPoint),
) -> Result<Walked, Error> {
    Ok(start(problem, param, from, to, (to - from).abs(), None)?.follow(from, to, settings, on_point))
}

/// The walk's first point: `orbit` (at λ = `from`) closed as a function of the parameter, its
/// tangent towards `to`; λ scaled by `rho` in the unknowns.
fn begin<'a>(problem: &'a PeriodicProblem, param: Parameter, from: f64, to: f64, rho: f64, orbit: &PolishedOrbit) -> Result<(Walk<'a>, Node), Error> {
    let sig = Signature { events: orbit.events().to_vec(), always: orbit.always_closed().to_vec() };
    let mut fam = Family::new(problem.model(), param, rho, 1.0, sig);
    fam.ys = fam.scale_of(orbit.initial_state());
    let d = fam.dim();
    let e_l = lambda_axis(d);
    let w0 = fam
        .correct(&fam.pack(orbit, from), &e_l, from / rho)
        .map_err(|why| Error::solve(format!("the polished orbit at {} = {from} did not close as a function of the parameter ({why})", param.name())))?;
    let dir = (to - from).signum();
    let prev: Vec<f64> = e_l.iter().map(|x| x * dir).collect();
    let here = fam.node(w0, &prev).ok_or_else(|| Error::solve(format!("singular Jacobian at {} = {from}", param.name())))?;
    Ok((Walk { problem, fam, points: Vec::new(), stop_at_fold: false, fold: None, end: None, reported: 0, drift: 0.0, behind: None, stopped: None }, here))
}

/// Where a front end's step along the exact branch ends ([`step`]).
#[derive(Clone, Debug)]
pub(super) enum Stepped {
    /// The branch reaches `to`: its exact orbit there.
    Reached(Box<PolishedOrbit>),
    /// The branch turns back before `to`: the fold's parameter (located by bisection on the arc,
    /// or at a grazing after which the new branch turns back).
    Fold(f64),
    /// The walk stopped short (why).
    Stopped(String),
}

/// A front end's re-solve as a step of the exact walk (issue 24 item 4): from `orbit`, the exact
/// orbit at λ = `from` of `problem` (whose parameter the family sets), along its branch to λ =
/// `to`, stopping at the first fold. λ is scaled by its own size (not by |to − from|), so that a
/// small change of the knob is a short arclength: one step or a few.
pub(super) fn step(problem: &PeriodicProblem, param: Parameter, from: f64, to: f64, orbit: &PolishedOrbit) -> Result<Stepped, Error> {
    check(problem)?;
    let rho = from.abs().max(to.abs()).max((to - from).abs());
    let defaults = ContinuationSettings::default();
    let reach = 1.2 * (to - from).abs() / rho;
    let settings = ContinuationSettings { initial_step: reach.min(defaults.exact_max_step), min_step: 1e-6 * reach, max_points: 400, ..defaults };
    let (mut walk, here) = begin(problem, param, from, to, rho, orbit)?;
    walk.stop_at_fold = true;
    let walked = walk.follow_to(here, from, to, &settings, &|_| {});
    Ok(match walked {
        (_, Some(at), _) => Stepped::Fold(at),
        (_, None, Some(end)) => Stepped::Reached(Box::new(end)),
        (w, None, None) => Stepped::Stopped(w.stop),
    })
}

impl Walk<'_> {
    /// The points added since the last report, each to `on_point` (progress).
    fn report(&mut self, on_point: &dyn Fn(&BranchPoint)) {
        self.points[self.reported..].iter().for_each(on_point);
        self.reported = self.points.len();
    }

    fn push(&mut self, node: &Node, event: Option<EventKind>, detail: String) {
        let lambda = node.lambda(self.fam.rho);
        let amplitude = if node.amplitude.is_empty() { self.amplitudes(&node.orbit).1 } else { node.amplitude.clone() };
        let max_multiplier = floquet::largest(&node.mu);
        rigid::trace_point(node, lambda);
        self.points.push(BranchPoint {
            parameter: lambda,
            amplitude,
            multipliers: node.mu.clone(),
            max_multiplier,
            stable: max_multiplier <= 1.0,
            period_multiple: 1,
            event,
            detail,
            certified: true,
            state: node.orbit.initial_state().to_vec(),
            time: node.orbit.times().first().copied().unwrap_or(0.0),
            masks: Vec::new(),
            tangent: node.tangent.clone(),
            source: Source::Exact,
        });
    }

    /// The touches and the outputs' amplitudes of `orbit`, from one sampling of its period.
    fn amplitudes(&self, orbit: &PolishedOrbit) -> (Vec<polish::Touch>, Vec<f64>) {
        let (touches, amplitude) =
            profile::timed(profile::Stage::Amplitudes, || orbit.touches_and_amplitudes(self.problem.output_map(), &self.problem.outputs().displacement));
        (touches, amplitude.into_iter().map(|a| a.unwrap_or(f64::NAN)).collect())
    }

    /// A front end's step (`stop_at_fold`): the branch past a change of signature starts at `n`
    /// turning back in λ against `dir`, so the old one ended there (a fold at a grazing), recorded.
    fn ends_here(&mut self, n: &Node, dir: f64) -> bool {
        let back = self.stop_at_fold && n.tangent[n.tangent.len() - 1] * dir < 0.0;
        if back {
            self.fold = Some(n.lambda(self.fam.rho));
        }
        back
    }

    fn name(&self) -> &'static str {
        self.points.first().map_or("parameter", |_| "λ")
    }

    fn follow(self, here: Node, from: f64, to: f64, settings: &ContinuationSettings, on_point: &dyn Fn(&BranchPoint)) -> Walked {
        let walked = self.follow_to(here, from, to, settings, on_point).0;
        profile::report(walked.points.len());
        walked
    }

    /// [`Self::follow`], with the fold it stopped at (when `stop_at_fold`) and the exact orbit
    /// where it reached `to`.
    fn follow_to(
        mut self,
        mut here: Node,
        from: f64,
        to: f64,
        settings: &ContinuationSettings,
        on_point: &dyn Fn(&BranchPoint),
    ) -> (Walked, Option<f64>, Option<PolishedOrbit>) {
        let done = |mut w: Walk, stop: String, reached: bool, turned_back: bool| {
            w.report(on_point);
            (Walked { points: w.points, stop, reached, turned_back, stopped: w.stopped }, w.fold, w.end)
        };
        let short = |mut w: Walk, here: &Node, stop: String| {
            w.stopped = Some(here.orbit.clone());
            done(w, stop, false, false)
        };
        let rho = self.fam.rho;
        let dir = (to - from).signum();
        let mut ds = settings.initial_step;
        // The controller's step before the last change of signature (the regrowth's cap), and the
        // controller's step of the last point it bound (not a landing, not a retry).
        let (mut cap, mut regular) = (0.0, settings.initial_step);
        // The first step since a change of signature not yet taken; it was cut short by failures.
        let (mut fresh, mut cut) = (false, false);
        let mut trace = StepTrace::new();
        loop {
            if self.points.len() >= settings.max_points {
                let stop = format!("{} points (the limit)", settings.max_points);
                return done(self, stop, false, false);
            }
            // A phase between two events of one contact shrinking to nothing: a grazing.
            // The step is measured in the metric: the tangent of unit metric length.
            let along = self.fam.metric.unit(&here.tangent);
            let shrinking = signature::shrinking(&self.fam, &here.w, &along);
            if let Some(&(e, len, _)) = shrinking.iter().find(|s| s.1 < VANISH) {
                let (ev, ne) = (self.fam.sig.events[e], self.fam.ne());
                let end = signature::partner(self.fam.base(), &self.fam.sig.events, e).unwrap_or((e + 1) % ne);
                let which = format!("contact {}: {:?} → {:?}, {len:.1e} of the period", ev.contact, ev.kind, self.fam.sig.events[end].kind);
                self.trace_reversed(&here, &which);
                let next = if self.rigid_event(e) { self.rigid_vanish(&here, e, to) } else { self.remove_pair(&here, e) };
                match next {
                    Some(next) if self.ends_here(&next, dir) => return done(self, "a fold at a grazing".into(), false, false),
                    Some(next) => {
                        here = next;
                        (ds, cap, fresh) = (settings.initial_step, regular, true);
                        continue;
                    }
                    None => {
                        let stop = format!("a phase of the orbit vanishes at λ = {} ({which}) and the branch could not go on without it", here.lambda(rho));
                        return short(self, &here, stop);
                    }
                }
            }
            // A short rigid flight vanishing within the step: merged at its located end, not approached.
            if let Some(next) = self.early_merge(&here, &shrinking, ds) {
                if self.ends_here(&next, dir) {
                    return done(self, "a fold at a grazing".into(), false, false);
                }
                self.report(on_point);
                (here, ds, cap, fresh) = (next, settings.initial_step, regular, true);
                continue;
            }
            // Land on a vanishing phase by quarters.
            let mut step = ds;
            for &(_, len, rate) in &shrinking {
                step = step.min(0.75 * len / rate);
            }
            trace.bound(step < ds);
            let old = self.fam.sig.clone();
            let landed = if step < ds { self.land(&here, &shrinking, &along) } else { None };
            let tried = match landed {
                Some((n, s)) => {
                    step = s;
                    Ok((n, None))
                }
                None => {
                    let pred: Vec<f64> = here.w.iter().zip(&along).map(|(w, t)| w + step * t).collect();
                    // Events that may pass each other did: the same step in their new order (not a change);
                    // the corrector may cross a close pair the predictor did not, or the reverse: then the
                    // pair's order toggled.
                    self.try_step(&here, pred.clone(), step, settings.min_step).or_else(|first| {
                        self.fam.sig = old.clone();
                        let toggled = signature::toggled(&self.fam, self.problem.model(), &here.w, &pred).ok_or(first)?;
                        self.try_step(&here, toggled, step, settings.min_step)
                    })
                }
            };
            // The step's own start and signature where a pass re-expressed `here` in its events' new
            // order: a retry goes back to them, since `here` has not crossed that pair (its times out
            // of order make a pair phase negative, read as vanishing: suspected of session 30's stop
            // at 1200.86 rad/s, "−9.3e-1 of the period"; validation/RECORD.md).
            let mut origin = None;
            let next = match tried {
                Ok((n, moved)) => {
                    if let Some(m) = moved {
                        origin = Some((std::mem::replace(&mut here, m), old));
                    }
                    n
                }
                Err(refused) => {
                    self.fam.sig = old;
                    // Right after a change, by quarters: the failures of the first step after a
                    // pair's insertion run from `initial_step` to ≈ 1e-5, the new phase's length.
                    ds = step / if fresh { 4.0 } else { 2.0 };
                    cut |= fresh;
                    trace.retry("corrector");
                    let merged = self.fam.unresolved_flight().filter(|_| step < UNRESOLVED_STEP).and_then(|e| {
                        let c = self.fam.sig.events[e].contact;
                        self.merge(&here, e, &format!("contact {c}: its free phase below resolution (its re-impact's time unresolved)"))
                    });
                    // Rigid events merging (a flight between two impacts, an impact fading): the branch past them.
                    let restarted = match merged {
                        None if ds < settings.min_step => self.rigid_stall(&here, to),
                        m => m,
                    };
                    if let Some(n) = restarted {
                        if self.ends_here(&n, dir) {
                            return done(self, "a fold at a grazing".into(), false, false);
                        }
                        self.report(on_point);
                        here = n;
                        (ds, cap, fresh) = (settings.initial_step, regular, true);
                        continue;
                    }
                    if ds < settings.min_step {
                        let stop = format!("no exact orbit at {} = {} with the smallest step ({refused})", self.name(), here.lambda(rho));
                        return short(self, &here, stop);
                    }
                    continue;
                }
            };
            // Past an end of the range: the point at the end, before a grazing beyond it is looked for.
            let lambda = next.lambda(rho);
            let past_to = (lambda - to) * dir > 0.0;
            let past_from = (lambda - from) * dir < 0.0;
            let next = if past_to || past_from {
                let bound = if past_to { to } else { from };
                let (l0, w0) = (here.lambda(rho), &here.w);
                let f = (bound - l0) / (lambda - l0);
                let pred: Vec<f64> = w0.iter().zip(&next.w).map(|(a, b)| a + f * (b - a)).collect();
                let d = self.fam.dim();
                let e_l = lambda_axis(d);
                profile::caller("bound", f64::NAN, || self.fam.correct(&pred, &e_l, bound / rho))
                    .ok()
                    .and_then(|w| self.fam.node_with(w, &next.tangent, false))
                    .unwrap_or(next)
            } else {
                next
            };
            let mut next = next;
            (next.touches, next.amplitude) = self.amplitudes(&next.orbit);
            // A rigid contact's signature broken between here and next: located, the branch goes on past it.
            if rigid::margin(&next) < -1e-9 && rigid::margin(&here) >= -1e-9 {
                let (sig, count) = (self.fam.sig.clone(), self.points.len());
                match self.rigid_crossing(&here, &next, to, step > UNLOCATED_STEP) {
                    Some(n) if self.ends_here(&n, dir) => return done(self, "a fold at a grazing".into(), false, false),
                    Some(n) => {
                        self.report(on_point);
                        here = n;
                        (ds, cap, fresh) = (settings.initial_step, regular, true);
                        continue;
                    }
                    // A long step across several changes (2355.54 → 2358.46 rad/s on the rigid coarse blade): shorter.
                    None if step > settings.min_step => {
                        (self.fam.sig, ds) = (sig, step / 2.0);
                        trace.retry("rigid crossing");
                        self.points.truncate(count.max(self.reported));
                        self.back(&mut here, origin);
                        continue;
                    }
                    None => {
                        let what = next.rigid_margin().map_or(String::new(), |m| format!(" (contact {}: the {} reaches zero)", m.contact, m.what));
                        let stop =
                            format!("a change of the rigid contacts' events near λ = {}{what}: the branch past it could not be started", here.lambda(rho));
                        return short(self, &here, stop);
                    }
                }
            }
            // A part of the rigid margin dipping below zero within the step, neither end seeing it: the step up to it.
            if step > settings.min_step
                && let Some(s) = self.dip(self.behind.as_ref(), &here, &next, step)
            {
                ds = s;
                trace.retry("rigid margin dip");
                self.back(&mut here, origin);
                continue;
            }
            // A contact's clearance crossed zero between its events: a grazing on the way.
            let tol = TOUCH_TOL * self.fam.ys;
            let crossed = |n: &Node| n.touches.iter().any(|t| t.value < -tol);
            if crossed(&next) && !crossed(&here) {
                // Located on the least touch over the state scale (continuous through the grazing).
                // Where the corrector fails inside the bracket the step jumped across a change it
                // cannot resolve (seed 138: a closed phase swallowed the open one after it in a
                // step of 0.1): tried again shorter.
                let least = |n: &Node| n.touches.iter().map(|t| t.value).fold(f64::INFINITY, f64::min) / self.fam.ys + TOUCH_TOL;
                let Some((lo, _)) = locate(&self.fam, &here, &next, Test::Value(&least), true) else {
                    if step > settings.min_step {
                        ds = step / 2.0;
                        trace.retry("grazing unlocated");
                        self.back(&mut here, origin);
                        continue;
                    }
                    let stop = format!("a grazing near λ = {}: it could not be located on the arc", here.lambda(rho));
                    return short(self, &here, stop);
                };
                match self.insert_pair(&here, &lo) {
                    Some(n) => {
                        self.report(on_point);
                        if self.ends_here(&n, dir) {
                            return done(self, "a fold at a grazing".into(), false, false);
                        }
                        here = n;
                        (ds, cap, fresh) = (settings.initial_step, regular, true);
                        continue;
                    }
                    None => {
                        let stop = format!("a grazing near λ = {}: the branch with the new contact phase could not be started", here.lambda(rho));
                        return short(self, &here, stop);
                    }
                }
            }
            let (events, missed) = self.events_on(&here, &next);
            // A trial's corrector failed in the bracket of an event the step crossed: the step
            // is tried again shorter, where the bracket is (the real blade's period doubling at
            // 1141.6022585 rad/s, 1150 → 1140: bracketed by 0.31 rad/s and given at its end).
            if missed && step > UNLOCATED_STEP {
                ds = step / 2.0;
                trace.retry("multiplier event unlocated");
                self.back(&mut here, origin);
                continue;
            }
            for (kind, node, detail) in events {
                if self.stop_at_fold && kind == EventKind::Fold {
                    self.fold = Some(node.lambda(rho));
                    return done(self, "a fold".into(), false, false);
                }
                self.push(&node, Some(kind), detail);
            }
            self.push(&next, None, String::new());
            self.report(on_point);
            if past_to {
                self.end = Some(next.orbit);
                return done(self, "reached".into(), true, false);
            }
            if past_from {
                let stop = format!("the branch turned back below {from}");
                return done(self, stop, false, true);
            }
            trace.point(lambda, step, ds, if cut { cap } else { 0.0 }, settings.exact_max_step, self.drift);
            if step == ds {
                regular = ds;
            }
            let before = std::mem::replace(&mut here, next);
            self.rescale(&mut here);
            // Not across a pass: `before`'s margins are keyed by its events' old order.
            self.behind = if origin.is_none() { rigid::Behind::of(&before, &here, step) } else { None };
            let grown = if cut && step < cap { (step * (STRAIGHT / self.drift).clamp(GROWTH, REGROWTH)).min(cap) } else { step * GROWTH };
            (fresh, cut) = (false, cut && step < cap);
            ds = grown.min(settings.exact_max_step);
        }
    }

    /// The state scale follows the orbit: set to `node`'s largest state component when that has
    /// moved by more than 2× from it (`node`'s unknowns and tangent re-expressed). With the scale
    /// of the first point, the coarse blade's resonant orbits (20× larger) made each arclength
    /// step a twentieth of the orbit's change it allows at the start, and the corrector's
    /// round-off 20× larger in the scaled unknowns.
    fn rescale(&mut self, node: &mut Node) {
        let n2 = node.w.len() - 1 - self.fam.ne();
        let scale = node.w[..n2].iter().fold(0.0f64, |m, w| m.max(w.abs()));
        if !(scale > 0.0 && scale.is_finite()) || (0.5..=2.0).contains(&scale) {
            return;
        }
        self.fam.ys *= scale;
        node.w[..n2].iter_mut().for_each(|w| *w /= scale);
        node.tangent[..n2].iter_mut().for_each(|t| *t /= scale);
        let norm = node.tangent.iter().map(|t| t * t).sum::<f64>().sqrt();
        node.tangent.iter_mut().for_each(|t| *t /= norm);
    }

    /// A step retried shorter starts again from its own start and signature (`origin`, where a
    /// pass had re-expressed `here` in a new order of its events).
    fn back(&mut self, here: &mut Node, origin: Option<(Node, Signature)>) {
        if let Some((start, sig)) = origin {
            (*here, self.fam.sig) = (start, sig);
        }
    }

    /// The predictor `pred` from `here` and, when events with identity state maps of different
    /// contacts have passed each other in it ([`signature::passed`]), the family switched to
    /// their new order with `pred` and `here` (unknowns and tangent) re-expressed in it; the
    /// caller restores the signature if the step fails.
    fn pass(&mut self, here: &Node, pred: Vec<f64>) -> (Vec<f64>, Option<Node>) {
        let Some((sig, order)) = signature::passed(&self.fam, self.problem.model(), &pred) else {
            return (pred, None);
        };
        self.fam.sig = sig;
        // Events that passed event 0 change the contacts closed after it, and with them the state
        // there (a massless tip's velocity): the state re-taken as the new phase 0 carries it,
        // else the predictor lies off the branch by that jump and the corrector lands a fixed
        // distance along it, however short the step (the event-0 crossing's stall).
        let mut moved = here.clone();
        moved.w = signature::reorder(&here.w, &order, true);
        moved.tangent = signature::reorder(&here.tangent, &order, false);
        let pred = signature::reorder(&pred, &order, true);
        let (Some(w), Some(sectioned)) = (self.fam.sectioned(&moved.w), self.fam.sectioned(&pred)) else {
            return (pred, Some(moved));
        };
        // The tangent through the same map (affine in the state; by central differences for θ_0).
        let h = 1e-6;
        let shifted = |s: f64| self.fam.sectioned(&moved.w.iter().zip(&moved.tangent).map(|(a, b)| a + s * b).collect::<Vec<_>>());
        if let (Some(up), Some(dn)) = (shifted(h), shifted(-h)) {
            moved.tangent = up.iter().zip(&dn).map(|(a, b)| (a - b) / (2.0 * h)).collect();
        }
        moved.w = w;
        (sectioned, Some(moved))
    }

    /// PC_TRACE_VANISH: the event times and pair phases of `n` where one is ≤ 0 long, which no
    /// corrected point of the family's signature has (its times increase within the period).
    fn trace_reversed(&self, n: &Node, at: &str) {
        if std::env::var_os("PC_TRACE_VANISH").is_none() || !signature::reversed(&self.fam, &n.w) {
            return;
        }
        let ne = self.fam.ne();
        let n2 = n.w.len() - 1 - ne;
        eprintln!("vanish trace ({at}): λ {:.10}, {ne} events, {} unknowns", n.lambda(self.fam.rho), n.w.len());
        for (e, ev) in self.fam.sig.events.iter().enumerate() {
            let pair = signature::pair_phase(&self.fam, &n.w, e);
            eprintln!("  {e}: contact {} {:?} θ {:.12} pair {pair:?}", ev.contact, ev.kind, n.w[n2 + e]);
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
