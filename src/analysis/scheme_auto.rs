//! `scheme = "auto"`: refine k until the result's own error estimate meets the requested
//! tolerance. The scheme, its pairing and the first k come from the policy
//! (`periodic::limits::auto_scheme`, applied when the scene is built); here k doubles, each
//! result estimated by Richardson against the neighbouring grid ([`super::accuracy`]), whose
//! solve is the previous k's (or the next k's, when k/2 breaks the stability limit), so the
//! refinement costs about two solves at the final k.
//!
//! It stops when the estimate is at most [`SAFETY`]⁻¹·tolerance and trusted (every mode
//! resolved, or the estimates falling at the scheme's order: [`in_asymptotic_range`]), or when the next k
//! would pass `max_steps`, the problem's size limits, or the time budget, or no estimate can
//! be made: then the finest result is returned with `met = false` and the reason.
use super::accuracy;
use crate::periodic::limits::AccuracyTarget;
use crate::periodic::{PeriodicProblem, SolveError};
use crate::response::{Response, SchemeChoice, SchemeTrial};
use crate::time::Discretization;
use std::time::Instant;

/// The estimate must be this many times below the tolerance. Why: on our families the
/// Richardson estimate of the second-order schemes reads 0.63–5.9× the true error (README
/// "What accuracy costs"), so a factor 2 covers the estimates that read low by up to 2×.
pub const SAFETY: f64 = 2.0;
/// The next k's solve is projected at this multiple of the current one's (2× the unknowns,
/// plus the FFTs' log factor and the LCP's growing active set).
const GROWTH: f64 = 2.5;

