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

/// Whether `continued` (a first-grid answer) is on the orbit of the chunk's `point`, compared on
/// the same grid: a refined point's first-grid answer (a k → 2k refinement moves the amplitude by
/// its discretisation error, ~1e-3, which sent every refined point after a seam to be solved again).
fn same_orbit(continued: &SweepPoint, point: &SweepPoint) -> bool {
    let close = |x: &[f64], y: &[f64]| {
        let scale = x.iter().chain(y).fold(0.0f64, |s, v| s.max(v.abs()));
        x.len() == y.len() && x.iter().zip(y).all(|(u, v)| (u - v).abs() <= SAME_ORBIT * scale)
    };
    let (amplitude, force) = point.first_grid.as_ref().map_or((&point.amplitude, &point.max_force), |(a, f)| (a, f));
    close(&continued.amplitude, amplitude) && close(&continued.max_force, force)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn point(amplitude: f64, force: f64, first_grid: Option<(f64, f64)>) -> SweepPoint {
        SweepPoint { amplitude: vec![amplitude], max_force: vec![force], first_grid: first_grid.map(|(a, f)| (vec![a], vec![f])), ..Default::default() }
    }

    /// A refined point is compared on its first grid: the continued first-grid answer equal to it
    /// to round-off is the same orbit although the refined amplitude is 1e-3 away; a first grid
    /// 1e-4 away (another orbit) is not, nor is an unrefined point 1e-4 away.
    #[test]
    fn a_seam_compares_a_refined_point_on_its_first_grid() {
        let continued = point(1.0e-3, 5.0, None);
        assert!(same_orbit(&continued, &point(1.001e-3, 5.004, Some((1.0e-3 * (1.0 + 1e-13), 5.0)))));
        assert!(!same_orbit(&continued, &point(1.0e-3, 5.0, Some((1.0001e-3, 5.0)))));
        assert!(!same_orbit(&continued, &point(1.0e-3, 5.0, Some((1.0e-3, 5.0005)))));
        assert!(same_orbit(&continued, &point(1.0e-3 * (1.0 - 1e-12), 5.0, None)));
        assert!(!same_orbit(&continued, &point(1.0001e-3, 5.0, None)));
    }
}
