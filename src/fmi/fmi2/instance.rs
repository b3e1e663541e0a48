//! One FMU instance: the state machine of FMI 2.0 co-simulation (src/formulation.md §1.3) over a model.
use super::logger::{Logger, to_cstring};
use super::machine::*;
use super::types::*;
use super::xml;
use crate::error::Error;
use crate::fmi::state::{StateReader, StateWriter};
use crate::fmi::table::{BaseType, Causality, SetPhase};
use crate::fmi::{CoSimModel, describe, uri};
use std::ffi::{CString, c_char};
use std::path::PathBuf;

/// Marks live instances and FMU states, so that a stray pointer of the wrong kind is refused
/// rather than used. Both structs are `#[repr(C)]` with the tag as their first field, so the
/// check on entry reads only the first 8 bytes behind a pointer, never past a smaller object.
pub(crate) const INSTANCE_MAGIC: u64 = 0x5043_464d_4932_494e; // "PCFMI2IN"
pub(crate) const STATE_MAGIC: u64 = 0x5043_464d_4932_5354; // "PCFMI2ST"

/// What `fmi2GetFMUstate` hands out (boxed, as an opaque `fmi2FMUstate`). `magic` stays first.
#[repr(C)]
pub struct FmuState<S> {
    pub(crate) magic: u64,
    guid: String,
    clock: Clock,
    model: S,
}

/// One instance (boxed, as an opaque `fmi2Component`). `magic` stays first.
#[repr(C)]
pub struct Instance<M: CoSimModel> {
    pub(crate) magic: u64,
    model: M,
    guid: String,
    logger: Logger,
    clock: Clock,
    /// Strings handed out by fmi2GetString; valid until the next call.
    strings: Vec<CString>,
    resources: Option<PathBuf>,
}

impl<M: CoSimModel> Instance<M> {
    /// `fmi2Instantiate`. `None` after logging why (a missing name, the wrong fmuType, a bad
    /// resource location, a model that cannot be built, a missing or wrong GUID).
    pub fn new(name: Option<&str>, fmu_type: i32, guid: Option<&str>, resource_location: Option<&str>, logger: Logger) -> Option<Box<Self>> {
        let fail = |m: String| {
            logger.error(&format!("fmi2Instantiate: {m}"));
            None
        };
        match name {
            None | Some("") => return fail("instanceName is NULL or empty".into()),
            Some(_) => {}
        }
        if fmu_type != FMI2_CO_SIMULATION {
            return fail(format!("fmuType {fmu_type} is not supported: this FMU provides co-simulation (fmi2CoSimulation = 1) only"));
        }
        let resources = match uri::resource_dir(resource_location) {
            Ok(r) => r,
            Err(e) => return fail(describe(&e)),
        };
        let model = match M::instantiate(resources.as_deref()) {
            Ok(m) => m,
            Err(e) => return fail(describe(&e)),
        };
        if let Err(m) = model.description().check() {
            return fail(format!("the model description is invalid: {}", describe(&m)));
        }
        let (_, expected) = xml::render(model.description());
        match guid {
            None => return fail(format!("fmuGUID is NULL; this FMU's GUID is {expected}")),
            Some(g) if g != expected => {
                return fail(format!(
                    "GUID mismatch: the importer passed \"{g}\", but this binary with these resources has \"{expected}\"; the modelDescription.xml does not belong to this binary and resources (re-package the FMU)"
                ));
            }
            Some(_) => {}
        }
        logger.event(&format!("fmi2Instantiate: GUID {expected}, resources {:?}", resources));
        Some(Box::new(Instance { magic: INSTANCE_MAGIC, model, guid: expected, logger, clock: Clock::new(), strings: Vec::new(), resources }))
    }

    pub fn model(&self) -> &M {
        &self.model
    }
    pub fn state(&self) -> MachineState {
        self.clock.state
    }
    pub fn time(&self) -> f64 {
        self.clock.time
    }
    pub fn guid(&self) -> &str {
        &self.guid
    }
    pub fn resources(&self) -> Option<&std::path::Path> {
        self.resources.as_deref()
    }
    pub fn logger(&self) -> &Logger {
        &self.logger
    }

    /// Logs `message` as an error and moves to the error state.
    fn fail(&mut self, message: &str) -> Status {
        self.logger.error(message);
        self.clock.state = MachineState::Error;
        Status::Error
    }

