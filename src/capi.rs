//! The native C API (`include/periodic_contact.h`): opaque handles with explicit free
//! functions, status codes, and the last error of the calling thread as a string.
//!
//! - `pc_problem`: a scene (from a file, from TOML text, or from matrices plus forces and
//!   contacts), the tunable values (frequency, force/motion scale, gap offset), the FFT plan and
//!   the last active set, so that a re-solve after a small change is warm-started.
//! - `pc_result`: one solved periodic response; its time series are copied into caller buffers.
//!
//! No panic crosses the boundary: every function runs inside `catch_unwind` and reports
//! `PC_ERROR_INTERNAL`. Distinct problems may be used from distinct threads; const readers of
//! one result may run concurrently (the JSON is cached in a `OnceLock`); a problem must not be
//! mutated while another thread solves it. Readers of contacts, pairing, warm start and
//! solver path: `inspect`.
use crate::analysis::accuracy::{self, neighbour::ESTIMATE_BUDGET_CPU_S as BUDGET};
use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};
use crate::periodic::Tuning;
use crate::periodic::{OutputSelection, PeriodicProblem, PeriodicSolver, SolveError, SolverSettings};
use crate::response::{Accuracy, Response};
use crate::scene::Scene;
use crate::time::{Discretization, Pairing, Scheme};
mod branch;
pub use branch::{pc_problem_set_stability, pc_result_jump, pc_result_stability};
pub mod estimate;
mod friction;
pub use friction::*;
mod inspect;
mod polish;

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

pub const PC_OK: c_int = 0;
/// A NULL pointer, an index out of range, a buffer too small, a value out of its domain.
pub const PC_ERROR_ARGUMENT: c_int = 1;
/// The scene or model is invalid (the message names the field and the value).
pub const PC_ERROR_INPUT: c_int = 2;
/// The solve failed (singular operator, LCP outcome other than solved, non-finite response).
pub const PC_ERROR_SOLVER: c_int = 3;
/// An internal error (a caught panic).
pub const PC_ERROR_INTERNAL: c_int = 4;

thread_local! {
    /// The message of the last failed call on this thread (the C API only; the FMU has no such state).
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_error(code: c_int, message: &str) -> c_int {
    let c = to_cstring(message);
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
    code
}

fn clear_error() {
    LAST_ERROR.with(|e| *e.borrow_mut() = CString::default());
}

fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_else(|| "panic".into())
}

/// Runs `f` with panics caught; the error (if any) is recorded for `pc_last_error`.
fn guarded(f: impl FnOnce() -> Result<(), (c_int, String)>) -> c_int {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            clear_error();
            PC_OK
        }
        Ok(Err((code, m))) => set_error(code, &m),
        Err(p) => set_error(PC_ERROR_INTERNAL, &format!("internal error (caught panic: {})", panic_message(p))),
    }
}

/// Like [`guarded`] for functions that return a pointer (NULL on failure).
fn guarded_ptr<T>(f: impl FnOnce() -> Result<Box<T>, (c_int, String)>) -> *mut T {
    let mut out = std::ptr::null_mut();
    guarded(|| {
        out = Box::into_raw(f()?);
        Ok(())
    });
    out
}

fn arg(m: impl Into<String>) -> (c_int, String) {
    (PC_ERROR_ARGUMENT, m.into())
}
fn input(e: impl ToString) -> (c_int, String) {
    (PC_ERROR_INPUT, e.to_string())
}
fn solver_error(e: SolveError) -> (c_int, String) {
    let status = if e.kind() == crate::ErrorKind::Solve { PC_ERROR_SOLVER } else { PC_ERROR_INPUT };
    (status, e.to_string())
}

unsafe fn c_str<'a>(p: *const c_char, what: &str) -> Result<&'a str, (c_int, String)> {
    if p.is_null() {
        return Err(arg(format!("{what} is NULL")));
    }
    // SAFETY: a NUL-terminated string from the caller.
    unsafe { CStr::from_ptr(p) }.to_str().map_err(|_| arg(format!("{what} is not UTF-8")))
}

unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], (c_int, String)> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() || n > isize::MAX as usize / size_of::<T>().max(1) {
        return Err(arg(format!("{what} is NULL or too long")));
    }
    // SAFETY: the caller promises n elements.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// An opaque problem handle.
pub struct PcProblem {
    base: PeriodicProblem,
    tuning: Tuning,
    /// Estimate the error of every result (`[discretization] error_estimate`, default true).
    estimate: bool,
    /// CPU seconds for the estimate's neighbour solves (`pc_problem_set_error_estimate_budget`).
    budget: f64,
    /// Refine every result by the event-fitted polish (`[discretization] polish`, default false).
    polish: bool,
    /// Built at the first solve.
    session: Option<PeriodicSolver>,
    /// The stability and the branch followed (`branch`).
    branch: branch::BranchState,
}

/// An opaque result handle.
pub struct PcResult {
    response: Response,
    warnings: Vec<CString>,
    /// `lcp.warm_start.outcome` and `lcp.path`, as C strings owned by the result.
    warm_start: CString,
    path: CString,
    /// `accuracy.method`, owned by the result.
    accuracy_method: CString,
    /// The polish's outcome and the response between the instants (`polish.rs`).
    refined: polish::Refined,
    /// The JSON, made on first request; a `OnceLock` so that const readers may run concurrently.
    json: std::sync::OnceLock<CString>,
    /// Its stability and jump (`branch`).
    branch: branch::BranchResult,
}

impl PcProblem {
    fn new(base: PeriodicProblem) -> Box<Self> {
        Box::new(PcProblem { tuning: Tuning::of(&base), base, estimate: true, budget: BUDGET, polish: false, session: None, branch: Default::default() })
    }
    /// Rebuilds the base problem after an edit, keeping the old one if the edit is invalid.
    fn edit(&mut self, f: impl FnOnce(&mut Model, &mut OutputSelection)) -> Result<(), (c_int, String)> {
        let mut model = self.base.model().clone();
        let mut outputs = self.base.outputs().clone();
        f(&mut model, &mut outputs);
        let mut edited = self.base.with_model(model, self.base.discretization()).map_err(solver_error)?;
        edited.set_outputs(outputs).map_err(solver_error)?;
        self.base = edited;
        Ok(())
    }
}

unsafe fn problem<'a>(p: *mut PcProblem) -> Result<&'a mut PcProblem, (c_int, String)> {
    // SAFETY: NULL or a handle from a pc_problem_* constructor.
    unsafe { p.as_mut() }.ok_or_else(|| arg("the problem handle is NULL"))
}

unsafe fn result<'a>(r: *const PcResult) -> Result<&'a PcResult, (c_int, String)> {
    // SAFETY: NULL or a handle from pc_problem_solve.
    unsafe { r.as_ref() }.ok_or_else(|| arg("the result handle is NULL"))
}

/// The library version, e.g. "0.1.0" (static storage).
#[unsafe(no_mangle)]
pub extern "C" fn pc_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr() as *const c_char
}

/// The message of the last failed call on this thread ("" after a success). Valid until the
/// next call on this thread.
#[unsafe(no_mangle)]
pub extern "C" fn pc_last_error() -> *const c_char {
    catch_unwind(|| LAST_ERROR.with(|e| e.borrow().as_ptr())).unwrap_or(c"internal error".as_ptr())
}

fn from_scene(scene: &Scene, file: &str) -> Result<Box<PcProblem>, (c_int, String)> {
    let built = scene.build(file).map_err(input)?;
    let mut p = PcProblem::new(built.problem);
    (p.estimate, p.polish) = (built.error_estimate, built.polish);
    p.branch.stability = built.stability;
    Ok(p)
}

