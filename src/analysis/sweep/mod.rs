//! Frequency sweeps: one periodic problem solved at many excitation frequencies.
//!
//! Everything that does not depend on the frequency is built once by the caller (the structure,
//! the Craig–Bampton reduction, the casing's phases, the output map) and shared by every point:
//! a point only changes `model.frequency`. The points are cut into contiguous chunks that run in
//! parallel (rayon); within a chunk each point is warm-started from the previous point's active
//! set, with a cold re-solve when the warm one fails, and its estimate and refinement run as a
//! second stage on whichever thread is free (`stages`). FFT plans are made once and shared.
//! The contact-free (linear) curve comes from the same assembly ([`Response::linear_displacement`]).
//!
//! Several periodic solutions can coexist (the hardening branch of a rubbing blade overhangs
//! the resonance): a warm-started chunk follows the branch it starts on, and each chunk starts
//! cold. With `steps = "auto"` every point shares one k, chosen at the sweep's lowest frequency
//! (the largest h = 2π/(ω·k), where the scheme's limit bites first). For a strictly sequential continuation in the direction of the sweep, use one thread
//! and one chunk (`--threads 1 --chunks-per-thread 1`).
pub mod exact;
#[cfg(feature = "reference")]
pub mod marching;
mod refill;
mod refine;
mod seam;
pub mod spectrum;
mod stages;

use crate::analysis::continuation;
use crate::model::{Labels, Quantity};
use crate::periodic::limits::AmplitudeMeasure;
use crate::periodic::{LEMKE_AFTER_SHOOTING_MAX, LcpMethod, PeriodicProblem, PeriodicSolver, SolveError, Tuning, WarmStart};
use crate::response::Response;
use std::sync::Mutex;
use std::time::Instant;

pub use refill::refill;

/// How to run a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepSettings {
    /// Warm-start each point from the previous point of its chunk.
    pub warm_start: bool,
    /// Worker threads; 0: rayon's default (every core).
    pub threads: usize,
    /// Contiguous chunks per thread (more balance the load, fewer keep more warm starts).
    pub chunks_per_thread: usize,
    /// Estimate every point's error ([`crate::analysis::accuracy`]): warm-started sweeps at k/2
    /// (or 2k where k/2 breaks the scheme's limit) and k/4 (the observed order) beside the first.
    pub estimate: bool,
    /// Refine every point whose estimate exceeds this (relative to the peak-to-peak amplitude):
    /// k → 2k while it does, up to `max_steps` ([`refine`]). Needs `estimate`.
    pub tolerance: Option<f64>,
    /// The largest k of a refinement.
    pub max_steps: usize,
    /// What `tolerance` and the points' `estimate_relative` are relative to.
    pub measure: AmplitudeMeasure,
}

impl Default for SweepSettings {
    fn default() -> Self {
        SweepSettings {
            warm_start: true,
            threads: 0,
            chunks_per_thread: 4,
            estimate: false,
            tolerance: None,
            max_steps: 8192,
            measure: AmplitudeMeasure::Largest,
        }
    }
}

/// The result at one frequency. Vectors follow the problem's `outputs.displacement` order and
/// the contact order.
#[derive(Clone, Debug, Default)]
pub struct SweepPoint {
    /// The excitation frequency ω [rad/s].
    pub frequency: f64,
    /// Peak-to-peak/2 of each displacement output.
    pub amplitude: Vec<f64>,
    /// The same, contact-free.
    pub linear_amplitude: Vec<f64>,
    /// Largest contact force over the period, per contact.
    pub max_force: Vec<f64>,
    /// Fraction of the instants with a force, per contact.
    pub contact_fraction: Vec<f64>,
    pub lcp_size: usize,
    /// Instants per period of the point's answer (the scene's k, or a refinement's).
    pub steps: usize,
    /// Pivots (or block exchanges plus pivots) of the point's final solve.
    pub pivots: usize,
    /// The solve started from the previous point's active set.
    pub warm_start_used: bool,
    /// The warm-started solve failed and a cold solve was made.
    pub cold_fallback: bool,
    /// Wall time of the point (both solves if there was a fallback) [s].
    pub time_s: f64,
    /// Assembly and LCP times of the final solve [s].
    pub assembly_s: f64,
    pub lcp_s: f64,
    /// The error estimate relative to the peak-to-peak amplitude (`SweepSettings::estimate`),
    /// and how it was made or why there is none.
    pub estimate_relative: Option<f64>,
    pub estimate_method: String,
    /// The failure, if the point could not be solved.
    pub error: Option<String>,
    /// The LCP methods that ran and the fallbacks taken (`lcp.path` of the JSON).
    pub lcp_path: String,
    /// ω sub-steps solved on the way from the last point (a large LCP whose warm shooting
    /// missed, see [`solve_guarded`]).
    pub substeps: usize,
    /// Active set of the solution (warm start of a neighbour).
    pub active_set: Vec<usize>,
    /// `sweep --exact` ([`exact`]): "exact", "polished" or "grid"; empty otherwise.
    pub source: String,
    /// A refined point's first-grid answer (amplitudes, largest forces): a seam compares the
    /// orbit it continues (solved on the first grid) with this, not with the refined answer.
    pub first_grid: Option<(Vec<f64>, Vec<f64>)>,
}

