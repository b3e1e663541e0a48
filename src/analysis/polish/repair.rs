//! The polish's start where the grid's event sequence is not the orbit's (issues 23/24: the real
//! blade at k = 512, 1150 rad/s, whose grid merged tip 15's flight of 1.1 steps and its contact
//! of 2.3 steps after it into one arc and a one-step run). Two remedies, in turn:
//! - where Newton converges but the orbit dips through a contact between its events (a clearance
//!   below zero in a flight, a held force below zero in an arc), the phase the grid missed is put
//!   back: that contact switched twice around the dip ([`events::with_run`]), Newton again from
//!   the last orbit's times, up to [`REPAIRS`] times;
//! - where that fails too (Newton stalls on a sequence that is not the orbit's), the grid is solved
//!   again at 2k, 4k, … up to [`FINEST`] and its sequence polished the same way: a missed phase a
//!   few steps long at k is many steps long there.
use super::events::{self, Event};
use super::{PolishFailure, PolishedOrbit, verify};
use crate::model::Model;
use crate::periodic::{AUTO_LEMKE_MAX, PeriodicProblem, PeriodicSolver, carried_active_set, carried_state, step_map};
use crate::response::Response;

/// A phase of one contact shorter than this (fraction of the period) after a repair is a pair
/// that collapsed onto its neighbours (the real blade at 2180 rad/s, k = 1024: tip 15's impact,
/// impact, release, release at one instant); the exact walk takes a phase below 1e-6 for vanished.
const COLLAPSED: f64 = 1e-6;
/// Missed phases put back in a row, each where the last orbit dips through a contact.
const REPAIRS: usize = 4;
/// The finest grid whose event sequence the polish tries (the real blade's LCP there: 139 264
/// unknowns, ≈ 1 s of shooting).
const FINEST: usize = 8192;

/// The polished orbit and, when the scene's grid did not give its sequence as read, how it was had.
pub struct Polished {
    pub orbit: PolishedOrbit,
    /// Empty when the grid's sequence (or it without its near-grazing runs) held as read.
    pub note: String,
}

/// The exact orbit from the grid's solution `r` of `problem`: its sequence, repaired where the
/// orbit dips ([`settle`]), else the sequences of grids 2k, 4k, … ≤ [`FINEST`] (see the module).
pub(super) fn polish_grid(problem: &PeriodicProblem, r: &Response) -> Result<Polished, PolishFailure> {
    let model = problem.model();
    let first = match from_grid(problem, r) {
        Ok(p) => return Ok(p),
        Err(e) => e,
    };
    let k = r.steps;
    let mut fine = problem.clone();
    let mut steps = 2 * k;
    // The coarser grid's orbit, carried to the next grid: its active set, shooting state and instants.
    let mut coarser = Carried::of(r, problem.instants());
    while steps <= FINEST {
        let mut disc = fine.discretization();
        disc.steps = steps;
        if fine.set_discretization(disc).is_err() {
            break;
        }
        let why = |w: &str| format!("the scene's k = {k} gave an event sequence that is not the orbit's ({}); {w}", first.0);
        let Some(finer) = finer_grid(&fine, &coarser) else {
            return Err(PolishFailure(why(&format!("the grid at k = {steps} did not solve from the k = {} grid's orbit", steps / 2))));
        };
        if finer.contacts.len() == model.contacts.len()
            && let Ok(p) = from_grid(&fine, &finer)
        {
            let how = if p.note.is_empty() { String::new() } else { format!(", {}", p.note) };
            return Ok(Polished { orbit: p.orbit, note: why(&format!("the sequence of the grid at k = {steps}{how}")) });
        }
        coarser = Carried::of(&finer, fine.instants());
        steps *= 2;
    }
    Err(first)
}

/// The solution of `fine` (twice the grid of `coarser`, its solution): Newton of shooting from
/// `coarser`'s orbit carried there, the same branch where orbits coexist (the real blade at
/// 1215.5 rad/s, whose cold k = 2048 solve misses); no cold search nor dense fallback (a 64-DOF
/// chain at ω = 0.03 rad/s spent 65 s at k = 4096 on those to fail); cold only where the LCP is
/// small enough for dense Lemke ([`AUTO_LEMKE_MAX`]) or the scheme has no step map. `None`: no solution.
fn finer_grid(fine: &PeriodicProblem, coarser: &Carried) -> Option<Response> {
    let m = fine.model().contacts.len().max(1);
    let (from, to) = (coarser.instants, fine.instants());
    let mut solver = PeriodicSolver::new(fine.clone());
    solver.set_warm_start(&carried_active_set(&coarser.active_set, m, from, to));
    solver.set_warm_state(coarser.state.as_deref().and_then(|s| carried_state(fine.discretization().scheme, s, from, to)));
    if let Ok(r) = solver.solve_by_shooting(true) {
        return Some(r);
    }
    let cold_is_cheap = to * m <= AUTO_LEMKE_MAX || step_map(fine).is_err();
    if cold_is_cheap { PeriodicSolver::new(fine.clone()).solve().ok() } else { None }
}

