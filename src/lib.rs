//! periodic-contact: steady-state periodic responses of structures under unilateral contact,
//! computed as one linear complementarity problem over a discretised period
//! (Meingast, Legrand & Pierre, IJNLM 66, 2014).
//!
//! Flow: [`scene`] (TOML) → [`model`] → [`time`] (circulant symbols) → [`periodic`] (assembly,
//! LCP, recovery) → [`response`]. The [`lcp`] solvers know nothing of mechanics.
pub mod lcp;
pub mod model;
pub mod time;
pub mod periodic;
pub mod response;
pub mod scene;
pub mod defaults;
pub mod fmi2;
pub mod fmu_model;
#[cfg(feature = "capi")]
pub mod capi;
