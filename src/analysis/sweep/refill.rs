//! The refill of a guarded sweep ([`super::solve_guarded`]): its failed points retried from their
//! solved neighbours, then cold with the offset homotopy.
use super::{ColdTry, SweepPoint, SweepSettings, refine, solve_guarded};
use crate::periodic::{PeriodicProblem, PeriodicSolver, WarmStart};
use crate::response::Response;
use std::sync::Mutex;
use std::time::Instant;

/// A guarded sweep's refill run beside the second stages, as soon as every first stage is done
/// ([`super::stages::run`]'s `after_firsts`), on the first-grid points. Why: it reads only their
/// failures, frequencies and active sets (a refined point keeps its first grid's set), and after
/// the second stages it was the two-thread wall's serial tail (issue 23). Its answers are kept
/// unless a seam replaced a point (the refill then reads other neighbours: it runs again).
pub(super) struct Early {
    /// Each point as its first stage left it (a non-guarded sweep: none).
    firsts: Vec<Mutex<Option<SweepPoint>>>,
    /// The points before the refill and after it, when one had failed.
    refilled: Mutex<Option<(Vec<SweepPoint>, Vec<SweepPoint>)>>,
}

impl Early {
    pub(super) fn new(points: usize) -> Self {
        Early { firsts: (0..points).map(|_| Mutex::new(None)).collect(), refilled: Mutex::new(None) }
    }

    /// Keeps point `index` as its first stage left it.
    pub(super) fn record(&self, index: usize, point: &SweepPoint) {
        if let Some(slot) = self.firsts.get(index) {
            *slot.lock().unwrap() = Some(point.clone());
        }
    }

    /// The refill of the recorded points (every first stage done).
    pub(super) fn run(&self, template: &PeriodicProblem, settings: &SweepSettings) {
        let before: Vec<SweepPoint> = self.firsts.iter().map(|s| s.lock().unwrap().take().expect("every first stage is done")).collect();
        if before.iter().any(|p| p.error.is_some()) {
            let mut after = before.clone();
            super::stages::profiled("refill, after the first stages", || refill(template, &mut after, settings));
            *self.refilled.lock().unwrap() = Some((before, after));
        }
    }

    /// Puts the refilled points into `points` (each point's time its stages' and the refill's), or
    /// refills `points` now when `replaced` (points the seams replaced) is not 0.
    pub(super) fn apply(self, template: &PeriodicProblem, points: &mut [SweepPoint], replaced: usize, settings: &SweepSettings) {
        match self.refilled.into_inner().unwrap() {
            Some((before, after)) if replaced == 0 => {
                for (i, (was, now)) in before.iter().zip(after).enumerate().filter(|(_, (was, _))| was.error.is_some()) {
                    let second_s = points[i].time_s - was.time_s;
                    points[i] = SweepPoint { time_s: now.time_s + second_s, ..now };
                }
            }
            None if replaced == 0 => {}
            _ => super::stages::profiled("refill", || refill(template, points, settings)),
        }
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    fn point(amplitude: f64, time_s: f64, failed: bool) -> SweepPoint {
        SweepPoint { amplitude: vec![amplitude], time_s, error: failed.then(|| "missed".to_string()), ..Default::default() }
    }

    /// The early refill's answers replace the failed points where no seam replaced a point, each
    /// with its stages' time plus the refill's; after a seam replaced one they are dropped and the
    /// points refilled again (here: none failed, so they stay as they are).
    #[test]
    fn an_early_refill_is_kept_only_where_no_seam_replaced_a_point() {
        let template = PeriodicProblem::new(
            crate::periodic::chain_with_massless_boundary(),
            crate::time::Discretization { scheme: crate::time::Scheme::Cds, steps: 64, pairing: Some(crate::time::Pairing::Same) },
            crate::periodic::OutputSelection::default(),
            crate::periodic::SolverSettings::default(),
        )
        .unwrap();
        let settings = SweepSettings::default();
        let firsts = [point(1.0, 0.5, false), point(0.0, 0.5, true), point(3.0, 0.5, false)];
        let early = |after: SweepPoint| {
            let e = Early::new(3);
            firsts.iter().enumerate().for_each(|(i, p)| e.record(i, p));
            let before: Vec<SweepPoint> = e.firsts.iter().map(|s| s.lock().unwrap().take().unwrap()).collect();
            *e.refilled.lock().unwrap() = Some((before, vec![firsts[0].clone(), after, firsts[2].clone()]));
            e
        };
        // The stages' times: 2 s for the failed point's two stages.
        let mut points = vec![point(1.0, 1.0, false), point(0.0, 2.0, true), point(3.0, 1.5, false)];
        early(point(7.0, 3.5, false)).apply(&template, &mut points, 0, &settings);
        assert_eq!(points.iter().map(|p| p.amplitude[0]).collect::<Vec<_>>(), [1.0, 7.0, 3.0]);
        assert!(points[1].error.is_none());
        assert_eq!(points.iter().map(|p| p.time_s).collect::<Vec<_>>(), [1.0, 3.5 + (2.0 - 0.5), 1.5]);
        let mut solved = vec![point(1.0, 1.0, false), point(2.0, 2.0, false), point(3.0, 1.5, false)];
        early(point(7.0, 3.5, false)).apply(&template, &mut solved, 1, &settings);
        assert_eq!(solved.iter().map(|p| (p.amplitude[0], p.time_s)).collect::<Vec<_>>(), [(1.0, 1.0), (2.0, 2.0), (3.0, 1.5)]);
    }
}