/// Loads a scene file (TOML). NULL on failure (see `pc_last_error`).
///
/// # Safety
/// `path` is a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_from_scene_file(path: *const c_char) -> *mut PcProblem {
    guarded_ptr(|| {
        let path = unsafe { c_str(path, "path") }?;
        let (scene, _) = Scene::load(Path::new(path)).map_err(input)?;
        from_scene(&scene, path)
    })
}

/// Parses scene text (TOML). NULL on failure.
///
/// # Safety
/// `toml` is a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_from_scene_text(toml: *const c_char) -> *mut PcProblem {
    guarded_ptr(|| from_scene(&Scene::parse(unsafe { c_str(toml, "toml") }?, "scene text").map_err(input)?, "scene text"))
}

/// A structure from n×n row-major matrices (damping may be NULL), without forces or contacts;
/// `scheme` is "bds1", "bds2", "cds", "galerkin" or "fourier"; `steps` instants per period.
/// Outputs: displacement and velocity of every DOF, and every contact. NULL on failure.
///
/// # Safety
/// `mass` and `stiffness` (and `damping` unless NULL) hold n·n doubles; `scheme` is a string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_from_matrices(
    n: usize,
    mass: *const f64,
    stiffness: *const f64,
    damping: *const f64,
    frequency: f64,
    scheme: *const c_char,
    steps: usize,
) -> *mut PcProblem {
    guarded_ptr(|| {
        if n == 0 {
            return Err(arg("n is 0"));
        }
        let nn = n.checked_mul(n).ok_or_else(|| arg("n is too large"))?;
        let rows = |p: *const f64, what: &str| -> Result<Matrix, (c_int, String)> {
            let v = unsafe { slice(p, nn, what) }?;
            Ok(Matrix::from_rows(&v.chunks(n).map(<[f64]>::to_vec).collect::<Vec<_>>()))
        };
        let mass = rows(mass, "mass")?;
        let stiffness = rows(stiffness, "stiffness")?;
        let damping = if damping.is_null() { None } else { Some(rows(damping, "damping")?) };
        let scheme: Scheme = unsafe { c_str(scheme, "scheme") }?.parse().map_err(input)?;
        let (forces, contacts, frictions, rubbing) = (vec![], vec![], vec![], vec![]);
        let model = Model { structure: Structure { mass, stiffness, damping }, forces, contacts, frequency, frictions, rubbing };
        let outputs = OutputSelection { displacement: (0..n).collect(), velocity: (0..n).collect(), acceleration: vec![], contacts: true };
        let disc = Discretization { scheme, steps, pairing: None };
        Ok(PcProblem::new(PeriodicProblem::new(model, disc, outputs, SolverSettings::default()).map_err(solver_error)?))
    })
}

/// Adds f[dof] += amplitude·cos(harmonic·ω·t + phase).
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_add_force(p: *mut PcProblem, dof: usize, amplitude: f64, harmonic: u32, phase: f64) -> c_int {
    guarded(|| unsafe { problem(p) }?.edit(|m, _| m.forces.push(Force { dof, term: Harmonic { amplitude, harmonic, phase } })))
}

/// Adds a unilateral contact on `dof`: direction +1 keeps x[dof] ≤ gap, −1 keeps x[dof] ≥ −gap;
/// `stiffness` > 0 makes it compliant, 0 rigid. Returns the contact's index in `*index` (may be NULL).
///
/// # Safety
/// `p` is NULL or a live problem handle; `index` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_add_contact(p: *mut PcProblem, dof: usize, direction: c_int, gap: f64, stiffness: f64, index: *mut usize) -> c_int {
    guarded(|| {
        if direction != 1 && direction != -1 {
            return Err(arg(format!("direction is {direction}, must be +1 or -1")));
        }
        if stiffness.is_nan() || stiffness < 0.0 {
            return Err(arg(format!("stiffness is {stiffness}, must be > 0 (compliant) or 0 (rigid)")));
        }
        let p = unsafe { problem(p) }?;
        let compliance = if stiffness > 0.0 { Compliance::Compliant { stiffness } } else { Compliance::Rigid };
        p.edit(|m, _| m.contacts.push(Contact::on_dof(dof, direction as f64, gap, compliance)))?;
        if let Some(i) = unsafe { index.as_mut() } {
            *i = p.base.model().contacts.len() - 1;
        }
        Ok(())
    })
}