impl SweepPoint {
    fn from_response(problem: &PeriodicProblem, frequency: f64, r: &Response) -> SweepPoint {
        let amp = |m: &std::collections::BTreeMap<String, Vec<f64>>| -> Vec<f64> {
            problem.outputs().displacement.iter().map(|d| m.get(&d.to_string()).map_or(f64::NAN, |s| Response::peak_to_peak(s) / 2.0)).collect()
        };
        SweepPoint {
            frequency,
            amplitude: amp(&r.displacement),
            linear_amplitude: amp(&r.linear_displacement),
            max_force: r.contacts.iter().map(|c| c.force.iter().copied().fold(0.0, f64::max)).collect(),
            contact_fraction: (0..r.contacts.len()).map(|i| r.contact_fraction(i)).collect(),
            lcp_size: r.lcp.size,
            steps: problem.discretization().steps,
            pivots: r.lcp.pivots,
            warm_start_used: false,
            cold_fallback: false,
            time_s: 0.0,
            assembly_s: r.timing_s.assembly,
            lcp_s: r.timing_s.lcp,
            estimate_relative: None,
            estimate_method: String::new(),
            error: None,
            lcp_path: r.lcp.path.clone(),
            substeps: 0,
            active_set: r.active_set.clone(),
            source: String::new(),
            first_grid: None,
        }
    }
}

/// `n` equally spaced values from `from` to `to` (both included): from + (to − from)·i/(n − 1).
pub fn linspace(from: f64, to: f64, n: usize) -> Vec<f64> {
    match n {
        0 => vec![],
        1 => vec![from],
        _ => (0..n).map(|i| from + (to - from) * i as f64 / (n - 1) as f64).collect(),
    }
}

/// Solves `problem` at one frequency, warm-started if `warm` is given, cold if that fails.
/// Returns the response (or the error) and whether a cold fallback was needed.
pub fn solve_point(problem: &PeriodicProblem, frequency: f64, warm: Option<&[usize]>) -> (Result<Response, crate::Error>, bool) {
    let mut solver = PeriodicSolver::new(problem.clone());
    if let Some(w) = warm {
        solver.set_warm_start(w);
    }
    let r = solver.update_frequency(frequency).and_then(|()| solver.solve()).map_err(crate::Error::from);
    (r, solver.last_start() == WarmStart::ColdFallback)
}

/// Refuses a frequency that is not finite and positive (every sweep's first check).
pub(super) fn check_frequencies(frequencies: &[f64]) -> Result<(), crate::Error> {
    match frequencies.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        Some(f) => Err(crate::Error::input(format!("frequency: {f} is not a finite angular frequency > 0 [rad/s]"))),
        None => Ok(()),
    }
}

