//! `scheme = "auto"`: refine k until the result's own error estimate meets the requested
//! tolerance. The scheme, its pairing and the first k come from the policy
//! (`periodic::limits::auto_scheme`, applied when the scene is built); here k doubles, each
//! result estimated by Richardson against the neighbouring grid ([`super::accuracy`]), whose
//! solve is the previous k's (or the next k's, when k/2 breaks the stability limit), so the
//! refinement costs about two solves at the final k.
//!
//! It stops when the result's error bound is at most [`SAFETY`]⁻¹·tolerance and trusted, or
//! when the next k would pass `max_steps`, the problem's size limits or the time budget, or no
//! estimate can be made: then the finest result is returned with `met = false` and the reason.
//! The bound is the envelope of the Richardson estimates ([`envelope`]), trusted only when every
//! contact phase is resolved ([`MIN_PHASE_STEPS`]) and the modes are resolved or the estimates
//! fall at the scheme's order ([`modes_in_asymptotic_range`]).
use super::accuracy::{self, neighbour};
use crate::periodic::limits::AccuracyTarget;
use crate::periodic::{PeriodicProblem, SolveError, carried_active_set};
use crate::response::{EstimateMissing, Response, SchemeChoice, SchemeTrial};
use crate::time::Discretization;
use std::time::Instant;

/// The bound must be this many times below the tolerance. Why: on the families of
/// tests/scheme_auto.rs the true error reached 1.38× the trusted bound (rigid stops with
/// sticking, a single estimate at k = 128; README "Scheme limits").
pub const SAFETY: f64 = 2.0;
/// The next k's solve is projected at this multiple of the current one's (2× the unknowns,
/// plus the FFTs' log factor and the LCP's growing active set).
const GROWTH: f64 = 2.5;
/// Fewest instants in every contact phase of a finite-force contact (compliant, rigid on a
/// massless DOF) before its estimate is trusted: the k/2 grid of the estimate then sees each
/// phase at 4 instants or more. Why: below, the measured estimate read 3.4× low (compliant stop
/// k_c = 6724, 9 instants in contact at k = 1024; tests/scheme_auto.rs).
pub const MIN_PHASE_STEPS: usize = 32;

/// Solves `problem` (already on the policy's scheme and first k) at doubling k until the
/// relative error bound ([`envelope`]) meets `target` and is trusted ([`distrust`]); `choice` is
/// the policy's reason. The result carries its Richardson estimate in `accuracy` and the
/// decision, with the bound, in `scheme_choice`; `met` is false when the
/// refinement stopped first (a warning says why). An error of the first solve is returned.
pub fn solve_to_tolerance(problem: &mut PeriodicProblem, target: &AccuracyTarget, choice: &str) -> Result<Response, SolveError> {
    solve_to_tolerance_within(problem, target, choice, neighbour::ESTIMATE_BUDGET_CPU_S)
}

/// [`solve_to_tolerance`] with each level's estimate bounded by `estimate_budget` CPU seconds
/// ([`neighbour::solve`]: warm shooting, cold shooting, dense Lemke only within what is left); a
/// neighbour past it or missed leaves that level without an estimate, typed in
/// `accuracy.missing`, and the refinement goes on to the next k as after any missing estimate.
pub fn solve_to_tolerance_within(problem: &mut PeriodicProblem, target: &AccuracyTarget, choice: &str, estimate_budget: f64) -> Result<Response, SolveError> {
    let mut tried: Vec<SchemeTrial> = Vec::new();
    // Results by k, for reuse as the neighbouring grid of the estimate.
    let mut solved: Vec<Response> = Vec::new();
    let goal = target.tolerance / SAFETY;
    let mut best: Option<Response> = None;
    // Why the last bound cannot be trusted yet (None: it can).
    let mut untrusted: Option<String> = None;
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
                    tried.push(SchemeTrial { steps: k, estimate: None, bound: None, seconds: t0.elapsed().as_secs_f64() });
                    problem.set_discretization(Discretization { steps: 2 * k, ..problem.discretization() }).map_err(|_| e)?;
                    continue;
                }
                Err(e) => return Err(e),
            },
        };
        let (active, instants) = (r.active_set.clone(), problem.instants());
        let rows = r.lcp.size / instants.max(1);
        let budget = neighbour::Budget::new(estimate_budget);
        let mut neighbour = |second: &PeriodicProblem, note: &str| -> Result<Response, EstimateMissing> {
            match solved.iter().find(|r| r.steps == second.instants()) {
                Some(r) => Ok(r.clone()),
                None => {
                    // Warm from this k's active set, as `accuracy::estimate` does (cold, the rigid
                    // massless blade missed in shooting at 2k = 1024: validation/RECORD.md "Against time
                    // marching"), and bounded as it is (an unbounded dense fallback ran minutes).
                    let rs = neighbour::solve(second, &carried_active_set(&active, rows, instants, second.instants()), &budget, note)?;
                    solved.push(rs.clone());
                    Ok(rs)
                }
            }
        };
        r.accuracy = accuracy::estimate_with(problem, &r, &mut neighbour);
        // With k/2 and k/4 at hand (the earlier levels), the observed order enters the estimate.
        let below = |n: usize| solved.iter().find(|s| s.steps * n == r.steps);
        if let (Some(half), Some(quarter), Ok((second, note))) = (below(2), below(4), accuracy::second_grid(problem, &r))
            && second.instants() == half.steps
            && r.accuracy.estimate.is_some()
        {
            r.accuracy = accuracy::estimate_from(problem, &r, half, Some(quarter), &note);
        }
        let seconds = t0.elapsed().as_secs_f64();
        let estimate = target.measure.of(&r.accuracy);
        let order = accuracy::expected_order(problem, &r).0.unwrap_or(1.0);
        let previous = tried.last().filter(|t| t.steps * 2 == k).and_then(|t| t.estimate);
        let bound = estimate.map(|e| envelope(e, k, order, &tried));
        tried.push(SchemeTrial { steps: k, estimate, bound, seconds });
        // k/2 stays for the next level's observed order.
        solved.retain(|s| s.steps > r.steps / 4);
        solved.push(r.clone());
        untrusted = distrust(problem, &r, estimate, previous, order);
        best = Some(r);
        // A missing estimate is a failed neighbour solve (a coarse LCP that is not a
        // P-matrix; the policy picks converging choices only): the next k reuses this one.
        if bound.is_some_and(|b| b <= goal) && untrusted.is_none() {
            break String::new();
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
    let stop = match (tried.last().and_then(|t| t.bound), &untrusted) {
        (Some(b), Some(why)) if !stop.is_empty() && b <= goal => {
            format!("{stop}; the bound {b:.2e} at k = {} is below tolerance/{SAFETY} but not trusted: {why}", r.steps)
        }
        _ => stop,
    };
    let met = stop.is_empty();
    let estimate = tried.last().and_then(|t| t.bound);
    let shown = estimate.map_or("none".to_string(), |e| format!("{e:.2e}"));
    let why = if met {
        format!(
            "{choice}; k = {}: error bound {shown} (the envelope of the Richardson estimates) ≤ tolerance/{SAFETY} = {goal:.1e}, every contact phase over ≥ {MIN_PHASE_STEPS} instants",
            r.steps
        )
    } else {
        let w = format!(
            "scheme = \"auto\" did not reach tolerance {:e}: the best is k = {} with error bound {shown} of the peak-to-peak amplitude; stopped because {stop}; remedy: raise discretization.max_steps or time_budget, loosen tolerance, or use a massless-boundary reduction (src/formulation.md §4.1)",
            target.tolerance, r.steps
        );
        r.warnings.push(w.clone());
        format!("{choice}; {w}")
    };
    r.scheme_choice =
        Some(SchemeChoice { tolerance: target.tolerance, met, scheme: r.scheme.clone(), pairing: r.pairing.clone(), steps: r.steps, estimate, why, tried });
    Ok(r)
}

