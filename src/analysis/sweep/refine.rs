//! Per-point accuracy of a sweep ([`super::SweepSettings::tolerance`]): where a point's error
//! estimate exceeds the tolerance, the point is solved again on the doubled grid (k → 2k, up to
//! `max_steps`), warm-started from its answer carried there, and estimated by Richardson between
//! the new answer and the coarser one it already has: each refinement costs one warm solve, the
//! estimate none. Why: on the real blade (issue 23) one k for 200 points meets 1e-3 at 37 points
//! with k = 1024 and 149 with 2048; the misses sit at the folds and where contact starts.
use super::{ColdTry, SweepPoint, SweepSettings, guarded, solve_guarded};
use crate::analysis::accuracy;
use crate::periodic::{PeriodicProblem, PeriodicSolver, SolveError};
use crate::response::{Accuracy, Response};
use crate::time::Discretization;

/// The chunk's sessions of the refined grids: `levels[l]` solves at 2^(l+1)·k, warm-started
/// along the chunk like the first grid's.
pub(super) type Levels = Vec<PeriodicSolver>;

/// Refines `point`, the answer `first` of `problem` (the chunk's first grid at the point's
/// frequency; `below`, its estimate's k/2 answer, or why there is none), while its estimate
/// exceeds the tolerance and the doubled k stays within `settings.max_steps`. The point keeps its
/// coarser answer where a refined solve fails (a large LCP's refined try is Newton from the
/// carried set alone, [`solve_guarded`]); the failure is noted in its `estimate_method`.
pub(super) fn refine(
    point: &mut SweepPoint,
    problem: &PeriodicProblem,
    first: &Response,
    below: Below,
    (levels, second): (&mut Levels, &mut Coarser),
    settings: &SweepSettings,
) {
    let Some(tolerance) = settings.tolerance else { return };
    let (below, skipped) = match below {
        Below::Solved(r) => (Some(*r), false),
        Below::None => (None, false),
        Below::Skipped => (None, true),
    };
    let f = point.frequency;
    let m = problem.model().contacts.len().max(1);
    // The two grids below the next one, coarse to fine: Richardson and the observed order.
    let (mut third, mut coarse): (Option<Response>, Option<Response>) = (below, None);
    for level in 0.. {
        let prev = coarse.as_ref().unwrap_or(first);
        let steps = problem.discretization().steps << (level + 1);
        if !((skipped && level == 0) || point.estimate_relative.is_some_and(|e| e > tolerance)) || steps > settings.max_steps {
            return;
        }
        if levels.len() == level {
            let mut p = problem.clone();
            if let Err(e) = p.set_discretization(Discretization { steps, ..problem.discretization() }) {
                point.estimate_method.push_str(&format!("; not refined to k = {steps}: {e}"));
                return;
            }
            levels.push(PeriodicSolver::new(p).with_warm_starts(settings.warm_start));
        }
        let solver = &mut levels[level];
        let carried = crate::periodic::carried_active_set(&prev.active_set, m, prev.lcp.size / m, solver.problem().instants());
        solver.set_warm_start(&carried);
        solver.set_warm_state(carried_state(prev, solver.problem(), m));
        let r =
            if guarded(solver.problem()) { solve_guarded(solver, None, f, ColdTry::No).0 } else { solver.update_frequency(f).and_then(|()| solver.solve()) };
        let r = match r {
            Ok(r) => r,
            Err(e) => {
                if skipped && level == 0 {
                    // The first grid keeps its answer: its own estimate after all.
                    estimate(point, problem, first, second, settings, None);
                }
                point.estimate_method.push_str(&format!("; refinement to k = {steps} failed ({}), k = {} kept", first_clause(&e), steps / 2));
                return;
            }
        };
        // Richardson between this grid and the one below, the observed order from the one
        // below that: both answers are at hand.
        let note = format!("k/2 = {}", steps / 2);
        let a = if skipped && level == 0 {
            first_skipped(solver.problem(), &r, (problem, first), second, settings, tolerance, &note)
        } else {
            accuracy::estimate_from(solver.problem(), &r, prev, third.as_ref().filter(|t| t.steps * 4 == steps), &note)
        };
        let Some(relative) = settings.measure.of(&a) else {
            point.estimate_method.push_str(&format!("; refined to k = {steps} without an estimate ({}), k = {} kept", a.method, steps / 2));
            return;
        };
        let mut refined = SweepPoint::from_response(solver.problem(), f, &r);
        (refined.estimate_relative, refined.estimate_method) = (Some(relative), a.method);
        (refined.substeps, refined.warm_start_used, refined.cold_fallback) = (point.substeps, point.warm_start_used, point.cold_fallback);
        // The first grid's active set stays: it warm-starts the neighbours (`refill`).
        (refined.time_s, refined.active_set) = (point.time_s, std::mem::take(&mut point.active_set));
        refined.first_grid = point.first_grid.take().or_else(|| Some((std::mem::take(&mut point.amplitude), std::mem::take(&mut point.max_force))));
        *point = refined;
        third = Some(coarse.take().unwrap_or_else(|| first.clone()));
        coarse = Some(r);
    }
}

