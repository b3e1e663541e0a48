//! Continuation of periodic contact orbits in one scalar parameter (issue 13): branches, not
//! points.
//!
//! Pseudo-arclength (Keller 1977) on the shooting formulation of the difference schemes: the
//! unknowns are the orbit's initial state s_0 and the parameter λ, the equations
//! s_0 = P(s_0; λ) with P the period map of the problem's step map at λ, bordered by the
//! arclength condition. P is piecewise affine in s_0 (a piece per active sets), so Newton is exact
//! on a piece and the path crosses kinks (grazings, stick/release, nonsmooth folds) by
//! shortening its step. Each point's Floquet multipliers are the eigenvalues of dP/ds_0 with the
//! active sets frozen (the discrete monodromy, src/formulation.md §7); events are located by bisection
//! ([`events`]). Every reported point is certified as the LCP `solve` solves: the branch's
//! session ([`PeriodicSolver`]) solves it warm-started from the point's active sets, and its
//! amplitudes are that certified response's.
mod corrector;
mod defences;
mod events;
mod exact;
mod exact_follow;
mod floquet;
mod follow;
mod friction;
mod handover;
pub mod optimal_load;
pub mod output;
mod parameter;
mod reentry;
mod switch;

pub use events::EventKind;
pub use floquet::{largest as largest_multiplier, multipliers};
pub use follow::{Current, Followed, Jump, Resolved, Stability, amplitude, follow, resolve, stability};
pub use parameter::Parameter;
pub use switch::{run_switching, switch_at};

use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver};
use crate::response::Response;
use corrector::{Family, Path};
use defences::{ZIGZAG_BAND, ZIGZAG_STEPS, merge_fold_pairs, zigzag_in};
use events::Node;
use num_complex::Complex64;

/// Settings with defaults. Steps are arclengths in (s_0, λ/|to − from|).
#[derive(Clone, Debug)]
pub struct ContinuationSettings {
    pub initial_step: f64,
    pub min_step: f64,
    pub max_step: f64,
    /// Most points (events included) before the continuation stops.
    pub max_points: usize,
    /// Relative defect of the corrector.
    pub tolerance: f64,
    /// Width of the differences of the stability monodromy, relative to the state's blocks
    /// (0: the piece's Jacobian, exact for the discrete map but jumping at its kinks).
    pub smoothing: f64,
    /// Successive folds closer than this (relative to |to − from|) are the path's wiggles
    /// across kinks of the discrete map, not turns ([`merge_fold_pairs`]; NLvib 03, k = 4096:
    /// pairs 3e-5 to 2e-4 apart near the peak, none between the true folds 0.102 apart; the
    /// demo's oscillator at k = 256: wiggles 5e-4 to 6e-3 apart on its unstable branch).
    pub fold_merge: f64,
    /// Largest arclength step of the exact walk (in y0/y_s, the event times over the period and
    /// λ/|to − from|): its branch is smooth between grazings, and the tangents' angle limits the
    /// step where it turns.
    pub exact_max_step: f64,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        ContinuationSettings {
            initial_step: 2e-3,
            min_step: 1e-9,
            max_step: 2e-2,
            max_points: 5000,
            tolerance: 1e-10,
            smoothing: 5e-3,
            fold_merge: 1e-2,
            exact_max_step: 0.1,
        }
    }
}

/// One orbit of the branch.
#[derive(Clone, Debug)]
pub struct BranchPoint {
    /// The parameter's value.
    pub parameter: f64,
    /// Peak-to-peak/2 of each displacement output (the problem's `outputs.displacement` order).
    pub amplitude: Vec<f64>,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex64>,
    /// The largest modulus.
    pub max_multiplier: f64,
    /// All multipliers inside the unit circle (|μ| ≤ 1).
    pub stable: bool,
    /// The orbit's period in forcing periods.
    pub period_multiple: usize,
    /// The event located at this point, if any.
    pub event: Option<EventKind>,
    /// The event's detail (multiplier, contact), empty otherwise.
    pub detail: String,
    /// The session's certified LCP solve from this point's active sets gave the same active set.
    pub certified: bool,
    /// The orbit's initial state s_0 (the step map's state; the exact orbit's just after its event 0).
    pub state: Vec<f64>,
    /// The instant of `state` [s]: 0 on the grid, event 0's time on the exact orbit (0 without events).
    pub time: f64,
    /// The active sets of the orbit's steps (bit c: contact c), for a switch of branch here.
    pub(crate) masks: Vec<u64>,
    /// The branch's unit tangent in (s_0, λ/ρ) here, for a switch of branch.
    pub(crate) tangent: Vec<f64>,
    /// What produced the point: the exact orbit, or the discrete walk on the grid.
    pub source: Source,
}