/// Runs the sweep over `frequencies` (any order; chunks are contiguous in the given order).
/// `on_point` is called with each point (from worker threads), e.g. to advance a progress bar
/// and show the point's time and solver.
pub fn run(
    template: &PeriodicProblem,
    frequencies: &[f64],
    settings: &SweepSettings,
    on_point: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<Vec<SweepPoint>, crate::Error> {
    check_frequencies(frequencies)?;
    let mut template = template.clone();
    // `steps = "auto"`: one k for every point, chosen at the lowest frequency (the largest h).
    if let Some(lowest) = frequencies.iter().copied().reduce(f64::min) {
        template
            .fit_auto_steps(lowest, &format!("chosen at the lowest frequency of the sweep ({lowest} rad/s), shared by every point"))
            .map_err(crate::Error::from)?;
    }
    // Parallelism is over points: each solve stays on its thread.
    template.set_parallel(false);
    // One plan for every chunk: the chunks clone this session.
    let base = &template;
    let session = PeriodicSolver::new(template.clone()).with_warm_starts(settings.warm_start);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(settings.threads).build().map_err(|e| crate::Error::input(format!("threads: {e}")))?;
    let threads = pool.current_num_threads().max(1);
    let n = frequencies.len();
    let chunks = (threads * settings.chunks_per_thread.max(1)).min(n).max(1);
    let bounds: Vec<(usize, usize)> = (0..chunks).map(|c| (c * n / chunks, (c + 1) * n / chunks)).collect();
    // A chunk's first-grid pass: the session, the last answer (the branch check) and the last
    // solved frequency (a guarded point's sub-steps start there).
    struct First {
        solver: PeriodicSolver,
        next: usize,
        last: Option<(f64, Response)>,
        last_solved: Option<f64>,
    }
    // A chunk's estimates and refinements: the sessions of their grids, warm-started along the
    // chunk, and the k the last point ended at (the next point's guess), with the points done.
    struct Second {
        coarser: refine::Coarser,
        levels: refine::Levels,
        predicted: Option<usize>,
        out: Vec<SweepPoint>,
    }
    // A first-grid answer on its way to the second stage, with its problem (at its frequency)
    // and the seconds it took.
    type Pending = (SweepPoint, Option<(Response, PeriodicProblem)>, f64);
    let firsts: Vec<Mutex<First>> =
        bounds.iter().map(|&(lo, _)| Mutex::new(First { solver: session.clone(), next: lo, last: None, last_solved: None })).collect();
    let seconds: Vec<Mutex<Second>> = bounds
        .iter()
        .map(|&(lo, hi)| Mutex::new(Second { coarser: Vec::new(), levels: refine::Levels::new(), predicted: None, out: Vec::with_capacity(hi - lo) }))
        .collect();
    // A large LCP's sweep never waits for the dense fallback (see `solve_guarded`); its
    // ω sub-steps follow the branch, and the branch check's continuation, which can
    // reach the dense fallback, is not run there.
    let guarded_sweep = settings.warm_start && guarded(session.problem());
    let early = refill::Early::new(if guarded_sweep { n } else { 0 });
    let first = |c: usize| -> Pending {
        let mut guard = firsts[c].lock().unwrap();
        let First { solver, next, last, last_solved } = &mut *guard;
        let (index, f) = (*next, frequencies[*next]);
        *next += 1;
        let t = Instant::now();
        let mut substeps = 0;
        let mut r = if guarded_sweep {
            // The cold try stops before the offset homotopy: past a fold it missed
            // after 70–100 kinks (2–5 s each), while the branch beyond (2473 rad/s)
            // is reached by Newton from the contact-free orbit and the refill follows
            // it back. The homotopy waits for the points the refill misses (`refill`).
            let (r, n) = solve_guarded(solver, *last_solved, f, ColdTry::WithoutHomotopy);
            substeps = n;
            r
        } else {
            solver.update_frequency(f).and_then(|()| solver.solve())
        };
        if let (Some((f0, before)), Ok(now)) = (&*last, &r)
            && settings.warm_start
            && !guarded_sweep
            && left_the_branch(before, now)
        {
            // Kept as it is when the branch cannot be followed.
            if let Ok(followed) = follow_from(solver, base, *f0, before, f) {
                r = Ok(followed);
            }
        }
        let mut point = match &r {
            Ok(r) => SweepPoint::from_response(solver.problem(), f, r),
            Err(e) => SweepPoint { frequency: f, error: Some(e.to_string()), ..Default::default() },
        };
        point.substeps = substeps;
        point.warm_start_used = r.is_ok() && solver.last_start() == WarmStart::Used;
        point.cold_fallback = solver.last_start() == WarmStart::ColdFallback;
        let answer = match r {
            Ok(r) => {
                *last_solved = Some(f);
                // Only the branch check reads it (not a guarded sweep's): no copy of the answer otherwise.
                *last = (settings.warm_start && !guarded_sweep).then(|| (f, r.clone()));
                Some((r, solver.problem().clone()))
            }
            Err(_) if guarded_sweep => {
                *last = None;
                None
            }
            Err(_) => {
                // The next point starts cold, as after any failure.
                solver.reset_warm_start();
                *last = None;
                None
            }
        };
        early.record(index, &point);
        (point, answer, t.elapsed().as_secs_f64())
    };
    let second = |c: usize, (mut point, answer, first_s): Pending| {
        let t = Instant::now();
        let mut guard = seconds[c].lock().unwrap();
        let Second { coarser, levels, predicted, out } = &mut *guard;
        if let Some((r, problem)) = &answer {
            let below = refine::estimate(&mut point, problem, r, coarser, settings, *predicted);
            refine::refine(&mut point, problem, r, below, (levels, coarser), settings);
        }
        *predicted = answer.is_some().then_some(point.steps);
        point.time_s = first_s + t.elapsed().as_secs_f64();
        on_point(&point);
        out.push(point);
    };
    let lengths: Vec<usize> = bounds.iter().map(|&(lo, hi)| hi - lo).collect();
    let refill_early = || early.run(base, settings);
    let after_firsts: Option<&(dyn Fn() + Sync)> = if guarded_sweep { Some(&refill_early) } else { None };
    pool.install(|| stages::run(&lengths, threads, &first, &second, after_firsts));
    let results = seconds.into_iter().map(|s| s.into_inner().unwrap().out);
    let mut points: Vec<SweepPoint> = results.into_iter().flatten().collect();
    let mut replaced = 0;
    if settings.warm_start && bounds.len() > 1 {
        let starts: Vec<usize> = bounds.iter().map(|b| b.0).collect();
        replaced = stages::profiled("seams", || seam::repair_seams(base, &mut points, &starts, settings));
    }
    if guarded_sweep {
        early.apply(base, &mut points, replaced, settings);
    }
    Ok(points)
}

/// The last try of [`solve_guarded`]: none, cold shooting, or cold shooting without its offset
/// homotopy (Newton from the contact-free orbit alone).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ColdTry {
    No,
    Full,
    WithoutHomotopy,
}