/// The estimate at 2k of a point whose first grid (k, `first` of `problem`) was not estimated
/// ([`Below::Skipped`]): where even Richardson at the scheme's order from k exceeds the tolerance
/// ([`accuracy::least_estimate`], a floor of the three-grid estimate) the point goes on to 4k
/// and k/2 is never solved; otherwise k/2 is solved now (carried from `first`) for the
/// three-grid estimate, the one the climb from k would have given.
fn first_skipped(
    refined: &PeriodicProblem,
    r: &Response,
    (problem, first): (&PeriodicProblem, &Response),
    second: &mut Coarser,
    settings: &SweepSettings,
    tolerance: f64,
    note: &str,
) -> Accuracy {
    if settings.measure.of(&accuracy::least_estimate(refined, r, first, note)).is_some_and(|e| e > tolerance) {
        let mut a = accuracy::estimate_from(refined, r, first, None, note);
        a.method.push_str(&format!("; k/4 = {} not solved: even Richardson at the scheme's order from k/2 exceeds the tolerance", r.steps / 4));
        return a;
    }
    let quarter = accuracy::second_grid(problem, first)
        .ok()
        .filter(|(g, _)| g.instants() < problem.instants())
        .and_then(|(g, _)| second_solve(second, &g, first, settings.warm_start, ColdTry::Full).ok());
    accuracy::estimate_from(refined, r, first, quarter.as_ref(), note)
}

/// The chunk's sessions of the estimates' coarser grids (k/2 and k/4, or 2k), each with the
/// frequency it last solved.
pub(super) type Coarser = Vec<(PeriodicSolver, Option<f64>)>;

/// The first grid's k/2 answer for [`refine`]: solved, none, or skipped ([`estimate`]'s
/// `predicted`).
pub(super) enum Below {
    Solved(Box<Response>),
    None,
    Skipped,
}

/// The previous point needed at least this many times the first grid's k for the next point to
/// skip the first grid's estimate ([`estimate`]): its k/2 and k/4 solves (a point needs one
/// coarser level than its neighbour 3 rad/s away at most).
const SKIP_FROM: usize = 4;

