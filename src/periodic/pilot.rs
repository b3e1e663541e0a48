//! The pilot of a cold shooting solve on a stiff model with rigid impacts on DOFs with mass
//! (a Craig–Bampton blade's tips under cds or galerkin, forward pairing): bds1 on a coarser
//! grid first, its active sets carried to the fine grid as shooting's warm start.
//!
//! Why: cold shooting starts from the contact-free orbit and follows the offset homotopy down to
//! the contacts; the stiff constraint modes ring after each impact, and the path meets hundreds
//! of kinks. Measured on the real blade reduced by Craig–Bampton (d = 138, 17 rigid tips,
//! ω = 2300 rad/s): cds at k = 16 384 ran 726 Newton iterations and 200 homotopy steps (66 s of
//! CPU) and missed; galerkin at k = 8192 the same (701, 42 s). bds1 (A-stable, damping the
//! unresolved modes) solves the coarse grid in 5 Newton iterations from the contact-free orbit,
//! and its orbit is on the fine grid's pieces or next to them: Newton from its sets then
//! converged in 6–9 iterations (validation/RECORD.md "Real-blade benchmark").
use super::{PeriodFft, PeriodicProblem, SolveError, SolverSettings};
use crate::lcp::{BlockCirculant, LcpMethod, LcpSolution};
use crate::time::{Discretization, Pairing, Scheme};

/// Fewest instants for which a cold solve is piloted: below, cold shooting is cheap enough (the
/// rigid coarse blade, cds k = 1024, solves cold in a second) and a pilot grid would be too coarse.
pub const PILOT_MIN_STEPS: usize = 2048;
/// The pilot grid is the fine one divided by this, within [`PILOT_STEPS`]. bds1 is first order:
/// its orbit at k/8 is near the fine one's (the blade's outputs within 2–3 % of the amplitude),
/// and it costs a small part of the fine solve.
const PILOT_DIVISOR: usize = 8;
/// The pilot grid's range of k.
const PILOT_STEPS: (usize, usize) = (256, 2048);

/// The active set of a bds1 solve on a coarser grid, carried to this problem's instants, and that
/// grid's k, when a cold solve of `problem` is worth a pilot (see the module); `None` otherwise,
/// or when the pilot is refused or misses (the cold solve then runs as without it).
pub(super) fn warm_start(problem: &PeriodicProblem) -> Option<(Vec<usize>, usize)> {
    let disc = problem.discretization();
    let model = problem.model();
    let stiff_impacts = matches!(disc.scheme, Scheme::Cds | Scheme::Galerkin) && super::limits::ContactClass::of(model).rigid_massive > 0;
    let plain = model.frictions.is_empty() && model.rubbing.is_empty();
    let shooting = matches!(problem.solver_settings().method, LcpMethod::Auto | LcpMethod::Shooting);
    if !(stiff_impacts && plain && shooting && problem.instants() >= PILOT_MIN_STEPS) {
        return None;
    }
    let steps = (disc.steps / PILOT_DIVISOR).clamp(PILOT_STEPS.0, PILOT_STEPS.1);
    let mut pilot = problem.clone();
    pilot.set_discretization(Discretization { scheme: Scheme::Bds1, steps, pairing: Some(Pairing::Same) }).ok()?;
    let r = pilot.solve_with(&PeriodFft::new(pilot.instants()), None).ok()?;
    Some((carried_active_set(&r.active_set, model.contacts.len(), pilot.instants(), problem.instants()), steps))
}

