//! The frequency walk of a lone rubbing solve (issue 25): where shooting and the μ-homotopy miss
//! at ω, the orbit a sweep reaches from below. On the real blade at 2300 rad/s (validation/RECORD.md
//! "Friction") the branch from below folds near 2278.4 rad/s and its orbits there are not joined
//! by a μ-path to μ = 0; a sweep crosses the fold as Newton from the last orbit before it, at the
//! next point past it, lands on the branch above. The walk is that sweep, on a grid ending at ω.
use crate::lcp::progress;
use crate::periodic::{PeriodicProblem, PeriodicSolver, SolverSettings};

/// The walk's step, a share of ω: the sweep's 5 rad/s at the real blade's 2300 rad/s.
const STEP: f64 = 5.0 / 2300.0;
/// Steps below ω where the walk starts cold, tried in turn: 6 (the real blade's sweep 2270 → 2300),
/// then 20 (2200 → 2300, session 19's).
const STARTS: [usize; 2] = [6, 20];
/// Halvings of a missed step's ω sub-steps from the last point solved (the sweep's: 1/16 of it).
const HALVINGS: u32 = 4;

/// Points past a fold per walk step where Newton from the last orbit before it is tried first
/// (the sweep's crossing: from 2278.1 rad/s the real blade's lands at 2293 rad/s, on the orbit the
/// sweep 2200 → 2300 follows).
const NEWTON_TRIES: f64 = 5.0;

/// Periods marched from the last orbit before a fold before Newton past it (time marching's
/// jump onto the attractor): ≈ 12 e-folds of a 0.5 % damped mode (one per 1/(2πζ) ≈ 32 periods).
/// Why: Newton from that orbit alone lands or not by luck (the real blade at 2300 rad/s: from
/// 2278.4 rad/s, 2280 misses and 2285 lands; on the grid 0.18 rad/s lower no point lands). It may
/// land on another orbit than the sweep's (the real blade: 6.9e-4 m at 2300 rad/s, not 2.47e-4).
const SETTLE_PERIODS: usize = 400;

/// The active set at ω reached by the walk, and a note for `lcp.path` (where it started, where
/// it crossed a fold). `Err`: why every start missed.
pub(super) fn walk_up(problem: &PeriodicProblem) -> Result<(Vec<usize>, String), String> {
    let target = problem.model().frequency;
    let step = STEP * target;
    let mut missed_starts = Vec::new();
    for n in STARTS {
        let from = target - n as f64 * step;
        match walk_from(problem, from, step, n) {
            Ok((set, jumps)) => {
                let past = jumps.iter().map(|j| format!(", crossing a fold: {j}")).collect::<String>();
                let note = format!(
                    "started from the orbit reached by a frequency walk from below: cold at {from:.2} rad/s, then warm steps of {step:.3} rad/s{past}; other orbits may coexist here between folds of the frequency response"
                );
                return Ok((set, note));
            }
            Err(e) => {
                progress(&format!("frequency walk from {from:.2} rad/s missed ({e})"));
                missed_starts.push(format!("from {from:.2} rad/s: {e}"));
            }
        }
    }
    Err(format!("the frequency walk from below missed too ({})", missed_starts.join("; ")))
}

/// Cold at `from`, then the `n` points `from + i·step` (the last exactly ω), each from the last
/// orbit solved; where one misses (a fold), Newton from the orbit nearest the fold at points past
/// it ([`NEWTON_TRIES`] per step), else time marching from that orbit then Newton ([`jump`]).
/// Returns the set at ω and how each fold was crossed.
fn walk_from(problem: &PeriodicProblem, from: f64, step: f64, n: usize) -> Result<(Vec<usize>, Vec<String>), String> {
    let target = problem.model().frequency;
    let grid = |i: usize| if i >= n { target } else { from + i as f64 * step };
    let mut session = PeriodicSolver::new(problem.clone());
    session.update_frequency(from).map_err(|e| e.to_string())?;
    session.solve_by_shooting(false).map_err(|e| format!("the cold solve there missed ({e})"))?;
    progress(&format!("frequency walk: cold at {from:.2} rad/s solved"));
    let (mut last, mut i, mut jumps) = (from, 1, Vec::new());
    while last < target {
        let w = grid(i);
        match reach(&mut session, last, w) {
            Ok(()) => {
                progress(&format!("frequency walk: {w:.2} rad/s solved"));
                last = w;
            }
            Err(end) => {
                let tries = ((target - w) * NEWTON_TRIES / step).ceil() as usize;
                let past = (0..=tries).map(|j| (w + j as f64 * step / NEWTON_TRIES).min(target));
                let (landed, how) = match past.clone().find(|&f| solves(&mut session, f)) {
                    Some(f) => (f, "Newton from its last orbit".to_string()),
                    None => {
                        let f = jump(&mut session, past).ok_or_else(|| {
                            format!("the branch from below ended near {end:.2} rad/s, and Newton from its last orbit, alone or after {SETTLE_PERIODS} periods marched, missed at every point from {w:.2} to {target} rad/s")
                        })?;
                        (f, format!("{SETTLE_PERIODS} periods marched from its last orbit then Newton"))
                    }
                };
                progress(&format!("frequency walk: {w:.2} rad/s missed; the branch ended near {end:.2} rad/s; {how} landed at {landed:.2} rad/s"));
                jumps.push(format!("the branch ended near {end:.2} rad/s and {how} landed at {landed:.2} rad/s"));
                last = landed;
            }
        }
        while i < n && grid(i) <= last {
            i += 1;
        }
    }
    let set = session.warm_start().ok_or("no active set at the end of the walk")?;
    Ok((set.to_vec(), jumps))
}

/// The first of `points` where [`SETTLE_PERIODS`] periods marched from the session's orbit then
/// Newton solve (the session keeps that answer; its settings are restored).
fn jump(session: &mut PeriodicSolver, mut points: impl Iterator<Item = f64>) -> Option<f64> {
    let plain = session.problem().clone();
    let mut settling = plain.clone();
    let settings = SolverSettings { shooting_settle: SETTLE_PERIODS, ..plain.solver_settings().clone() };
    settling.set_solver_settings(settings).ok()?;
    session.update_problem(settling);
    let landed = points.find(|&f| solves(session, f));
    let mut back = session.problem().clone();
    back.set_solver_settings(plain.solver_settings().clone()).ok()?;
    session.update_problem(back);
    landed
}

/// Warm shooting at `f` from the session's orbit (its answer becomes the next warm start).
fn solves(session: &mut PeriodicSolver, f: f64) -> bool {
    session.update_frequency(f).and_then(|()| session.solve_by_shooting(true)).is_ok()
}

/// Warm shooting at `w`; where it misses, ω sub-steps from `last` (halved on a miss, each from
/// the one before). A miss leaves the session at the last sub-step solved, nearest a fold, and
/// returns its frequency.
fn reach(session: &mut PeriodicSolver, last: f64, w: f64) -> Result<(), f64> {
    if solves(session, w) {
        return Ok(());
    }
    let (mut here, mut h) = (last, (w - last) / 2.0);
    while h >= (w - last) / f64::from(1u32 << HALVINGS) {
        let next = if w - here <= h { w } else { here + h };
        match solves(session, next) {
            true if next == w => return Ok(()),
            true => here = next,
            false => h /= 2.0,
        }
    }
    Err(here)
}
