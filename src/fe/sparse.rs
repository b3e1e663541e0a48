//! Sparse helpers: DOF clamping (removal), sub-matrices, sparse × dense products.
use crate::model::Matrix;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Accum, Mat, MatRef, Par};

/// A DOF that cannot be clamped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClampError {
    #[error("fixed DOF {dof} is out of range: the model has {n} DOFs (0-based indices 0..{n})")]
    OutOfRange { dof: usize, n: usize },
    #[error("every one of the {n} DOFs is fixed; nothing is left to solve for")]
    Everything { n: usize },
}

/// The numbering after removing fixed DOFs.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    /// For each original DOF: its index in the clamped model, or `None` if it is fixed.
    pub old_to_new: Vec<Option<usize>>,
    /// For each clamped-model DOF: its original index (increasing).
    pub new_to_old: Vec<usize>,
}

impl DofMap {
    /// Removes the DOFs `fixed` (0-based, any order, repeats allowed) out of `n`.
    pub fn clamping(n: usize, fixed: &[usize]) -> Result<DofMap, ClampError> {
        let mut keep = vec![true; n];
        for &d in fixed {
            if d >= n {
                return Err(ClampError::OutOfRange { dof: d, n });
            }
            keep[d] = false;
        }
        let new_to_old: Vec<usize> = (0..n).filter(|&d| keep[d]).collect();
        if new_to_old.is_empty() {
            return Err(ClampError::Everything { n });
        }
        let mut old_to_new = vec![None; n];
        for (k, &d) in new_to_old.iter().enumerate() {
            old_to_new[d] = Some(k);
        }
        Ok(DofMap { old_to_new, new_to_old })
    }
    /// The identity map on `n` DOFs.
    pub fn identity(n: usize) -> DofMap {
        DofMap { old_to_new: (0..n).map(Some).collect(), new_to_old: (0..n).collect() }
    }
    pub fn n_old(&self) -> usize {
        self.old_to_new.len()
    }
    pub fn n_new(&self) -> usize {
        self.new_to_old.len()
    }
    /// The clamped-model index of original DOF `old` (`None` if fixed or out of range).
    pub fn new_index(&self, old: usize) -> Option<usize> {
        self.old_to_new.get(old).copied().flatten()
    }
    /// Keeps the rows and columns of the free DOFs of a square sparse matrix.
    pub fn apply(&self, a: &SparseColMat<usize, f64>) -> SparseColMat<usize, f64> {
        assert_eq!(a.nrows(), self.n_old(), "matrix size does not match the DOF map");
        submatrix(a, &self.old_to_new, &self.old_to_new, self.n_new(), self.n_new())
    }
    /// Same as [`DofMap::apply`] for the engine's matrix type (dense stays dense).
    pub fn apply_matrix(&self, a: &Matrix) -> Matrix {
        match a {
            Matrix::Sparse(s) => Matrix::Sparse(self.apply(s)),
            Matrix::Dense(d) => {
                let m = &self.new_to_old;
                Matrix::Dense(Mat::from_fn(m.len(), m.len(), |i, j| d[(m[i], m[j])]))
            }
        }
    }
}

/// Removes the DOFs `fixed` from a square sparse matrix: returns the clamped matrix and the map
/// from the old to the new numbering. Apply the same map to M, C and K with [`DofMap::apply`].
pub fn clamp(a: &SparseColMat<usize, f64>, fixed: &[usize]) -> Result<(SparseColMat<usize, f64>, DofMap), ClampError> {
    let map = DofMap::clamping(a.nrows(), fixed)?;
    Ok((map.apply(a), map))
}

/// The sub-matrix with rows `row_map[i] = Some(new_i)` and columns `col_map[j] = Some(new_j)`.
pub fn submatrix(a: &SparseColMat<usize, f64>, row_map: &[Option<usize>], col_map: &[Option<usize>], nrows: usize, ncols: usize) -> SparseColMat<usize, f64> {
    let mut t = Vec::new();
    for j in 0..a.ncols() {
        let Some(nj) = col_map[j] else { continue };
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if let Some(ni) = row_map[i] {
                t.push(Triplet::new(ni, nj, v));
            }
        }
    }
    SparseColMat::try_new_from_triplets(nrows, ncols, &t).expect("indices are in range")
}

/// A dense copy of the sub-matrix (rows `row_map`, columns `col_map`).
pub fn dense_submatrix(a: &SparseColMat<usize, f64>, rows: &[Option<usize>], cols: &[Option<usize>], nrows: usize, ncols: usize) -> Mat<f64> {
    let mut d = Mat::zeros(nrows, ncols);
    for j in 0..a.ncols() {
        let Some(nj) = cols[j] else { continue };
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if let Some(ni) = rows[i] {
                d[(ni, nj)] += v;
            }
        }
    }
    d
}

/// A · X for sparse A and dense X. One pass over A for all columns of X (X is copied to a
/// row-major buffer): several times faster than column-by-column products, which are limited
/// by memory bandwidth.
pub fn sparse_times_dense(a: &SparseColMat<usize, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    let (n, m, p) = (a.nrows(), a.ncols(), x.ncols());
    assert_eq!(x.nrows(), m, "sparse_times_dense: shapes do not match");
    if p <= 1 {
        let mut y = Mat::zeros(n, p);
        faer::sparse::linalg::matmul::sparse_dense_matmul(y.as_mut(), Accum::Replace, a.as_ref(), x, 1.0, Par::Seq);
        return y;
    }
    let mut xr = vec![0.0; m * p];
    for k in 0..p {
        for j in 0..m {
            xr[j * p + k] = x[(j, k)];
        }
    }
    let mut yr = vec![0.0; n * p];
    for j in 0..m {
        let xj = &xr[j * p..(j + 1) * p];
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            let yi = &mut yr[i * p..(i + 1) * p];
            for (y, &xv) in yi.iter_mut().zip(xj) {
                *y += v * xv;
            }
        }
    }
    Mat::from_fn(n, p, |i, k| yr[i * p + k])
}

/// y = A x for a sparse A.
pub fn sparse_mul_vec(a: &SparseColMat<usize, f64>, x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for j in 0..a.ncols() {
        let xj = x[j];
        if xj == 0.0 {
            continue;
        }
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            y[i] += v * xj;
        }
    }
}

/// The largest |A_ij − A_ji| relative to the largest |A_ij|.
pub fn asymmetry(a: &SparseColMat<usize, f64>) -> f64 {
    let scale = a.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            let rows = a.row_idx_of_col_raw(i);
            let t = rows.binary_search(&j).map_or(0.0, |p| a.val_of_col(i)[p]);
            worst = worst.max((v - t).abs());
        }
    }
    if scale > 0.0 { worst / scale } else { 0.0 }
}

/// Removes the DOFs `fixed` from M, K and C (if any) of a structure, consistently.
pub fn clamp_structure(s: &crate::model::Structure, fixed: &[usize]) -> Result<(crate::model::Structure, DofMap), ClampError> {
    let map = DofMap::clamping(s.mass.nrows(), fixed)?;
    let out = crate::model::Structure {
        mass: map.apply_matrix(&s.mass),
        stiffness: map.apply_matrix(&s.stiffness),
        damping: s.damping.as_ref().map(|c| map.apply_matrix(c)),
    };
    Ok((out, map))
}