/// A cold `auto` solve whose shooting misses, re-tried from a bds1 pilot's active sets on the same
/// grid before the dense fallbacks; `None` when it does not apply (a warm start, friction or
/// rubbing, another method, or a bds1/fourier problem), and then the caller solves as before.
///
/// Why (issue 23, the compliant real blade at ω = 2535.5 rad/s, cds k = 256): the offset path
/// from the contact-free orbit folds back at δ = 1.2e-6 m (10 % of the gap), climbs to 1.5e-4,
/// folds again at 1.2e-6 and closes on the contact-free family after 52 steps (≈ 1500 set
/// changes): the answer at δ = 0 is on another branch, and block pivoting (ray) and dense Lemke
/// (1722 pivots, 2.5–4 s) followed. bds1 (A-stable, damped) on the same grid solves cold in
/// 0.2 s, and Newton from its sets reaches the cds orbit (validation/RECORD.md "On a family, not one case").
pub(super) fn solve_after_cold_miss(problem: &PeriodicProblem, a: &BlockCirculant, q: &[f64]) -> Option<Result<(LcpSolution, Option<String>), SolveError>> {
    let settings = problem.solver_settings();
    let model = problem.model();
    let disc = problem.discretization();
    let plain = model.frictions.is_empty() && model.rubbing.is_empty();
    let full_reach = !settings.shooting_warm_only && settings.shooting_homotopy;
    if !(plain && full_reach && settings.method == LcpMethod::Auto && matches!(disc.scheme, Scheme::Cds | Scheme::Galerkin | Scheme::Bds2) && !q.is_empty()) {
        return None;
    }
    // Shooting alone first: what `auto` tries first, without its dense fallbacks.
    let mut shooting = problem.clone();
    shooting.set_solver_settings(SolverSettings { method: LcpMethod::Shooting, ..settings.clone() }).ok()?;
    match shooting.solve_lcp(a, q, None) {
        Ok(sol) => return Some(Ok((sol, None))),
        // Not a miss (no step map, a refused size): `auto` as before, no pilot to pay for.
        Err(e) if !matches!(e, SolveError::Lcp { .. }) => return Some(problem.solve_lcp(a, q, None).map(|sol| (sol, None))),
        Err(_) => {}
    }
    crate::lcp::progress(&format!("cold shooting missed at k = {}; a bds1 pilot on the same grid next", disc.steps));
    let pilot = bds1_active_set(problem, disc.steps);
    let note = pilot.as_ref().map(|_| format!("cold shooting missed; started from a bds1 pilot's active sets at k = {}", disc.steps));
    // Where dense Lemke is cheap (small N), `auto` from the pilot's sets and its dense fallback, as before.
    if crate::lcp::dense_lemke_seconds(q.len()) <= NEIGHBOUR_AFTER_LEMKE_S {
        return Some(problem.solve_lcp(a, q, pilot.as_deref()).map(|sol| (sol, note)));
    }
    if let Some(sets) = &pilot
        && let Ok(sol) = shooting.solve_lcp(a, q, Some(sets))
    {
        return Some(Ok((sol, note)));
    }
    crate::lcp::progress(&format!("the bds1 pilot missed too at ω = {} rad/s; a cold solve at a neighbouring ω and warm steps back next", model.frequency));
    if let Some((sets, from)) = from_neighbour(&shooting)
        && let Ok(sol) = shooting.solve_lcp(a, q, Some(&sets))
    {
        let note = format!("cold shooting and its bds1 pilot missed; reached from a cold solve at ω = {from:.3} rad/s by warm-started steps");
        return Some(Ok((sol, Some(note))));
    }
    // The dense fallbacks (or their refusal, with its remedies) as before.
    Some(problem.solve_lcp(a, q, pilot.as_deref()).map(|sol| (sol, note)))
}

/// The neighbours are tried only where dense Lemke is projected to take longer than this [s]
/// (N ≳ 2 700): below, the dense fallback is cheaper than up to six cold solves (≈ 0.3–0.5 s
/// each on a 2-DOF model at k = 4096), and the test suite's random families ran 2× slower.
const NEIGHBOUR_AFTER_LEMKE_S: f64 = 2.0;
/// Relative offsets of ω tried for a cold solve when the cold solve at ω and its bds1 pilot miss,
/// nearest first, above then below.
const NEIGHBOUR_OFFSETS: [f64; 6] = [5e-3, -5e-3, 1e-2, -1e-2, 2e-2, -2e-2];
/// The largest warm step towards ω, relative: the rigid real blade's sweep steps 0.4 % of ω warm.
const NEIGHBOUR_STEP: f64 = 2.5e-3;
/// Halvings of a warm step that misses before the neighbour is given up.
const NEIGHBOUR_HALVINGS: usize = 4;