impl BranchPoint {
    /// A discrete, certified, stable point with only its amplitudes (no multipliers, state or sets
    /// yet): the friction walk's points, which add none of the rest.
    pub(crate) fn discrete(parameter: f64, amplitude: Vec<f64>) -> Self {
        BranchPoint {
            parameter,
            amplitude,
            multipliers: Vec::new(),
            max_multiplier: 0.0,
            stable: true,
            period_multiple: 1,
            event: None,
            detail: String::new(),
            certified: true,
            state: Vec::new(),
            time: 0.0,
            masks: Vec::new(),
            tangent: Vec::new(),
            source: Source::Discrete,
        }
    }
}

/// The progress callback of a walk: each point as it is added.
pub type OnPoint<'a> = dyn Fn(&BranchPoint) + 'a;

/// What produced a point of the branch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The exact hybrid orbit (exact flows between events, event times; [`exact`]).
    Exact,
    /// The discrete orbit of the grid's step map (its error is the scheme's at k).
    Discrete,
}

impl Source {
    pub fn name(self) -> &'static str {
        match self {
            Source::Exact => "exact",
            Source::Discrete => "discrete",
        }
    }
}

/// A continued branch.
#[derive(Clone, Debug)]
pub struct Branch {
    pub parameter: Parameter,
    pub points: Vec<BranchPoint>,
    /// Why the continuation stopped ("reached", "reached from both ends: …", or the reason).
    pub stop: String,
    /// Marches of the period map made.
    pub marches: usize,
    /// The orbits' period in forcing periods (1: T, 2: the branch switched to at a period doubling).
    pub period_multiple: usize,
    /// "T", or "2T from frequency = 0.7386603" for a branch switched to at a period doubling.
    pub label: String,
}

impl Branch {
    /// The branch spans the whole range (in one walk, or in two that meet at a fold).
    pub fn reached(&self) -> bool {
        self.stop.starts_with("reached")
    }

    /// The event points, in order along the branch.
    pub fn events(&self) -> impl Iterator<Item = &BranchPoint> {
        self.points.iter().filter(|p| p.event.is_some())
    }
}

/// Continues the orbit of `problem` at λ = `from` in the parameter up to λ = `to`, or until the
/// branch leaves [from, to] the other way: the exact orbit's branch where the polish applies
/// (compliant contacts, one forcing period: [`exact`]), the discrete walk ([`run_discrete`])
/// where it does not, and from where the exact walk stopped short. Each point says which
/// ([`BranchPoint::source`]). `on_point` with each point as it is added (progress).
pub fn run(problem: &PeriodicProblem, param: Parameter, from: f64, to: f64, settings: &ContinuationSettings, on_point: &OnPoint) -> Result<Branch, Error> {
    check_range(from, to)?;
    if !problem.model().frictions.is_empty() || param == Parameter::NormalForce {
        return friction::walk(problem, param, from, to, settings, on_point);
    }
    let walked = match exact::walk(problem, param, from, to, settings, on_point) {
        Ok(w) => w,
        Err(e) => {
            let mut b = run_discrete(problem, param, from, to, settings, on_point)?;
            b.stop = format!("{} (discrete walk: {e})", b.stop);
            return Ok(b);
        }
    };
    let label = "T".to_string();
    if walked.reached || walked.turned_back {
        return Ok(Branch { parameter: param, points: walked.points, stop: walked.stop, marches: 0, period_multiple: 1, label });
    }
    // The rest of the range by the discrete walk, from where the exact one stopped, and the exact walk again past it.
    reentry::go_on(problem, param, (from, to), settings, on_point, walked)
}

fn check_range(from: f64, to: f64) -> Result<(), Error> {
    if !(from.is_finite() && to.is_finite() && from != to) {
        return Err(Error::input(format!("--from/--to: are {from} and {to}, must be finite and different")));
    }
    Ok(())
}