    /// The allowed-call table: `Err(fmi2Error)` (and the error state) outside `mask`.
    fn allow(&mut self, f: &str, mask: u8) -> Result<(), Status> {
        if self.clock.state.bit() & mask != 0 {
            return Ok(());
        }
        let m = if self.clock.state == MachineState::Error {
            format!("{f}: the instance is in the error state after an earlier fmi2Error; call fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance")
        } else {
            format!("{f}: illegal call sequence: not allowed in state {} (allowed in: {})", self.clock.state.name(), mask_names(mask))
        };
        Err(self.fail(&m))
    }

    /// Called by the FFI layer when a panic was caught inside a call.
    pub fn panicked(&mut self, f: &str, what: &str) -> Status {
        self.fail(&format!("{f}: internal error (caught panic: {what}); the instance is in the error state, call fmi2Reset or fmi2FreeInstance"))
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Status {
        match self.logger.set_debug_logging(on, categories) {
            Ok(()) => Status::Ok,
            Err(e) => {
                self.logger.error(&format!("fmi2SetDebugLogging: {}", describe(&e)));
                Status::Error
            }
        }
    }

    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start_time: f64, stop_time: Option<f64>) -> Status {
        if let Err(s) = self.allow("fmi2SetupExperiment", INST) {
            return s;
        }
        if !start_time.is_finite() {
            return self.fail(&format!("fmi2SetupExperiment: startTime {start_time} is not finite"));
        }
        if let Some(stop) = stop_time
            && (stop.is_nan() || stop < start_time)
        {
            return self.fail(&format!("fmi2SetupExperiment: stopTime {stop} is before startTime {start_time}"));
        }
        if let Some(t) = tolerance {
            self.logger.event(&format!("fmi2SetupExperiment: tolerance {t} is not used (the periodic solve is direct)"));
        }
        self.clock.start_time = start_time;
        self.clock.time = start_time;
        self.clock.stop_time = stop_time;
        Status::Ok
    }

    pub fn enter_initialization_mode(&mut self) -> Status {
        if let Err(s) = self.allow("fmi2EnterInitializationMode", INST) {
            return s;
        }
        self.clock.state = MachineState::InitializationMode;
        self.clock.time = self.clock.start_time;
        self.model.enter_initialization(self.clock.start_time);
        Status::Ok
    }

    pub fn exit_initialization_mode(&mut self) -> Status {
        if let Err(s) = self.allow("fmi2ExitInitializationMode", INIT) {
            return s;
        }
        match self.model.exit_initialization(self.clock.start_time, &self.logger) {
            Ok(warnings) => {
                self.clock.state = MachineState::StepComplete;
                self.clock.time = self.clock.start_time;
                self.clock.last_successful_time = self.clock.start_time;
                for w in &warnings {
                    self.logger.warning(&format!("fmi2ExitInitializationMode: {w}"));
                }
                if warnings.is_empty() { Status::Ok } else { Status::Warning }
            }
            Err(e) => self.fail(&format!("fmi2ExitInitializationMode: {}", describe(&e))),
        }
    }

    pub fn terminate(&mut self) -> Status {
        if let Err(s) = self.allow("fmi2Terminate", COMPLETE | FAILED) {
            return s;
        }
        self.clock.state = MachineState::Terminated;
        Status::Ok
    }

    pub fn reset(&mut self) -> Status {
        if let Err(s) = self.allow("fmi2Reset", ANY) {
            return s;
        }
        self.model.reset();
        self.clock = Clock::new();
        Status::Ok
    }

    /// Checks a whole get call's references up front, then reads.
    fn get<T>(&mut self, f: &str, ty: BaseType, vrs: &[Fmi2ValueReference], out: &mut [T], read: impl Fn(&mut M, u32) -> crate::error::Result<T>) -> Status {
        if let Err(s) = self.allow(f, INIT | COMPLETE | FAILED | TERMINATED | ERROR) {
            return s;
        }
        for (vr, slot) in vrs.iter().zip(out.iter_mut()) {
            if let Err(m) = self.model.description().variables.lookup(*vr, ty) {
                return self.fail(&format!("{f}: {}", describe(&m)));
            }
            match read(&mut self.model, *vr) {
                Ok(v) => *slot = v,
                Err(e) => return self.fail(&format!("{f}: {}", describe(&e))),
            }
        }
        Status::Ok
    }

