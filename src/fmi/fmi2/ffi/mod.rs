//! The 34 FMI 2.0 co-simulation entry points as generic functions over raw pointers.
//!
//! Every body runs inside `catch_unwind`: no panic crosses the C boundary. A NULL (or foreign)
//! instance gives `fmi2Error` (`fmi2FreeInstance(NULL)` does nothing); NULL arrays are accepted
//! when their length is 0. [`export_fmi2!`](crate::export_fmi2) turns these into the exported,
//! unmangled symbols of an FMU binary.
//!
//! - here: the pointer helpers, [`call`] (the `catch_unwind` wrapper), the instance life cycle
//!   and the value getters and setters;
//! - [`states`]: the FMU-state functions;
//! - [`status`]: stepping, output derivatives, unsupported functions, status getters.
mod states;
mod status;

pub use states::*;
pub use status::*;

use super::instance::{INSTANCE_MAGIC, Instance};
use super::logger::Logger;
use super::types::*;
use crate::fmi::CoSimModel;
use std::any::Any;
use std::ffi::{CStr, c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};

fn panic_text(p: &(dyn Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".into()
    }
}

/// A borrowed slice from a C array; `None` for NULL with n > 0 or an impossible length.
pub(super) unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        return Some(&[]);
    }
    if p.is_null() || n > isize::MAX as usize / size_of::<T>().max(1) {
        return None;
    }
    // SAFETY: the importer promises n valid elements at p.
    Some(unsafe { std::slice::from_raw_parts(p, n) })
}

pub(super) unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        return Some(&mut []);
    }
    if p.is_null() || n > isize::MAX as usize / size_of::<T>().max(1) {
        return None;
    }
    // SAFETY: the importer promises n writable elements at p.
    Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// A copy of a C string (lossy UTF-8), `None` for NULL.
unsafe fn string(p: Fmi2String) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: a NUL-terminated string from the importer, read during the call only.
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

unsafe fn instance<'a, M: CoSimModel>(c: Fmi2Component) -> Option<&'a mut Instance<M>> {
    let p = c as *mut Instance<M>;
    // SAFETY: non-NULL pointers are ours from fmi2Instantiate; the magic refuses freed or
    // foreign ones in the common cases.
    if p.is_null() || unsafe { (*p).magic } != INSTANCE_MAGIC {
        return None;
    }
    Some(unsafe { &mut *p })
}

/// Runs `f` on the instance `c` with panics caught.
pub(super) unsafe fn call<M: CoSimModel>(c: Fmi2Component, name: &str, f: impl FnOnce(&mut Instance<M>) -> Status) -> Fmi2Status {
    let p = c as *mut Instance<M>;
    // SAFETY: see `instance`.
    if unsafe { instance::<M>(c) }.is_none() {
        return Status::Error.raw();
    }
    match catch_unwind(AssertUnwindSafe(|| f(unsafe { &mut *p }))) {
        Ok(s) => s.raw(),
        Err(e) => {
            let what = panic_text(e.as_ref());
            match catch_unwind(AssertUnwindSafe(|| unsafe { &mut *p }.panicked(name, &what))) {
                Ok(s) => s.raw(),
                Err(_) => Status::Fatal.raw(),
            }
        }
    }
}

pub fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

pub fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

/// # Safety
/// `categories` holds `n` C strings (or is NULL with n = 0).
pub unsafe fn set_debug_logging<M: CoSimModel>(c: Fmi2Component, on: Fmi2Boolean, n: usize, categories: *const Fmi2String) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetDebugLogging", |i| {
            let Some(cats) = slice(categories, n) else { return i.bad_argument("fmi2SetDebugLogging", "categories is NULL with nCategories > 0") };
            let mut names = Vec::with_capacity(n);
            for &p in cats {
                match string(p) {
                    Some(s) => names.push(s),
                    None => return i.bad_argument("fmi2SetDebugLogging", "a category is a NULL pointer"),
                }
            }
            i.set_debug_logging(on != FMI2_FALSE, &names)
        })
    }
}

