//! What is computed from solved periodic responses: sweeps over a parameter, spectra, and the
//! comparison with time marching.
//!
//! This is the room for the analyses that call the solver session ([`crate::periodic::PeriodicSolver`])
//! many times or post-process its responses: continuation of branches through folds, Floquet
//! stability and bifurcations, and an event-fitted polish each go here as a module of their
//! own, beside [`sweep`] (a sweep is the simplest continuation: fixed steps, no predictor).
//! [`accuracy`] gives every result an error estimate; [`interpolant`] the response between the
//! instants for the front ends.
pub mod accuracy;
pub mod continuation;
pub mod hysteresis;
pub mod interpolant;
pub mod polish;
pub mod scheme_auto;
pub mod sweep;