/// Moves the obstacle of contact `contact`: gap(t) += amplitude·cos(harmonic·ω·t + phase).
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_add_contact_motion(p: *mut PcProblem, contact: usize, amplitude: f64, harmonic: u32, phase: f64) -> c_int {
    guarded(|| {
        let p = unsafe { problem(p) }?;
        let m = p.base.model().contacts.len();
        if contact >= m {
            return Err(arg(format!("contact {contact} does not exist ({m} contacts)")));
        }
        p.edit(|model, _| model.contacts[contact].motion.push(Harmonic { amplitude, harmonic, phase }))
    })
}

/// Chooses the recovered outputs (DOF lists; any pointer may be NULL with its count 0) and
/// whether contact forces and gaps are recovered.
///
/// # Safety
/// Each array holds its count of elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_outputs(
    p: *mut PcProblem,
    displacement: *const usize,
    n_displacement: usize,
    velocity: *const usize,
    n_velocity: usize,
    acceleration: *const usize,
    n_acceleration: usize,
    contacts: c_int,
) -> c_int {
    guarded(|| {
        let d = unsafe { slice(displacement, n_displacement, "displacement") }?.to_vec();
        let v = unsafe { slice(velocity, n_velocity, "velocity") }?.to_vec();
        let a = unsafe { slice(acceleration, n_acceleration, "acceleration") }?.to_vec();
        unsafe { problem(p) }?.edit(|_, o| *o = OutputSelection { displacement: d, velocity: v, acceleration: a, contacts: contacts != 0 })
    })
}

/// Sets the pairing of every contact: "same", "forward", or NULL for the per-contact default.
///
/// # Safety
/// `p` is NULL or a live problem handle; `pairing` is NULL or a string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_pairing(p: *mut PcProblem, pairing: *const c_char) -> c_int {
    guarded(|| {
        let p = unsafe { problem(p) }?;
        p.base.set_pairing(if pairing.is_null() { None } else { Some(unsafe { c_str(pairing, "pairing") }?.parse::<Pairing>().map_err(input)?) });
        Ok(())
    })
}

/// Whether the harmonics are factorised on rayon's global thread pool (1, the default) or
/// on the calling thread only (0).
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_set_parallel(p: *mut PcProblem, parallel: c_int) -> c_int {
    guarded(|| {
        unsafe { problem(p) }?.base.set_parallel(parallel != 0);
        Ok(())
    })
}

macro_rules! tuning_setter {
    ($name:ident, $field:ident, $check:expr, $what:literal) => {
        #[doc = concat!("Sets ", $what, " for the next solve.")]
        ///
        /// # Safety
        /// `p` is NULL or a live problem handle.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(p: *mut PcProblem, value: f64) -> c_int {
            guarded(|| {
                let check: fn(f64) -> bool = $check;
                if !check(value) {
                    return Err(arg(format!(concat!($what, " = {} is out of range"), value)));
                }
                unsafe { problem(p) }?.tuning.$field = value;
                Ok(())
            })
        }
    };
}
tuning_setter!(pc_problem_set_frequency, frequency, |v| v.is_finite() && v > 0.0, "the fundamental angular frequency ω [rad/s] (> 0)");
tuning_setter!(pc_problem_set_force_scale, force_scale, f64::is_finite, "the factor on every force amplitude");
tuning_setter!(pc_problem_set_gap_offset, gap_offset, f64::is_finite, "the offset added to every static clearance");
tuning_setter!(pc_problem_set_motion_scale, motion_scale, f64::is_finite, "the factor on every obstacle-motion amplitude");

