//! Craig–Bampton reduction (src/formulation.md §4).
//!
//! Boundary DOFs x_b (every contact DOF, plus any extra DOF: forced or observed DOFs are best kept
//! there too) stay physical; internal DOFs x_i are represented by static modes
//! Ψ = −K_ii⁻¹ K_ib and η fixed-interface modes (K_ii − ω_r² M_ii) φ_r = 0, mass-normalised:
//!
//! x ≈ Φ q,  Φ = [[I, 0], [Ψ, Φ_η]],  q = [x_b; p],  M_r = Φᵀ M Φ,  K_r = Φᵀ K Φ.
//!
//! One sparse Cholesky factorisation of K_ii serves both Ψ (n_b solves) and the shift-invert
//! Lanczos for Φ_η. M_r and K_r are formed as Φᵀ(MΦ) and Φᵀ(KΦ) (a Rayleigh–Ritz projection, so
//! every reduced eigenfrequency bounds the full one from above, and adding modes can only lower
//! them). K_r is block-diagonal up to round-off: K_bb + K_bi Ψ and diag(ω_r²).
//!
//! Storage: the basis Φ is kept dense, n_full × (n_b + η) doubles, in the **full model's
//! numbering** (row d is full DOF d), so any full DOF can be recovered from q: x_d = Φ[d, :]·q.
//! For the fine blade (30 000 DOFs, 3 boundary DOFs, η = 20) that is 5.5 MB.
use super::eigen::{self, EigenError, LanczosOptions, Modes, dense_modes};
use crate::fe::sparse::{sparse_times_dense, submatrix};
use crate::model::{Matrix, Structure};
use faer::linalg::solvers::Solve;
use faer::sparse::SparseColMat;
use faer::{Mat, MatRef};
use std::time::Instant;

/// Fixed-interface modes kept by default. On the coarse blade with the three tip contact DOFs
/// as boundary, the first five eigenfrequencies of the reduced model are then within 1e-5 of
/// the full model's (measured 8.3e-6 worst; 0.1 % is already reached at η = 6, see
/// `tests/reduction.rs`); on the fine blade 2.0e-6.
pub const DEFAULT_MODES: usize = 20;

/// Why a reduction failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReductionError {
    #[error("boundary DOF {dof} is out of range: the model has {n} DOFs")]
    BoundaryOutOfRange { dof: usize, n: usize },
    #[error("boundary DOF {dof} is listed twice")]
    BoundaryRepeated { dof: usize },
    #[error("mass ({m}×{m}) and stiffness ({k}×{k}) sizes differ")]
    SizeMismatch { m: usize, k: usize },
    #[error("{requested} fixed-interface modes requested but only {internal} internal DOFs remain")]
    TooManyModes { requested: usize, internal: usize },
    #[error("K_ii (internal DOFs, boundary fixed) is not positive definite: is the structure clamped? ({0})")]
    InternalStiffness(String),
    #[error("fixed-interface modes: {0}")]
    Eigen(#[from] EigenError),
    #[error("damping: {0}")]
    Damping(String),
    #[error("K is not positive definite: is the structure clamped? ({0})")]
    Stiffness(String),
    #[error(
        "the residual flexibility at the boundary is not positive definite ({0}): the modes kept already span the boundary's static deflections; keep fewer free-interface modes (reduction.modes) or fewer boundary DOFs"
    )]
    ResidualFlexibility(String),
}

/// Which reduction made a [`ReducedModel`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Craig–Bampton: q = [x_b; p], fixed-interface modes (src/formulation.md §4).
    CraigBampton,
    /// Massless boundary (MacNeal's residual flexibility): q = [u_b; q_modal], free-interface
    /// modes, the boundary coordinates carry neither mass nor damping (src/formulation.md §4.1).
    MasslessBoundary,
}

/// Settings of the reduction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CraigBamptonOptions {
    /// Number η of fixed-interface modes.
    pub modes: usize,
    pub lanczos: LanczosOptions,
}

impl Default for CraigBamptonOptions {
    fn default() -> Self {
        CraigBamptonOptions { modes: DEFAULT_MODES, lanczos: LanczosOptions::default() }
    }
}

/// Damping of the reduced model.
#[derive(Clone, Debug)]
pub enum Damping {
    None,
    /// C = αM + βK on the full model, projected: C_r = α M_r + β K_r (exact projection).
    Rayleigh {
        alpha: f64,
        beta: f64,
    },
    /// Modal damping ratios ζ_j on the modes of the reduced model (ascending frequency; the last
    /// ratio is repeated for the remaining modes): C_r = M_r Φ_r diag(2 ζ_j ω_j) Φ_rᵀ M_r.
    ModalRatios(Vec<f64>),
    /// A full damping matrix, projected: C_r = Φᵀ C Φ.
    Matrix(SparseColMat<usize, f64>),
}