/// The point's error estimate ([`SweepSettings::estimate`]): a second solve on the other grid and
/// a third at k/4 for the observed order ([`accuracy::estimate_from`]), in the chunk's sessions
/// for those grids. Returns the k/2 answer (the refinement's third grid). `predicted`: the k the
/// previous point of the chunk ended at; from [`SKIP_FROM`] times this k on, with a tolerance,
/// the estimate is skipped and the point refined at once ([`Below::Skipped`], [`first_skipped`]).
/// Why: the real blade's 1e-3 sweep (issue 23) needs k = 4096–8192 at 84 of 200 points, whose
/// k/2 and k/4 solves of the first grid served only to find k = 1024 short. From twice this k
/// on, k/4 is solved only where the two grids' estimate is within the tolerance.
pub(super) fn estimate(
    point: &mut SweepPoint,
    problem: &PeriodicProblem,
    r: &Response,
    second: &mut Coarser,
    settings: &SweepSettings,
    predicted: Option<usize>,
) -> Below {
    if !settings.estimate {
        return Below::None;
    }
    let (grid, note) = match accuracy::second_grid(problem, r) {
        Ok(g) => g,
        Err(a) => {
            (point.estimate_relative, point.estimate_method) = (settings.measure.of(&a), a.method);
            return Below::None;
        }
    };
    let steps = problem.discretization().steps;
    if let Some(before) = predicted.filter(|&p| p >= SKIP_FROM * steps && settings.tolerance.is_some() && 2 * steps <= settings.max_steps)
        && grid.instants() < problem.instants()
    {
        (point.estimate_relative, point.estimate_method) = (None, format!("none at k = {steps}: the previous point needed k = {before}, refined at once"));
        return Below::Skipped;
    }
    let half = match second_solve(second, &grid, r, settings.warm_start, ColdTry::Full) {
        Ok(h) => h,
        Err(e) => {
            point.estimate_method = format!("none: the second solve at {note} failed: {}", e.to_string().split(':').next().unwrap_or_default());
            return Below::None;
        }
    };
    let coarser = grid.instants() < problem.instants();
    // A point refined whatever k/4 says skips it (`accuracy::least_estimate`).
    let refinable = 2 * steps <= settings.max_steps;
    let exceeds = |a: &Accuracy| settings.tolerance.is_some_and(|t| settings.measure.of(a).is_some_and(|e| e > t));
    let refined_anyway = refinable && exceeds(&accuracy::least_estimate(problem, r, &half, &note));
    // The previous point was refined and this one's two-grid estimate exceeds the tolerance: it
    // is refined at once, and its refined estimate never reads k/4. That estimate is then the
    // plain difference (rigid contacts on massless DOFs; elsewhere it is `least_estimate`, which
    // refines anyway), which k/4 could have lowered to about a third: the point may be refined
    // where k/4 would have accepted it, never the reverse. Why: on the real blade's 1e-3 sweep
    // (issue 23) 21 of its 34 k/4 tries were at such points (1.4 s of 33.6 s of tries, 10 misses).
    let two_grids = (coarser && !refined_anyway && refinable && predicted.is_some_and(|p| p >= 2 * steps))
        .then(|| accuracy::estimate_from(problem, r, &half, None, &note))
        .filter(|a| exceeds(a));
    if let Some(a) = two_grids {
        let before = predicted.unwrap_or_default();
        (point.estimate_relative, point.estimate_method) =
            (settings.measure.of(&a), a.method + &format!("; k/4 not solved: the previous point needed k = {before} and two grids exceed the tolerance"));
        // The k/4 session's last solve is no longer this point's neighbour: no ω sub-steps from it.
        if let Some(s) = second.iter_mut().find(|s| s.0.problem().discretization().steps == steps / 4) {
            s.1 = None;
        }
        return Below::Solved(Box::new(half));
    }
    // Newton from the carried set alone: a k/4 grid near its stability limit can miss, and
    // then the estimate has two grids (a cold try there cost seconds per point).
    let quarter = (coarser && !refined_anyway)
        .then(|| accuracy::third_grid(&grid))
        .flatten()
        .and_then(|g| second_solve(second, &g, r, settings.warm_start, ColdTry::No).ok());
    let a = accuracy::estimate_from(problem, r, &half, quarter.as_ref(), &note);
    let skipped = if coarser && refined_anyway { "; k/4 not solved: even Richardson at the scheme's order from k/2 exceeds the tolerance" } else { "" };
    (point.estimate_relative, point.estimate_method) = (settings.measure.of(&a), a.method + skipped);
    if coarser { Below::Solved(Box::new(half)) } else { Below::None }
}

