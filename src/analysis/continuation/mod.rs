//! Continuation of periodic contact orbits in one scalar parameter (issue 13): branches, not
//! points.
//!
//! Pseudo-arclength (Keller 1977) on the shooting formulation of the difference schemes: the
//! unknowns are the orbit's initial state s_0 and the parameter λ, the equations
//! s_0 = P(s_0; λ) with P the period map of the problem's step map at λ, bordered by the
//! arclength condition. P is piecewise affine in s_0 (a piece per active sets), so Newton is exact
//! on a piece and the path crosses kinks (grazings, stick/release, nonsmooth folds) by
//! shortening its step. Each point's Floquet multipliers are the eigenvalues of dP/ds_0 with the
//! active sets frozen (the discrete monodromy, notes §7); events are located by bisection
//! ([`events`]). Every reported point is certified as the LCP `solve` solves: the branch's
//! session ([`PeriodicSolver`]) solves it warm-started from the point's active sets, and its
//! amplitudes are that certified response's.
mod corrector;
mod events;
mod floquet;
mod follow;
pub mod output;

pub use events::EventKind;
pub use floquet::multipliers;
pub use follow::{Current, Followed, Jump, Resolved, Stability, amplitude, follow, resolve, stability};

use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver};
use crate::response::Response;
use corrector::{Family, Path};
use events::Node;
use num_complex::Complex64;

/// The continued parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameter {
    /// The excitation frequency ω [rad/s] (the period T = 2π/ω; k steps per period).
    Frequency,
}

impl Parameter {
    /// From its CLI name.
    pub fn parse(name: &str) -> Result<Parameter, Error> {
        match name {
            "frequency" => Ok(Parameter::Frequency),
            other => Err(Error::input(format!("--param: is \"{other}\"; continuation takes frequency"))),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Parameter::Frequency => "frequency",
        }
    }
    /// Sets the parameter of `problem` to `value`, checked.
    fn apply(self, problem: &mut PeriodicProblem, value: f64) -> Result<(), Error> {
        match self {
            Parameter::Frequency => problem.set_frequency(value).map_err(Error::from),
        }
    }
}

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
    /// Two successive folds closer than this (relative to |to − from|) are the path's wiggle
    /// across kinks of the discrete map, not a turn: both are dropped (NLvib 03, k = 4096: pairs
    /// 3e-5 to 2e-4 apart near the peak, none between the true folds 0.102 apart).
    pub fold_merge: f64,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        ContinuationSettings { initial_step: 2e-3, min_step: 1e-9, max_step: 2e-2, max_points: 5000, tolerance: 1e-10, smoothing: 5e-3, fold_merge: 1e-3 }
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
    /// The orbit's initial state s_0 (the step map's state).
    pub state: Vec<f64>,
}

/// A continued branch.
#[derive(Clone, Debug)]
pub struct Branch {
    pub parameter: Parameter,
    pub points: Vec<BranchPoint>,
    /// Why the continuation stopped ("reached", or the reason).
    pub stop: String,
    /// Marches of the period map made.
    pub marches: usize,
}

impl Branch {
    /// The event points, in order along the branch.
    pub fn events(&self) -> impl Iterator<Item = &BranchPoint> {
        self.points.iter().filter(|p| p.event.is_some())
    }
}

