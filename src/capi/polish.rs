//! The event-fitted polish through the C API: switching it on, its outcome, its events, and the
//! response at any time (the polished orbit's, exact between the instants, or else the
//! interpolated samples).
use super::{PcProblem, PcResult, arg, guarded, problem, result, to_cstring};
use crate::analysis::interpolant::{Series, locate};
use crate::analysis::polish::{self, PolishedOrbit};
use crate::periodic::{OutputMap, PeriodFft, PeriodicProblem};
use crate::response::Response;
use crate::time::Scheme;
use std::collections::BTreeMap;
use std::ffi::{CString, c_char, c_int};

pub const PC_POLISH_OFF: c_int = 0;
pub const PC_POLISH_POLISHED: c_int = 1;
pub const PC_POLISH_FALLBACK: c_int = 2;

/// What a result keeps for the polish and the response between the instants.
pub(super) struct Refined {
    status: c_int,
    /// The fallback's reason ("" otherwise), owned by the result.
    reason: CString,
    orbit: Option<PolishedOrbit>,
    map: Option<OutputMap>,
    /// Displacement and velocity interpolants of each DOF output with both.
    motion: BTreeMap<usize, (Series, Series)>,
    h: f64,
    omega: f64,
}

impl Refined {
    /// Polishes `r` (solved from `problem`) when `on`, then keeps what the readers need.
    pub(super) fn new(problem: &PeriodicProblem, r: &mut Response, fft: &PeriodFft, on: bool) -> Refined {
        let orbit = if on { polish::apply(problem, r) } else { None };
        let (status, reason) = match &r.polish {
            None => (PC_POLISH_OFF, String::new()),
            Some(s) if s.status == "polished" => (PC_POLISH_POLISHED, String::new()),
            Some(s) => (PC_POLISH_FALLBACK, s.reason.clone()),
        };
        let omega = problem.model().frequency;
        let fourier = (problem.discretization().scheme == Scheme::Fourier).then_some(fft);
        let motion = r
            .displacement
            .iter()
            .filter_map(|(key, x)| {
                let v = r.velocity.get(key)?;
                Some((key.parse().ok()?, (Series::motion(x, v, 0, fourier, omega), Series::motion(x, v, 1, fourier, omega))))
            })
            .collect();
        let h = r.period / r.steps as f64;
        Refined { status, reason: to_cstring(&reason), orbit, map: problem.output_map().cloned(), motion, h, omega }
    }
}

/// Whether each solve is refined by the event-fitted polish (`on` = 1; 0, the default unless the
/// scene says `[discretization] polish = true`).
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_polish(p: *mut PcProblem, on: c_int) -> c_int {
    guarded(|| {
        let p = unsafe { problem(p) }?;
        if on != 0 && on != 1 {
            return Err(arg(format!("on is {on}, must be 0 or 1")));
        }
        p.polish = on == 1;
        Ok(())
    })
}

/// The polish's outcome: `*status` = PC_POLISH_OFF (not asked), PC_POLISH_POLISHED or
/// PC_POLISH_FALLBACK (the samples are the LCP's); `*reason` the fallback's cause ("" otherwise,
/// owned by the result; also among the warnings). Either output may be NULL.
///
/// # Safety
/// `r` is NULL or a live result handle; non-NULL outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_polish(r: *const PcResult, status: *mut c_int, reason: *mut *const c_char) -> c_int {
    guarded(|| {
        let f = &unsafe { result(r) }?.refined;
        // SAFETY: NULL or writable, as the caller promises.
        unsafe {
            if let Some(s) = status.as_mut() {
                *s = f.status;
            }
            if let Some(s) = reason.as_mut() {
                *s = f.reason.as_ptr();
            }
        }
        Ok(())
    })
}

/// The number of events of the polished orbit (0 for NULL or without a polished orbit).
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_event_count(r: *const PcResult) -> usize {
    std::panic::catch_unwind(|| unsafe { r.as_ref() }.and_then(|r| r.response.polish.as_ref()).map_or(0, |p| p.events.len())).unwrap_or(0)
}

