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
//! converged in 6–9 iterations (README "Real-blade benchmark").
use super::{PeriodFft, PeriodicProblem};
use crate::lcp::LcpMethod;
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