/// What a rung of the ladder takes from the coarser grid's solution.
struct Carried {
    active_set: Vec<usize>,
    state: Option<Vec<f64>>,
    instants: usize,
}

impl Carried {
    fn of(r: &Response, instants: usize) -> Carried {
        Carried { active_set: r.active_set.clone(), state: r.orbit_state.clone(), instants }
    }
}

/// The orbit on the sequence of one grid's solution: as read, else without its near-grazing runs
/// ([`events::without_short_runs`]), each repaired where the orbit dips ([`settle`]).
fn from_grid(problem: &PeriodicProblem, r: &Response) -> Result<Polished, PolishFailure> {
    let model = problem.model();
    let offsets: Vec<usize> = (0..model.contacts.len()).map(|i| problem.pairing_at(i).offset()).collect();
    let (evs, always) = events::from_response(model, r, &offsets);
    let evs = events::isolated_first(evs, model.period());
    let first = match settle(model, evs.clone(), &always) {
        Ok((orbit, note)) => return Ok(Polished { orbit, note }),
        Err(e) => e,
    };
    // Once more without the runs of at most two steps at a near-grazing (events.rs).
    let span = 2.5 * model.period() / r.steps as f64;
    let fewer = events::without_short_runs(model, &evs, span, model.period());
    if fewer.len() == evs.len() {
        return Err(first);
    }
    let (orbit, note) = settle(model, events::isolated_first(fewer, model.period()), &always).map_err(|_| first)?;
    let dropped =
        format!("the grid's runs shorter than 2.5 steps at a near-grazing dropped{}", if note.is_empty() { String::new() } else { format!(", {note}") });
    Ok(Polished { orbit, note: dropped })
}

/// Newton on `evs`, then the check; where the orbit dips through a contact between its events,
/// the phase the grid missed put back around the dip and Newton again from the orbit's times, up
/// to [`REPAIRS`] times. The note names the phases put back (empty: none); the error is the first.
fn settle(model: &Model, evs: Vec<Event>, always: &[usize]) -> Result<(PolishedOrbit, String), PolishFailure> {
    let clock = std::time::Instant::now();
    let mut orbit = PolishedOrbit::solve(model, evs, always)?;
    super::profile("Newton", clock);
    let period = model.period();
    let mut first: Option<PolishFailure> = None;
    let mut put_back: Vec<String> = Vec::new();
    loop {
        let dip = match verify::check_dip(&orbit) {
            Ok(()) => break,
            Err((e, dip)) => {
                let dip = dip.filter(|_| put_back.len() < REPAIRS);
                match dip {
                    Some(d) => {
                        first.get_or_insert(e);
                        d
                    }
                    None => return Err(first.unwrap_or(e)),
                }
            }
        };
        let parts = orbit.parts();
        let (evs, always) = events::with_run(model, &parts.events, &parts.always, (dip.contact, dip.time, dip.closed), dip.half_width(period, &parts.events));
        let phase = if dip.closed { "a flight" } else { "a contact" };
        put_back.push(format!("{phase} of contact[{}] at t = {:.6}", dip.contact, dip.time.rem_euclid(period)));
        let mut next = PolishedOrbit::reusing(model, events::normalised(evs, period), &always, &orbit.phases).map_err(|_| first.clone().expect("a dip"))?;
        if next.newton().is_err() {
            return Err(first.expect("a dip"));
        }
        orbit = next;
    }
    super::profile("admissibility check", clock);
    if !put_back.is_empty() {
        orbit = pruned(model, orbit);
    }
    let note = if put_back.is_empty() { String::new() } else { format!("the phases the grid missed put back where the orbit dipped: {}", put_back.join(", ")) };
    Ok((orbit, note))
}

