//! The 34 FMI 2.0 co-simulation entry points as generic functions over raw pointers.
//!
//! Every body runs inside `catch_unwind`: no panic crosses the C boundary. A NULL (or foreign)
//! instance gives `fmi2Error` (`fmi2FreeInstance(NULL)` does nothing); NULL arrays are accepted
//! when their length is 0. [`export_fmi2!`](crate::export_fmi2) turns these into the exported,
//! unmangled symbols of an FMU binary.
use super::Fmi2Model;
use super::instance::{FmuState, INSTANCE_MAGIC, Instance, STATE_MAGIC};
use super::logger::Logger;
use super::types::*;
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
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        return Some(&[]);
    }
    if p.is_null() || n > isize::MAX as usize / size_of::<T>().max(1) {
        return None;
    }
    // SAFETY: the importer promises n valid elements at p.
    Some(unsafe { std::slice::from_raw_parts(p, n) })
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
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

unsafe fn instance<'a, M: Fmi2Model>(c: Fmi2Component) -> Option<&'a mut Instance<M>> {
    let p = c as *mut Instance<M>;
    // SAFETY: non-NULL pointers are ours from fmi2Instantiate; the magic refuses freed or
    // foreign ones in the common cases.
    if p.is_null() || unsafe { (*p).magic } != INSTANCE_MAGIC {
        return None;
    }
    Some(unsafe { &mut *p })
}

/// Runs `f` on the instance `c` with panics caught.
unsafe fn call<M: Fmi2Model>(c: Fmi2Component, name: &str, f: impl FnOnce(&mut Instance<M>) -> Status) -> Fmi2Status {
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
pub unsafe fn set_debug_logging<M: Fmi2Model>(c: Fmi2Component, on: Fmi2Boolean, n: usize, categories: *const Fmi2String) -> Fmi2Status {
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
pub unsafe fn instantiate<M: Fmi2Model>(
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
pub unsafe fn free_instance<M: Fmi2Model>(c: Fmi2Component) {
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
pub unsafe fn setup_experiment<M: Fmi2Model>(
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
pub unsafe fn enter_initialization_mode<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2EnterInitializationMode", |i| i.enter_initialization_mode()) }
}
/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn exit_initialization_mode<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2ExitInitializationMode", |i| i.exit_initialization_mode()) }
}
/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn terminate<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2Terminate", |i| i.terminate()) }
}
/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn reset<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2Reset", |i| i.reset()) }
}

macro_rules! getter {
    ($fn:ident, $method:ident, $t:ty, $name:literal) => {
        /// # Safety
        /// `vr` and `value` hold `nvr` elements (or are NULL with nvr = 0).
        pub unsafe fn $fn<M: Fmi2Model>(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *mut $t) -> Fmi2Status {
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
        pub unsafe fn $fn<M: Fmi2Model>(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const $t) -> Fmi2Status {
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
pub unsafe fn set_string<M: Fmi2Model>(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const Fmi2String) -> Fmi2Status {
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

unsafe fn fmu_state<'a, S>(p: Fmi2FmuState) -> Option<&'a mut FmuState<S>> {
    let p = p as *mut FmuState<S>;
    // SAFETY: non-NULL states are ours from fmi2GetFMUstate/fmi2DeSerializeFMUstate.
    if p.is_null() || unsafe { (*p).magic } != STATE_MAGIC {
        return None;
    }
    Some(unsafe { &mut *p })
}

/// # Safety
/// `state` points to an `fmi2FMUstate` (NULL or a state from this FMU).
pub unsafe fn get_fmu_state<M: Fmi2Model>(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetFMUstate", |i| {
            if state.is_null() {
                return i.bad_argument("fmi2GetFMUstate", "FMUstate is NULL");
            }
            let existing = if (*state).is_null() {
                None
            } else {
                match fmu_state::<M::Snapshot>(*state) {
                    Some(s) => Some(s),
                    None => return i.bad_argument("fmi2GetFMUstate", "*FMUstate is not a state of this FMU"),
                }
            };
            match i.get_fmu_state(existing) {
                Ok(Some(b)) => {
                    *state = Box::into_raw(b) as Fmi2FmuState;
                    Status::Ok
                }
                Ok(None) => Status::Ok,
                Err(s) => s,
            }
        })
    }
}

/// # Safety
/// `state`: a state from this FMU.
pub unsafe fn set_fmu_state<M: Fmi2Model>(c: Fmi2Component, state: Fmi2FmuState) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetFMUstate", |i| match fmu_state::<M::Snapshot>(state) {
            Some(s) => i.set_fmu_state(s),
            None => i.bad_argument("fmi2SetFMUstate", "FMUstate is NULL or not a state of this FMU"),
        })
    }
}

