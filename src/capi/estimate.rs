//! The error estimate through the C API: switching it on or off, reading it.
use super::{PcProblem, PcResult, arg, guarded, problem, result};
use std::ffi::{c_char, c_int};

/// Whether every solve also estimates its error by a second solve at k/2 (`on` = 1, the default;
/// 0 for speed). A scene's `[discretization] error_estimate` sets the start value.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_error_estimate(p: *mut PcProblem, on: c_int) -> c_int {
    guarded(|| {
        let p = unsafe { problem(p) }?;
        if on != 0 && on != 1 {
            return Err(arg(format!("on is {on}, must be 0 or 1")));
        }
        p.estimate = on == 1;
        Ok(())
    })
}

/// The CPU seconds the error estimate's neighbour solves may take together (default 30, ≥ 0).
/// Past it a result has no estimate (`pc_result_accuracy`: `*estimated` = 0, `*method` "none:
/// no estimate: …, remedy: …"); its own answer is the one without the estimate.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_error_estimate_budget(p: *mut PcProblem, seconds: f64) -> c_int {
    guarded(|| {
        let p = unsafe { problem(p) }?;
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(arg(format!("seconds is {seconds}, must be finite and ≥ 0")));
        }
        p.budget = seconds;
        Ok(())
    })
}

/// The result's error estimate (the JSON's `accuracy`): `*estimated` = 1 and `*estimate` [length]
/// and `*relative` (of the peak-to-peak amplitude; 0 when that is 0) when there is one, else
/// `*estimated` = 0 and both 0; `*method` says how or why not (owned by the result). Any output
/// may be NULL.
///
/// # Safety
/// Non-NULL pointers are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_accuracy(
    r: *const PcResult,
    estimated: *mut c_int,
    estimate: *mut f64,
    relative: *mut f64,
    method: *mut *const c_char,
) -> c_int {
    guarded(|| {
        let r = unsafe { result(r) }?;
        let a = &r.response.accuracy;
        unsafe {
            if let Some(s) = estimated.as_mut() {
                *s = c_int::from(a.estimate.is_some());
            }
            if let Some(s) = estimate.as_mut() {
                *s = a.estimate.unwrap_or(0.0);
            }
            if let Some(s) = relative.as_mut() {
                *s = a.relative.unwrap_or(0.0);
            }
            if let Some(s) = method.as_mut() {
                *s = r.accuracy_method.as_ptr();
            }
        }
        Ok(())
    })
}