/// `orbit` without its collapsed phases ([`COLLAPSED`]): each shortest pair of one contact's
/// events removed in turn while the orbit without it converges and is admissible.
fn pruned(model: &Model, mut orbit: PolishedOrbit) -> PolishedOrbit {
    let period = model.period();
    loop {
        let parts = orbit.parts();
        let ne = parts.events.len();
        let mut spans: Vec<(f64, usize, usize)> = (0..ne)
            .filter_map(|a| {
                let b = (1..ne).map(|s| (a + s) % ne).find(|&b| parts.events[b].contact == parts.events[a].contact)?;
                let span = (parts.events[b].seed - parts.events[a].seed).rem_euclid(period);
                (span < COLLAPSED * period).then_some((span, a, b))
            })
            .collect();
        spans.sort_by(|x, y| x.0.total_cmp(&y.0));
        let better = spans.into_iter().find_map(|(_, a, b)| {
            let kept: Vec<Event> = parts.events.iter().enumerate().filter(|(k, _)| *k != a && *k != b).map(|(_, e)| *e).collect();
            let mut next = PolishedOrbit::reusing(model, events::normalised(kept, period), &parts.always, &orbit.phases).ok()?;
            next.newton().ok()?;
            verify::check(&next).ok()?;
            Some(next)
        });
        match better {
            Some(next) => orbit = next,
            None => return orbit,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Structure};
    use crate::periodic::{OutputSelection, SolverSettings};
    use crate::time::{Discretization, Scheme};

    /// A fixed–free chain of `n` unit masses and unit springs, damping 0.02 on the diagonal,
    /// 0.1 cos ωt on the last DOF against a compliant stop (50, gap 1): the front ends' slow
    /// re-solve (64 DOFs at ω = 0.0303 rad/s spent 65 s on a cold k = 4096 grid of this ladder).
    fn chain(n: usize, omega: f64, steps: usize) -> PeriodicProblem {
        let row = |i: usize, f: &dyn Fn(usize) -> f64| (0..n).map(|j| if j == i { f(i) } else { 0.0 }).collect::<Vec<f64>>();
        let mass = Matrix::from_rows(&(0..n).map(|i| row(i, &|_| 1.0)).collect::<Vec<_>>());
        let damping = Matrix::from_rows(&(0..n).map(|i| row(i, &|_| 0.02)).collect::<Vec<_>>());
        let stiffness: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        if i == j {
                            if i + 1 < n { 2.0 } else { 1.0 }
                        } else if i.abs_diff(j) == 1 {
                            -1.0
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect();
        let model = Model {
            structure: Structure { mass, stiffness: Matrix::from_rows(&stiffness), damping: Some(damping) },
            forces: vec![Force { dof: n - 1, term: Harmonic { amplitude: 0.1, harmonic: 1, phase: 0.0 } }],
            contacts: vec![Contact::on_dof(n - 1, 1.0, 1.0, Compliance::Compliant { stiffness: 50.0 })],
            frequency: omega,
            frictions: vec![],
            rubbing: vec![],
        };
        let outputs = OutputSelection { displacement: vec![n - 1], velocity: vec![], acceleration: vec![], contacts: true };
        PeriodicProblem::new(model, Discretization { scheme: Scheme::Bds2, steps, pairing: None }, outputs, SolverSettings::default()).unwrap()
    }

    #[test]
    fn a_finer_grid_of_the_ladder_is_one_warm_newton_run_from_the_coarser_orbit() {
        // Reference: the same grid solved cold.
        // The rung starts from the coarser grid's orbit: at most one Newton run (30 iterations).
        let (n, omega) = (16, 0.0303);
        let coarse = chain(n, omega, 1024);
        let coarser = Carried::of(&PeriodicSolver::new(coarse.clone()).solve().unwrap(), coarse.instants());
        let fine = chain(n, omega, 2048);
        let rung = finer_grid(&fine, &coarser).expect("the rung solves from the coarser orbit");
        let cold = PeriodicSolver::new(fine).solve().unwrap();
        assert!(rung.lcp.pivots <= 30, "the rung took {} Newton iterations (cold: {})", rung.lcp.pivots, cold.lcp.pivots);
        let (a, b) = (rung.displacement.values().next().unwrap(), cold.displacement.values().next().unwrap());
        let scale = b.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        let diff = a.iter().zip(b).fold(0.0f64, |s, (x, y)| s.max((x - y).abs()));
        eprintln!("rung {} iterations, cold {}; max difference {diff:.3e} of {scale:.3e}", rung.lcp.pivots, cold.lcp.pivots);
        assert!(diff <= 1e-8 * scale, "the rung's orbit differs from the cold one by {diff:.3e} (of {scale:.3e})");
    }
}
