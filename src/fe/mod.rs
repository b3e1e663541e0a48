//! Finite-element input: Matrix Market files, DOF clamping, the hexahedral element and the
//! built-in blade generator.
pub mod blade;
pub mod hex8;
pub mod mtx;
pub mod sparse;

pub use blade::{Blade, BladeError, BladeParams, BladeSpec, MeshDensity, Preset, TIP_NODES};
pub use hex8::{ElementKind, Material};
pub use mtx::{parse_matrix_market, read_matrix_market, write_matrix_market, MtxError, MtxErrorKind};
pub use sparse::{clamp, clamp_structure, ClampError, DofMap};