/// Halvings of the ω step when a sub-step misses: down to 1/16 of the sweep's step.
const SUBSTEP_HALVINGS: u32 = 4;

/// A point of a sweep over an LCP too large for a quick dense fallback (N >
/// `LEMKE_AFTER_SHOOTING_MAX`; block pivoting then dense Lemke took minutes at N = 17 408 on the
/// real blade, issue 23): shooting from the last point's active sets; where it misses, natural
/// continuation in ω from the last solved frequency `last` (sub-steps, halved on a miss, each
/// warm-started from the previous); then cold shooting. Never the dense fallback: a point still
/// missed is a typed failure naming the cause and the remedy, and the sweep goes on. Each try
/// is bounded by shooting's work budget. Returns the answer and the sub-steps solved before it.
/// `cold`: how to end ([`ColdTry`]; `No`: a miss after the sub-steps is the failure).
fn solve_guarded(solver: &mut PeriodicSolver, last: Option<f64>, f: f64, cold: ColdTry) -> (Result<Response, SolveError>, usize) {
    let profile = std::env::var_os("PERIODIC_CONTACT_PROFILE").is_some();
    let at = |solver: &mut PeriodicSolver, w: f64, warm: bool| {
        let t = Instant::now();
        let r = solver.update_frequency(w).and_then(|()| solver.solve_by_shooting(warm));
        if profile {
            let how = if r.is_ok() { "solved" } else { "missed" };
            eprintln!(
                "sweep profile: ω = {f} rad/s, try at {w} rad/s (k = {}, warm {warm}) {how} in {:.3} s",
                solver.problem().discretization().steps,
                t.elapsed().as_secs_f64()
            );
        }
        r
    };
    let had_warm = solver.warm_start().is_some();
    let first = match at(solver, f, true) {
        Ok(r) => return (Ok(r), 0),
        Err(e) => e,
    };
    let mut substeps = 0;
    if let Some(f0) = last {
        let (mut here, mut h) = (f0, (f - f0) / 2.0);
        let smallest = (f - f0).abs() / f64::from(1u32 << SUBSTEP_HALVINGS);
        while h != 0.0 && h.abs() >= smallest {
            let next = if (f - here).abs() <= h.abs() { f } else { here + h };
            match at(solver, next, true) {
                Ok(r) if next == f => return (Ok(r), substeps),
                Ok(_) => {
                    here = next;
                    substeps += 1;
                }
                Err(_) => h /= 2.0,
            }
        }
    }
    // Cold shooting, unless the first try already was.
    let last_try = match cold {
        ColdTry::Full if had_warm => at(solver, f, false),
        ColdTry::WithoutHomotopy if had_warm => solver.update_frequency(f).and_then(|()| solver.solve_by_shooting_with(false, false)),
        _ => Err(first),
    };
    match last_try {
        Ok(r) => (Ok(r), substeps),
        Err(SolveError::Lcp { outcome, info, .. }) => {
            let how = if cold == ColdTry::WithoutHomotopy { " (without the offset homotopy, which the refill tries last)" } else { "" };
            let from = last.map_or_else(|| "no solved point just before it".to_string(), |f0| format!("{substeps} ω sub-steps from {f0} rad/s"));
            let hint = format!(
                "shooting missed ω = {f} rad/s from the last point's active sets, after {from}, and cold{how}; the sweep skips the dense fallback above N = {LEMKE_AFTER_SHOOTING_MAX} (block pivoting then Lemke: minutes); remedies: more --points (a smaller ω step), or `periodic-contact solve SCENE --frequency {f}` for this point alone (it runs the dense fallback)"
            );
            (Err(SolveError::Lcp { outcome, info, hint }), substeps)
        }
        Err(e) => (Err(e), substeps),
    }
}