/// Wall times of the steps [s].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Extracting K_ii, K_ib, M_ii and factorising K_ii.
    pub factor: f64,
    /// Static modes Ψ (n_b solves).
    pub static_modes: f64,
    /// Fixed-interface modes (Lanczos).
    pub eigen: f64,
    /// Φᵀ M Φ, Φᵀ K Φ.
    pub projection: f64,
    pub total: f64,
}

/// A Craig–Bampton reduced model. Reduced coordinates: q = [x_b (in the order of `boundary`); p].
#[derive(Clone, Debug)]
pub struct ReducedModel {
    pub method: Method,
    /// DOF count of the full model.
    pub n_full: usize,
    /// Full-model DOFs kept physical; reduced coordinate i < n_b is full DOF `boundary[i]`.
    pub boundary: Vec<usize>,
    /// Reduced mass M_r ((n_b + η)², dense, symmetric).
    pub mass: Mat<f64>,
    /// Reduced stiffness K_r.
    pub stiffness: Mat<f64>,
    /// Reduced damping C_r, if any.
    pub damping: Option<Mat<f64>>,
    /// Fixed-interface (Craig–Bampton) or free-interface (massless boundary) eigenfrequencies
    /// ω_r [rad/s] of the modes kept.
    pub interface_omega: Vec<f64>,
    /// Relative residuals of those modes, ‖K_ii φ − ω² M_ii φ‖ / ‖K_ii φ‖.
    pub interface_residual: Vec<f64>,
    pub timings: Timings,
    /// Φ, n_full × (n_b + η), full numbering.
    pub(super) basis: Mat<f64>,
    /// Massless boundary only: the free-interface modes at the boundary DOFs Φ_b (n_b × η), to
    /// rebuild Φ = T_q + Ψ Φ_b for a projected damping matrix.
    pub(super) modes_at_boundary: Option<Mat<f64>>,
}

impl ReducedModel {
    /// Number of reduced coordinates n_b + η.
    pub fn n(&self) -> usize {
        self.basis.ncols()
    }
    pub fn n_boundary(&self) -> usize {
        self.boundary.len()
    }
    pub fn n_modes(&self) -> usize {
        self.n() - self.n_boundary()
    }
    /// The reduced coordinate of a boundary DOF (the engine's DOF index for a contact on it).
    pub fn reduced_dof(&self, full_dof: usize) -> Option<usize> {
        self.boundary.iter().position(|&b| b == full_dof)
    }
    /// Row `full_dof` of Φ: x[full_dof] = Σ_k row[k]·q[k]. For a boundary DOF it is a unit row.
    /// A force f on full DOF d projects to the reduced force row·f (f_r = Φᵀ f).
    pub fn basis_row(&self, full_dof: usize) -> Vec<f64> {
        (0..self.n()).map(|k| self.basis[(full_dof, k)]).collect()
    }
    /// The whole basis Φ (n_full × (n_b + η)).
    pub fn basis(&self) -> MatRef<'_, f64> {
        self.basis.as_ref()
    }
    /// The full displacement vector Φ q.
    pub fn recover(&self, q: &[f64]) -> Vec<f64> {
        assert_eq!(q.len(), self.n());
        (0..self.n_full).map(|d| (0..self.n()).map(|k| self.basis[(d, k)] * q[k]).sum()).collect()
    }
    /// Selected full DOFs of Φ q.
    pub fn recover_dofs(&self, q: &[f64], dofs: &[usize]) -> Vec<f64> {
        dofs.iter().map(|&d| (0..self.n()).map(|k| self.basis[(d, k)] * q[k]).sum()).collect()
    }
    /// Φᵀ f for a full-model force vector.
    pub fn project_vector(&self, f: &[f64]) -> Vec<f64> {
        assert_eq!(f.len(), self.n_full);
        (0..self.n()).map(|k| (0..self.n_full).map(|d| self.basis[(d, k)] * f[d]).sum()).collect()
    }
    /// Φᵀ A Φ for a full-model sparse matrix.
    pub fn project_matrix(&self, a: &SparseColMat<usize, f64>) -> Mat<f64> {
        let ab = sparse_times_dense(a, self.basis.as_ref());
        symmetric(self.basis.transpose() * ab)
    }
    /// Sets the reduced damping.
    pub fn set_damping(&mut self, damping: &Damping) -> Result<(), ReductionError> {
        if self.method == Method::MasslessBoundary {
            self.damping = super::massless::damping(self, damping)?;
            return Ok(());
        }
        self.damping = match damping {
            Damping::None => None,
            Damping::Rayleigh { alpha, beta } => Some(Mat::from_fn(self.n(), self.n(), |i, j| alpha * self.mass[(i, j)] + beta * self.stiffness[(i, j)])),
            Damping::Matrix(c) => {
                if c.nrows() != self.n_full || c.ncols() != self.n_full {
                    return Err(ReductionError::Damping(format!("the damping matrix is {}×{}, the model has {} DOFs", c.nrows(), c.ncols(), self.n_full)));
                }
                Some(self.project_matrix(c))
            }
            Damping::ModalRatios(z) => {
                check_ratios(z)?;
                let modes = dense_modes(self.stiffness.as_ref(), self.mass.as_ref(), self.n())?;
                let n = self.n();
                let mphi = &self.mass * &modes.shapes;
                let d = Mat::from_fn(n, n, |i, j| if i == j { 2.0 * z[i.min(z.len() - 1)] * modes.omega[i] } else { 0.0 });
                Some(symmetric(&mphi * d * mphi.transpose()))
            }
        };
        Ok(())
    }
    /// The reduced structure for the engine (dense M_r, K_r, C_r).
    pub fn structure(&self) -> Structure {
        Structure { mass: Matrix::Dense(self.mass.clone()), stiffness: Matrix::Dense(self.stiffness.clone()), damping: self.damping.clone().map(Matrix::Dense) }
    }
    /// Bytes held by the basis.
    pub fn basis_bytes(&self) -> usize {
        8 * self.basis.nrows() * self.basis.ncols()
    }
    /// The lowest `count` eigenmodes of the reduced model (dense).
    pub fn modes(&self, count: usize) -> Result<Modes, EigenError> {
        dense_modes(self.stiffness.as_ref(), self.mass.as_ref(), count)
    }
}

