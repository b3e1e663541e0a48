//! The C types of the FMI 2.0 headers (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`).
//!
//! C enums that come *in* from the importer (`fmi2Type`, `fmi2StatusKind`) are received as
//! `c_int` and checked, never transmuted into Rust enums.
use std::ffi::{c_char, c_int, c_uint, c_void};

pub type Fmi2Component = *mut c_void;
pub type Fmi2ComponentEnvironment = *mut c_void;
pub type Fmi2FmuState = *mut c_void;
pub type Fmi2ValueReference = c_uint;
pub type Fmi2Real = f64;
pub type Fmi2Integer = c_int;
/// `int`, not `bool`: fmi2True = 1, fmi2False = 0.
pub type Fmi2Boolean = c_int;
pub type Fmi2Char = c_char;
pub type Fmi2String = *const c_char;
pub type Fmi2Byte = c_char;
/// The status as returned through the ABI.
pub type Fmi2Status = c_int;

pub const FMI2_TRUE: Fmi2Boolean = 1;
pub const FMI2_FALSE: Fmi2Boolean = 0;
/// `fmi2Type`: only co-simulation is provided.
pub const FMI2_MODEL_EXCHANGE: c_int = 0;
pub const FMI2_CO_SIMULATION: c_int = 1;
/// `fmi2StatusKind`.
pub const FMI2_DO_STEP_STATUS: c_int = 0;
pub const FMI2_PENDING_STATUS: c_int = 1;
pub const FMI2_LAST_SUCCESSFUL_TIME: c_int = 2;
pub const FMI2_TERMINATED: c_int = 3;

/// `fmi2Status`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[repr(i32)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
    Pending = 5,
}

impl Status {
    pub fn raw(self) -> Fmi2Status {
        self as Fmi2Status
    }
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "fmi2OK",
            Status::Warning => "fmi2Warning",
            Status::Discard => "fmi2Discard",
            Status::Error => "fmi2Error",
            Status::Fatal => "fmi2Fatal",
            Status::Pending => "fmi2Pending",
        }
    }
}

/// The variadic, printf-style logger. The shell always calls it with the format `"%s"`.
pub type Fmi2CallbackLogger = Option<unsafe extern "C" fn(Fmi2ComponentEnvironment, Fmi2String, Fmi2Status, Fmi2String, Fmi2String, ...)>;
pub type Fmi2CallbackAllocateMemory = Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>;
pub type Fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(*mut c_void)>;
pub type Fmi2StepFinished = Option<unsafe extern "C" fn(Fmi2ComponentEnvironment, Fmi2Status)>;

/// `fmi2CallbackFunctions` (`#pragma pack(8)` is the natural alignment on 64-bit targets).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct Fmi2CallbackFunctions {
    pub logger: Fmi2CallbackLogger,
    /// Ignored: the model description declares `canNotUseMemoryManagementFunctions="true"`.
    pub allocate_memory: Fmi2CallbackAllocateMemory,
    pub free_memory: Fmi2CallbackFreeMemory,
    /// Ignored: `fmi2DoStep` never returns `fmi2Pending`.
    pub step_finished: Fmi2StepFinished,
    pub component_environment: Fmi2ComponentEnvironment,
}