/// # Safety
/// `state` points to an `fmi2FMUstate`; it is set to NULL.
pub unsafe fn free_fmu_state<M: Fmi2Model>(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2FreeFMUstate", |i| {
            let s = i.check_state_fn("fmi2FreeFMUstate");
            if s != Status::Ok {
                return s;
            }
            if state.is_null() || (*state).is_null() {
                return Status::Ok;
            }
            match fmu_state::<M::Snapshot>(*state) {
                Some(s) => {
                    s.magic = 0;
                    drop(Box::from_raw(*state as *mut FmuState<M::Snapshot>));
                    *state = std::ptr::null_mut();
                    Status::Ok
                }
                None => i.bad_argument("fmi2FreeFMUstate", "*FMUstate is not a state of this FMU"),
            }
        })
    }
}

/// # Safety
/// `state`: a state from this FMU; `size` writable.
pub unsafe fn serialized_fmu_state_size<M: Fmi2Model>(c: Fmi2Component, state: Fmi2FmuState, size: *mut usize) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SerializedFMUstateSize", |i| {
            let s = i.check_state_fn("fmi2SerializedFMUstateSize");
            if s != Status::Ok {
                return s;
            }
            let Some(st) = fmu_state::<M::Snapshot>(state) else {
                return i.bad_argument("fmi2SerializedFMUstateSize", "FMUstate is NULL or not a state of this FMU");
            };
            if size.is_null() {
                return i.bad_argument("fmi2SerializedFMUstateSize", "size is NULL");
            }
            *size = i.serialize_fmu_state(st).len();
            Status::Ok
        })
    }
}

/// # Safety
/// `state`: a state from this FMU; `bytes` holds `size` writable bytes.
pub unsafe fn serialize_fmu_state<M: Fmi2Model>(c: Fmi2Component, state: Fmi2FmuState, bytes: *mut Fmi2Byte, size: usize) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SerializeFMUstate", |i| {
            let s = i.check_state_fn("fmi2SerializeFMUstate");
            if s != Status::Ok {
                return s;
            }
            let Some(st) = fmu_state::<M::Snapshot>(state) else {
                return i.bad_argument("fmi2SerializeFMUstate", "FMUstate is NULL or not a state of this FMU");
            };
            let data = i.serialize_fmu_state(st);
            if size < data.len() {
                return i.bad_argument("fmi2SerializeFMUstate", &format!("the buffer has {size} bytes, the state needs {}", data.len()));
            }
            let Some(out) = slice_mut(bytes as *mut u8, data.len()) else {
                return i.bad_argument("fmi2SerializeFMUstate", "serializedState is NULL");
            };
            out.copy_from_slice(&data);
            Status::Ok
        })
    }
}

/// # Safety
/// `bytes` holds `size` bytes; `state` is writable.
pub unsafe fn deserialize_fmu_state<M: Fmi2Model>(c: Fmi2Component, bytes: *const Fmi2Byte, size: usize, state: *mut Fmi2FmuState) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2DeSerializeFMUstate", |i| {
            let Some(data) = slice(bytes as *const u8, size) else {
                return i.bad_argument("fmi2DeSerializeFMUstate", "serializedState is NULL with size > 0");
            };
            if state.is_null() {
                return i.bad_argument("fmi2DeSerializeFMUstate", "FMUstate is NULL");
            }
            match i.deserialize_fmu_state(data) {
                Ok(b) => {
                    *state = Box::into_raw(b) as Fmi2FmuState;
                    Status::Ok
                }
                Err(s) => s,
            }
        })
    }
}

/// # Safety
/// `c`: NULL or a live instance (the arrays are not read: the function is not provided).
pub unsafe fn get_directional_derivative<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2GetDirectionalDerivative", |i| i.get_directional_derivative()) }
}

/// # Safety
/// `c`: NULL or a live instance (the arrays are not read: the function is not provided).
pub unsafe fn set_real_input_derivatives<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2SetRealInputDerivatives", |i| i.set_real_input_derivatives()) }
}

/// # Safety
/// `vr`, `order` and `value` hold `nvr` elements (or are NULL with nvr = 0).
pub unsafe fn get_real_output_derivatives<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    order: *const Fmi2Integer,
    value: *mut f64,
) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetRealOutputDerivatives", |i| {
            let (Some(vrs), Some(orders), Some(out)) = (slice(vr, nvr), slice(order, nvr), slice_mut(value, nvr)) else {
                return i.bad_argument("fmi2GetRealOutputDerivatives", "vr, order or value is NULL with nvr > 0");
            };
            i.get_real_output_derivatives(vrs, orders, out)
        })
    }
}