/// # Safety
/// Pointer arguments as in the FMI 2.0 standard (each may be NULL; NULL is refused with a log).
pub unsafe fn instantiate<M: CoSimModel>(
    name: Fmi2String,
    fmu_type: c_int,
    guid: Fmi2String,
    resources: Fmi2String,
    functions: *const Fmi2CallbackFunctions,
    _visible: Fmi2Boolean,
    logging_on: Fmi2Boolean,
) -> Fmi2Component {
    let r = catch_unwind(AssertUnwindSafe(|| {
        if functions.is_null() {
            return std::ptr::null_mut();
        }
        // SAFETY: a valid callback struct from the importer; copied.
        let cb = unsafe { *functions };
        let name = unsafe { string(name) };
        let logger = Logger::new(cb.logger, cb.component_environment, name.as_deref().unwrap_or(""), logging_on != FMI2_FALSE);
        let guid = unsafe { string(guid) };
        let resources = unsafe { string(resources) };
        match Instance::<M>::new(name.as_deref(), fmu_type, guid.as_deref(), resources.as_deref(), logger) {
            Some(b) => Box::into_raw(b) as Fmi2Component,
            None => std::ptr::null_mut(),
        }
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// # Safety
/// `c` is NULL or an instance from `instantiate`, not used afterwards.
pub unsafe fn free_instance<M: CoSimModel>(c: Fmi2Component) {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        if let Some(i) = unsafe { instance::<M>(c) } {
            i.magic = 0;
            // SAFETY: allocated by Box in `instantiate`.
            drop(unsafe { Box::from_raw(c as *mut Instance<M>) });
        }
    }));
}

/// # Safety
/// `c` as for every function: NULL or a live instance.
pub unsafe fn setup_experiment<M: CoSimModel>(
    c: Fmi2Component,
    tol_defined: Fmi2Boolean,
    tol: f64,
    start: f64,
    stop_defined: Fmi2Boolean,
    stop: f64,
) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetupExperiment", |i| {
            i.setup_experiment((tol_defined != FMI2_FALSE).then_some(tol), start, (stop_defined != FMI2_FALSE).then_some(stop))
        })
    }
}

/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn enter_initialization_mode<M: CoSimModel>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2EnterInitializationMode", |i| i.enter_initialization_mode()) }
}
/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn exit_initialization_mode<M: CoSimModel>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2ExitInitializationMode", |i| i.exit_initialization_mode()) }
}
/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn terminate<M: CoSimModel>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2Terminate", |i| i.terminate()) }
}
/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn reset<M: CoSimModel>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2Reset", |i| i.reset()) }
}

macro_rules! getter {
    ($fn:ident, $method:ident, $t:ty, $name:literal) => {
        /// # Safety
        /// `vr` and `value` hold `nvr` elements (or are NULL with nvr = 0).
        pub unsafe fn $fn<M: CoSimModel>(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *mut $t) -> Fmi2Status {
            unsafe {
                call::<M>(c, $name, |i| {
                    let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
                        return i.bad_argument($name, "vr or value is NULL with nvr > 0");
                    };
                    i.$method(vrs, out)
                })
            }
        }
    };
}
getter!(get_real, get_real, f64, "fmi2GetReal");
getter!(get_integer, get_integer, Fmi2Integer, "fmi2GetInteger");
getter!(get_boolean, get_boolean, Fmi2Boolean, "fmi2GetBoolean");
getter!(get_string, get_string, Fmi2String, "fmi2GetString");

macro_rules! setter {
    ($fn:ident, $method:ident, $t:ty, $name:literal) => {
        /// # Safety
        /// `vr` and `value` hold `nvr` elements (or are NULL with nvr = 0).
        pub unsafe fn $fn<M: CoSimModel>(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const $t) -> Fmi2Status {
            unsafe {
                call::<M>(c, $name, |i| {
                    let (Some(vrs), Some(values)) = (slice(vr, nvr), slice(value, nvr)) else {
                        return i.bad_argument($name, "vr or value is NULL with nvr > 0");
                    };
                    i.$method(vrs, values)
                })
            }
        }
    };
}
setter!(set_real, set_real, f64, "fmi2SetReal");
setter!(set_integer, set_integer, Fmi2Integer, "fmi2SetInteger");
setter!(set_boolean, set_boolean, Fmi2Boolean, "fmi2SetBoolean");

/// # Safety
/// `vr` and `value` hold `nvr` elements (or are NULL with nvr = 0).
pub unsafe fn set_string<M: CoSimModel>(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const Fmi2String) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetString", |i| {
            let (Some(vrs), Some(values)) = (slice(vr, nvr), slice(value, nvr)) else {
                return i.bad_argument("fmi2SetString", "vr or value is NULL with nvr > 0");
            };
            let copies: Vec<Option<String>> = values.iter().map(|&p| string(p)).collect();
            i.set_string(vrs, &copies)
        })
    }
}
