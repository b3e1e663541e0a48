//! Friction contacts through the C API (`include/periodic_contact.h`, "friction"): their number,
//! the normal-load scale, and each contact's force, slip velocity, stuck flags, tangential
//! displacement and dissipated energy at the instants (the result JSON's `friction` entries).
use super::{PcProblem, PcResult, arg, copy_out, guarded, problem, result};
use crate::response::FrictionResponse;
use std::ffi::c_int;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// The number of `[[friction]]` contacts of the problem, 0 for NULL.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_friction_count(p: *const PcProblem) -> usize {
    catch_unwind(AssertUnwindSafe(|| unsafe { p.as_ref() }.map_or(0, |p| p.base.model().frictions.len()))).unwrap_or(0)
}

/// Sets the factor on every friction contact's normal load N (so on its slip force μN) for the
/// next solve: finite and ≥ 0 (1: the scene's loads; 0: no friction).
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_normal_force_scale(p: *mut PcProblem, scale: f64) -> c_int {
    guarded(|| {
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(arg(format!("normal_force_scale = {scale} is out of range: must be finite and >= 0 (a tensile normal load cannot hold friction)")));
        }
        unsafe { problem(p) }?.tuning.normal_force_scale = scale;
        Ok(())
    })
}

/// The number of friction contacts of the result, 0 for NULL.
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_friction_count(r: *const PcResult) -> usize {
    catch_unwind(AssertUnwindSafe(|| unsafe { r.as_ref() }.map_or(0, |r| r.response.friction.len()))).unwrap_or(0)
}

fn friction<'a>(r: *const PcResult, i: usize) -> Result<&'a FrictionResponse, (c_int, String)> {
    let r = unsafe { result(r) }?;
    let n = r.response.friction.len();
    r.response.friction.get(i).ok_or_else(|| arg(format!("friction contact {i} does not exist in this result ({n} friction contacts)")))
}

/// Copies the series `pick` of friction contact `i` into `out` (len ≥ k).
unsafe fn friction_series(r: *const PcResult, i: usize, out: *mut f64, len: usize, pick: fn(&FrictionResponse) -> &[f64]) -> c_int {
    guarded(|| copy_out(pick(friction(r, i)?), out, len))
}

/// Copies the friction force f of friction contact `i` at the k instants: it acts on the
/// structure as −f along the sliding direction; |f| ≤ μN, f = μN·sign(v) while slipping.
///
/// # Safety
/// `r` is NULL or a live result handle; `out` holds `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_friction_force(r: *const PcResult, i: usize, out: *mut f64, len: usize) -> c_int {
    unsafe { friction_series(r, i, out, len, |f| &f.force) }
}

/// Copies the slip velocity v of friction contact `i` at the k instants (bds1's backward
/// difference; a Jenkins element's slider velocity); 0 while stuck.
///
/// # Safety
/// `r` is NULL or a live result handle; `out` holds `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_friction_slip_velocity(r: *const PcResult, i: usize, out: *mut f64, len: usize) -> c_int {
    unsafe { friction_series(r, i, out, len, |f| &f.slip_velocity) }
}

/// Copies the tangential displacement u = b·x of friction contact `i` at the k instants (the
/// abscissa of its force–displacement loop).
///
/// # Safety
/// `r` is NULL or a live result handle; `out` holds `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_friction_displacement(r: *const PcResult, i: usize, out: *mut f64, len: usize) -> c_int {
    unsafe { friction_series(r, i, out, len, |f| &f.displacement) }
}

/// Copies the stuck flags of friction contact `i` at the k instants (1 stuck: |f| < μN, 0
/// slipping) into `out` (len ≥ k ints).
///
/// # Safety
/// `r` is NULL or a live result handle; `out` holds `len` writable ints.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_friction_stuck(r: *const PcResult, i: usize, out: *mut c_int, len: usize) -> c_int {
    guarded(|| {
        let stuck = &friction(r, i)?.stuck;
        if out.is_null() || len < stuck.len() {
            return Err(arg(format!("the output buffer is NULL or shorter ({len}) than the {} instants", stuck.len())));
        }
        // SAFETY: the caller promises len ≥ k writable ints.
        let out = unsafe { std::slice::from_raw_parts_mut(out, stuck.len()) };
        out.iter_mut().zip(stuck).for_each(|(o, s)| *o = c_int::from(*s));
        Ok(())
    })
}

/// The energy friction contact `i` dissipates per period, ∮ f v dt ≥ 0 (force unit × length
/// unit), and its slip force μN (the load's scale applied); either output may be NULL.
///
/// # Safety
/// `r` is NULL or a live result handle; non-NULL outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_friction(r: *const PcResult, i: usize, dissipated_energy: *mut f64, slip_force: *mut f64) -> c_int {
    guarded(|| {
        let f = friction(r, i)?;
        // SAFETY: NULL or writable, as documented.
        unsafe {
            if let Some(e) = dissipated_energy.as_mut() {
                *e = f.dissipated_energy;
            }
            if let Some(s) = slip_force.as_mut() {
                *s = f.coefficient * f.normal_force;
            }
        }
        Ok(())
    })
}
