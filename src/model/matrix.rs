//! Structural matrices, dense or sparse, behind one type.
use faer::Mat;
use faer::sparse::SparseColMat;

#[derive(Clone, Debug)]
pub enum Matrix {
    Dense(Mat<f64>),
    /// Compressed sparse column, both triangles stored.
    Sparse(SparseColMat<usize, f64>),
}

/// Equal when of the same shape with the same entries (a stored zero equals a missing one).
impl PartialEq for Matrix {
    fn eq(&self, other: &Matrix) -> bool {
        if (self.nrows(), self.ncols()) != (other.nrows(), other.ncols()) {
            return false;
        }
        let mut same = true;
        self.for_each(|i, j, v| same &= other.get(i, j) == v);
        other.for_each(|i, j, v| same &= self.get(i, j) == v);
        same
    }
}

impl Matrix {
    pub fn from_rows(rows: &[Vec<f64>]) -> Matrix {
        let n = rows.len();
        let c = rows.first().map_or(0, |r| r.len());
        Matrix::Dense(Mat::from_fn(n, c, |i, j| rows[i][j]))
    }
    pub fn nrows(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.nrows(),
            Matrix::Sparse(m) => m.nrows(),
        }
    }
    pub fn ncols(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.ncols(),
            Matrix::Sparse(m) => m.ncols(),
        }
    }
    /// Entry (i, j); O(1) dense, O(log nnz(col)) sparse.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        match self {
            Matrix::Dense(m) => m[(i, j)],
            Matrix::Sparse(m) => {
                let rows = m.row_idx_of_col_raw(j);
                let vals = m.val_of_col(j);
                rows.binary_search(&i).map_or(0.0, |p| vals[p])
            }
        }
    }
    /// Visit every stored entry (i, j, v).
    pub fn for_each(&self, mut f: impl FnMut(usize, usize, f64)) {
        match self {
            Matrix::Dense(m) => {
                for j in 0..m.ncols() {
                    for i in 0..m.nrows() {
                        f(i, j, m[(i, j)]);
                    }
                }
            }
            Matrix::Sparse(m) => {
                for j in 0..m.ncols() {
                    for (&i, &v) in m.row_idx_of_col_raw(j).iter().zip(m.val_of_col(j)) {
                        f(i, j, v);
                    }
                }
            }
        }
    }
    /// A dense copy (for small models and tests).
    pub fn to_dense(&self) -> Mat<f64> {
        match self {
            Matrix::Dense(m) => m.clone(),
            Matrix::Sparse(s) => {
                let mut d = Mat::zeros(s.nrows(), s.ncols());
                self.for_each(|i, j, v| d[(i, j)] += v);
                let _ = s;
                d
            }
        }
    }
    /// y = A x.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        self.for_each(|i, j, v| y[i] += v * x[j]);
    }
    /// α·self + β·other, same kind when both agree (sparse otherwise), of self's shape.
    ///
    /// Operands of different sizes never panic: entries of `other` outside self's shape are
    /// dropped. Such a result is never used, since [`crate::model::Model::validate`] refuses the
    /// mismatched operand; but the scene builds Rayleigh damping C = αM + βK before validating,
    /// and a 2×2 M with a 1×1 K used to panic here (found by tests/props.rs).
    pub fn lincomb(&self, alpha: f64, other: &Matrix, beta: f64) -> Matrix {
        let (r, c) = (self.nrows(), self.ncols());
        match (self, other) {
            (Matrix::Dense(a), Matrix::Dense(b)) => Matrix::Dense(Mat::from_fn(r, c, |i, j| {
                let bij = if i < b.nrows() && j < b.ncols() { b[(i, j)] } else { 0.0 };
                alpha * a[(i, j)] + beta * bij
            })),
            _ => {
                let mut t = Vec::new();
                self.for_each(|i, j, v| t.push(faer::sparse::Triplet::new(i, j, alpha * v)));
                other.for_each(|i, j, v| {
                    if i < r && j < c {
                        t.push(faer::sparse::Triplet::new(i, j, beta * v))
                    }
                });
                Matrix::Sparse(SparseColMat::try_new_from_triplets(r, c, &t).expect("triplets within the shape"))
            }
        }
    }
    pub fn is_sparse(&self) -> bool {
        matches!(self, Matrix::Sparse(_))
    }
}

impl Matrix {
    /// The block of rows `rows` and columns `cols` (in that order), of the same kind.
    pub fn block(&self, rows: &[usize], cols: &[usize]) -> Matrix {
        let map = |idx: &[usize], n: usize| {
            let mut m = vec![usize::MAX; n];
            idx.iter().enumerate().for_each(|(new, &old)| m[old] = new);
            m
        };
        let (rm, cm) = (map(rows, self.nrows()), map(cols, self.ncols()));
        match self {
            Matrix::Dense(d) => Matrix::Dense(Mat::from_fn(rows.len(), cols.len(), |i, j| d[(rows[i], cols[j])])),
            Matrix::Sparse(_) => {
                let mut t = Vec::new();
                self.for_each(|i, j, v| {
                    if rm[i] != usize::MAX && cm[j] != usize::MAX {
                        t.push(faer::sparse::Triplet::new(rm[i], cm[j], v));
                    }
                });
                Matrix::Sparse(SparseColMat::try_new_from_triplets(rows.len(), cols.len(), &t).expect("triplets within the block"))
            }
        }
    }
    /// Whether a Cholesky factorisation (lower triangle) succeeds: symmetric positive definite.
    pub fn is_positive_definite(&self) -> bool {
        match self {
            Matrix::Dense(m) => m.llt(faer::Side::Lower).is_ok(),
            Matrix::Sparse(s) => s.sp_cholesky(faer::Side::Lower).is_ok(),
        }
    }
}
