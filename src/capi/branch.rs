//! Branches through the C API (issue 13 item 6): each solve continues the last orbit along its
//! branch (`continuation::resolve`), counts the jumps where a branch ended at a fold, and, when
//! asked (`[output] stability` or `pc_problem_set_stability`), reports the orbit's Floquet
//! stability.
use super::{PcProblem, PcResult, arg, guarded, problem, result, solver_error, to_cstring};
use crate::analysis::continuation::{self, Current, Jump, Stability};
use crate::analysis::polish::PolishedOrbit;
use crate::periodic::{PeriodicSolver, Tuning};
use crate::response::Response;
use crate::time::Discretization;
use std::ffi::{CString, c_char, c_int};

/// What a problem keeps between solves.
#[derive(Clone, Debug, Default)]
pub(super) struct BranchState {
    /// Compute the stability of every result.
    pub stability: bool,
    /// The last orbit: its values, grid, active set and amplitude.
    last: Option<(Tuning, Discretization, Vec<usize>, f64)>,
    /// Its exact orbit on the followed branch, when the branch was followed exactly.
    orbit: Option<PolishedOrbit>,
    /// Jumps since the problem was made.
    jumps: usize,
}

/// What a result says of its branch.
#[derive(Debug, Default)]
pub(super) struct BranchResult {
    stability: Option<Stability>,
    /// Why there is no stability (owned by the result).
    why: CString,
    jump: Option<Jump>,
    jumps: usize,
}

/// The solve of `pc_problem_solve`: the response and its branch.
pub(super) fn solve(p: &mut PcProblem) -> Result<(Response, BranchResult), (c_int, String)> {
    let disc = p.base.discretization();
    let problem = p.tuning.apply(&p.base, disc).map_err(solver_error)?;
    let session = p.session.get_or_insert_with(|| PeriodicSolver::new(problem));
    let state = &mut p.branch;
    let orbit = state.orbit.as_ref();
    let current = state.last.as_ref().map(|(t, d, set, a)| Current { tuning: *t, disc: *d, active_set: set, amplitude: *a, orbit, exact: true });
    let resolved = continuation::resolve(session, &p.base, disc, p.tuning, current).map_err(|e| (super::PC_ERROR_SOLVER, e.to_string()))?;
    let r = resolved.response;
    state.jumps += usize::from(resolved.jump.is_some());
    state.last = Some((p.tuning, disc, r.active_set.clone(), continuation::amplitude(&r)));
    state.orbit = resolved.orbit;
    // The exact orbit's multipliers where the branch was followed exactly, else the discrete ones.
    let (stability, why) = match (state.stability, resolved.stability) {
        (false, _) => (None, "not requested (pc_problem_set_stability, [output] stability)".to_string()),
        (true, Some(exact)) => (Some(exact), String::new()),
        (true, None) => match continuation::stability(session.problem(), &r.active_set) {
            Ok(s) => (Some(s), String::new()),
            Err(why) => (None, why),
        },
    };
    Ok((r, BranchResult { stability, why: to_cstring(&why), jump: resolved.jump, jumps: state.jumps }))
}

/// Whether every solve also computes the orbit's Floquet stability (`on` = 1; default 0, or the
/// scene's `[output] stability`). Needs the step map of a difference scheme: without one
/// `pc_result_stability` says why.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_stability(p: *mut PcProblem, on: c_int) -> c_int {
    guarded(|| {
        let p = unsafe { problem(p) }?;
        if on != 0 && on != 1 {
            return Err(arg(format!("on is {on}, must be 0 or 1")));
        }
        p.branch.stability = on == 1;
        Ok(())
    })
}

/// The result's Floquet stability: `*computed` = 1 with `*stable` (1: every multiplier inside
/// the unit circle) and `*multiplier` (the largest modulus), or `*computed` = 0, both 0 and
/// `*why` saying why not (owned by the result; "" when computed). Any output may be NULL.
///
/// # Safety
/// Non-NULL pointers are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_stability(
    r: *const PcResult,
    computed: *mut c_int,
    stable: *mut c_int,
    multiplier: *mut f64,
    why: *mut *const c_char,
) -> c_int {
    guarded(|| {
        let b = &unsafe { result(r) }?.branch;
        unsafe {
            if let Some(v) = computed.as_mut() {
                *v = c_int::from(b.stability.is_some());
            }
            if let Some(v) = stable.as_mut() {
                *v = c_int::from(b.stability.as_ref().is_some_and(|s| s.stable));
            }
            if let Some(v) = multiplier.as_mut() {
                *v = b.stability.as_ref().map_or(0.0, |s| s.largest);
            }
            if let Some(v) = why.as_mut() {
                *v = b.why.as_ptr();
            }
        }
        Ok(())
    })
}

/// Whether this solve jumped: `*jumped` = 1 when the branch of the previous result's orbit ended
/// at a fold between the previous values and these, so the answer is the orbit that exists;
/// then `*fold_frequency` [rad/s] where the branch turned back and the amplitudes (half the
/// largest peak-to-peak of the displacement outputs) before and after, else all 0. `*jumps`:
/// the problem's jumps so far. Any output may be NULL.
///
/// # Safety
/// Non-NULL pointers are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_jump(
    r: *const PcResult,
    jumped: *mut c_int,
    fold_frequency: *mut f64,
    from_amplitude: *mut f64,
    to_amplitude: *mut f64,
    jumps: *mut usize,
) -> c_int {
    guarded(|| {
        let b = &unsafe { result(r) }?.branch;
        let j = b.jump.as_ref();
        unsafe {
            if let Some(v) = jumped.as_mut() {
                *v = c_int::from(j.is_some());
            }
            for (out, value) in
                [(fold_frequency, j.map(|j| j.fold.frequency)), (from_amplitude, j.map(|j| j.from_amplitude)), (to_amplitude, j.map(|j| j.to_amplitude))]
            {
                if let Some(v) = out.as_mut() {
                    *v = value.unwrap_or(0.0);
                }
            }
            if let Some(v) = jumps.as_mut() {
                *v = b.jumps;
            }
        }
        Ok(())
    })
}
