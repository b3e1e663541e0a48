//! periodic-contact: steady-state periodic responses of structures under unilateral contact,
//! computed as one linear complementarity problem over a discretised period
//! (Meingast, Legrand & Pierre, IJNLM 66, 2014).
//!
//! Flow: [`scene`] (TOML) → [`model`] → [`time`] (circulant symbols) → [`periodic`] (assembly,
//! LCP, recovery) → [`response`]. The [`lcp`] solvers know nothing of mechanics.
/// Sweeps, spectra and the comparison with time marching; the room for continuation,
/// stability and polish.
pub mod analysis;
/// The native C API (include/periodic_contact.h).
#[cfg(feature = "capi")]
pub mod capi;
/// The crate error: kinds every front end maps to its statuses.
pub mod error;
/// Semi-analytic periodic orbits: the independent references of the tests.
#[cfg(feature = "reference")]
pub mod exact;
/// Finite elements: Matrix Market input, DOF clamping, the blade model.
pub mod fe;
/// The FMI 2.0 co-simulation shell (knows nothing of contact).
pub mod fmi;
/// The FMU's physics adapter: a scene as a quasi-steady co-simulation model.
pub mod fmu_model;
/// LCP solvers; they know nothing of mechanics.
pub mod lcp;
/// Numerical building blocks shared by mechanics and LCP (the FFT plans); no mechanics.
pub mod linalg;
/// Explicit time marching with forward-increment Lagrange multipliers (the paper's reference).
#[cfg(feature = "reference")]
pub mod marching;
/// The mechanical model and its checks.
pub mod model;
/// Assembly in the frequency domain, the LCP of the period, recovery.
pub mod periodic;
#[cfg(feature = "plots")]
/// PNG line charts.
pub mod plot;
/// Craig–Bampton reduction and modal analysis.
pub mod reduction;
/// The periodic response as written to JSON.
pub mod response;
/// Scene files (TOML).
pub mod scene;
/// Studies: accuracy against cost, warm starts (`periodic-contact study`).
#[cfg(feature = "studies")]
pub mod study;
/// Time schemes as circulant symbols; pairing.
pub mod time;

pub use analysis::sweep;
pub use error::{Error, ErrorKind};