/// Event `i` (in time order): `*time` in [0, T), `*contact`, `*kind` ("impact", "release",
/// "contact_on", "contact_off"; static storage) and `*impulse` (> 0 at an impact, else 0).
/// Any output may be NULL.
///
/// # Safety
/// `r` is NULL or a live result handle; non-NULL outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_event(
    r: *const PcResult,
    i: usize,
    time: *mut f64,
    contact: *mut usize,
    kind: *mut *const c_char,
    impulse: *mut f64,
) -> c_int {
    guarded(|| {
        let events = unsafe { result(r) }?.response.polish.as_ref().map_or(&[][..], |p| &p.events[..]);
        let e = events.get(i).ok_or_else(|| arg(format!("event {i} does not exist ({} events)", events.len())))?;
        let name = match e.kind.as_str() {
            "impact" => c"impact",
            "release" => c"release",
            "contact_on" => c"contact_on",
            _ => c"contact_off",
        };
        // SAFETY: NULL or writable, as the caller promises.
        unsafe {
            if let Some(s) = time.as_mut() {
                *s = e.time;
            }
            if let Some(s) = contact.as_mut() {
                *s = e.contact;
            }
            if let Some(s) = kind.as_mut() {
                *s = name.as_ptr();
            }
            if let Some(s) = impulse.as_mut() {
                *s = e.impulse;
            }
        }
        Ok(())
    })
}

/// Writes two values and the exact flag into the caller's outputs, each NULL or writable.
fn write(a: *mut f64, b: *mut f64, exact: *mut c_int, (va, vb, e): (f64, f64, c_int)) {
    // SAFETY: NULL or writable, as the caller promises.
    unsafe {
        if let Some(s) = a.as_mut() {
            *s = va;
        }
        if let Some(s) = b.as_mut() {
            *s = vb;
        }
        if let Some(s) = exact.as_mut() {
            *s = e;
        }
    }
}

fn finite(t: f64) -> Result<(), (c_int, String)> {
    if t.is_finite() { Ok(()) } else { Err(arg(format!("t = {t} is not finite"))) }
}

/// Displacement and velocity of `dof` at any time `t` (periodic). `*exact` = 1: from the
/// polished orbit, exact between the instants (any DOF of the user's numbering); 0: interpolated
/// from the samples (trigonometric for fourier, cubic Hermite through (x_j, v_j) otherwise; the
/// DOF must have both displacement and velocity outputs). Any output may be NULL.
///
/// # Safety
/// `r` is NULL or a live result handle; non-NULL outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_state_at(r: *const PcResult, dof: usize, t: f64, displacement: *mut f64, velocity: *mut f64, exact: *mut c_int) -> c_int {
    guarded(|| {
        let r = unsafe { result(r) }?;
        finite(t)?;
        let f = &r.refined;
        let xve = match &f.orbit {
            Some(o) => {
                let (x, v) = o.user_state(f.map.as_ref(), dof, t).ok_or_else(|| arg(format!("DOF {dof} is not in the model's output map")))?;
                (x, v, 1)
            }
            None => {
                let (xs, vs) = f.motion.get(&dof).ok_or_else(|| arg(format!("DOF {dof} needs both displacement and velocity outputs to be interpolated")))?;
                (xs.at(t, f.h, r.response.steps, f.omega).0, vs.at(t, f.h, r.response.steps, f.omega).0, 0)
            }
        };
        write(displacement, velocity, exact, xve);
        Ok(())
    })
}

/// Contact `i`'s compressive force and clearance at any time `t`. `*exact` = 1: the polished
/// orbit's (a stuck rigid contact's force or a compliant one's stiffness·penetration; a rigid
/// impact is an impulse, see pc_result_event, not a force); 0: the samples interpolated linearly
/// (a rigid contact's samples are impulse per step / h). Any output may be NULL.
///
/// # Safety
/// `r` is NULL or a live result handle; non-NULL outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_contact_at(r: *const PcResult, i: usize, t: f64, force: *mut f64, gap: *mut f64, exact: *mut c_int) -> c_int {
    guarded(|| {
        let r = unsafe { result(r) }?;
        finite(t)?;
        let c = r.response.contacts.get(i).ok_or_else(|| arg(format!("contact {i} does not exist in this result")))?;
        let f = &r.refined;
        let zge = match &f.orbit {
            Some(o) => (o.contact_force(i, t), o.clearance_at(i, t), 1),
            None => {
                let k = r.response.steps;
                let (j, j1, s) = locate(t.rem_euclid(r.response.period), f.h, k);
                let lin = |y: &[f64]| (1.0 - s) * y[j] + s * y[j1];
                (lin(&c.force), lin(&c.gap), 0)
            }
        };
        write(force, gap, exact, zge);
        Ok(())
    })
}
