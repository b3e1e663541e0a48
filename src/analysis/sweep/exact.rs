//! `sweep --exact`: every point's exact orbit (the event-fitted polish's, src/analysis/polish).
//! With compliant contacts only, by shooting with switch detection from the state at t = 0
//! predicted by the secant through the two previous orbits ([`polish::follow_detected`]: the
//! signature is the flow's own, so any number of switches may appear or vanish between points).
//! Otherwise (or where that fails) by Newton from the previous point's exact orbit (same event
//! signature, its event times scaled to the new period, the phases' eigendecompositions reused:
//! [`polish::follow`]); where the signature changes, the neighbouring signatures the previous orbit predicts are tried
//! ([`polish::follow_across`]: an arc that shrank away removed, a grazing crossed added); where
//! none holds, the point is solved on the grid and polished ([`polish::apply`]), and the walk goes on from that orbit; where
//! the polish fails too the point is the grid's, with its error estimate. Each point says which
//! (`source` = exact | polished | grid). The range is cut into one contiguous chunk per thread,
//! each starting on the grid.
use super::{SweepPoint, SweepSettings, solve_point};
use crate::analysis::accuracy;
use crate::analysis::polish::{self, PolishedOrbit};
use crate::periodic::PeriodicProblem;
use crate::response::Response;
use rayon::prelude::*;
use std::time::Instant;

/// Instants per period at which an exact point's largest contact force is taken.
const FORCE_SAMPLES: usize = 256;

