//! The refill of a guarded sweep ([`super::solve_guarded`]): its failed points retried from their
//! solved neighbours, then cold with the offset homotopy.
use super::{ColdTry, SweepPoint, SweepSettings, refine, solve_guarded};
use crate::periodic::{PeriodicProblem, PeriodicSolver, WarmStart};
use crate::response::Response;
use std::time::Instant;

/// Retries the failed points of a sweep of `template` from their nearest solved neighbours
/// ([`refill_pass`]): from the neighbour after each first (the branch beyond a fold, followed
/// back), then from the one before. `run` does this for a guarded sweep.
/// Then the points still missed get the full cold try (with the offset homotopy, which the
/// forward pass skips), and the refill runs again from those it solves.
pub fn refill(template: &PeriodicProblem, points: &mut [SweepPoint], settings: &SweepSettings) {
    if points.iter().all(|x| x.error.is_none()) {
        return;
    }
    let mut solver = PeriodicSolver::new(template.clone());
    let (mut second, mut levels) = (refine::Coarser::new(), refine::Levels::new());
    for reverse in [true, false] {
        refill_pass(&mut solver, (&mut second, &mut levels), settings, points, reverse);
    }
    let mut reached = false;
    for i in 0..points.len() {
        if points[i].error.is_none() {
            continue;
        }
        let (t, f) = (Instant::now(), points[i].frequency);
        solver.reset_warm_start();
        let (r, _) = solve_guarded(&mut solver, None, f, ColdTry::Full);
        let before = points[i].time_s;
        if let Ok(r) = r {
            points[i] = refilled_point(&solver, (&mut second, &mut levels), settings, &r, 0);
            reached = true;
        }
        points[i].time_s = before + t.elapsed().as_secs_f64();
    }
    if reached {
        for reverse in [true, false] {
            refill_pass(&mut solver, (&mut second, &mut levels), settings, points, reverse);
        }
    }
}

/// The sweep point of an answer `r` the refill found (after `substeps` ω sub-steps), estimated
/// and refined like a point of the forward pass.
pub(super) fn refilled_point(
    solver: &PeriodicSolver,
    (second, levels): (&mut refine::Coarser, &mut refine::Levels),
    settings: &SweepSettings,
    r: &Response,
    substeps: usize,
) -> SweepPoint {
    let f = solver.problem().model().frequency;
    let mut point = SweepPoint::from_response(solver.problem(), f, r);
    (point.substeps, point.warm_start_used) = (substeps, solver.last_start() == WarmStart::Used);
    let below = refine::estimate(&mut point, solver.problem(), r, second, settings, None);
    refine::refine(&mut point, solver.problem(), r, below, (levels, second), settings);
    point
}

/// Retries a guarded sweep's failed points from their nearest solved neighbour in the sweep's
/// order, scanning backwards (`reverse`: the neighbour after each) or forwards: warm shooting
/// from the neighbour's active sets with ω sub-steps from its frequency, no cold try (the
/// point's own pass made it). Why (issue 23, real blade): past the fold where the contact
/// branch ends, the forward pass loses the orbit (the neighbour's sets lead nowhere and cold
/// shooting's homotopy misses), while the other branch, once reached further up, continues
/// down to those points in a few Newton iterations each. A point still missed keeps its failure.
fn refill_pass(
    solver: &mut PeriodicSolver,
    (second, levels): (&mut refine::Coarser, &mut refine::Levels),
    settings: &SweepSettings,
    points: &mut [SweepPoint],
    reverse: bool,
) {
    let order: Vec<usize> = if reverse { (0..points.len()).rev().collect() } else { (0..points.len()).collect() };
    let mut neighbour: Option<usize> = None;
    for i in order {
        let Some(j) = neighbour.filter(|_| points[i].error.is_some()) else {
            neighbour = if points[i].error.is_none() { Some(i) } else { neighbour };
            continue;
        };
        let t = Instant::now();
        let f = points[i].frequency;
        solver.set_warm_start(&points[j].active_set);
        let (r, substeps) = solve_guarded(solver, Some(points[j].frequency), f, ColdTry::No);
        let before = points[i].time_s;
        match r {
            Ok(r) => {
                points[i] = refilled_point(solver, (&mut *second, &mut *levels), settings, &r, substeps);
                points[i].time_s = before + t.elapsed().as_secs_f64();
                neighbour = Some(i);
            }
            Err(_) => points[i].time_s = before + t.elapsed().as_secs_f64(),
        }
    }
}
