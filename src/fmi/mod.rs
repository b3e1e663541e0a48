//! A version-neutral co-simulation layer that knows nothing of contact mechanics (in the spirit
//! of the modelica Reference FMUs, which keep `model.h` apart from `fmi2Functions.c`).
//!
//! - [`CoSimModel`]: what a model provides — its [`ModelDescription`] (one [`table::VariableTable`]
//!   that is the single source of truth for the accessors and for the model description),
//!   get/set by value reference, the work of leaving initialisation and of a step, and
//!   snapshots for the FMU-state functions. No type of a particular FMI version appears here.
//! - [`table`] (variables), [`guid`], [`uri`] (resource location), [`package`] (the `.fmu` zip),
//!   [`state`] (the checked, versioned codec of serialized FMU states).
//! - [`fmi2`]: the FMI 2.0 shell over a [`CoSimModel`] (state machine, the 34 C entry points,
//!   `modelDescription.xml`, the logger, [`export_fmi2!`](crate::export_fmi2)).
//! - An FMI 3.0 shell would go beside it in `src/fmi/fmi3/` (its own instance, entry points,
//!   XML and logger over the same [`CoSimModel`], table, codec, GUID and package).
//!
//! Dependencies: this folder uses only `crate::error` of the crate (never the contact rooms:
//! `periodic`, `model`, `scene`, `lcp`, `response`, `time`).
//!
//! Nothing here is global or thread-local: everything lives in the boxed instance.
pub mod fmi2;
pub mod guid;
pub mod package;
pub mod state;
pub mod table;
pub mod uri;

use crate::error::{Error, ErrorKind, Result};
use std::path::Path;
use table::{EnumerationType, UnitDefinition, VariableTable};

/// How a shell names the kind of an error in its log ("input error: …", "solver failure: …"):
/// the status stays the one the standard asks for, the kind tells the user what to change.
pub fn kind_label(kind: ErrorKind) -> &'static str {
    match kind {
        ErrorKind::Input => "input error",
        ErrorKind::Limit => "size limit",
        ErrorKind::Io => "I/O error",
        ErrorKind::Solve => "solver failure",
    }
}

/// `"<kind>: <message>"`, for a log line.
pub fn describe(e: &Error) -> String {
    format!("{}: {}", kind_label(e.kind()), e.message())
}

/// Where a model reports its events (solves, re-solves). Each shell passes its own logger.
pub trait EventLog {
    /// Whether an event would be shown (so callers can skip formatting).
    fn events_enabled(&self) -> bool;
    fn event(&self, message: &str);
}

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
    /// Output derivatives (FMI 2 `fmi2GetRealOutputDerivatives`) are available for orders 1..=this.
    pub max_output_derivative_order: u32,
}

impl ModelDescription {
    /// The variable table's checks ([`VariableTable::check`]), and every Real's unit is one of
    /// `units` (fmpy refuses an undefined unit).
    pub fn check(&self) -> Result<()> {
        self.variables.check()?;
        for (_, v) in self.variables.iter() {
            if let table::Kind::Real { unit: Some(u), .. } = &v.kind
                && !self.units.iter().any(|d| d.name == *u)
            {
                return Err(Error::input(format!("{}: its unit \"{u}\" is not in the unit definitions", v.name)));
            }
        }
        Ok(())
    }
}

/// A co-simulation model behind the shell. Value references are positions in
/// `description().variables`; the shell has checked the reference, its type and (for setters)
/// that the variable may be set in the current state before calling a setter or getter.
pub trait CoSimModel: Sized {
    /// Everything an FMU state (FMI 2 `fmi2GetFMUstate`) must capture of the model.
    type Snapshot: Clone;
    /// The version of the model's part of a serialized state (see [`state`]); raise it when
    /// [`serialize`](Self::serialize) changes, so that older states are refused by name.
    const STATE_VERSION: u16;

    /// Builds the model from the unpacked `resources` folder (`None`: the importer gave none).
    fn instantiate(resources: Option<&Path>) -> Result<Self>;
    fn description(&self) -> &ModelDescription;
    /// Back to the start values, nothing solved (a reset of the instance).
    fn reset(&mut self);
    /// Entering initialisation mode (outputs read in initialisation mode are at `start_time`).
    fn enter_initialization(&mut self, _start_time: f64) {}

    fn set_real(&mut self, vr: u32, value: f64) -> Result<()>;
    fn set_integer(&mut self, vr: u32, value: i32) -> Result<()>;
    fn set_boolean(&mut self, vr: u32, _value: bool) -> Result<()> {
        Err(Error::input(format!("value reference {vr} cannot be set as Boolean")))
    }
    fn set_string(&mut self, vr: u32, _value: &str) -> Result<()> {
        Err(Error::input(format!("value reference {vr} cannot be set as String")))
    }
    /// Getters may compute (e.g. outputs read in initialisation mode).
    fn get_real(&mut self, vr: u32) -> Result<f64>;
    fn get_integer(&mut self, vr: u32) -> Result<i32>;
    fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        Err(Error::input(format!("value reference {vr} cannot be read as Boolean")))
    }
    fn get_string(&mut self, vr: u32) -> Result<String> {
        Err(Error::input(format!("value reference {vr} cannot be read as String")))
    }

    /// Leaving initialisation mode: the heavy work. `Ok(warnings)`: each is logged and the call
    /// returns a warning status; `Err`: an error status.
    fn exit_initialization(&mut self, start_time: f64, log: &dyn EventLog) -> Result<Vec<String>>;
    /// A step from `t` to `t + h`. `Err`: the step is discarded; the model must then be unchanged.
    fn do_step(&mut self, t: f64, h: f64, log: &dyn EventLog) -> Result<()>;
    /// The `order`-th time derivative of output `vr` at the current time (order ≥ 1).
    fn output_derivative(&self, vr: u32, order: i32) -> Result<f64>;

    fn snapshot(&self) -> Self::Snapshot;
    fn restore(&mut self, snapshot: &Self::Snapshot);
    fn serialize(snapshot: &Self::Snapshot, out: &mut state::StateWriter);
    fn deserialize(&self, input: &mut state::StateReader<'_>) -> Result<Self::Snapshot>;
}