/// The discrete branch: pseudo-arclength on the grid's step map (its kinks, zigzags and fold
/// chains handled as below), from the session's solve at λ = `from`.
pub fn run_discrete(
    problem: &PeriodicProblem,
    param: Parameter,
    from: f64,
    to: f64,
    settings: &ContinuationSettings,
    on_point: &dyn Fn(&BranchPoint),
) -> Result<Branch, Error> {
    run_discrete_until((problem, param), (from, to), (settings, on_point), (&[], None))
}

/// [`run_discrete`], its first solve warm-started from `warm` when not empty (the exact orbit's
/// active set where the exact walk stopped), its walk from `from` stopped where `until` says of a
/// step's new points (events, then the step's point) that the exact walk re-enters there: that
/// point dropped.
fn run_discrete_until(
    (problem, param): (&PeriodicProblem, Parameter),
    (from, to): (f64, f64),
    (settings, on_point): (&ContinuationSettings, &dyn Fn(&BranchPoint)),
    (warm, until): (&[usize], Option<&Until>),
) -> Result<Branch, Error> {
    check_range(from, to)?;
    let rho = (to - from).abs();
    let mut fam = family(problem, param, rho, settings);
    fam.map_at(from)?;
    let mut solver = PeriodicSolver::new(fam.problem_at(from)?);
    let up = walk_from(&mut fam, &mut solver, from, to, settings, on_point, (warm, until))?;
    let (mut points, mut stop) = (up.points, up.stop);
    // A walk stopped in a zigzag (a fold of the orbit finer than the discrete branch's kinks,
    // the coarse blade's resonance tip): the rest of the curve from the other end, which meets
    // it there.
    if let Some(band) = up.zigzag {
        let down = walk_from(&mut fam, &mut solver, to, from, settings, on_point, (&[], None))?;
        match down.zigzag {
            Some(other) if (other.0 - band.0).abs() <= ZIGZAG_MEET * rho => {
                let (lo, hi) = (band.1.min(other.1), band.2.max(other.2));
                join_at_fold(&mut points, down.points, (lo, hi));
                stop = format!("reached from both ends: the walks from {from} and from {to} meet at a fold in [{lo}, {hi}]");
            }
            _ => stop = format!("{stop}; the walk from {to} did not meet it ({})", down.stop),
        }
    }
    let p = problem.period_multiple();
    let label = if p == 1 { "T".to_string() } else { format!("{p}T") };
    Ok(Branch { parameter: param, points, stop, marches: fam.marches, period_multiple: p, label })
}

/// Two zigzags meet when their centres are this close (relative to the range): a fold's two
/// sides at the coarse blade's tip, k = 1024: 2796.02 and 2795.94 rad/s over a range of 750.
const ZIGZAG_MEET: f64 = 1e-3;

/// One walk's outcome.
struct Walked {
    points: Vec<BranchPoint>,
    stop: String,
    /// Stopped in a zigzag: (its centre, lowest, highest parameter).
    zigzag: Option<(f64, f64, f64)>,
}

/// The branch from the orbit the session's solve finds at λ = `from`, towards `to`.
fn walk_from(
    fam: &mut Family,
    solver: &mut PeriodicSolver,
    from: f64,
    to: f64,
    settings: &ContinuationSettings,
    on_point: &dyn Fn(&BranchPoint),
    (warm, until): (&[usize], Option<&Until>),
) -> Result<Walked, Error> {
    let name = fam.name();
    let dir = (to - from).signum();
    solver.update_problem(fam.problem_at(from)?);
    // A cold solve, as `solve` makes: an empty warm start would be Newton from the contact-free guess.
    solver.reset_warm_start();
    if !warm.is_empty() {
        solver.set_warm_start(warm);
    }
    let first = solver.solve().map_err(|e| Error::from(e).context(format!("the start of the continuation at {name} = {from}")))?;
    let (k, m) = (solver.problem().instants(), solver.problem().model().contacts.len());
    let mut masks = vec![0u64; k];
    for &i in &first.active_set {
        masks[i / m] |= 1 << (i % m);
    }
    let start = fam.start(from, &masks).ok_or_else(|| Error::solve(format!("continuation: the orbit at {name} = {from} did not close on its active sets")))?;
    let d = start.v.len() - 1;
    let border: Vec<f64> = (0..=d).map(|i| if i == d { dir } else { 0.0 }).collect();
    let tangent = start.tangent(&border).ok_or_else(|| Error::solve(format!("continuation: singular Jacobian at {name} = {from}")))?;
    let here = Node::new(fam, start, tangent);
    let points = vec![point(fam, solver, &here, None, String::new())?];
    on_point(&points[0]);
    let walk = Walk { from, to, secant: false, settings, on_point, until };
    walk.follow(fam, solver, here, points, None)
}