    fn set<T: Copy>(
        &mut self,
        f: &str,
        ty: BaseType,
        vrs: &[Fmi2ValueReference],
        values: &[T],
        write: impl Fn(&mut M, u32, T) -> crate::error::Result<()>,
    ) -> Status {
        if let Err(s) = self.allow(f, INST | INIT | COMPLETE) {
            return s;
        }
        let phase = match self.clock.state {
            MachineState::Instantiated => SetPhase::Instantiated,
            MachineState::InitializationMode => SetPhase::InitializationMode,
            _ => SetPhase::Simulation,
        };
        for (vr, v) in vrs.iter().zip(values) {
            if let Err(m) = self.model.description().variables.check_settable(*vr, ty, phase) {
                return self.fail(&format!("{f}: {}", describe(&m)));
            }
            if let Err(m) = write(&mut self.model, *vr, *v) {
                return self.fail(&format!("{f}: {}", describe(&m)));
            }
        }
        Status::Ok
    }

    pub fn get_real(&mut self, vrs: &[Fmi2ValueReference], out: &mut [f64]) -> Status {
        self.get("fmi2GetReal", BaseType::Real, vrs, out, |m, vr| m.get_real(vr))
    }
    pub fn get_integer(&mut self, vrs: &[Fmi2ValueReference], out: &mut [Fmi2Integer]) -> Status {
        self.get("fmi2GetInteger", BaseType::Integer, vrs, out, |m, vr| m.get_integer(vr))
    }
    pub fn get_boolean(&mut self, vrs: &[Fmi2ValueReference], out: &mut [Fmi2Boolean]) -> Status {
        self.get("fmi2GetBoolean", BaseType::Boolean, vrs, out, |m, vr| m.get_boolean(vr).map(|b| if b { FMI2_TRUE } else { FMI2_FALSE }))
    }
    /// Fills `out` with pointers valid until the next call on this instance.
    pub fn get_string(&mut self, vrs: &[Fmi2ValueReference], out: &mut [*const c_char]) -> Status {
        let mut values = vec![String::new(); vrs.len()];
        let s = self.get("fmi2GetString", BaseType::String, vrs, &mut values, |m, vr| m.get_string(vr));
        if s == Status::Ok {
            self.strings = values.iter().map(|v| to_cstring(v)).collect();
            for (slot, c) in out.iter_mut().zip(&self.strings) {
                *slot = c.as_ptr();
            }
        }
        s
    }

    pub fn set_real(&mut self, vrs: &[Fmi2ValueReference], values: &[f64]) -> Status {
        self.set("fmi2SetReal", BaseType::Real, vrs, values, |m, vr, v| m.set_real(vr, v))
    }
    pub fn set_integer(&mut self, vrs: &[Fmi2ValueReference], values: &[Fmi2Integer]) -> Status {
        self.set("fmi2SetInteger", BaseType::Integer, vrs, values, |m, vr, v| m.set_integer(vr, v))
    }
    pub fn set_boolean(&mut self, vrs: &[Fmi2ValueReference], values: &[Fmi2Boolean]) -> Status {
        self.set("fmi2SetBoolean", BaseType::Boolean, vrs, values, |m, vr, v| m.set_boolean(vr, v != FMI2_FALSE))
    }
    pub fn set_string(&mut self, vrs: &[Fmi2ValueReference], values: &[Option<String>]) -> Status {
        if values.iter().any(Option::is_none) {
            return self.fail("fmi2SetString: a value is a NULL pointer");
        }
        let values: Vec<&str> = values.iter().map(|v| v.as_deref().unwrap_or("")).collect();
        self.set("fmi2SetString", BaseType::String, vrs, &values, |m, vr, v| m.set_string(vr, v))
    }

    // --- FMU states -------------------------------------------------------------------------

    const STATE_FNS: u8 = ANY;

    /// `fmi2GetFMUstate`: a new state, or `existing` overwritten.
    pub fn get_fmu_state(&mut self, existing: Option<&mut FmuState<M::Snapshot>>) -> Result<Option<Box<FmuState<M::Snapshot>>>, Status> {
        self.allow("fmi2GetFMUstate", Self::STATE_FNS)?;
        let s = FmuState { magic: STATE_MAGIC, guid: self.guid.clone(), clock: self.clock, model: self.model.snapshot() };
        match existing {
            Some(e) => {
                *e = s;
                Ok(None)
            }
            None => Ok(Some(Box::new(s))),
        }
    }

