//! The co-simulation state machine of FMI 2.0 (src/formulation.md §1.3): the states, the masks of the
//! allowed-call table, and the clock an FMU state keeps.
use crate::error::{Error, Result};
use crate::fmi::state::{StateReader, StateWriter};

/// The co-simulation states we can be in (we never return fmi2Pending, so *stepInProgress* and
/// *stepCanceled* do not occur).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MachineState {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
}

pub(crate) const INST: u8 = 1;
pub(crate) const INIT: u8 = 2;
pub(crate) const COMPLETE: u8 = 4;
pub(crate) const FAILED: u8 = 8;
pub(crate) const TERMINATED: u8 = 16;
pub(crate) const ERROR: u8 = 32;
pub(crate) const ANY: u8 = INST | INIT | COMPLETE | FAILED | TERMINATED | ERROR;

impl MachineState {
    pub(crate) fn bit(self) -> u8 {
        match self {
            MachineState::Instantiated => INST,
            MachineState::InitializationMode => INIT,
            MachineState::StepComplete => COMPLETE,
            MachineState::StepFailed => FAILED,
            MachineState::Terminated => TERMINATED,
            MachineState::Error => ERROR,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            MachineState::Instantiated => "instantiated",
            MachineState::InitializationMode => "initializationMode",
            MachineState::StepComplete => "stepComplete",
            MachineState::StepFailed => "stepFailed",
            MachineState::Terminated => "terminated",
            MachineState::Error => "error",
        }
    }
    pub(crate) fn code(self) -> u8 {
        // The bits are 1 << 0 ..= 1 << 5, so the position fits a u8.
        u8::try_from(self.bit().trailing_zeros()).expect("a bit position of a u8")
    }
    pub(crate) fn from_code(c: u8) -> Option<Self> {
        [Self::Instantiated, Self::InitializationMode, Self::StepComplete, Self::StepFailed, Self::Terminated, Self::Error].into_iter().find(|s| s.code() == c)
    }
}

pub(crate) fn mask_names(mask: u8) -> String {
    let all = [MachineState::Instantiated, MachineState::InitializationMode, MachineState::StepComplete, MachineState::StepFailed, MachineState::Terminated];
    all.iter().filter(|s| s.bit() & mask != 0).map(|s| s.name()).collect::<Vec<_>>().join(", ")
}

/// The shell's part of an FMU state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clock {
    pub state: MachineState,
    pub time: f64,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub last_successful_time: f64,
    pub terminate_requested: bool,
}

impl Clock {
    pub(crate) fn new() -> Self {
        Clock { state: MachineState::Instantiated, time: 0.0, start_time: 0.0, stop_time: None, last_successful_time: 0.0, terminate_requested: false }
    }
}

/// Communication points are the master's: accept round-off (fmpy computes start + n·h, ecos
/// accumulates t += h, Dymola is off by 3e-12), never compare with `==`.
pub fn same_time(a: f64, b: f64, h: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0) + 1e-6 * h.abs()
}

impl Clock {
    /// The clock's part of a serialized FMU state.
    pub(crate) fn write(&self, w: &mut StateWriter) {
        w.u8(self.state.code());
        w.f64(self.time);
        w.f64(self.start_time);
        w.bool(self.stop_time.is_some());
        w.f64(self.stop_time.unwrap_or(0.0));
        w.f64(self.last_successful_time);
        w.bool(self.terminate_requested);
    }

    pub(crate) fn read(r: &mut StateReader<'_>) -> Result<Clock> {
        let code = r.u8()?;
        let state = MachineState::from_code(code).ok_or_else(|| Error::input(format!("serialized FMU state: {code} is not a machine state")))?;
        let (time, start_time, has_stop, stop) = (r.f64()?, r.f64()?, r.bool()?, r.f64()?);
        let (last_successful_time, terminate_requested) = (r.f64()?, r.bool()?);
        Ok(Clock { state, time, start_time, stop_time: has_stop.then_some(stop), last_successful_time, terminate_requested })
    }
}
