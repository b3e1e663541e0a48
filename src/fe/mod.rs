//! Finite-element input: Matrix Market files, CalculiX's matrix output, node maps, DOF clamping,
//! the hexahedral element and the built-in blade generator.
pub mod blade;
pub mod calculix;
mod deck;
pub mod hex8;
pub mod mtx;
pub mod nodes;
pub mod sparse;

pub use blade::{Blade, BladeError, BladeParams, BladeSpec, MeshDensity, Preset, TIP_NODES};
pub use calculix::{CalculixError, CalculixModel, read_calculix};
pub use hex8::{ElementKind, Material};
pub use mtx::{MtxError, MtxErrorKind, parse_matrix_market, read_matrix_market, write_matrix_market};
pub use nodes::{NodeDofs, NodeError, NodeMap, axis_index};
pub use sparse::{ClampError, DofMap, clamp, clamp_structure};

/// Under `PERIODIC_CONTACT_PROFILE`: the calling thread's CPU time so far [s] (Linux
/// /proc/thread-self/schedstat, the figure to read on a loaded machine), for the set-up's profile.
pub(crate) fn profile_cpu() -> Option<f64> {
    std::env::var_os("PERIODIC_CONTACT_PROFILE")?;
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}