/// Runs the exact sweep over `frequencies` (see the module); `on_point` as for [`super::run`].
pub fn run(
    template: &PeriodicProblem,
    frequencies: &[f64],
    settings: &SweepSettings,
    on_point: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<Vec<SweepPoint>, crate::Error> {
    super::check_frequencies(frequencies)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(settings.threads).build().map_err(|e| crate::Error::input(format!("threads: {e}")))?;
    let chunks = pool.current_num_threads().max(1);
    let size = frequencies.len().div_ceil(chunks).max(1);
    let results: Vec<Vec<SweepPoint>> = pool.install(|| frequencies.par_chunks(size).map(|chunk| walk(template, chunk, on_point)).collect());
    Ok(results.into_iter().flatten().collect())
}

/// One chunk, in order: exact from the previous orbit where it holds, else grid and polish.
fn walk(template: &PeriodicProblem, chunk: &[f64], on_point: &(dyn Fn(&SweepPoint) + Sync)) -> Vec<SweepPoint> {
    let mut out = Vec::with_capacity(chunk.len());
    let (mut prev, mut linear): (Option<PolishedOrbit>, Option<PolishedOrbit>) = (None, None);
    let mut active: Option<Vec<usize>> = None;
    // (ω, state at t = 0) of the last exact or polished orbits in a row: the predictor's points.
    let mut trail: Vec<(f64, Vec<f64>)> = Vec::new();
    // The phases of the contact sets met so far, re-tuned at each point rather than made again.
    let mut bank = polish::PhaseBank::default();
    for &f in chunk {
        let t0 = Instant::now();
        let mut problem = template.clone();
        let mut point = match problem.set_frequency(f) {
            Err(e) => failed(f, e.to_string()),
            Ok(()) => {
                let model = problem.model();
                // Without loads the contact-free orbit is rest (a casing drives the blade only
                // through contact): its amplitudes are 0, and the orbit is not solved.
                let rest = model.forces.is_empty();
                if !rest {
                    linear = polish::linear(model, linear.as_ref()).ok();
                }
                let followed = prev.as_ref().map(|p| {
                    let start = predicted(&trail, f);
                    polish::follow_detected_with(model, p, &start, &mut bank).or_else(|e| {
                        polish::profile(&format!("switch detection failed at {f}: {e}"), t0);
                        polish::follow_across(model, p)
                    })
                });
                match followed {
                    Some(Ok(orbit)) => {
                        polish::profile(&format!("exact at {f}: {} Newton iterations, {} events", orbit.iterations(), orbit.events().len()), t0);
                        let point = exact_point(&problem, f, &orbit, if rest { Err(()) } else { Ok(linear.as_ref()) });
                        polish::profile("the point's amplitudes, forces and fractions", t0);
                        prev = Some(orbit);
                        point
                    }
                    Some(Err(e)) => grid_point(&problem, f, &mut prev, &mut active, Some(&e.0)),
                    None => grid_point(&problem, f, &mut prev, &mut active, None),
                }
            }
        };
        match &prev {
            Some(p) if point.error.is_none() => trail.push((f, p.state(0.0).as_slice().to_vec())),
            Some(_) => {}
            None => trail.clear(),
        }
        if trail.len() > 2 {
            trail.remove(0);
        }
        point.time_s = t0.elapsed().as_secs_f64();
        on_point(&point);
        out.push(point);
    }
    out
}

/// The state at t = 0 predicted at `f`: the secant through the last two orbits' (one orbit's
/// own state when there is one; the forcing phase at t = 0 is the same at every ω).
fn predicted(trail: &[(f64, Vec<f64>)], f: f64) -> Vec<f64> {
    match trail {
        [.., (f0, y0), (f1, y1)] => {
            let s = (f - f1) / (f1 - f0);
            y1.iter().zip(y0).map(|(a, b)| a + s * (a - b)).collect()
        }
        [.., (_, y1)] => y1.clone(),
        [] => Vec::new(),
    }
}

fn failed(f: f64, why: String) -> SweepPoint {
    SweepPoint { frequency: f, error: Some(why), source: "grid".into(), ..SweepPoint::default() }
}

/// The point of an exact orbit: amplitudes at the orbit's own extrema, contact fractions from the
/// phases' durations, the largest force at [`FORCE_SAMPLES`] instants; the estimate is the last
/// Newton correction over the largest peak-to-peak amplitude. `linear` is the contact-free orbit
/// (`Err` where it is rest: no loads).
fn exact_point(problem: &PeriodicProblem, f: f64, orbit: &PolishedOrbit, linear: Result<Option<&PolishedOrbit>, ()>) -> SweepPoint {
    let dofs = &problem.outputs().displacement;
    let map = problem.output_map();
    let amplitude: Vec<f64> = orbit.amplitudes(map, dofs).into_iter().map(|a| a.unwrap_or(f64::NAN)).collect();
    let linear_amplitude = match linear {
        Err(()) => vec![0.0; dofs.len()],
        Ok(linear) => linear.map_or_else(|| vec![f64::NAN; dofs.len()], |l| l.amplitudes(map, dofs).into_iter().map(|a| a.unwrap_or(f64::NAN)).collect()),
    };
    let scale = 2.0 * amplitude.iter().copied().filter(|a| a.is_finite()).fold(0.0, f64::max);
    let estimate = orbit.correction().max(f64::EPSILON * scale);
    SweepPoint {
        frequency: f,
        amplitude,
        linear_amplitude,
        max_force: orbit.max_forces(FORCE_SAMPLES),
        contact_fraction: orbit.contact_fractions(),
        pivots: orbit.iterations(),
        estimate_relative: (scale > 0.0).then(|| estimate / scale),
        estimate_method: format!("exact orbit ({} events): the last Newton correction", orbit.events().len()),
        lcp_path: String::new(),
        source: "exact".into(),
        ..SweepPoint::default()
    }
}

/// The grid's point, polished where the polish succeeds (then `prev` is its orbit, else `None`);
/// `why` says why the exact follow failed, for the record.
fn grid_point(problem: &PeriodicProblem, f: f64, prev: &mut Option<PolishedOrbit>, active: &mut Option<Vec<usize>>, why: Option<&str>) -> SweepPoint {
    let (solved, cold) = solve_point(problem, f, active.as_deref());
    let mut r: Response = match solved {
        Ok(r) => r,
        Err(e) => {
            *prev = None;
            return failed(f, e.to_string());
        }
    };
    *active = Some(r.active_set.clone());
    *prev = polish::apply(problem, &mut r);
    let mut point = SweepPoint::from_response(problem, f, &r);
    point.warm_start_used = active.is_some() && !cold;
    point.cold_fallback = cold;
    let follow = why.map_or(String::new(), |w| format!(" (the exact follow failed: {w})"));
    if let Some(orbit) = prev.as_ref() {
        // The orbit's own extrema and phase durations: the grid's instants would put an O(h²)
        // sampling error (2e-5 at k = 2048 on the real blade) under a 1e-14 estimate.
        let exact = orbit.amplitudes(problem.output_map(), &problem.outputs().displacement);
        if exact.iter().all(Option::is_some) {
            point.amplitude = exact.into_iter().flatten().collect();
        }
        point.max_force = orbit.max_forces(FORCE_SAMPLES);
        point.contact_fraction = orbit.contact_fractions();
        point.source = "polished".into();
        point.estimate_relative = r.accuracy.relative;
        point.estimate_method = format!("{}{follow}", r.accuracy.method);
    } else {
        let a = accuracy::estimate(problem, &r);
        point.source = "grid".into();
        point.estimate_relative = a.relative;
        point.estimate_method = format!("{}{follow}", a.method);
    }
    point
}
