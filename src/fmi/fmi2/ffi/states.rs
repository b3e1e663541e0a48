//! The FMU-state entry points: get, set, free, serialize, deserialize.
use super::{call, slice, slice_mut};
use crate::fmi::CoSimModel;
use crate::fmi::fmi2::instance::{FmuState, STATE_MAGIC};
use crate::fmi::fmi2::types::*;
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
pub unsafe fn get_fmu_state<M: CoSimModel>(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
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
pub unsafe fn set_fmu_state<M: CoSimModel>(c: Fmi2Component, state: Fmi2FmuState) -> Fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetFMUstate", |i| match fmu_state::<M::Snapshot>(state) {
            Some(s) => i.set_fmu_state(s),
            None => i.bad_argument("fmi2SetFMUstate", "FMUstate is NULL or not a state of this FMU"),
        })
    }
}

/// # Safety
/// `state` points to an `fmi2FMUstate`; it is set to NULL.
pub unsafe fn free_fmu_state<M: CoSimModel>(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
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
pub unsafe fn serialized_fmu_state_size<M: CoSimModel>(c: Fmi2Component, state: Fmi2FmuState, size: *mut usize) -> Fmi2Status {
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
pub unsafe fn serialize_fmu_state<M: CoSimModel>(c: Fmi2Component, state: Fmi2FmuState, bytes: *mut Fmi2Byte, size: usize) -> Fmi2Status {
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
pub unsafe fn deserialize_fmu_state<M: CoSimModel>(c: Fmi2Component, bytes: *const Fmi2Byte, size: usize, state: *mut Fmi2FmuState) -> Fmi2Status {
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