/// Solves `problem` (already on the policy's scheme and first k) at doubling k until the
/// relative error estimate meets `target`; `choice` is the policy's reason. The result carries
/// its estimate in `accuracy` and the decision in `scheme_choice`; `met` is false when the
/// refinement stopped first (a warning says why). An error of the first solve is returned.
pub fn solve_to_tolerance(problem: &mut PeriodicProblem, target: &AccuracyTarget, choice: &str) -> Result<Response, SolveError> {
    let mut tried: Vec<SchemeTrial> = Vec::new();
    // Results by k, for reuse as the neighbouring grid of the estimate.
    let mut solved: Vec<Response> = Vec::new();
    let goal = target.tolerance / SAFETY;
    let mut best: Option<Response> = None;
    let stop: String = loop {
        let k = problem.discretization().steps;
        let t0 = Instant::now();
        let mut r = match solved.iter().position(|r| r.steps == problem.instants()) {
            Some(i) => solved.swap_remove(i),
            None => match problem.solve() {
                Ok(r) => r,
                Err(e) if best.is_some() => break format!("the solve at k = {k} failed: {e}"),
                // A failure at the first k may be the coarse grid's (an LCP that is not a
                // P-matrix): try the next k once, else the failure is the answer.
                Err(e) if tried.is_empty() && 2 * k <= target.max_steps => {
                    tried.push(SchemeTrial { steps: k, estimate: None, seconds: t0.elapsed().as_secs_f64() });
                    problem.set_discretization(Discretization { steps: 2 * k, ..problem.discretization() }).map_err(|_| e)?;
                    continue;
                }
                Err(e) => return Err(e),
            },
        };
        let mut neighbour = |second: &PeriodicProblem| -> Result<Response, SolveError> {
            match solved.iter().find(|r| r.steps == second.instants()) {
                Some(r) => Ok(r.clone()),
                None => {
                    let rs = second.solve()?;
                    solved.push(rs.clone());
                    Ok(rs)
                }
            }
        };
        r.accuracy = accuracy::estimate_with(problem, &r, &mut neighbour);
        let seconds = t0.elapsed().as_secs_f64();
        let estimate = r.accuracy.relative;
        let previous = tried.last().filter(|t| t.steps * 2 == k).and_then(|t| t.estimate);
        tried.push(SchemeTrial { steps: k, estimate, seconds });
        solved.retain(|s| s.steps > r.steps / 2);
        solved.push(r.clone());
        best = Some(r);
        let asymptotic = in_asymptotic_range(problem, estimate, previous);
        match estimate {
            Some(e) if e <= goal && asymptotic => break String::new(),
            Some(_) => {}
            // The policy picks converging choices only, so a missing estimate is a failed
            // neighbour solve (a coarse LCP that is not a P-matrix): the next k reuses this one.
            None => {}
        }
        let next = 2 * k;
        let last_reason = best.as_ref().map_or(String::new(), |b| b.accuracy.method.clone());
        if next > target.max_steps && estimate.is_none() {
            break format!("no error estimate at k = {k} ({last_reason}) and the next k = {next} passes max_steps = {}", target.max_steps);
        }
        if next > target.max_steps {
            break format!("the next k = {next} passes max_steps = {} (discretization.max_steps)", target.max_steps);
        }
        let projected = GROWTH * seconds;
        if projected > target.time_budget {
            break format!(
                "the solve at k = {next} is projected at {projected:.1} s (k = {k} took {seconds:.2} s with its estimate), past time_budget = {} s (discretization.time_budget)",
                target.time_budget
            );
        }
        if let Err(e) = problem.set_discretization(Discretization { steps: next, ..problem.discretization() }) {
            break format!("k = {next} is refused: {e}");
        }
    };
    let mut r = best.expect("the first solve either succeeded or returned");
    let last = tried.iter().rev().find(|t| t.estimate.is_some());
    let stop = match last {
        Some(t) if !stop.is_empty() && t.estimate.is_some_and(|e| e <= goal) => {
            format!(
                "{stop}; the estimate {:.2e} at k = {} is below tolerance/{SAFETY} but not trusted: the estimates did not fall at the scheme's order between k/2 and k (pre-asymptotic)",
                t.estimate.unwrap_or(0.0),
                t.steps
            )
        }
        _ => stop,
    };
    let met = stop.is_empty();
    let estimate = r.accuracy.relative;
    let shown = estimate.map_or("none".to_string(), |e| format!("{e:.2e}"));
    let why = if met {
        format!("{choice}; k = {}: estimate {shown} ≤ tolerance/{SAFETY} = {goal:.1e}", r.steps)
    } else {
        let w = format!(
            "scheme = \"auto\" did not reach tolerance {:e}: the best is k = {} with estimate {shown} of the peak-to-peak amplitude; stopped because {stop}; remedy: raise discretization.max_steps or time_budget, loosen tolerance, or use a massless-boundary reduction (src/formulation.md §4.1)",
            target.tolerance, r.steps
        );
        r.warnings.push(w.clone());
        format!("{choice}; {w}")
    };
    r.scheme_choice =
        Some(SchemeChoice { tolerance: target.tolerance, met, scheme: r.scheme.clone(), pairing: r.pairing.clone(), steps: r.steps, estimate, why, tried });
    Ok(r)
}

/// Whether a Richardson estimate can be trusted:
/// - it did not fall much faster than the scheme's order p from k/2 (observed order ≤ p + 1.5):
///   a faster fall says k/2 was pre-asymptotic, and the estimate reads low (measured: the stiff
///   compliant stop k_c = 5585, galerkin, 5.0e-2 → 2.3e-4 from k = 512 to 1024 with a true error
///   of 4.2e-3; tests/scheme_auto.rs);
/// - and every mode is resolved (ω_max·h < 2√3, the stable range of the policy's steppers), or
///   the estimate fell at least at order p − 1 from k/2. Why: bds1/bds2 past that (stiff modes
///   unresolved) are pre-asymptotic and their estimate reads low (the compliant stop with
///   k_c = 1e5 under bds2 at k = 512: estimate 3.2e-2, true error 0.24).
fn in_asymptotic_range(problem: &PeriodicProblem, estimate: Option<f64>, previous: Option<f64>) -> bool {
    let p = problem.discretization().scheme.order().unwrap_or(2) as f64;
    if let (Some(e), Some(e2)) = (estimate, previous) {
        if e2 > e * 2f64.powf(p + 1.5) {
            return false;
        }
    }
    let h = problem.period() / problem.instants() as f64;
    if problem.omega_max() * h < 2.0 * 3f64.sqrt() {
        return true;
    }
    matches!((estimate, previous), (Some(e), Some(e2)) if e <= e2 * 2f64.powf(1.0 - p))
}