/// Whether a sweep guards this problem's points ([`solve_guarded`]): `auto` on an LCP above
/// `LEMKE_AFTER_SHOOTING_MAX`, where the dense fallback costs minutes.
fn guarded(problem: &PeriodicProblem) -> bool {
    problem.solver_settings().method == LcpMethod::Auto && problem.instants() * problem.model().contacts.len() > LEMKE_AFTER_SHOOTING_MAX
}

/// A warm-started answer whose amplitude differs from the last point's (an orbit in contact) by
/// more than this (relative) is checked by continuing the last orbit to the new frequency: the
/// active-set warm start alone can land on a coexisting orbit (the coarse blade's contact branch,
/// lost at 2720 rad/s with 10 rad/s steps and at 2790 with 2, below its tip at 2796).
const BRANCH_CHECK: f64 = 0.1;

fn left_the_branch(before: &Response, now: &Response) -> bool {
    let (a, b) = (continuation::amplitude(before), continuation::amplitude(now));
    !before.active_set.is_empty() && (a - b).abs() > BRANCH_CHECK * a.max(b)
}

/// The orbit at `f` continued along its branch from the last point's (`continuation::resolve`,
/// the FMU's re-solve): where the branch ends at a fold on the way, the orbit the solver finds.
fn follow_from(solver: &mut PeriodicSolver, base: &PeriodicProblem, f0: f64, before: &Response, f: f64) -> Result<Response, crate::Error> {
    let disc = solver.problem().discretization();
    let tuning = Tuning { frequency: f0, ..Tuning::of(base) };
    let current = continuation::Current { tuning, disc, active_set: &before.active_set, amplitude: continuation::amplitude(before), orbit: None, exact: false };
    continuation::resolve(solver, base, disc, Tuning { frequency: f, ..tuning }, Some(current)).map(|r| r.response)
}