/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn do_step<M: Fmi2Model>(c: Fmi2Component, t: f64, h: f64, _no_set_prior: Fmi2Boolean) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2DoStep", |i| i.do_step(t, h)) }
}

/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn cancel_step<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2CancelStep", |i| i.cancel_step()) }
}

/// # Safety
/// `value` is writable (not written: no status of this kind is available).
pub unsafe fn get_status<M: Fmi2Model>(c: Fmi2Component, kind: c_int, value: *mut Fmi2Status) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetStatus", |i| {
            if value.is_null() {
                return i.bad_argument("fmi2GetStatus", "value is NULL");
            }
            i.get_status(kind)
        })
    }
}

/// # Safety
/// `value` is writable.
pub unsafe fn get_real_status<M: Fmi2Model>(c: Fmi2Component, kind: c_int, value: *mut f64) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetRealStatus", |i| {
            if value.is_null() {
                return i.bad_argument("fmi2GetRealStatus", "value is NULL");
            }
            i.get_real_status(kind, &mut *value)
        })
    }
}

/// # Safety
/// `value` is writable (not written: no Integer status exists).
pub unsafe fn get_integer_status<M: Fmi2Model>(c: Fmi2Component, kind: c_int, value: *mut Fmi2Integer) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetIntegerStatus", |i| {
            if value.is_null() {
                return i.bad_argument("fmi2GetIntegerStatus", "value is NULL");
            }
            i.get_integer_status(kind)
        })
    }
}

/// # Safety
/// `value` is writable.
pub unsafe fn get_boolean_status<M: Fmi2Model>(c: Fmi2Component, kind: c_int, value: *mut Fmi2Boolean) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetBooleanStatus", |i| {
            if value.is_null() {
                return i.bad_argument("fmi2GetBooleanStatus", "value is NULL");
            }
            i.get_boolean_status(kind, &mut *value)
        })
    }
}

/// # Safety
/// `value` is writable (not written: no String status is available).
pub unsafe fn get_string_status<M: Fmi2Model>(c: Fmi2Component, kind: c_int, value: *mut Fmi2String) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetStringStatus", |i| {
            if value.is_null() {
                return i.bad_argument("fmi2GetStringStatus", "value is NULL");
            }
            i.get_string_status(kind)
        })
    }
}