/// Joins a walk that ended in a zigzag with the walk from the range's other end that ended in
/// the same zigzag: the second reversed after the first, the events inside the zigzag (the
/// discrete branch's turns back and forth) dropped, one fold where they meet.
fn join_at_fold(points: &mut Vec<BranchPoint>, mut other: Vec<BranchPoint>, band: (f64, f64)) {
    let inside = |p: &BranchPoint| p.parameter >= band.0 && p.parameter <= band.1;
    for p in points.iter_mut().chain(other.iter_mut()).filter(|p| inside(p)) {
        p.event = None;
        p.detail.clear();
    }
    if let Some(tip) = points.iter_mut().rev().find(|p| p.certified) {
        tip.event = Some(EventKind::Fold);
        tip.detail = format!("the walks from both ends meet in a zigzag of the discrete branch over [{}, {}]: the fold lies there", band.0, band.1);
    }
    other.reverse();
    for p in &mut other {
        p.tangent.iter_mut().for_each(|t| *t = -*t);
    }
    points.extend(other);
}

/// The family of `problem`'s orbits with the settings' corrector tolerance and smoothing.
fn family(problem: &PeriodicProblem, param: Parameter, rho: f64, settings: &ContinuationSettings) -> Family {
    let mut fam = Family::new(problem, Path::Parameter(param), rho);
    fam.tolerance = settings.tolerance;
    fam.smoothing = settings.smoothing;
    fam
}

/// The step below which a secant walk that keeps failing tries the Jacobian's tangent instead.
const SECANT_GIVES_UP: f64 = 1e-6;

/// Pseudo-arclength along a branch between the parameter values `from` and `to`.
struct Walk<'a> {
    from: f64,
    to: f64,
    /// Tangents by secants of the last two points instead of the piece Jacobian's kernel. Why:
    /// near a branch point (the 2T branch at its period doubling) the branch runs along the
    /// near-kernel of dF/ds_0, where the piece Jacobian differs most from the smoothed one and its
    /// kernel points off the branch (NLvib 03, k = 4096: the 2T branch turned back at once).
    secant: bool,
    settings: &'a ContinuationSettings,
    on_point: &'a dyn Fn(&BranchPoint),
    /// Where the walk stops for the exact walk to re-enter ([`run_discrete_until`]).
    until: Option<&'a Until<'a>>,
}

/// Whether the exact walk re-enters at a step's last new point (its new points given).
type Until<'a> = dyn Fn(&[BranchPoint]) -> bool + 'a;

