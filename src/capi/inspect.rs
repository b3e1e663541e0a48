//! Readers of a problem's contacts and of a result's pairing, warm start and solver path, and
//! the per-contact pairing override (`include/periodic_contact.h`, "inspection").
use super::{PC_ERROR_ARGUMENT, PcProblem, PcResult, arg, c_str, guarded, input, problem, result, solver_error};
use crate::time::Pairing;
use std::ffi::{c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// A pairing's name with static storage.
fn pairing_name(name: &str) -> *const c_char {
    match name {
        "same" => c"same".as_ptr(),
        "forward" => c"forward".as_ptr(),
        _ => std::ptr::null(),
    }
}

fn const_problem<'a>(p: *const PcProblem) -> Result<&'a PcProblem, (c_int, String)> {
    // SAFETY: NULL or a live handle from a pc_problem_* constructor.
    unsafe { p.as_ref() }.ok_or_else(|| arg("the problem handle is NULL"))
}

/// The number of DOFs in the user's numbering (the full model of a reduced or clamped scene;
/// fixed DOFs among them cannot be output), 0 for NULL.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_dof_count(p: *const PcProblem) -> usize {
    catch_unwind(AssertUnwindSafe(|| {
        let Ok(p) = const_problem(p) else { return 0 };
        match p.base.output_map() {
            None => p.base.model().n(),
            Some(map) => map.rows.keys().copied().chain(map.contact_rows.iter().flatten().map(|e| e.0)).max().map_or(0, |d| d + 1),
        }
    }))
    .unwrap_or(0)
}

/// The number of contacts of the problem, 0 for NULL.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_contact_count(p: *const PcProblem) -> usize {
    catch_unwind(AssertUnwindSafe(|| const_problem(p).map_or(0, |p| p.base.model().contacts.len()))).unwrap_or(0)
}

/// Contact `i`'s DOF in the user's numbering and its direction (+1 or −1); either output may be NULL.
/// For a contact along a normal over several DOFs: the DOF of the normal's largest |coefficient|
/// and that coefficient's sign.
///
/// # Safety
/// `p` is NULL or a live problem handle; non-NULL outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_contact(p: *const PcProblem, i: usize, dof: *mut usize, direction: *mut c_int) -> c_int {
    guarded(|| {
        let p = const_problem(p)?;
        let contacts = &p.base.model().contacts;
        contacts.get(i).ok_or_else(|| arg(format!("contact {i} does not exist ({} contacts)", contacts.len())))?;
        let (user_dof, sign) = crate::model::label_of(p.base.user_row(i));
        // SAFETY: NULL or writable, as the caller promises.
        unsafe {
            if let Some(d) = dof.as_mut() {
                *d = user_dof;
            }
            if let Some(d) = direction.as_mut() {
                *d = sign as c_int;
            }
        }
        Ok(())
    })
}

/// Sets the pairing of contact `contact` alone: "same", "forward", or NULL to drop the override
/// (back to pc_problem_set_pairing's, else the scheme's default).
///
/// # Safety
/// `p` is NULL or a live problem handle; `pairing` is NULL or a string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_contact_pairing(p: *mut PcProblem, contact: usize, pairing: *const c_char) -> c_int {
    guarded(|| {
        let p = unsafe { problem(p) }?;
        let pairing = if pairing.is_null() { None } else { Some(unsafe { c_str(pairing, "pairing") }?.parse::<Pairing>().map_err(input)?) };
        p.base.set_contact_pairing(contact, pairing).map_err(|e| (PC_ERROR_ARGUMENT, solver_error(e).1))
    })
}

/// The pairing contact `i` will be solved with ("same" or "forward", static storage); NULL for a
/// NULL handle or an index out of range.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_contact_pairing(p: *const PcProblem, i: usize) -> *const c_char {
    catch_unwind(AssertUnwindSafe(|| match const_problem(p) {
        Ok(p) if i < p.base.model().contacts.len() => pairing_name(p.base.pairing_at(i).name()),
        _ => std::ptr::null(),
    }))
    .unwrap_or(std::ptr::null())
}

/// The pairing contact `i` was solved with ("same" or "forward", static storage); NULL for a
/// NULL handle or an index out of range.
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_contact_pairing(r: *const PcResult, i: usize) -> *const c_char {
    catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: NULL or a live handle.
        unsafe { r.as_ref() }.and_then(|r| r.response.contacts.get(i)).map_or(std::ptr::null(), |c| pairing_name(&c.pairing))
    }))
    .unwrap_or(std::ptr::null())
}

/// Copies the gap each force sample of contact `i` is complementary to (`paired_gap`: the gap at
/// the same instant, or the next one for forward pairing) at the k instants.
///
/// # Safety
/// `out` holds `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_contact_paired_gap(r: *const PcResult, i: usize, out: *mut f64, len: usize) -> c_int {
    unsafe { super::contact_series(r, i, out, len, |c| &c.paired_gap) }
}

/// What became of the warm start: `*outcome` receives "cold", "accepted", "repaired" or
/// "rejected" (owned by the result), `*pivots` the pivots of the solve that gave the answer.
/// Either output may be NULL.
///
/// # Safety
/// `r` is NULL or a live result handle; non-NULL outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_warm_start(r: *const PcResult, outcome: *mut *const c_char, pivots: *mut usize) -> c_int {
    guarded(|| {
        let r = unsafe { result(r) }?;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe {
            if let Some(o) = outcome.as_mut() {
                *o = r.warm_start.as_ptr();
            }
            if let Some(n) = pivots.as_mut() {
                *n = r.response.lcp.warm_start.pivots;
            }
        }
        Ok(())
    })
}

/// The LCP methods that ran and the fallbacks taken, one line (`lcp.path` of the JSON), owned
/// by the result; NULL for NULL.
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_lcp_path(r: *const PcResult) -> *const c_char {
    // SAFETY: NULL or a live handle.
    unsafe { r.as_ref() }.map_or(std::ptr::null(), |r| r.path.as_ptr())
}