    pub fn set_fmu_state(&mut self, state: &FmuState<M::Snapshot>) -> Status {
        if let Err(s) = self.allow("fmi2SetFMUstate", Self::STATE_FNS) {
            return s;
        }
        if state.guid != self.guid {
            return self.fail(&format!("fmi2SetFMUstate: the state belongs to a model with GUID {}, this instance has {}", state.guid, self.guid));
        }
        self.model.restore(&state.model);
        self.clock = state.clock;
        Status::Ok
    }

    pub fn check_state_fn(&mut self, f: &str) -> Status {
        match self.allow(f, Self::STATE_FNS) {
            Ok(()) => Status::Ok,
            Err(s) => s,
        }
    }

    pub fn serialize_fmu_state(&self, state: &FmuState<M::Snapshot>) -> Vec<u8> {
        let mut w = StateWriter::new(M::STATE_VERSION);
        w.str(&state.guid);
        state.clock.write(&mut w);
        M::serialize(&state.model, &mut w);
        w.into_bytes()
    }

    pub fn deserialize_fmu_state(&mut self, bytes: &[u8]) -> Result<Box<FmuState<M::Snapshot>>, Status> {
        self.allow("fmi2DeSerializeFMUstate", Self::STATE_FNS)?;
        let parsed = (|| -> crate::error::Result<FmuState<M::Snapshot>> {
            let mut r = StateReader::new(bytes, M::STATE_VERSION)?;
            let guid = r.str()?;
            if guid != self.guid {
                return Err(Error::input(format!("the state belongs to a model with GUID {guid}, this instance has {}", self.guid)));
            }
            let clock = Clock::read(&mut r)?;
            let model = self.model.deserialize(&mut r)?;
            r.finish()?;
            Ok(FmuState { magic: STATE_MAGIC, guid, clock, model })
        })();
        parsed.map(Box::new).map_err(|e| self.fail(&format!("fmi2DeSerializeFMUstate: {}", describe(&e))))
    }

    // --- co-simulation --------------------------------------------------------------------

    pub fn do_step(&mut self, t: f64, h: f64) -> Status {
        if let Err(s) = self.allow("fmi2DoStep", COMPLETE) {
            return s;
        }
        if !(t.is_finite() && h.is_finite() && h > 0.0) {
            return self.fail(&format!("fmi2DoStep: currentCommunicationPoint {t} must be finite and communicationStepSize {h} finite and > 0"));
        }
        if !same_time(t, self.clock.time, h) {
            return self
                .fail(&format!("fmi2DoStep: currentCommunicationPoint {t} does not match the FMU's time {} (the end of the previous step)", self.clock.time));
        }
        if let Some(stop) = self.clock.stop_time
            && t + h > stop
            && !same_time(t + h, stop, h)
        {
            return self.fail(&format!("fmi2DoStep: the step to {} goes beyond stopTime {stop}", t + h));
        }
        match self.model.do_step(t, h, &self.logger) {
            Ok(()) => {
                self.clock.time = t + h;
                self.clock.last_successful_time = t + h;
                Status::Ok
            }
            Err(e) => {
                self.logger.discard(&format!("fmi2DoStep at t = {t}: {}; the step was not taken (fmi2Terminated is true)", describe(&e)));
                self.clock.state = MachineState::StepFailed;
                self.clock.time = t;
                self.clock.last_successful_time = t;
                self.clock.terminate_requested = true;
                Status::Discard
            }
        }
    }

    pub fn get_real_output_derivatives(&mut self, vrs: &[Fmi2ValueReference], orders: &[Fmi2Integer], out: &mut [f64]) -> Status {
        let f = "fmi2GetRealOutputDerivatives";
        if let Err(s) = self.allow(f, COMPLETE | FAILED | TERMINATED | ERROR) {
            return s;
        }
        let max = self.model.description().max_output_derivative_order as i32;
        for ((vr, order), slot) in vrs.iter().zip(orders).zip(out.iter_mut()) {
            let v = match self.model.description().variables.lookup(*vr, BaseType::Real) {
                Ok(v) => v,
                Err(e) => return self.fail(&format!("{f}: {}", describe(&e))),
            };
            if v.causality != Causality::Output {
                let m = format!("{f}: {} (value reference {vr}) is not an output", v.name);
                return self.fail(&m);
            }
            if !(1..=max).contains(order) {
                return self.fail(&format!("{f}: order {order} is not supported (maxOutputDerivativeOrder = {max})"));
            }
            match self.model.output_derivative(*vr, *order) {
                Ok(d) => *slot = d,
                Err(e) => return self.fail(&format!("{f}: {}", describe(&e))),
            }
        }
        Status::Ok
    }