/// The second solve of a point's error estimate, in the chunk's session for that grid (made on
/// the first point, or again when the grid changes), with the frequency it last solved. On a
/// large LCP ([`guarded`]) it starts from the active set of `first`, the point's answer on the
/// first grid, carried to this grid (the same orbit at other instants: a closer guess than this
/// grid's last point) and never runs the dense fallback ([`solve_guarded`]).
fn second_solve(sessions: &mut Coarser, problem: &PeriodicProblem, first: &Response, warm: bool, cold: ColdTry) -> Result<Response, SolveError> {
    let steps = problem.discretization().steps;
    let i = match sessions.iter().position(|s| s.0.problem().discretization().steps == steps) {
        Some(i) => i,
        None => {
            sessions.push((PeriodicSolver::new(problem.clone()).with_warm_starts(warm), None));
            sessions.len() - 1
        }
    };
    let (solver, last) = &mut sessions[i];
    let f = problem.model().frequency;
    if !(warm && guarded(solver.problem())) {
        solver.update_frequency(f)?;
        return solver.solve();
    }
    let m = problem.model().contacts.len();
    let k_first = first.lcp.size / m.max(1);
    let carried = crate::periodic::carried_active_set(&first.active_set, m, k_first, solver.problem().instants());
    solver.set_warm_start(&carried);
    solver.set_warm_state(carried_state(first, solver.problem(), m));
    let (r, _) = solve_guarded(solver, *last, f, cold);
    *last = r.as_ref().ok().map(|_| f);
    r
}

/// The orbit state of `answer` (a shooting answer on another grid of the same orbit, `m` contact
/// rows) carried to the grid of `to`: Newton there starts from it with the carried active set
/// instead of that set's frozen fixed point (a march and a period Jacobian saved per solve).
fn carried_state(answer: &Response, to: &PeriodicProblem, m: usize) -> Option<Vec<f64>> {
    let state = answer.orbit_state.as_deref()?;
    crate::periodic::carried_state(to.discretization().scheme, state, answer.lcp.size / m.max(1), to.instants())
}