/// The error bound at k: the largest of the Richardson estimate `estimate` and the earlier
/// levels' estimates carried to k at the scheme's order p, max_n e_{k/2ⁿ}·2^(−n·p). Why: at a
/// contact's kink the error's constant depends on where the grid meets the event, so two
/// neighbouring grids can share most of their error and their difference reads low (measured:
/// the compliant stop k_c = 6724 under galerkin, estimates 1.4e-4, 4.0e-5, 3.7e-5 at k = 1024,
/// 2048, 4096 with true errors 4.8e-4, 4.1e-4, 3.0e-4); the envelope of the estimates still
/// falls at order p (src/formulation.md §3), and it bounded every true error of our families.
pub fn envelope(estimate: f64, k: usize, order: f64, earlier: &[SchemeTrial]) -> f64 {
    earlier
        .iter()
        .filter(|t| t.steps < k && k.is_multiple_of(t.steps))
        .filter_map(|t| t.estimate.map(|e| e * (t.steps as f64 / k as f64).powf(order)))
        .fold(estimate, f64::max)
}

/// Why the bound of `r` cannot be trusted yet, or `None`:
/// - a contact phase of a finite-force contact spans fewer than [`MIN_PHASE_STEPS`] instants;
/// - or a mode is unresolved (ω_max·h ≥ 2√3, the stable range of the policy's steppers) and the
///   estimate did not fall at least at order p − 1 from k/2. Why: bds1/bds2 past that are
///   pre-asymptotic and their estimate reads low (the compliant stop with k_c = 1e5 under bds2
///   at k = 512: estimate 3.2e-2, true error 0.24).
fn distrust(problem: &PeriodicProblem, r: &Response, estimate: Option<f64>, previous: Option<f64>, order: f64) -> Option<String> {
    let model = problem.model();
    let finite = |i: usize| model.contacts.get(i).is_some_and(|c| !c.is_rigid() || model.contact_is_massless(c));
    let shortest = r.contacts.iter().enumerate().filter(|(i, _)| finite(*i)).filter_map(|(_, c)| shortest_phase(&c.force)).min();
    if let Some(n) = shortest.filter(|&n| n < MIN_PHASE_STEPS) {
        return Some(format!("a contact phase spans {n} instants at k = {}, fewer than {MIN_PHASE_STEPS} (its event is not resolved)", r.steps));
    }
    let h = problem.period() / problem.instants() as f64;
    let resolved = problem.omega_max() * h < 2.0 * 3f64.sqrt();
    match (estimate, previous) {
        _ if resolved => None,
        (Some(e), Some(e2)) if e <= e2 * 2f64.powf(1.0 - order) => None,
        _ => Some(format!(
            "ω_max·h = {:.2} ≥ 2√3 (stiff modes unresolved) and the estimates did not fall at order ≥ {} from k/2 (pre-asymptotic)",
            problem.omega_max() * h,
            order - 1.0
        )),
    }
}

/// The fewest instants of a run of positive force, cyclically; `None` without contact or in
/// permanent contact (no event to resolve).
fn shortest_phase(force: &[f64]) -> Option<usize> {
    let k = force.len();
    let start = (0..k).find(|&j| force[j] <= 0.0)?;
    let (mut shortest, mut run) = (None::<usize>, 0);
    for j in 1..=k {
        if force[(start + j) % k] > 0.0 {
            run += 1;
        } else if run > 0 {
            shortest = Some(shortest.map_or(run, |s| s.min(run)));
            run = 0;
        }
    }
    shortest
}