/// The active set at ω of `problem` (shooting only) reached from a neighbouring ω' where a cold
/// solve succeeds, by warm-started solves stepped back to ω, and ω'; `None` when no neighbour
/// solves or the steps back miss. Why (issue 23, the rigid real blade, cds k = 1024): cold
/// shooting and the bds1 pilot miss at ω = 2030, 2390, 2400, 2404, 2406 rad/s, where the offset
/// homotopy from the contact-free orbit meets too many kinks, while ω ± 0.5 % solve cold and a
/// sweep's warm steps of 0.4 % pass through (validation/RECORD.md "Cold misses").
fn from_neighbour(problem: &PeriodicProblem) -> Option<(Vec<usize>, f64)> {
    let omega = problem.model().frequency;
    let fft = PeriodFft::new(problem.instants());
    let at = |w: f64, warm: Option<&[usize]>| -> Option<Vec<usize>> {
        let mut p = problem.clone();
        p.set_frequency(w).ok()?;
        p.solve_with(&fft, warm).ok().map(|r| r.active_set)
    };
    for offset in NEIGHBOUR_OFFSETS {
        let from = omega * (1.0 + offset);
        let Some(mut sets) = at(from, None) else { continue };
        let (mut w, mut step, mut halvings) = (from, NEIGHBOUR_STEP * omega, 0);
        while w != omega && halvings <= NEIGHBOUR_HALVINGS {
            let next = if (omega - w).abs() <= step { omega } else { w + step * (omega - w).signum() };
            match at(next, Some(&sets)) {
                Some(s) => (sets, w) = (s, next),
                None => (step, halvings) = (0.5 * step, halvings + 1),
            }
        }
        if w == omega {
            return Some((sets, from));
        }
    }
    None
}

/// The active set of a bds1 solve of `problem` at `steps` per period, carried to its instants.
fn bds1_active_set(problem: &PeriodicProblem, steps: usize) -> Option<Vec<usize>> {
    let mut pilot = problem.clone();
    pilot.set_discretization(Discretization { scheme: Scheme::Bds1, steps, pairing: Some(Pairing::Same) }).ok()?;
    // Shooting only: a pilot that misses hands over to the fine grid's own fallbacks.
    pilot.set_solver_settings(SolverSettings { method: LcpMethod::Shooting, ..problem.solver_settings().clone() }).ok()?;
    let r = pilot.solve_with(&PeriodFft::new(pilot.instants()), None).ok()?;
    Some(carried_active_set(&r.active_set, problem.model().contacts.len(), pilot.instants(), problem.instants()))
}

/// An active set (indices j·m + c of instant j, row c of `rows`) of a grid of `from` instants,
/// carried to a grid of `to` instants over the same period: instant j of the new grid takes the
/// set of instant ⌊j·from/to⌋ (k → 2k: instants 2j and 2j + 1 take j; k → k/2: j takes 2j).
/// A warm start for the same orbit sampled at other instants (the pilot, the estimate, a sweep's
/// k/2 grid).
pub fn carried_active_set(active: &[usize], rows: usize, from: usize, to: usize) -> Vec<usize> {
    if rows == 0 || from == 0 {
        return Vec::new();
    }
    let mut on = vec![false; from * rows];
    for &i in active {
        if let Some(a) = on.get_mut(i) {
            *a = true;
        }
    }
    (0..to * rows).filter(|&i| on[(i / rows) * from / to * rows + i % rows]).collect()
}
