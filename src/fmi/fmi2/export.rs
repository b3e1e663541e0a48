//! [`export_fmi2!`](crate::export_fmi2): the 34 `#[unsafe(no_mangle)]` symbols of an FMU binary.

/// Exports the 34 FMI 2.0 co-simulation functions for the model type `$model`, as
/// `#[unsafe(no_mangle)] extern "C"` symbols of the crate that invokes it (the FMU cdylib).
#[macro_export]
macro_rules! export_fmi2 {
    ($model:ty) => {
        use ::std::ffi::{c_char, c_int};
        use $crate::fmi::fmi2::ffi as __ffi;
        use $crate::fmi::fmi2::types::*;

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