    /// Optional functions we do not provide: a log line and fmi2Error, the state is kept.
    pub fn unsupported(&mut self, f: &str, why: &str) -> Status {
        self.logger.error(&format!("{f}: not supported by this FMU ({why})"));
        Status::Error
    }

    pub fn set_real_input_derivatives(&mut self) -> Status {
        if let Err(s) = self.allow("fmi2SetRealInputDerivatives", INST | INIT | COMPLETE) {
            return s;
        }
        self.unsupported("fmi2SetRealInputDerivatives", "canInterpolateInputs=\"false\"")
    }

    pub fn get_directional_derivative(&mut self) -> Status {
        if let Err(s) = self.allow("fmi2GetDirectionalDerivative", INIT | COMPLETE | FAILED | TERMINATED | ERROR) {
            return s;
        }
        self.unsupported("fmi2GetDirectionalDerivative", "providesDirectionalDerivative=\"false\"")
    }

    pub fn cancel_step(&mut self) -> Status {
        // Only legal in stepInProgress, which this FMU never enters (it never returns fmi2Pending).
        match self.allow("fmi2CancelStep", 0) {
            Ok(()) => Status::Ok,
            Err(s) => s,
        }
    }

    const STATUS_FNS: u8 = COMPLETE | FAILED | TERMINATED | ERROR;

    fn status_kind(&mut self, f: &str, kind: i32) -> Result<(), Status> {
        self.allow(f, Self::STATUS_FNS)?;
        if !(FMI2_DO_STEP_STATUS..=FMI2_TERMINATED).contains(&kind) {
            return Err(self.fail(&format!("{f}: {kind} is not an fmi2StatusKind")));
        }
        Ok(())
    }

    fn not_available(&self, f: &str, kind: i32) -> Status {
        let name = ["fmi2DoStepStatus", "fmi2PendingStatus", "fmi2LastSuccessfulTime", "fmi2Terminated"][kind as usize];
        self.logger.discard(&format!("{f}({name}): not available (this FMU never returns fmi2Pending)"));
        Status::Discard
    }

    pub fn get_status(&mut self, kind: i32) -> Status {
        if let Err(s) = self.status_kind("fmi2GetStatus", kind) {
            return s;
        }
        self.not_available("fmi2GetStatus", kind)
    }

    pub fn get_real_status(&mut self, kind: i32, out: &mut f64) -> Status {
        if let Err(s) = self.status_kind("fmi2GetRealStatus", kind) {
            return s;
        }
        if kind == FMI2_LAST_SUCCESSFUL_TIME {
            *out = self.clock.last_successful_time;
            return Status::Ok;
        }
        self.not_available("fmi2GetRealStatus", kind)
    }

    pub fn get_integer_status(&mut self, kind: i32) -> Status {
        if let Err(s) = self.status_kind("fmi2GetIntegerStatus", kind) {
            return s;
        }
        self.not_available("fmi2GetIntegerStatus", kind)
    }

    pub fn get_boolean_status(&mut self, kind: i32, out: &mut Fmi2Boolean) -> Status {
        if let Err(s) = self.status_kind("fmi2GetBooleanStatus", kind) {
            return s;
        }
        if kind == FMI2_TERMINATED {
            *out = if self.clock.terminate_requested { FMI2_TRUE } else { FMI2_FALSE };
            return Status::Ok;
        }
        self.not_available("fmi2GetBooleanStatus", kind)
    }

    pub fn get_string_status(&mut self, kind: i32) -> Status {
        if let Err(s) = self.status_kind("fmi2GetStringStatus", kind) {
            return s;
        }
        self.not_available("fmi2GetStringStatus", kind)
    }

    /// Reports a bad pointer argument (NULL array with n > 0, NULL output).
    pub fn bad_argument(&mut self, f: &str, what: &str) -> Status {
        self.fail(&format!("{f}: {what}"))
    }
}
