//! The frequency walk of a lone rubbing solve (issue 25): where shooting and the μ-homotopy miss
//! at ω, the orbit a sweep reaches from below. On the real blade at 2300 rad/s (README
//! "Friction") the branch from below folds near 2278.4 rad/s and its orbits there are not joined
//! by a μ-path to μ = 0; a sweep crosses the fold as Newton from the last orbit before it, at the
//! next point past it, lands on the branch above. The walk is that sweep, on a grid ending at ω.
use crate::lcp::progress;
use crate::periodic::{PeriodicProblem, PeriodicSolver};

/// The walk's step, a share of ω: the sweep's 5 rad/s at the real blade's 2300 rad/s.
const STEP: f64 = 5.0 / 2300.0;
/// Steps below ω where the walk starts cold, tried in turn: 6 (the real blade's sweep 2270 → 2300),
/// then 20 (2200 → 2300, session 19's).
const STARTS: [usize; 2] = [6, 20];
/// Halvings of a missed step's ω sub-steps from the last point solved (the sweep's: 1/16 of it).
const HALVINGS: u32 = 4;

/// The active set at ω reached by the walk, and a note for `lcp.path` (where it started, the
/// points it missed). `Err`: why every start missed.
pub(super) fn walk_up(problem: &PeriodicProblem) -> Result<(Vec<usize>, String), String> {
    let target = problem.model().frequency;
    let step = STEP * target;
    let mut missed_starts = Vec::new();
    for n in STARTS {
        let from = target - n as f64 * step;
        match walk_from(problem, from, step, n) {
            Ok((set, missed)) => {
                let past = if missed.is_empty() { String::new() } else { format!(", crossing a fold: missed at {}", list(&missed)) };
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

fn list(frequencies: &[f64]) -> String {
    frequencies.iter().map(|w| format!("{w:.2}")).collect::<Vec<_>>().join(", ")
}

/// Cold at `from`, then the `n` points `from + i·step` (the last exactly ω) each from the last
/// orbit solved. Returns the set at ω and the points missed on the way.
fn walk_from(problem: &PeriodicProblem, from: f64, step: f64, n: usize) -> Result<(Vec<usize>, Vec<f64>), String> {
    let target = problem.model().frequency;
    let mut session = PeriodicSolver::new(problem.clone());
    session.update_frequency(from).map_err(|e| e.to_string())?;
    session.solve_by_shooting(false).map_err(|e| format!("the cold solve there missed ({e})"))?;
    progress(&format!("frequency walk: cold at {from:.2} rad/s solved"));
    let (mut last, mut missed) = (from, Vec::new());
    for i in 1..=n {
        let w = if i == n { target } else { from + i as f64 * step };
        if reach(&mut session, last, w) {
            progress(&format!("frequency walk: {w:.2} rad/s solved"));
            last = w;
        } else {
            progress(&format!("frequency walk: {w:.2} rad/s missed; the next point from the last orbit solved"));
            missed.push(w);
        }
    }
    match session.warm_start() {
        Some(set) if last == target => Ok((set.to_vec(), missed)),
        _ => Err(format!("{target} rad/s missed after the points {}", list(&missed))),
    }
}

/// Warm shooting at `w`; where it misses, ω sub-steps from `last` (halved on a miss, each from
/// the one before). A miss leaves the session at the last sub-step solved: nearer a fold, from
/// where the next point may land past it.
fn reach(session: &mut PeriodicSolver, last: f64, w: f64) -> bool {
    let mut solves = |f: f64| session.update_frequency(f).and_then(|()| session.solve_by_shooting(true)).is_ok();
    if solves(w) {
        return true;
    }
    let (mut here, mut h) = (last, (w - last) / 2.0);
    while h >= (w - last) / f64::from(1u32 << HALVINGS) {
        let next = if w - here <= h { w } else { here + h };
        match solves(next) {
            true if next == w => return true,
            true => here = next,
            false => h /= 2.0,
        }
    }
    false
}