impl Walk<'_> {
    /// The unit tangent at `next`, oriented along the branch from `here`.
    fn tangent(&self, next: &corrector::Solved, here: &Node) -> Option<Vec<f64>> {
        if !self.secant {
            // Oriented as the path is, not by the last tangent: a step may end past a sharp turn.
            let t = next.tangent(&here.tangent)?;
            let flip = next.orientation(&t) != here.solved.orientation(&here.tangent);
            return Some(if flip { t.iter().map(|x| -x).collect() } else { t });
        }
        let sec: Vec<f64> = next.v.iter().zip(&here.solved.v).map(|(a, b)| a - b).collect();
        let norm = sec.iter().map(|x| x * x).sum::<f64>().sqrt();
        (norm.is_finite() && norm > 0.0).then(|| sec.iter().map(|x| x / norm).collect())
    }

    /// Follows the branch from `here` (already in `points`) until λ passes `to` ("reached", the
    /// last point at `to` exactly) or `from` (the branch turned back), the step gets too small,
    /// the points run out, or `rejoin` sees the branch meet the T branch again.
    fn follow(
        &self,
        fam: &mut Family,
        solver: &mut PeriodicSolver,
        mut here: Node,
        mut points: Vec<BranchPoint>,
        mut rejoin: Option<&mut switch::Rejoin>,
    ) -> Result<Walked, Error> {
        let (from, to, settings, rho) = (self.from, self.to, self.settings, fam.rho);
        let dir = (to - from).signum();
        let name = fam.name();
        let m = solver.problem().model().contacts.len();
        let d = here.solved.v.len() - 1;
        let mut ds = settings.initial_step;
        // Whether the tangent at `here` was already replaced by the Jacobian's (secant walks).
        let mut turned = false;
        // The parameter of the last steps: a walk that only goes back and forth is in a zigzag.
        let mut recent: Vec<f64> = Vec::new();
        let mut left: std::collections::VecDeque<Vec<u64>> = std::collections::VecDeque::new();
        let mut zigzag = None;
        let stop = loop {
            if points.len() >= settings.max_points {
                break format!("{} points (the limit)", settings.max_points);
            }
            let pred: Vec<f64> = here.solved.v.iter().zip(&here.tangent).map(|(v, t)| v + ds * t).collect();
            // A branch crosses each piece of the map once: an orbit on a piece it has left is a
            // return along the branch (near a sharp turn the hyperplane ahead meets both arms).
            let fresh = |c: &(corrector::Solved, usize)| !left.contains(&c.0.masks);
            let corrected = fam.correct(&pred, &here.tangent, &here.solved.masks).filter(fresh);
            // The hyperplane ahead met no orbit: a kink the branch turns at (a nonsmooth fold)?
            let crossed = match corrected {
                None if ds <= CROSS_BELOW => fam.cross_kink(&here.solved, &here.tangent, ds).filter(|k| !left.contains(&k.next.masks)),
                _ => None,
            };
            let turn = crossed.as_ref().map(|k| k.turn.clone());
            let corrected = corrected.or_else(|| crossed.map(|k| (k.next, 3)));
            let Some((next, iterations)) = corrected else {
                ds /= 2.0;
                // A secant cannot turn a corner of the branch (a contact change of the orbit):
                // once it has failed down to small steps, try the piece Jacobian's tangent there.
                if self.secant && ds < SECANT_GIVES_UP && !turned {
                    if let Some(t) = here.solved.tangent(&here.tangent) {
                        here.tangent = t;
                        ds = settings.initial_step;
                    }
                    turned = true;
                    continue;
                }
                if ds < settings.min_step {
                    break format!("no convergence at {name} = {} with the smallest step", here.solved.parameter(rho));
                }
                continue;
            };
            let t_next = match &turn {
                Some(turn) => next.tangent(turn),
                None => self.tangent(&next, &here),
            };
            let Some(t_next) = t_next else {
                ds /= 2.0;
                continue;
            };
            let mut next = Node::new(fam, next, t_next);
            // Unknown multipliers (an unconverged Schur form) would read as no event and print NaN:
            // the point is refused like an unconverged corrector (the exact walk does the same).
            if floquet::largest(&next.mu).is_nan() {
                ds /= 2.0;
                if ds < settings.min_step {
                    break format!(
                        "the monodromy's Schur form does not converge at {name} = {} (multipliers unknown) with the smallest step",
                        next.solved.parameter(rho)
                    );
                }
                continue;
            }
            let lambda = next.solved.parameter(rho);
            // Past an end of the range: the last point at that end exactly, interpolated.
            let end = [(to, (lambda - to) * dir > 0.0), (from, (lambda - from) * dir < 0.0)].into_iter().find(|e| e.1).map(|e| e.0);
            if let Some(bound) = end {
                let l0 = here.solved.parameter(rho);
                let f = (bound - l0) / (lambda - l0);
                let pred: Vec<f64> = here.solved.v.iter().zip(&next.solved.v).map(|(a, b)| a + f * (b - a)).collect();
                let normal: Vec<f64> = (0..=d).map(|i| if i == d { 1.0 } else { 0.0 }).collect();
                if let Some((end, _)) = fam.correct(&pred, &normal, &here.solved.masks)
                    && let Some(t) = self.tangent(&end, &here)
                {
                    next = Node::new(fam, end, t);
                }
            }
            let joined = match rejoin.as_deref_mut() {
                Some(r) => r.check(fam, &here, &next),
                None => None,
            };
            let (last, detail) = match joined {
                Some(node) => (node, "rejoins the T branch (its period doubling)".to_string()),
                None => (next, String::new()),
            };
            // Across a kink where λ turned back: the fold at the last point before it (within a
            // step of at most CROSS_BELOW), and the events beyond it from that point.
            let mut from_node = here.clone();
            if let Some(turn) = turn {
                if turn[d] * here.tangent[d] < 0.0
                    && let Some(p) = points.last_mut().filter(|p| p.event.is_none())
                {
                    p.event = Some(EventKind::Fold);
                    p.detail = "at a kink of the map (a nonsmooth fold), within one step".to_string();
                }
                from_node.tangent = turn;
            }
            let added = points.len();
            for (kind, node, detail) in events::between(fam, &from_node, &last, m) {
                points.push(point(fam, solver, &node, Some(kind), detail)?);
            }
            points.push(point(fam, solver, &last, None, detail.clone())?);
            // The exact orbit's start replaces the step's point there.
            let reentered = end.is_none() && detail.is_empty() && self.until.is_some_and(|u| u(&points[added..]));
            if reentered {
                points.pop();
            }
            points[added..].iter().for_each(|p| (self.on_point)(p));
            if reentered {
                break format!("the exact walk re-enters at {name} = {}", last.solved.parameter(rho));
            }
            if !detail.is_empty() {
                break format!("rejoined the T branch at {name} = {}", last.solved.parameter(rho));
            }
            match end {
                Some(b) if b == to => break "reached".to_string(),
                Some(_) => break format!("the branch turned back below {name} = {from}"),
                None => {}
            }
            recent.push(last.solved.parameter(rho));
            if let Some(band) = zigzag_in(&recent, ZIGZAG_BAND * rho) {
                zigzag = Some(band);
                break format!(
                    "the discrete branch zigzags about {name} = {} (over [{}, {}], {ZIGZAG_STEPS} steps): a fold of the orbit sharper than the kinks of the map at this k",
                    band.0, band.1, band.2
                );
            }
            if last.solved.masks != here.solved.masks {
                left.push_back(std::mem::take(&mut here.solved.masks));
                if left.len() > PIECES_REMEMBERED {
                    left.pop_front();
                }
            }
            here = last;
            turned = false;
            if iterations <= 3 {
                ds = (ds * 1.5).min(settings.max_step);
            } else if iterations >= 6 {
                ds *= 0.6;
            }
            ds = ds.max(settings.min_step);
        };
        merge_fold_pairs(&mut points, settings.fold_merge * rho);
        Ok(Walked { points, stop, zigzag })
    }
}

