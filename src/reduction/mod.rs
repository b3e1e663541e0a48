//! Model reduction (Craig–Bampton, massless boundary) and modal analysis.
pub mod craig_bampton;
pub mod eigen;
mod massless;

pub use craig_bampton::{
    CraigBamptonOptions, DEFAULT_MODES, Damping, Method, ReducedModel, ReductionError, Timings, craig_bampton, reduce_structure, to_sparse,
};
pub use eigen::{EigenError, LanczosOptions, Modes, dense_modes, lanczos, sparse_modes, symmetric_eigen};
pub use massless::massless_boundary;

use crate::model::Matrix;
use std::f64::consts::PI;
use std::fmt;

/// The lowest `count` eigenmodes of a model given as the engine's matrices: sparse shift-invert
/// Lanczos when K is sparse, the dense LLᵀ solver otherwise.
pub fn modes(stiffness: &Matrix, mass: &Matrix, count: usize) -> Result<Modes, EigenError> {
    match (stiffness, mass) {
        (Matrix::Dense(k), Matrix::Dense(m)) => dense_modes(k.as_ref(), m.as_ref(), count),
        _ => sparse_modes(&to_sparse(stiffness), &to_sparse(mass), count),
    }
}

/// One line of [`ModeTable`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeRow {
    /// 1-based mode number.
    pub mode: usize,
    pub full_rad_s: f64,
    pub full_hz: f64,
    pub reduced_rad_s: f64,
    pub reduced_hz: f64,
    /// (reduced − full) / full.
    pub rel_diff: f64,
}

/// Full versus reduced eigenfrequencies, for `periodic-contact modes`.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeTable {
    pub rows: Vec<ModeRow>,
    /// DOFs of the full and of the reduced model.
    pub n_full: usize,
    pub n_reduced: usize,
}

impl ModeTable {
    /// Computes the `count` lowest eigenfrequencies of the full model (sparse Lanczos when the
    /// matrices are sparse) and of the reduced model (dense), side by side.
    pub fn compare(stiffness: &Matrix, mass: &Matrix, reduced: &ReducedModel, count: usize) -> Result<ModeTable, EigenError> {
        let count = count.min(reduced.n()).min(stiffness.nrows());
        let full = modes(stiffness, mass, count)?;
        let red = reduced.modes(count)?;
        Ok(ModeTable::from_omegas(&full.omega, &red.omega, stiffness.nrows(), reduced.n()))
    }
    /// Builds the table from two lists of ω [rad/s] (the shorter length is used).
    pub fn from_omegas(full: &[f64], reduced: &[f64], n_full: usize, n_reduced: usize) -> ModeTable {
        let rows = full
            .iter()
            .zip(reduced)
            .enumerate()
            .map(|(i, (&f, &r))| ModeRow {
                mode: i + 1,
                full_rad_s: f,
                full_hz: f / (2.0 * PI),
                reduced_rad_s: r,
                reduced_hz: r / (2.0 * PI),
                rel_diff: (r - f) / f,
            })
            .collect();
        ModeTable { rows, n_full, n_reduced }
    }
}

impl fmt::Display for ModeTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "mode  full [Hz] ({} DOFs)   reduced [Hz] ({} DOFs)   full [rad/s]    reduced [rad/s]   rel. diff", self.n_full, self.n_reduced)?;
        for r in &self.rows {
            writeln!(
                f,
                "{:>4}  {:>22.6}   {:>25.6}   {:>13.4}   {:>15.4}   {:>+10.3e}",
                r.mode, r.full_hz, r.reduced_hz, r.full_rad_s, r.reduced_rad_s, r.rel_diff
            )?;
        }
        Ok(())
    }
}