/// The CSV of a sweep: the parameter, amplitude per displacement output (nonlinear, then
/// linear), max force and contact fraction per contact, LCP size, pivots (shooting: Newton
/// iterations), warm start, fallback, the solver's methods ([`solver_label`]), the ω sub-steps,
/// time (the point's, its estimate included) and status. A column with a unit names it after its key, `amplitude_1903 [mm]`, in the
/// scene's units (`labels`); the key before " [" is stable.
pub fn to_csv(param: &str, values: &[f64], problem: &PeriodicProblem, points: &[SweepPoint], labels: &Labels) -> String {
    let mut s = String::new();
    let (hz, mm, kn) = (labels.unit(Quantity::Frequency), labels.unit(Quantity::Length), labels.unit(Quantity::Force));
    let mut head = vec![format!("{param} {hz}")];
    if param != "frequency" {
        head.push(format!("frequency {hz}"));
    }
    head.extend(problem.outputs().displacement.iter().map(|d| format!("amplitude_{d} {mm}")));
    head.extend(problem.outputs().displacement.iter().map(|d| format!("linear_amplitude_{d} {mm}")));
    let contact_dofs = contact_labels(problem);
    head.extend(contact_dofs.iter().enumerate().map(|(i, d)| format!("max_force_c{i}_dof{d} {kn}")));
    head.extend(contact_dofs.iter().enumerate().map(|(i, d)| format!("contact_fraction_c{i}_dof{d}")));
    head.extend(["lcp_size", "steps", "pivots", "warm_start_used", "cold_fallback", "solver", "substeps", "time_s", "status"].map(String::from));
    let estimated = points.iter().any(|p| !p.estimate_method.is_empty());
    if estimated {
        head.push("error_estimate_relative".into());
    }
    let sourced = points.iter().any(|p| !p.source.is_empty());
    if sourced {
        head.push("source".into());
    }
    s.push_str(&head.join(","));
    s.push('\n');
    for (v, p) in values.iter().zip(points) {
        let mut row = vec![v.to_string()];
        if param != "frequency" {
            row.push(p.frequency.to_string());
        }
        let nd = problem.outputs().displacement.len();
        let nc = contact_dofs.len();
        let num = |x: Option<&f64>| x.map_or("nan".to_string(), |x| format!("{x:e}"));
        row.extend((0..nd).map(|i| num(p.amplitude.get(i))));
        row.extend((0..nd).map(|i| num(p.linear_amplitude.get(i))));
        row.extend((0..nc).map(|i| num(p.max_force.get(i))));
        row.extend((0..nc).map(|i| num(p.contact_fraction.get(i))));
        row.push(p.lcp_size.to_string());
        row.push(p.steps.to_string());
        row.push(p.pivots.to_string());
        row.push(u8::from(p.warm_start_used).to_string());
        row.push(u8::from(p.cold_fallback).to_string());
        row.push(solver_label(&p.lcp_path));
        row.push(p.substeps.to_string());
        row.push(format!("{:.6}", p.time_s));
        row.push(match &p.error {
            None => "solved".to_string(),
            Some(e) => format!("\"{}\"", e.replace('"', "'")),
        });
        if estimated {
            row.push(num(p.estimate_relative.as_ref()));
        }
        if sourced {
            row.push(p.source.clone());
        }
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s
}

/// The methods of an LCP path (`render_path`'s line) in one CSV cell: "shooting",
/// "shooting>pivoting>lemke", "lemke"; "none" without an LCP.
pub fn solver_label(path: &str) -> String {
    let Some((_, steps)) = path.split_once("): ") else { return "none".to_string() };
    let names: Vec<&str> = steps
        .split("; fallback: ")
        .map(|step| match step {
            s if s.starts_with("shooting") => "shooting",
            s if s.starts_with("block pivoting") => "pivoting",
            _ => "lemke",
        })
        .collect();
    names.join(">")
}

/// The user's DOF that labels each contact (its normal's largest |coefficient|).
pub fn contact_labels(problem: &PeriodicProblem) -> Vec<usize> {
    (0..problem.model().contacts.len()).map(|a| crate::model::label_of(problem.user_row(a)).0).collect()
}

/// The frequency of the largest value of `amplitude(point)` over the solved points, if any.
pub fn peak(points: &[SweepPoint], amplitude: impl Fn(&SweepPoint) -> f64) -> Option<(f64, f64)> {
    points.iter().filter(|p| p.error.is_none()).map(|p| (p.frequency, amplitude(p))).filter(|(_, a)| a.is_finite()).fold(
        None,
        |best: Option<(f64, f64)>, (f, a)| match best {
            Some((_, b)) if b >= a => best,
            _ => Some((f, a)),
        },
    )
}

/// The axis labels of the frequency-response curve of the scene's DOF `d` over `param`:
/// ("excitation frequency ω [rad/s]", "amplitude of MC:y [mm] (peak-to-peak / 2)").
pub fn frc_axes(param: &str, d: usize, labels: &Labels) -> (String, String) {
    let hz = labels.unit(Quantity::Frequency);
    let x = match param {
        "speed" => format!("rotation speed Ω {hz}"),
        _ => format!("excitation frequency ω {hz}"),
    };
    (x, format!("amplitude of {} {} (peak-to-peak / 2)", labels.dof(d), labels.unit(Quantity::Length)))
}

/// The jumps of a swept curve, in sweep order: the pairs of neighbouring points between which
/// the amplitude changes by more than a fifth of its range, five times the median change between
/// neighbours and three times either neighbouring change (the sweep left a branch at a fold; a
/// steep or under-resolved peak changes as much on its neighbouring steps, a jump alone).
pub fn jumps(curve: &[(f64, f64)]) -> Vec<((f64, f64), (f64, f64))> {
    let steps: Vec<f64> = curve.windows(2).map(|w| (w[1].1 - w[0].1).abs()).collect();
    let (lo, hi) = curve.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p.1), h.max(p.1)));
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2) else { return Vec::new() };
    let isolated = |j: usize| {
        let around = steps.get(j.wrapping_sub(1)).copied().unwrap_or(0.0).max(steps.get(j + 1).copied().unwrap_or(0.0));
        steps[j] > 3.0 * around
    };
    (0..steps.len()).filter(|&j| steps[j] > 0.2 * (hi - lo) && steps[j] > 5.0 * median && isolated(j)).map(|j| (curve[j], curve[j + 1])).collect()
}