/// Modal damping ratios: at least one, each finite and ≥ 0.
pub(super) fn check_ratios(z: &[f64]) -> Result<(), ReductionError> {
    if z.is_empty() {
        return Err(ReductionError::Damping("no modal damping ratio given".into()));
    }
    if let Some(bad) = z.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(ReductionError::Damping(format!("modal damping ratio {bad} is not a finite number ≥ 0")));
    }
    Ok(())
}

/// The boundary as a mask over the full model's DOFs, checked (in range, no repeats), after
/// checking that M and K have the same size.
pub(super) fn boundary_mask(k: &SparseColMat<usize, f64>, m: &SparseColMat<usize, f64>, boundary: &[usize]) -> Result<Vec<bool>, ReductionError> {
    let n = k.nrows();
    if m.nrows() != n || k.ncols() != n || m.ncols() != n {
        return Err(ReductionError::SizeMismatch { m: m.nrows(), k: n });
    }
    let mut is_b = vec![false; n];
    for &d in boundary {
        if d >= n {
            return Err(ReductionError::BoundaryOutOfRange { dof: d, n });
        }
        if is_b[d] {
            return Err(ReductionError::BoundaryRepeated { dof: d });
        }
        is_b[d] = true;
    }
    Ok(is_b)
}

pub(super) fn symmetric(a: Mat<f64>) -> Mat<f64> {
    let n = a.nrows();
    Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// Reduces (K, M) keeping `boundary` (full-model DOFs, any order, no repeats) physical.
pub fn craig_bampton(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    boundary: &[usize],
    opts: &CraigBamptonOptions,
) -> Result<ReducedModel, ReductionError> {
    let t0 = Instant::now();
    let n = k.nrows();
    let is_b = boundary_mask(k, m, boundary)?;
    let nb = boundary.len();
    let internal: Vec<usize> = (0..n).filter(|&d| !is_b[d]).collect();
    let ni = internal.len();
    if opts.modes > ni {
        return Err(ReductionError::TooManyModes { requested: opts.modes, internal: ni });
    }
    let r = nb + opts.modes;
    let mut basis = Mat::<f64>::zeros(n, r);
    for (i, &d) in boundary.iter().enumerate() {
        basis[(d, i)] = 1.0;
    }
    let mut timings = Timings::default();
    let mut interface_omega = Vec::new();
    let mut interface_residual = Vec::new();
    if ni > 0 {
        let mut imap = vec![None; n];
        for (p, &d) in internal.iter().enumerate() {
            imap[d] = Some(p);
        }
        let mut bmap = vec![None; n];
        for (p, &d) in boundary.iter().enumerate() {
            bmap[d] = Some(p);
        }
        let k_ii = submatrix(k, &imap, &imap, ni, ni);
        let m_ii = submatrix(m, &imap, &imap, ni, ni);
        let k_ib = crate::fe::sparse::dense_submatrix(k, &imap, &bmap, ni, nb);
        let llt = eigen::cholesky(&k_ii).map_err(|e| ReductionError::InternalStiffness(e.to_string()))?;
        timings.factor = t0.elapsed().as_secs_f64();

        let t1 = Instant::now();
        let mut psi = -k_ib;
        if nb > 0 {
            llt.solve_in_place(psi.as_mut());
        }
        timings.static_modes = t1.elapsed().as_secs_f64();

        let t2 = Instant::now();
        // With η = 0 one mode is still computed, to detect a singular K_ii.
        let mut modes = eigen::lanczos(&k_ii, &m_ii, &llt, opts.modes.max(1), &opts.lanczos).map_err(|e| match e {
            EigenError::Singular { .. } => ReductionError::InternalStiffness(e.to_string()),
            e => ReductionError::Eigen(e),
        })?;
        if opts.modes == 0 {
            modes = Modes { omega: vec![], shapes: Mat::zeros(ni, 0), residual: vec![], krylov_dim: modes.krylov_dim };
        }
        timings.eigen = t2.elapsed().as_secs_f64();
        interface_omega = modes.omega.clone();
        interface_residual = modes.residual.clone();

        for (p, &d) in internal.iter().enumerate() {
            for j in 0..nb {
                basis[(d, j)] = psi[(p, j)];
            }
            for j in 0..opts.modes {
                basis[(d, nb + j)] = modes.shapes[(p, j)];
            }
        }
    }
    let t3 = Instant::now();
    let mass = symmetric(basis.transpose() * sparse_times_dense(m, basis.as_ref()));
    let stiffness = symmetric(basis.transpose() * sparse_times_dense(k, basis.as_ref()));
    timings.projection = t3.elapsed().as_secs_f64();
    timings.total = t0.elapsed().as_secs_f64();
    Ok(ReducedModel {
        method: Method::CraigBampton,
        n_full: n,
        boundary: boundary.to_vec(),
        mass,
        stiffness,
        damping: None,
        interface_omega,
        interface_residual,
        timings,
        basis,
        modes_at_boundary: None,
    })
}

/// A sparse matrix as it is (no copy of a real blade's 4 million entries), a dense one converted.
fn sparse_view(a: &Matrix) -> std::borrow::Cow<'_, SparseColMat<usize, f64>> {
    match a {
        Matrix::Sparse(s) => std::borrow::Cow::Borrowed(s),
        Matrix::Dense(_) => std::borrow::Cow::Owned(to_sparse(a)),
    }
}

