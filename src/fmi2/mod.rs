//! A generic FMI 2.0 co-simulation shell that knows nothing of contact mechanics (in the spirit
//! of the modelica Reference FMUs).
//!
//! - [`Fmi2Model`]: what a model provides — its [`ModelDescription`] (one [`table::VariableTable`]
//!   that is the single source of truth for the accessors and for `modelDescription.xml`),
//!   get/set by value reference, the work of `fmi2ExitInitializationMode` and `fmi2DoStep`, and
//!   snapshots for the FMU-state functions.
//! - [`instance::Instance`]: the state machine with the allowed-call table, argument checks,
//!   communication-point tolerance, status getters and FMU states.
//! - [`ffi`]: the 34 C entry points as generic `unsafe fn`s over raw pointers, each body inside
//!   `catch_unwind`; [`export_fmi2!`](crate::export_fmi2) stamps out the `#[unsafe(no_mangle)]`
//!   symbols in the crate that builds the FMU binary.
//! - [`logger`], [`uri`] (resource location), [`xml`] (model description), [`guid`],
//!   [`package`] (the `.fmu` zip), [`bytes`] (serialized states).
//!
//! Nothing here is global or thread-local: everything lives in the boxed instance.
//!
//! Error policy: an illegal call sequence, an invalid argument, an unknown value reference or a
//! failed initialisation returns `fmi2Error`, logs why, and moves the instance to the *error*
//! state, from which only getters, `fmi2Reset`, `fmi2FreeInstance`, `fmi2SetFMUstate` (and the
//! other FMU-state functions) and `fmi2SetDebugLogging` are accepted. Optional functions this
//! FMU does not provide (directional derivatives, input derivatives, `fmi2CancelStep`) return
//! `fmi2Error` with a log line but leave the state alone, as do unknown log categories. Status
//! kinds that are not available (`fmi2DoStepStatus`, `fmi2PendingStatus`) give `fmi2Discard`.
//! A failed step gives `fmi2Discard`, the *stepFailed* state and `fmi2Terminated` = true.
//! A panic is caught, logged, and treated as an error (`fmi2Reset` rebuilds the model).
pub mod bytes;
pub mod ffi;
pub mod guid;
pub mod instance;
pub mod logger;
pub mod package;
pub mod table;
pub mod types;
pub mod uri;
pub mod xml;

use std::path::Path;
use table::{EnumerationType, UnitDefinition, VariableTable};

pub use instance::Instance;
pub use logger::Logger;
pub use types::Status;

/// `<DefaultExperiment>`.
#[derive(Clone, Debug, PartialEq)]
pub struct DefaultExperiment {
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
}

/// Everything a model says about itself in `modelDescription.xml`. The shell adds the
/// capability flags it implements and the log categories.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelDescription {
    pub model_name: String,
    /// The binary is `binaries/<platform>/<model_identifier>.so`.
    pub model_identifier: String,
    pub description: String,
    pub generation_tool: String,
    pub variables: VariableTable,
    pub units: Vec<UnitDefinition>,
    pub enumerations: Vec<EnumerationType>,
    pub default_experiment: Option<DefaultExperiment>,
    /// `fmi2GetRealOutputDerivatives` supports orders 1..=this.
    pub max_output_derivative_order: u32,
}

/// A co-simulation model behind the shell. Value references are positions in
/// `description().variables`; the shell has checked the reference, its type and (for setters)
/// that the variable may be set in the current state before calling a setter or getter.
pub trait Fmi2Model: Sized {
    /// Everything `fmi2GetFMUstate` must capture of the model.
    type Snapshot: Clone;

    /// Builds the model from the unpacked `resources` folder (`None`: the importer gave none).
    fn instantiate(resources: Option<&Path>) -> Result<Self, String>;
    fn description(&self) -> &ModelDescription;
    /// Back to the start values, nothing solved (`fmi2Reset`).
    fn reset(&mut self);
    /// `fmi2EnterInitializationMode` (outputs read in initialisation mode are at `start_time`).
    fn enter_initialization(&mut self, _start_time: f64) {}

    fn set_real(&mut self, vr: u32, value: f64) -> Result<(), String>;
    fn set_integer(&mut self, vr: u32, value: i32) -> Result<(), String>;
    fn set_boolean(&mut self, vr: u32, _value: bool) -> Result<(), String> {
        Err(format!("value reference {vr} cannot be set as Boolean"))
    }
    fn set_string(&mut self, vr: u32, _value: &str) -> Result<(), String> {
        Err(format!("value reference {vr} cannot be set as String"))
    }
    /// Getters may compute (e.g. outputs read in initialisation mode).
    fn get_real(&mut self, vr: u32) -> Result<f64, String>;
    fn get_integer(&mut self, vr: u32) -> Result<i32, String>;
    fn get_boolean(&mut self, vr: u32) -> Result<bool, String> {
        Err(format!("value reference {vr} cannot be read as Boolean"))
    }
    fn get_string(&mut self, vr: u32) -> Result<String, String> {
        Err(format!("value reference {vr} cannot be read as String"))
    }

    /// `fmi2ExitInitializationMode`: the heavy work. `Ok(warnings)` (each is logged and the call
    /// returns `fmi2Warning`), `Err` → `fmi2Error`.
    fn exit_initialization(&mut self, start_time: f64, log: &Logger) -> Result<Vec<String>, String>;
    /// `fmi2DoStep` from `t` to `t + h`. `Err` → `fmi2Discard`; the model must then be unchanged.
    fn do_step(&mut self, t: f64, h: f64, log: &Logger) -> Result<(), String>;
    /// The `order`-th time derivative of output `vr` at the current time (order ≥ 1).
    fn output_derivative(&self, vr: u32, order: i32) -> Result<f64, String>;

    fn snapshot(&self) -> Self::Snapshot;
    fn restore(&mut self, snapshot: &Self::Snapshot);
    fn serialize(snapshot: &Self::Snapshot, out: &mut bytes::ByteWriter);
    fn deserialize(&self, input: &mut bytes::ByteReader<'_>) -> Result<Self::Snapshot, String>;
}