/// The ratio of the larger to the smaller of two peaks (∞ when one is zero): above 10 a linear
/// amplitude axis squashes the smaller curve, and the CLI suggests `--log-amplitude`.
pub fn peak_ratio(a: f64, b: f64) -> f64 {
    a.max(b) / a.min(b)
}

/// PNG of the frequency-response curve of displacement output `i`: with contact and linear,
/// labelled with the DOF's name and the scene's units, each jump of the contact curve drawn as a
/// dashed vertical segment. `swept`: the parameter's name, its values and the points; `log`: a
/// log amplitude axis.
#[cfg(feature = "plots")]
pub fn plot_frc(
    path: &std::path::Path,
    swept: (&str, &[f64], &[SweepPoint]),
    problem: &PeriodicProblem,
    i: usize,
    labels: &Labels,
    title: &str,
    log: bool,
) -> Result<(), crate::Error> {
    use crate::plot::{Chart, Legend, Line, Look, Scale, Series, styled_panel_chart};
    let (param, values, points) = swept;
    let d = problem.outputs().displacement[i];
    let pts = |lin: bool| -> Vec<(f64, f64)> {
        values.iter().zip(points).filter(|(_, p)| p.error.is_none()).map(|(v, p)| (*v, if lin { p.linear_amplitude[i] } else { p.amplitude[i] })).collect()
    };
    let contact = pts(false);
    let found = jumps(&contact);
    let mut series = vec![
        Series { label: "with contact".into(), points: contact, markers: false },
        Series { label: "linear (contact-free)".into(), points: pts(true), markers: false },
    ];
    let mut looks =
        vec![Look { colour: 0, line: Line::Solid, marker: None, hollow: false }, Look { colour: 1, line: Line::Solid, marker: None, hollow: false }];
    for (j, (a, b)) in found.iter().enumerate() {
        let x = 0.5 * (a.0 + b.0);
        let label = if j == 0 { format!("jump ({} in the sweep)", found.len()) } else { String::new() };
        series.push(Series { label, points: vec![(x, a.1), (x, b.1)], markers: true });
        looks.push(Look { colour: 3, line: Line::Dashed, marker: Some(1), hollow: true });
    }
    let (x_label, y_label) = frc_axes(param, d, labels);
    let title = format!("{title} of {}", labels.dof(d));
    let y_scale = if log { Scale::Log } else { Scale::Linear };
    let chart = Chart { title: &title, x_label: &x_label, y_label: &y_label, x_scale: Scale::Linear, y_scale };
    styled_panel_chart(path, &[(&chart, &series, &looks)], 1, 1000, 650, Legend::Default).map_err(crate::Error::from)
}