/// The current frequency ω [rad/s] (NaN for a NULL handle).
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_frequency(p: *const PcProblem) -> f64 {
    catch_unwind(AssertUnwindSafe(|| unsafe { p.as_ref() }.map_or(f64::NAN, |p| p.tuning.frequency))).unwrap_or(f64::NAN)
}

/// Solves with the current values, continuing this problem's previous orbit along its branch
/// (same number of instants; a jump when the branch ended at a fold: `pc_result_jump`). NULL on
/// failure.
///
/// # Safety
/// `p` is NULL or a live problem handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_solve(p: *mut PcProblem) -> *mut PcResult {
    guarded_ptr(|| {
        let p = unsafe { problem(p) }?;
        // The session keeps the plan, the active set and the assembly across solves of the same
        // grid; `branch::solve` continues the last orbit along its branch.
        let (mut response, branch) = branch::solve(p)?;
        let session = p.session.as_ref().expect("made by branch::solve");
        response.accuracy = if p.estimate {
            accuracy::estimate_within(session.problem(), &response, p.budget)
        } else {
            Accuracy { method: "none: not requested (pc_problem_set_error_estimate)".into(), ..Accuracy::default() }
        };
        let refined = polish::Refined::new(session.problem(), &mut response, session.fft(), p.polish);
        let accuracy_method = to_cstring(&response.accuracy.method);
        let warnings = response.warnings.iter().map(|w| to_cstring(w)).collect();
        let (warm_start, path) = (to_cstring(&response.lcp.warm_start.outcome), to_cstring(&response.lcp.path));
        Ok(Box::new(PcResult { response, warnings, warm_start, path, accuracy_method, refined, json: std::sync::OnceLock::new(), branch }))
    })
}

/// Frees a problem (NULL is ignored).
///
/// # Safety
/// `p` is NULL or a live problem handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_problem_free(p: *mut PcProblem) {
    if !p.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(p) })));
    }
}

/// Frees a result (NULL is ignored).
///
/// # Safety
/// `r` is NULL or a live result handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_free(r: *mut PcResult) {
    if !r.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(r) })));
    }
}

/// Number of instants k (0 for NULL).
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_steps(r: *const PcResult) -> usize {
    unsafe { r.as_ref() }.map_or(0, |r| r.response.steps)
}

/// The period T = 2π/ω [s] (NaN for NULL).
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_period(r: *const PcResult) -> f64 {
    unsafe { r.as_ref() }.map_or(f64::NAN, |r| r.response.period)
}

fn copy_out(series: &[f64], out: *mut f64, len: usize) -> Result<(), (c_int, String)> {
    if out.is_null() || len < series.len() {
        return Err(arg(format!("the output buffer is NULL or shorter ({len}) than the {} instants", series.len())));
    }
    // SAFETY: the caller promises len ≥ k writable doubles.
    unsafe { std::ptr::copy_nonoverlapping(series.as_ptr(), out, series.len()) };
    Ok(())
}

/// Copies the k instants t_j = j·T/k into `out` (len ≥ k).
///
/// # Safety
/// `out` holds `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_time(r: *const PcResult, out: *mut f64, len: usize) -> c_int {
    guarded(|| copy_out(&unsafe { result(r) }?.response.time, out, len))
}

macro_rules! dof_series {
    ($name:ident, $field:ident, $what:literal) => {
        #[doc = concat!("Copies the ", $what, " of `dof` at the k instants into `out` (len ≥ k); the DOF must be in the outputs.")]
        ///
        /// # Safety
        /// `out` holds `len` writable doubles.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(r: *const PcResult, dof: usize, out: *mut f64, len: usize) -> c_int {
            guarded(|| {
                let r = unsafe { result(r) }?;
                let s =
                    r.response.$field.get(&dof.to_string()).ok_or_else(|| arg(format!(concat!("no ", $what, " for DOF {} in this result's outputs"), dof)))?;
                copy_out(s, out, len)
            })
        }
    };
}
dof_series!(pc_result_displacement, displacement, "displacement");
dof_series!(pc_result_velocity, velocity, "velocity");
dof_series!(pc_result_acceleration, acceleration, "acceleration");