/// Exports the 34 FMI 2.0 co-simulation functions for the model type `$model`, as
/// `#[unsafe(no_mangle)] extern "C"` symbols of the crate that invokes it (the FMU cdylib).
#[macro_export]
macro_rules! export_fmi2 {
    ($model:ty) => {
        use ::std::ffi::{c_char, c_int};
        use $crate::fmi2::ffi as __ffi;
        use $crate::fmi2::types::*;

        #[unsafe(no_mangle)]
        pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
            __ffi::get_types_platform()
        }
        #[unsafe(no_mangle)]
        pub extern "C" fn fmi2GetVersion() -> *const c_char {
            __ffi::get_version()
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetDebugLogging(c: Fmi2Component, on: Fmi2Boolean, n: usize, categories: *const Fmi2String) -> Fmi2Status {
            unsafe { __ffi::set_debug_logging::<$model>(c, on, n, categories) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2Instantiate(
            name: Fmi2String,
            fmu_type: c_int,
            guid: Fmi2String,
            resources: Fmi2String,
            functions: *const Fmi2CallbackFunctions,
            visible: Fmi2Boolean,
            logging_on: Fmi2Boolean,
        ) -> Fmi2Component {
            unsafe { __ffi::instantiate::<$model>(name, fmu_type, guid, resources, functions, visible, logging_on) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2FreeInstance(c: Fmi2Component) {
            unsafe { __ffi::free_instance::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetupExperiment(
            c: Fmi2Component,
            tol_defined: Fmi2Boolean,
            tol: f64,
            start: f64,
            stop_defined: Fmi2Boolean,
            stop: f64,
        ) -> Fmi2Status {
            unsafe { __ffi::setup_experiment::<$model>(c, tol_defined, tol, start, stop_defined, stop) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Fmi2Component) -> Fmi2Status {
            unsafe { __ffi::enter_initialization_mode::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Fmi2Component) -> Fmi2Status {
            unsafe { __ffi::exit_initialization_mode::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2Terminate(c: Fmi2Component) -> Fmi2Status {
            unsafe { __ffi::terminate::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2Reset(c: Fmi2Component) -> Fmi2Status {
            unsafe { __ffi::reset::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetReal(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *mut Fmi2Real) -> Fmi2Status {
            unsafe { __ffi::get_real::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetInteger(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *mut Fmi2Integer) -> Fmi2Status {
            unsafe { __ffi::get_integer::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetBoolean(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *mut Fmi2Boolean) -> Fmi2Status {
            unsafe { __ffi::get_boolean::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetString(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *mut Fmi2String) -> Fmi2Status {
            unsafe { __ffi::get_string::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetReal(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const Fmi2Real) -> Fmi2Status {
            unsafe { __ffi::set_real::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetInteger(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const Fmi2Integer) -> Fmi2Status {
            unsafe { __ffi::set_integer::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetBoolean(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const Fmi2Boolean) -> Fmi2Status {
            unsafe { __ffi::set_boolean::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetString(c: Fmi2Component, vr: *const Fmi2ValueReference, nvr: usize, value: *const Fmi2String) -> Fmi2Status {
            unsafe { __ffi::set_string::<$model>(c, vr, nvr, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetFMUstate(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
            unsafe { __ffi::get_fmu_state::<$model>(c, state) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetFMUstate(c: Fmi2Component, state: Fmi2FmuState) -> Fmi2Status {
            unsafe { __ffi::set_fmu_state::<$model>(c, state) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2FreeFMUstate(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
            unsafe { __ffi::free_fmu_state::<$model>(c, state) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SerializedFMUstateSize(c: Fmi2Component, state: Fmi2FmuState, size: *mut usize) -> Fmi2Status {
            unsafe { __ffi::serialized_fmu_state_size::<$model>(c, state, size) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SerializeFMUstate(c: Fmi2Component, state: Fmi2FmuState, bytes: *mut Fmi2Byte, size: usize) -> Fmi2Status {
            unsafe { __ffi::serialize_fmu_state::<$model>(c, state, bytes, size) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2DeSerializeFMUstate(c: Fmi2Component, bytes: *const Fmi2Byte, size: usize, state: *mut Fmi2FmuState) -> Fmi2Status {
            unsafe { __ffi::deserialize_fmu_state::<$model>(c, bytes, size, state) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
            c: Fmi2Component,
            _unknown: *const Fmi2ValueReference,
            _n_unknown: usize,
            _known: *const Fmi2ValueReference,
            _n_known: usize,
            _dv_known: *const Fmi2Real,
            _dv_unknown: *mut Fmi2Real,
        ) -> Fmi2Status {
            unsafe { __ffi::get_directional_derivative::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
            c: Fmi2Component,
            _vr: *const Fmi2ValueReference,
            _nvr: usize,
            _order: *const Fmi2Integer,
            _value: *const Fmi2Real,
        ) -> Fmi2Status {
            unsafe { __ffi::set_real_input_derivatives::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
            c: Fmi2Component,
            vr: *const Fmi2ValueReference,
            nvr: usize,
            order: *const Fmi2Integer,
            value: *mut Fmi2Real,
        ) -> Fmi2Status {
            unsafe { __ffi::get_real_output_derivatives::<$model>(c, vr, nvr, order, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2DoStep(c: Fmi2Component, t: Fmi2Real, h: Fmi2Real, no_set_prior: Fmi2Boolean) -> Fmi2Status {
            unsafe { __ffi::do_step::<$model>(c, t, h, no_set_prior) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2CancelStep(c: Fmi2Component) -> Fmi2Status {
            unsafe { __ffi::cancel_step::<$model>(c) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetStatus(c: Fmi2Component, kind: c_int, value: *mut Fmi2Status) -> Fmi2Status {
            unsafe { __ffi::get_status::<$model>(c, kind, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetRealStatus(c: Fmi2Component, kind: c_int, value: *mut Fmi2Real) -> Fmi2Status {
            unsafe { __ffi::get_real_status::<$model>(c, kind, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetIntegerStatus(c: Fmi2Component, kind: c_int, value: *mut Fmi2Integer) -> Fmi2Status {
            unsafe { __ffi::get_integer_status::<$model>(c, kind, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetBooleanStatus(c: Fmi2Component, kind: c_int, value: *mut Fmi2Boolean) -> Fmi2Status {
            unsafe { __ffi::get_boolean_status::<$model>(c, kind, value) }
        }
        /// # Safety
        /// FMI 2.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2GetStringStatus(c: Fmi2Component, kind: c_int, value: *mut Fmi2String) -> Fmi2Status {
            unsafe { __ffi::get_string_status::<$model>(c, kind, value) }
        }
    };
}
