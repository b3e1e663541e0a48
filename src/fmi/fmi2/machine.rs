//! The co-simulation state machine of FMI 2.0 (notes §1.3): the states, the masks of the
//! allowed-call table, and the clock an FMU state keeps.

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
    pub(crate) fn code(self) -> u64 {
        self.bit().trailing_zeros() as u64
    }
    pub(crate) fn from_code(c: u64) -> Option<Self> {
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
