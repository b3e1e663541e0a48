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
