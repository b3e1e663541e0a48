//! The seams of a sweep cut into chunks: each chunk starts cold, and where orbits coexist its
//! first point can land on another orbit than the one the chunk before ends on (the one-thread
//! sweep's branch). Each seam is re-checked by continuing the orbit of the point before it across
//! the seam; where the continued orbit differs from the chunk's own, the chunk's points are
//! replaced by the continued branch until the two agree again.
use super::refill::refilled_point;
use super::{ColdTry, SweepPoint, SweepSettings, follow_from, guarded, left_the_branch, refine, solve_guarded};
use crate::periodic::{PeriodicProblem, PeriodicSolver};
use std::time::Instant;

/// Two certified answers of one LCP on one orbit agree to round-off; coexisting orbits differ
/// in amplitude or contact force by far more than this (relative).
const SAME_ORBIT: f64 = 1e-6;

fn same_orbit(a: &SweepPoint, b: &SweepPoint) -> bool {
    let close = |x: &[f64], y: &[f64]| {
        let scale = x.iter().chain(y).fold(0.0f64, |s, v| s.max(v.abs()));
        x.len() == y.len() && x.iter().zip(y).all(|(u, v)| (u - v).abs() <= SAME_ORBIT * scale)
    };
    close(&a.amplitude, &b.amplitude) && close(&a.max_force, &b.max_force)
}

/// Re-checks the seams before the chunks starting at `starts` (indices into `points`, in sweep
/// order) and repairs them; returns the points replaced.
pub(super) fn repair_seams(template: &PeriodicProblem, points: &mut [SweepPoint], starts: &[usize], settings: &SweepSettings) -> usize {
    let mut replaced = 0;
    for &lo in starts.iter().filter(|&&lo| lo > 0) {
        let mut prev = lo - 1;
        if points[prev].error.is_some() {
            continue;
        }
        let mut solver = PeriodicSolver::new(template.clone());
        let (mut second, mut levels) = (refine::Coarser::new(), refine::Levels::new());
        let guarded = guarded(solver.problem());
        // The orbit before the seam, again (its response: the branch check continues it).
        solver.set_warm_start(&points[prev].active_set);
        let Ok(mut before) = solver.update_frequency(points[prev].frequency).and_then(|()| solver.solve()) else { continue };
        for i in lo..points.len() {
            if points[i].error.is_some() {
                break;
            }
            let (t, f) = (Instant::now(), points[i].frequency);
            let (mut r, substeps) = if guarded {
                solve_guarded(&mut solver, Some(points[prev].frequency), f, ColdTry::No)
            } else {
                (solver.update_frequency(f).and_then(|()| solver.solve()), 0)
            };
            // As the forward pass: an answer off the branch is replaced by the continued orbit.
            if let Ok(now) = &r
                && !guarded
                && left_the_branch(&before, now)
                && let Ok(followed) = follow_from(&mut solver, template, points[prev].frequency, &before, f)
            {
                r = Ok(followed);
            }
            let Ok(r) = r else { break };
            let continued = super::SweepPoint::from_response(solver.problem(), f, &r);
            if same_orbit(&continued, &points[i]) {
                break;
            }
            let old = points[i].time_s;
            points[i] = refilled_point(&solver, (&mut second, &mut levels), settings, &r, substeps);
            points[i].time_s = old + t.elapsed().as_secs_f64();
            solver.set_warm_start(&r.active_set);
            replaced += 1;
            prev = i;
            before = r;
        }
    }
    replaced
}
