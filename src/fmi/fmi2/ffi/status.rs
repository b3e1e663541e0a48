//! Stepping, output derivatives, the optional functions this FMU does not provide, and the
//! status getters.
use super::{call, slice, slice_mut};
use crate::fmi::CoSimModel;
use crate::fmi::fmi2::types::*;
use std::ffi::c_int;
/// # Safety
/// `c`: NULL or a live instance (the arrays are not read: the function is not provided).
pub unsafe fn get_directional_derivative<M: CoSimModel>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2GetDirectionalDerivative", |i| i.get_directional_derivative()) }
}

/// # Safety
/// `c`: NULL or a live instance (the arrays are not read: the function is not provided).
pub unsafe fn set_real_input_derivatives<M: CoSimModel>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2SetRealInputDerivatives", |i| i.set_real_input_derivatives()) }
}

/// # Safety
/// `vr`, `order` and `value` hold `nvr` elements (or are NULL with nvr = 0).
pub unsafe fn get_real_output_derivatives<M: CoSimModel>(
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
pub unsafe fn do_step<M: CoSimModel>(c: Fmi2Component, t: f64, h: f64, _no_set_prior: Fmi2Boolean) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2DoStep", |i| i.do_step(t, h)) }
}

/// # Safety
/// `c`: NULL or a live instance.
pub unsafe fn cancel_step<M: CoSimModel>(c: Fmi2Component) -> Fmi2Status {
    unsafe { call::<M>(c, "fmi2CancelStep", |i| i.cancel_step()) }
}

/// # Safety
/// `value` is writable (not written: no status of this kind is available).
pub unsafe fn get_status<M: CoSimModel>(c: Fmi2Component, kind: c_int, value: *mut Fmi2Status) -> Fmi2Status {
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
pub unsafe fn get_real_status<M: CoSimModel>(c: Fmi2Component, kind: c_int, value: *mut f64) -> Fmi2Status {
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
pub unsafe fn get_integer_status<M: CoSimModel>(c: Fmi2Component, kind: c_int, value: *mut Fmi2Integer) -> Fmi2Status {
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
pub unsafe fn get_boolean_status<M: CoSimModel>(c: Fmi2Component, kind: c_int, value: *mut Fmi2Boolean) -> Fmi2Status {
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
pub unsafe fn get_string_status<M: CoSimModel>(c: Fmi2Component, kind: c_int, value: *mut Fmi2String) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetStringStatus", |i| {
            if value.is_null() {
                return i.bad_argument("fmi2GetStringStatus", "value is NULL");
            }
            i.get_string_status(kind)
        })
    }
}