/// Continues the orbit of `problem` at λ = `from` (the session's solve, warm starts as in a
/// sweep) in the parameter up to λ = `to`, or until the branch leaves [from, to] the other way.
/// `on_point(λ)` after each point (a progress bar).
pub fn run(problem: &PeriodicProblem, param: Parameter, from: f64, to: f64, settings: &ContinuationSettings, on_point: &dyn Fn(f64)) -> Result<Branch, Error> {
    if !(from.is_finite() && to.is_finite() && from != to) {
        return Err(Error::input(format!("--from/--to: are {from} and {to}, must be finite and different")));
    }
    let (rho, dir) = ((to - from).abs(), (to - from).signum());
    let mut fam = Family::new(problem, Path::Parameter(param), rho);
    fam.tolerance = settings.tolerance;
    fam.smoothing = settings.smoothing;
    let (k, m) = (problem.discretization().steps, problem.model().contacts.len());
    fam.map_at(from)?;
    let mut solver = PeriodicSolver::new(fam.problem_at(from)?);
    let first = solver.solve().map_err(|e| Error::from(e).context(format!("the start of the continuation at {} = {from}", param.name())))?;
    let mut masks = vec![0u32; k];
    for &i in &first.active_set {
        masks[i / m] |= 1 << (i % m);
    }
    let start = fam
        .start(from, &masks)
        .ok_or_else(|| Error::solve(format!("continuation: the orbit at {} = {from} did not close on its active sets", param.name())))?;
    let d = start.v.len() - 1;
    let border: Vec<f64> = (0..=d).map(|i| if i == d { dir } else { 0.0 }).collect();
    let tangent = start.tangent(&border).ok_or_else(|| Error::solve(format!("continuation: singular Jacobian at {} = {from}", param.name())))?;
    let mut here = Node::new(&mut fam, start, tangent);
    let mut points = vec![point(&fam, &mut solver, &here, None, String::new())?];
    on_point(from);
    let mut ds = settings.initial_step;
    let stop = loop {
        if points.len() >= settings.max_points {
            break format!("{} points (the limit)", settings.max_points);
        }
        let pred: Vec<f64> = here.solved.v.iter().zip(&here.tangent).map(|(v, t)| v + ds * t).collect();
        let Some((next, iterations)) = fam.correct(&pred, &here.tangent, &here.solved.masks) else {
            ds /= 2.0;
            if ds < settings.min_step {
                break format!("no convergence at {} = {} with the smallest step", param.name(), here.solved.parameter(rho));
            }
            continue;
        };
        let Some(t_next) = next.tangent(&here.tangent) else {
            ds /= 2.0;
            continue;
        };
        let mut next = Node::new(&mut fam, next, t_next);
        let lambda = next.solved.parameter(rho);
        let past_end = (lambda - to) * dir > 0.0;
        if past_end {
            // The last point at λ = to exactly, interpolated between here and next.
            let l0 = here.solved.parameter(rho);
            let f = (to - l0) / (lambda - l0);
            let pred: Vec<f64> = here.solved.v.iter().zip(&next.solved.v).map(|(a, b)| a + f * (b - a)).collect();
            let normal: Vec<f64> = (0..=d).map(|i| if i == d { 1.0 } else { 0.0 }).collect();
            if let Some((end, _)) = fam.correct(&pred, &normal, &here.solved.masks)
                && let Some(t) = end.tangent(&here.tangent)
            {
                next = Node::new(&mut fam, end, t);
            }
        }
        for (kind, node, detail) in events::between(&mut fam, &here, &next, m) {
            points.push(point(&fam, &mut solver, &node, Some(kind), detail)?);
        }
        points.push(point(&fam, &mut solver, &next, None, String::new())?);
        on_point(next.solved.parameter(rho));
        if past_end {
            break "reached".to_string();
        }
        if (next.solved.parameter(rho) - from) * dir < 0.0 {
            break format!("the branch turned back below {} = {from}", param.name());
        }
        here = next;
        if iterations <= 3 {
            ds = (ds * 1.5).min(settings.max_step);
        } else if iterations >= 6 {
            ds *= 0.6;
        }
        ds = ds.max(settings.min_step);
    };
    merge_fold_pairs(&mut points, settings.fold_merge * rho);
    Ok(Branch { parameter: param, points, stop, marches: fam.marches })
}

/// Drops successive fold events closer than `width` in the parameter, pairwise.
fn merge_fold_pairs(points: &mut [BranchPoint], width: f64) {
    let folds: Vec<usize> = (0..points.len()).filter(|&i| points[i].event == Some(EventKind::Fold)).collect();
    let mut i = 0;
    while i + 1 < folds.len() {
        let (a, b) = (folds[i], folds[i + 1]);
        if (points[a].parameter - points[b].parameter).abs() < width {
            points[a].event = None;
            points[b].event = None;
            i += 2;
        } else {
            i += 1;
        }
    }
}

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
    Ok(BranchPoint {
        parameter: lambda,
        amplitude,
        multipliers: node.mu.clone(),
        max_multiplier,
        stable: max_multiplier <= 1.0,
        period_multiple: 1,
        event,
        detail,
        certified: got == set,
        state: node.solved.v[..node.solved.v.len() - 1].to_vec(),
    })
}

/// Indices j·m + c of the active pairs (the LCP's z order), m contacts.
fn active_set(masks: &[u32], m: usize) -> Vec<usize> {
    masks.iter().enumerate().flat_map(|(j, mask)| (0..m).filter(move |c| mask >> c & 1 == 1).map(move |c| j * m + c)).collect()
}

/// Peak-to-peak/2 of each displacement output.
fn amplitudes(problem: &PeriodicProblem, r: &Response) -> Vec<f64> {
    problem.outputs().displacement.iter().map(|d| r.displacement.get(&d.to_string()).map_or(0.0, |s| Response::peak_to_peak(s) / 2.0)).collect()
}