/// Converts the engine's matrix to sparse (dense input is scanned for non-zeros).
pub fn to_sparse(a: &Matrix) -> SparseColMat<usize, f64> {
    match a {
        Matrix::Sparse(s) => s.clone(),
        Matrix::Dense(d) => {
            let mut t = Vec::new();
            for j in 0..d.ncols() {
                for i in 0..d.nrows() {
                    if d[(i, j)] != 0.0 {
                        t.push(faer::sparse::Triplet::new(i, j, d[(i, j)]));
                    }
                }
            }
            SparseColMat::try_new_from_triplets(d.nrows(), d.ncols(), &t).expect("in range")
        }
    }
}

/// Reduces an engine [`Structure`] by `method`. Its damping matrix, if any, is projected
/// (Φᵀ C Φ) unless `damping` is given, which then replaces it.
pub fn reduce_structure(
    s: &Structure,
    method: Method,
    boundary: &[usize],
    opts: &CraigBamptonOptions,
    damping: Option<&Damping>,
) -> Result<ReducedModel, ReductionError> {
    let (k, m) = (sparse_view(&s.stiffness), sparse_view(&s.mass));
    let mut red = match method {
        Method::CraigBampton => craig_bampton(&k, &m, boundary, opts)?,
        Method::MasslessBoundary => super::massless::massless_boundary(&k, &m, boundary, opts)?,
    };
    match (damping, &s.damping) {
        (Some(d), _) => red.set_damping(d)?,
        (None, Some(c)) => red.set_damping(&Damping::Matrix(to_sparse(c)))?,
        (None, None) => {}
    }
    Ok(red)
}
