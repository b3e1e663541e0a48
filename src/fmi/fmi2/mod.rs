//! The FMI 2.0 co-simulation shell over a [`CoSimModel`](crate::fmi::CoSimModel).
//!
//! - [`instance::Instance`]: the state machine with the allowed-call table, argument checks,
//!   communication-point tolerance, status getters and FMU states.
//! - [`ffi`]: the 34 C entry points as generic `unsafe fn`s over raw pointers, each body inside
//!   `catch_unwind`; [`export_fmi2!`](crate::export_fmi2) stamps out the `#[unsafe(no_mangle)]`
//!   symbols in the crate that builds the FMU binary.
//! - [`types`] (the C types of the headers), [`logger`] (the variadic callback), [`xml`]
//!   (`modelDescription.xml`).
//!
//! Error policy: an illegal call sequence, an invalid argument, an unknown value reference or a
//! failed initialisation returns `fmi2Error`, logs why (with the kind of the error: input,
//! limit, I/O or solver failure), and moves the instance to the *error* state, from which only
//! getters, `fmi2Reset`, `fmi2FreeInstance`, `fmi2SetFMUstate` (and the other FMU-state
//! functions) and `fmi2SetDebugLogging` are accepted. Optional functions this FMU does not
//! provide (directional derivatives, input derivatives, `fmi2CancelStep`) return `fmi2Error`
//! with a log line but leave the state alone, as do unknown log categories. Status kinds that
//! are not available (`fmi2DoStepStatus`, `fmi2PendingStatus`) give `fmi2Discard`. A failed
//! step gives `fmi2Discard`, the *stepFailed* state and `fmi2Terminated` = true. A panic is
//! caught, logged, and treated as an error (`fmi2Reset` rebuilds the model).
mod export;
pub mod ffi;
pub mod instance;
pub mod logger;
pub mod machine;
pub mod types;
pub mod xml;

pub use instance::Instance;
pub use logger::Logger;
pub use types::Status;