fn first_clause(e: &SolveError) -> String {
    let s = e.to_string();
    s.split(':').next().unwrap_or(&s).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The massless-boundary chain (`periodic::chain_with_massless_boundary`) with its two rigid
    /// contacts on massless DOFs alone, 10 µm from them (in contact over part of the period), under
    /// cds with the same pairing: the two-grid estimate is the plain difference; k = 256 (k/2 and
    /// k/4 within cds's stability limit), at ω.
    fn chain(omega: f64) -> PeriodicProblem {
        use crate::model::{Compliance, Contact};
        use crate::time::{Discretization, Pairing, Scheme};
        let mut model = crate::periodic::chain_with_massless_boundary();
        model.contacts = vec![Contact::on_dof(0, 1.0, 1e-5, Compliance::Rigid), Contact::on_dof(3, -1.0, 1e-5, Compliance::Rigid)];
        model.frequency = omega;
        let disc = Discretization { scheme: Scheme::Cds, steps: 256, pairing: Some(Pairing::Same) };
        let outputs = crate::periodic::OutputSelection { displacement: vec![3, 9, 12], contacts: true, ..Default::default() };
        PeriodicProblem::new(model, disc, outputs, crate::periodic::SolverSettings::default()).unwrap()
    }

    /// A point whose previous point was refined skips k/4 exactly where its two-grid estimate
    /// exceeds the tolerance (here set between Richardson at order 2 and the plain difference,
    /// 3× apart), and is then refined to the answer the climb with k/4 refines it to, bit for
    /// bit, when that climb refines too; where k/4 would have kept it at k, its 2k answer is
    /// within the tolerance and within the k answer's estimate of it. With the tolerance above
    /// the two grids' estimate, or no refined previous point, k/4 is solved as before.
    #[test]
    fn after_a_refined_point_k4_is_skipped_only_where_two_grids_exceed_the_tolerance() {
        let mut skipped = 0;
        for omega in [30.0, 37.0, 44.0] {
            let p = chain(omega);
            let r = PeriodicSolver::new(p.clone()).solve().unwrap();
            let (grid, note) = accuracy::second_grid(&p, &r).unwrap();
            let half = PeriodicSolver::new(grid).solve().unwrap();
            let (least, two) =
                (accuracy::least_estimate(&p, &r, &half, &note).relative.unwrap(), accuracy::estimate_from(&p, &r, &half, None, &note).relative.unwrap());
            if two < 2.5 * least {
                // No contact, or not second order: the two grids' estimate is Richardson's, which refines anyway.
                assert_eq!(two, least, "ω = {omega}");
                eprintln!(
                    "ω = {omega}: the two grids' estimate is Richardson's ({})",
                    r.contacts.iter().flat_map(|c| c.force.iter().copied()).fold(0.0, f64::max)
                );
                continue;
            }
            let k = p.discretization().steps;
            let run = |tolerance: f64, predicted: Option<usize>| {
                let settings = SweepSettings { estimate: true, tolerance: Some(tolerance), max_steps: 2 * k, threads: 1, ..Default::default() };
                let (mut coarser, mut levels) = (Coarser::new(), Levels::new());
                let mut point = SweepPoint::from_response(&p, omega, &r);
                let below = estimate(&mut point, &p, &r, &mut coarser, &settings, predicted);
                let quarter = coarser.iter().any(|s| s.0.problem().discretization().steps == k / 4);
                let noted = point.estimate_method.contains("k/4 not solved: the previous point needed");
                let kept = point.clone();
                refine(&mut point, &p, &r, below, (&mut levels, &mut coarser), &settings);
                (kept, point, quarter, noted)
            };
            let between = (least * two).sqrt();
            let (first, skip, quarter, noted) = run(between, Some(2 * k));
            eprintln!("ω = {omega}: Richardson {least:.3e}, two grids {two:.3e}; skipped: k = {}, {:.3e}", skip.steps, skip.estimate_relative.unwrap());
            assert!(!quarter && noted, "ω = {omega}: k/4 solved ({})", first.estimate_method);
            assert_eq!(first.estimate_relative, Some(two), "ω = {omega}");
            assert_eq!(skip.steps, 2 * k, "ω = {omega}: not refined");
            skipped += 1;
            let (climb_first, climb, quarter, noted) = run(between, None);
            assert!(quarter && !noted, "ω = {omega}: without a refined previous point k/4 is solved");
            if climb.steps == 2 * k {
                assert_eq!(skip.amplitude, climb.amplitude, "ω = {omega}");
                assert_eq!(skip.estimate_relative, climb.estimate_relative, "ω = {omega}");
            } else {
                let e = climb_first.estimate_relative.unwrap();
                let ptp = 2.0 * climb.amplitude.iter().copied().fold(0.0, f64::max);
                let moved = skip.amplitude.iter().zip(&climb.amplitude).fold(0.0f64, |w, (a, b)| w.max((a - b).abs()));
                eprintln!("  the climb keeps k = {k} ({e:.3e}); the 2k answer moved {:.3e} of the peak-to-peak", moved / ptp);
                assert!(skip.estimate_relative.unwrap() <= between && moved <= e * ptp, "ω = {omega}: moved {moved:e}, estimate {e:e}");
            }
            // Above the two grids' estimate, or after a point kept at k: k/4 as before.
            for (tolerance, predicted) in [(1.01 * two, Some(2 * k)), (between, Some(k))] {
                let (_, _, quarter, noted) = run(tolerance, predicted);
                assert!(quarter && !noted, "ω = {omega}: tolerance {tolerance:e}, previous k {predicted:?}");
            }
        }
        assert!(skipped >= 1, "no point with the plain difference");
    }
}