/// The step below which a failed corrector looks for a kink to cross ([`Family::cross_kink`]),
/// small enough that the predictor's line stays within round-off of the branch up to the kink.
const CROSS_BELOW: f64 = 1e-4;

/// Pieces of the map a walk remembers having left.
const PIECES_REMEMBERED: usize = 64;

/// The reported point of a node: multipliers, and the amplitudes of the session's certified solve
/// warm-started from the node's active sets.
fn point(fam: &Family, solver: &mut PeriodicSolver, node: &Node, event: Option<EventKind>, detail: String) -> Result<BranchPoint, Error> {
    let lambda = node.solved.parameter(fam.rho);
    solver.update_problem(fam.problem_at(lambda)?);
    let set = active_set(&node.solved.masks, solver.problem().model().contacts.len());
    solver.set_warm_start(&set);
    let r = solver.solve().map_err(|e| Error::from(e).context(format!("certifying the continuation's orbit at {lambda}")))?;
    let mut got = r.active_set.clone();
    got.sort_unstable();
    let amplitude = amplitudes(solver.problem(), &r);
    let max_multiplier = floquet::largest(&node.mu);
    if max_multiplier.is_nan() {
        return Err(Error::solve(format!(
            "the orbit at {lambda} has no stability: its monodromy's Schur form did not converge (multipliers unknown); remedy: another k or a smaller step"
        )));
    }
    Ok(BranchPoint {
        parameter: lambda,
        amplitude,
        multipliers: node.mu.clone(),
        max_multiplier,
        stable: max_multiplier <= 1.0,
        period_multiple: solver.problem().period_multiple(),
        event,
        detail,
        certified: got == set,
        state: node.solved.v[..node.solved.v.len() - 1].to_vec(),
        time: 0.0,
        masks: node.solved.masks.clone(),
        tangent: node.tangent.clone(),
        source: Source::Discrete,
    })
}

/// Indices j·m + c of the active pairs (the LCP's z order), m contacts.
fn active_set(masks: &[u64], m: usize) -> Vec<usize> {
    masks.iter().enumerate().flat_map(|(j, mask)| (0..m).filter(move |c| mask >> c & 1 == 1).map(move |c| j * m + c)).collect()
}

/// Peak-to-peak/2 of each displacement output.
fn amplitudes(problem: &PeriodicProblem, r: &Response) -> Vec<f64> {
    problem.outputs().displacement.iter().map(|d| r.displacement.get(&d.to_string()).map_or(0.0, |s| Response::peak_to_peak(s) / 2.0)).collect()
}