/// Number of contacts in the result (0 for NULL or when contacts are not output).
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_contact_count(r: *const PcResult) -> usize {
    unsafe { r.as_ref() }.map_or(0, |r| r.response.contacts.len())
}

/// Copies the series `pick` of contact `i` of result `r` into `out` (len ≥ k).
///
/// # Safety
/// `r` is NULL or a live result handle; `out` holds `len` writable doubles.
unsafe fn contact_series(r: *const PcResult, i: usize, out: *mut f64, len: usize, pick: fn(&crate::response::ContactResponse) -> &[f64]) -> c_int {
    guarded(|| {
        let r = unsafe { result(r) }?;
        let c = r.response.contacts.get(i).ok_or_else(|| arg(format!("contact {i} does not exist in this result")))?;
        copy_out(pick(c), out, len)
    })
}

/// Copies the compressive force (≥ 0) of contact `i` at the k instants.
///
/// # Safety
/// `out` holds `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_contact_force(r: *const PcResult, i: usize, out: *mut f64, len: usize) -> c_int {
    unsafe { contact_series(r, i, out, len, |c| &c.force) }
}

/// Copies the clearance (≥ 0) of contact `i` at the k instants.
///
/// # Safety
/// `out` holds `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_contact_gap(r: *const PcResult, i: usize, out: *mut f64, len: usize) -> c_int {
    unsafe { contact_series(r, i, out, len, |c| &c.gap) }
}

/// LCP diagnostics: size k·m (0 without contact), pivots, residual ‖min(z, Az+q)‖∞, and whether
/// the warm start was accepted. Any output pointer may be NULL.
///
/// # Safety
/// Non-NULL pointers are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_lcp(r: *const PcResult, size: *mut usize, pivots: *mut usize, residual: *mut f64, warm_start_used: *mut c_int) -> c_int {
    guarded(|| {
        let l = &unsafe { result(r) }?.response.lcp;
        unsafe {
            if let Some(s) = size.as_mut() {
                *s = l.size;
            }
            if let Some(s) = pivots.as_mut() {
                *s = l.pivots;
            }
            if let Some(s) = residual.as_mut() {
                *s = l.residual;
            }
            if let Some(s) = warm_start_used.as_mut() {
                *s = c_int::from(l.warm_start_used);
            }
        }
        Ok(())
    })
}

/// Number of warnings (e.g. a scheme/pairing that does not converge for rigid contact).
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_warning_count(r: *const PcResult) -> usize {
    unsafe { r.as_ref() }.map_or(0, |r| r.warnings.len())
}

/// Warning `i`, valid as long as the result (NULL when out of range).
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_warning(r: *const PcResult, i: usize) -> *const c_char {
    unsafe { r.as_ref() }.and_then(|r| r.warnings.get(i)).map_or(std::ptr::null(), |c| c.as_ptr())
}

/// The result as the CLI's JSON (the result contract), valid as long as the result. NULL on failure.
///
/// # Safety
/// `r` is NULL or a live result handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pc_result_json(r: *const PcResult) -> *const c_char {
    let mut out = std::ptr::null();
    guarded(|| {
        // SAFETY: NULL or a live handle.
        let r = unsafe { r.as_ref() }.ok_or_else(|| arg("the result handle is NULL"))?;
        if r.json.get().is_none() {
            let text = serde_json::to_string_pretty(&r.response).map_err(|e| (PC_ERROR_INTERNAL, e.to_string()))?;
            // A concurrent reader may have set it first: both texts are equal, the first stays.
            let _ = r.json.set(to_cstring(&text));
        }
        out = r.json.get().expect("set above").as_ptr();
        Ok(())
    });
    out
}

/// A C string of `s`; an interior NUL (which C cannot hold) is written as the two characters "\\0".
fn to_cstring(s: &str) -> CString {
    CString::new(s.replace('\0', "\\0")).expect("no interior NUL left")
}
