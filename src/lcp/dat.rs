//! Siconos dense `.dat` LCP format (placeholder: being written).
use super::DenseMatrix;
use std::path::Path;
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct DatError(pub String);
pub fn read_dat(path: &Path) -> Result<(DenseMatrix, Vec<f64>), DatError> { Err(DatError(format!("{}: not yet", path.display()))) }
