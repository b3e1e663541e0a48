//! Numerical building blocks shared by the mechanics and the LCP solvers.
//!
//! This room depends on nothing of the crate (no mechanics, no LCP): only on the numerical crates
//! (realfft/rustfft). Whatever both `periodic` and `lcp` need goes here, so that neither imports
//! the other's internals.
pub mod fft;

pub use fft::PeriodFft;
