//! Lowest modes of K φ = ω² M φ (K, M symmetric; K positive definite; M positive semi-definite).
//!
//! - Sparse: shift-invert block Lanczos on the operator K⁻¹M, which is self-adjoint in the
//!   M inner product. One sparse Cholesky factorisation of K (faer `sp_cholesky`, reusable: the
//!   Craig–Bampton reduction passes the factor it already has for the static modes). Full
//!   M-reorthogonalisation (classical Gram–Schmidt, twice), exact Rayleigh–Ritz on the projected
//!   matrix Qᵀ M K⁻¹ M Q, Ritz residual estimates from the last block, and a final check of the
//!   true residual ‖K φ − ω² M φ‖ / ‖K φ‖. Memory: the Krylov basis, n × (dimension) doubles.
//! - Dense: M = LLᵀ, eigen of L⁻¹ K L⁻ᵀ, φ = L⁻ᵀ y (for small, e.g. reduced, models).
//!
//! Every mode returned is mass-normalised (φᵀ M φ = 1) and signed so that its largest-magnitude
//! entry is positive.
use crate::fe::sparse::sparse_times_dense;
use faer::linalg::solvers::Solve;
use faer::sparse::SparseColMat;
use faer::sparse::linalg::solvers::Llt;
use faer::{Mat, MatRef, Side};

/// Why modes could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EigenError {
    #[error("the stiffness matrix is not positive definite (is every rigid-body motion clamped?): {0}")]
    StiffnessNotDefinite(String),
    #[error("the mass matrix is not positive definite: {0}")]
    MassNotDefinite(String),
    #[error("mass ({m}×{m}) and stiffness ({k}×{k}) sizes differ")]
    SizeMismatch { m: usize, k: usize },
    #[error("{requested} modes requested from a model with {n} DOFs")]
    TooManyModes { requested: usize, n: usize },
    #[error("Lanczos did not converge: {converged} of {requested} modes after a {dim}-dimensional Krylov space")]
    NotConverged { converged: usize, requested: usize, dim: usize },
    #[error("the eigen decomposition failed: {0}")]
    Decomposition(String),
    #[error(
        "the stiffness matrix is singular to working precision (lowest ω² = {omega2:e}, against a stiffness/mass scale of {scale:e}): \
         is every rigid-body motion clamped?"
    )]
    Singular { omega2: f64, scale: f64 },
    #[error("mode {mode} did not converge: relative residual {residual:e}")]
    Inaccurate { mode: usize, residual: f64 },
}

/// max diag(K) / max diag(M): the scale of ω² for a singularity test.
fn stiffness_mass_scale(k: &SparseColMat<usize, f64>, m: &SparseColMat<usize, f64>) -> f64 {
    let diag_max = |a: &SparseColMat<usize, f64>| {
        (0..a.ncols())
            .map(|j| {
                let rows = a.row_idx_of_col_raw(j);
                rows.binary_search(&j).map_or(0.0, |p| a.val_of_col(j)[p].abs())
            })
            .fold(0.0f64, f64::max)
    };
    diag_max(k) / diag_max(m)
}

/// Lanczos settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LanczosOptions {
    /// Relative Ritz residual ‖K⁻¹Mφ − θφ‖_M / θ below which a mode counts as converged.
    pub tol: f64,
    /// Block size (finds eigenvalues of multiplicity up to this).
    pub block: usize,
    /// Largest Krylov dimension before giving up (capped at n).
    pub max_dim: usize,
    /// Seed of the deterministic start block.
    pub seed: u64,
}

impl Default for LanczosOptions {
    fn default() -> Self {
        LanczosOptions { tol: 1e-10, block: 4, max_dim: 2000, seed: 0x5eed_c0de }
    }
}

/// Modes in ascending frequency.
#[derive(Clone, Debug)]
pub struct Modes {
    /// Angular eigenfrequencies ω [rad/s].
    pub omega: Vec<f64>,
    /// Mass-normalised mode shapes, one per column (n × count).
    pub shapes: Mat<f64>,
    /// ‖K φ − ω² M φ‖₂ / ‖K φ‖₂ per mode.
    pub residual: Vec<f64>,
    /// Krylov dimension used (0 for the dense solver).
    pub krylov_dim: usize,
}

impl Modes {
    /// Eigenfrequencies in Hz.
    pub fn hertz(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / (2.0 * std::f64::consts::PI)).collect()
    }
}

/// Factorises a sparse SPD matrix (lower triangle read).
pub fn cholesky(k: &SparseColMat<usize, f64>) -> Result<Llt<usize, f64>, EigenError> {
    k.sp_cholesky(Side::Lower).map_err(|e| EigenError::StiffnessNotDefinite(format!("{e:?}")))
}

/// The `count` lowest modes of a sparse pencil (K, M).
pub fn sparse_modes(k: &SparseColMat<usize, f64>, m: &SparseColMat<usize, f64>, count: usize) -> Result<Modes, EigenError> {
    if k.nrows() != m.nrows() {
        return Err(EigenError::SizeMismatch { m: m.nrows(), k: k.nrows() });
    }
    let llt = cholesky(k)?;
    lanczos(k, m, &llt, count, &LanczosOptions::default())
}

/// Deterministic pseudo-random numbers in (−1, 1) (splitmix64).
fn random_block(n: usize, p: usize, seed: u64) -> Mat<f64> {
    let mut s = seed;
    Mat::from_fn(n, p, |_, _| {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    })
}

/// Removes from `w` its M-projection on the basis blocks `q` (whose M-images are `mq`), twice,
/// then M-orthonormalises its columns among themselves (modified Gram–Schmidt, twice). Returns
/// the orthonormal block V, its M-image MV, and the triangular factor R with W = V R (rows =
/// kept columns). Columns whose norm falls below `drop_tol` times their norm after the block
/// projection are dropped (deflation). Two sparse products with M per call.
fn m_orthonormalise(m: &SparseColMat<usize, f64>, q: &[Mat<f64>], mq: &[Mat<f64>], mut w: Mat<f64>, drop_tol: f64) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
    let p = w.ncols();
    let n = w.nrows();
    for _pass in 0..2 {
        for (qb, mqb) in q.iter().zip(mq) {
            let c = mqb.transpose() * &w;
            // W −= Q_b C accumulated into W: no n × p temporary per block (memory-bound pass).
            faer::linalg::matmul::matmul(w.as_mut(), faer::Accum::Add, qb.as_ref(), c.as_ref(), -1.0, faer::get_global_parallelism());
        }
    }
    let mut mw = sparse_times_dense(m, w.as_ref());
    let mut r = Mat::<f64>::zeros(p, p);
    // Columns are orthonormalised in place in w and mw (no copy per column: the blocks are n × p,
    // megabytes each); `kept` lists the columns already done.
    let mut kept: Vec<usize> = Vec::new();
    let (mut v, mut mv) = (vec![0.0; n], vec![0.0; n]);
    for j in 0..p {
        v.copy_from_slice(w.col_as_slice(j));
        mv.copy_from_slice(mw.col_as_slice(j));
        let norm0 = dot(&v, &mv).max(0.0).sqrt();
        for _pass in 0..2 {
            for (idx, &kj) in kept.iter().enumerate() {
                let (u, mu) = (w.col_as_slice(kj), mw.col_as_slice(kj));
                let c = dot(mu, &v);
                for i in 0..n {
                    v[i] -= c * u[i];
                    mv[i] -= c * mu[i];
                }
                r[(idx, j)] += c;
            }
        }
        let norm = dot(&v, &mv).max(0.0).sqrt();
        if !(norm > drop_tol * norm0) || !norm.is_finite() {
            continue;
        }
        r[(kept.len(), j)] = norm;
        for (x, y) in w.col_as_slice_mut(j).iter_mut().zip(&v) {
            *x = y / norm;
        }
        for (x, y) in mw.col_as_slice_mut(j).iter_mut().zip(&mv) {
            *x = y / norm;
        }
        kept.push(j);
    }
    let k = kept.len();
    let r = Mat::from_fn(k, p, |i, j| r[(i, j)]);
    if k == p {
        return (w, mw, r);
    }
    let v = Mat::from_fn(n, k, |i, j| w[(i, kept[j])]);
    let mv = Mat::from_fn(n, k, |i, j| mw[(i, kept[j])]);
    (v, mv, r)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The `count` lowest modes by shift-invert block Lanczos, with a given Cholesky factor of K.
pub fn lanczos(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    k_factor: &Llt<usize, f64>,
    count: usize,
    opts: &LanczosOptions,
) -> Result<Modes, EigenError> {
    let n = k.nrows();
    if count > n {
        return Err(EigenError::TooManyModes { requested: count, n });
    }
    if count == 0 {
        return Ok(Modes { omega: vec![], shapes: Mat::zeros(n, 0), residual: vec![], krylov_dim: 0 });
    }
    let p = opts.block.max(1).min(n);
    let max_dim = opts.max_dim.max(count + 2 * p).min(n);
    // K⁻¹ applied to an M-image.
    let solve = |mut y: Mat<f64>| -> Mat<f64> {
        k_factor.solve_in_place(y.as_mut());
        y
    };

    // Thread CPU of the solves, the orthonormalisation and the Ritz steps (profile only).
    let (mut cpu_solve, mut cpu_orth, mut cpu_ritz, mut steps) = (0.0, 0.0, 0.0, 0usize);
    let lap = |acc: &mut f64, since: &mut Option<f64>| {
        let now = crate::fe::profile_cpu();
        if let (Some(a), Some(b)) = (now, *since) {
            *acc += a - b;
        }
        *since = now;
    };
    let mut seed = opts.seed;
    // Start block: K⁻¹M applied to random vectors (purges the null space of M).
    let w = solve(sparse_times_dense(m, random_block(n, p, seed).as_ref()));
    let (mut v, mut mv, _) = m_orthonormalise(m, &[], &[], w, 1e-12);
    if v.ncols() == 0 {
        return Err(EigenError::MassNotDefinite("K⁻¹M annihilates every start vector".into()));
    }
    let mut q: Vec<Mat<f64>> = Vec::new();
    let mut mq: Vec<Mat<f64>> = Vec::new();
    let mut t = Mat::<f64>::zeros(0, 0);
    let mut dim = 0usize;
    let mut last_r: Mat<f64>;
    let mut last_block_len: usize;
    let mut checks = 0usize;
    loop {
        // Extend the basis with v.
        let pb = v.ncols();
        let mut since = crate::fe::profile_cpu();
        let w = solve(mv.clone());
        lap(&mut cpu_solve, &mut since);
        steps += 1;
        q.push(v);
        mq.push(mv);
        let new_dim = dim + pb;
        let mut t2 = Mat::<f64>::zeros(new_dim, new_dim);
        t2.as_mut().submatrix_mut(0, 0, dim, dim).copy_from(&t);
        // Column block of T: Q_allᵀ M (K⁻¹M Q_b) = (MQ_all)ᵀ W.
        let mut row = 0;
        for mqb in &mq {
            let c = mqb.transpose() * &w;
            for i in 0..c.nrows() {
                for j in 0..pb {
                    t2[(row + i, dim + j)] = c[(i, j)];
                    t2[(dim + j, row + i)] = c[(i, j)];
                }
            }
            row += mqb.ncols();
        }
        // Symmetrise the new diagonal block.
        for i in 0..pb {
            for j in 0..i {
                let a = 0.5 * (t2[(dim + i, dim + j)] + t2[(dim + j, dim + i)]);
                t2[(dim + i, dim + j)] = a;
                t2[(dim + j, dim + i)] = a;
            }
        }
        t = t2;
        dim = new_dim;
        last_block_len = pb;
        let (vn, mvn, r) = if dim < n { m_orthonormalise(m, &q, &mq, w, 1e-10) } else { (Mat::zeros(n, 0), Mat::zeros(n, 0), Mat::zeros(0, pb)) };
        lap(&mut cpu_orth, &mut since);
        last_r = r;
        v = vn;
        mv = mvn;

        let exhausted = dim >= max_dim;
        let want_check = dim >= count + p && (dim < 120 || checks.is_multiple_of(3) || exhausted || v.ncols() == 0);
        checks += 1;
        if want_check || exhausted || v.ncols() == 0 {
            let (theta, s) = ritz(&t)?;
            // Largest θ ↔ lowest ω²; θ ascending from ritz(): take from the end.
            let mut converged = 0;
            for r_idx in 0..count.min(dim) {
                let col = dim - 1 - r_idx;
                let th = theta[col];
                let mut est = 0.0;
                for i in 0..last_r.nrows() {
                    let mut acc = 0.0;
                    for j in 0..last_block_len {
                        acc += last_r[(i, j)] * s[(dim - last_block_len + j, col)];
                    }
                    est += acc * acc;
                }
                if th > 0.0 && est.sqrt() <= opts.tol * th {
                    converged += 1;
                } else {
                    break;
                }
            }
            lap(&mut cpu_ritz, &mut since);
            if converged >= count || dim >= n {
                let modes = finish(k, m, &q, &theta, &s, count, dim);
                if let Some(end) = crate::fe::profile_cpu() {
                    let done = since.unwrap_or(end);
                    eprintln!(
                        "set-up profile: lanczos {steps} blocks to dimension {dim}: thread CPU solves {cpu_solve:.3} s, orthonormalisation {cpu_orth:.3} s, Ritz {cpu_ritz:.3} s, modes and residuals {:.3} s",
                        end - done
                    );
                }
                return check(k, m, modes);
            }
            if exhausted {
                return Err(EigenError::NotConverged { converged, requested: count, dim });
            }
        }
        if v.ncols() == 0 {
            // Invariant subspace: continue with fresh random directions.
            seed = seed.wrapping_add(1);
            let w = solve(sparse_times_dense(m, random_block(n, p, seed).as_ref()));
            let (vn, mvn, _) = m_orthonormalise(m, &q, &mq, w, 1e-10);
            if vn.ncols() == 0 {
                let (theta, s) = ritz(&t)?;
                return check(k, m, finish(k, m, &q, &theta, &s, count.min(dim), dim));
            }
            v = vn;
            mv = mvn;
        }
    }
}

/// Refuses a singular K (ω² negligible against the stiffness/mass scale: the Cholesky factor of
/// a singular K can succeed in floating point) and modes whose true residual is poor.
fn check(k: &SparseColMat<usize, f64>, m: &SparseColMat<usize, f64>, modes: Modes) -> Result<Modes, EigenError> {
    let scale = stiffness_mass_scale(k, m);
    if let Some(&w) = modes.omega.first()
        && !(w * w > 1e-12 * scale)
    {
        return Err(EigenError::Singular { omega2: w * w, scale });
    }
    if let Some((i, &r)) = modes.residual.iter().enumerate().find(|(_, r)| !(**r < 1e-6)) {
        return Err(EigenError::Inaccurate { mode: i + 1, residual: r });
    }
    Ok(modes)
}

/// Eigen of the projected symmetric matrix, ascending.
fn ritz(t: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), EigenError> {
    symmetric_eigen(t.as_ref())
}

/// Eigenvalues (ascending) and orthonormal eigenvectors of a dense symmetric matrix (lower
/// triangle read).
///
/// The matrix is scaled to unit max-norm first: faer 0.24.4's `self_adjoint_eigen` loses
/// accuracy on matrices of order ≳ 128 whose norm is far from 1 (measured on a tridiagonal test
/// matrix, n = 200: relative residual 2e-15 at norm 1, 6e-10 at norm 1e6, 1e-4 at norm 1e13).
pub fn symmetric_eigen(a: MatRef<'_, f64>) -> Result<(Vec<f64>, Mat<f64>), EigenError> {
    let n = a.nrows();
    let mut scale = 0.0f64;
    for j in 0..n {
        for i in j..n {
            scale = scale.max(a[(i, j)].abs());
        }
    }
    if !scale.is_finite() {
        return Err(EigenError::Decomposition("the matrix has non-finite entries".into()));
    }
    if scale == 0.0 {
        scale = 1.0;
    }
    let b = Mat::from_fn(n, n, |i, j| if i >= j { a[(i, j)] / scale } else { a[(j, i)] / scale });
    let e = b.self_adjoint_eigen(Side::Lower).map_err(|e| EigenError::Decomposition(format!("{e:?}")))?;
    let vals = (0..n).map(|i| e.S()[i] * scale).collect();
    Ok((vals, e.U().to_owned()))
}

fn finish(k: &SparseColMat<usize, f64>, m: &SparseColMat<usize, f64>, q: &[Mat<f64>], theta: &[f64], s: &Mat<f64>, count: usize, dim: usize) -> Modes {
    let n = k.nrows();
    // Ritz coefficients of the wanted modes (largest θ first).
    let sel = Mat::from_fn(dim, count, |i, j| s[(i, dim - 1 - j)]);
    let mut shapes = Mat::<f64>::zeros(n, count);
    let mut row = 0;
    for qb in q {
        let b = qb.ncols();
        shapes += qb * sel.as_ref().subrows(row, b);
        row += b;
    }
    let omega: Vec<f64> = (0..count).map(|j| (1.0 / theta[dim - 1 - j]).sqrt()).collect();
    let (shapes, residual) = normalise_and_check(k, m, shapes, &omega);
    Modes { omega, shapes, residual, krylov_dim: dim }
}

/// Mass-normalises and signs each column; returns the relative residuals.
fn normalise_and_check(k: &SparseColMat<usize, f64>, m: &SparseColMat<usize, f64>, mut shapes: Mat<f64>, omega: &[f64]) -> (Mat<f64>, Vec<f64>) {
    let mut mphi = sparse_times_dense(m, shapes.as_ref());
    for j in 0..shapes.ncols() {
        let nm: f64 = (0..shapes.nrows()).map(|i| shapes[(i, j)] * mphi[(i, j)]).sum::<f64>().sqrt();
        let big = (0..shapes.nrows()).max_by(|&a, &b| shapes[(a, j)].abs().total_cmp(&shapes[(b, j)].abs())).unwrap_or(0);
        let sign = if shapes[(big, j)] < 0.0 { -1.0 } else { 1.0 };
        // M φ scales with φ: one product with M, not two (the residual's round-off only).
        for i in 0..shapes.nrows() {
            shapes[(i, j)] *= sign / nm;
            mphi[(i, j)] *= sign / nm;
        }
    }
    let kphi = sparse_times_dense(k, shapes.as_ref());
    let residual = (0..shapes.ncols())
        .map(|j| {
            let w2 = omega[j] * omega[j];
            let (mut r, mut kn) = (0.0, 0.0);
            for i in 0..shapes.nrows() {
                let d = kphi[(i, j)] - w2 * mphi[(i, j)];
                r += d * d;
                kn += kphi[(i, j)] * kphi[(i, j)];
            }
            (r / kn).sqrt()
        })
        .collect();
    (shapes, residual)
}

/// The `count` lowest modes of a dense pencil (K, M) with M positive definite (all when
/// `count ≥ n`).
pub fn dense_modes(k: MatRef<'_, f64>, m: MatRef<'_, f64>, count: usize) -> Result<Modes, EigenError> {
    let n = k.nrows();
    if m.nrows() != n {
        return Err(EigenError::SizeMismatch { m: m.nrows(), k: n });
    }
    let count = count.min(n);
    let ms = Mat::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let ks = Mat::from_fn(n, n, |i, j| 0.5 * (k[(i, j)] + k[(j, i)]));
    let par = faer::Par::Seq;
    // B = L⁻¹ A L⁻ᵀ = L⁻¹ (L⁻¹ A)ᵀ for A symmetric, LLᵀ the factor of the other matrix.
    let congruence = |l: MatRef<'_, f64>, a: &Mat<f64>| -> Mat<f64> {
        let mut x = a.clone();
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, x.as_mut(), par);
        let mut b = x.transpose().to_owned();
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, b.as_mut(), par);
        Mat::from_fn(n, n, |i, j| 0.5 * (b[(i, j)] + b[(j, i)]))
    };
    let (lambda, mut phi) = if let Ok(llt) = ks.llt(Side::Lower) {
        // K = LLᵀ (K positive definite): the eigenvalues μ = 1/ω² of L⁻¹ M L⁻ᵀ. The lowest modes
        // are its largest eigenvalues, so they get full relative accuracy (the shift-invert
        // idea); φ = L⁻ᵀ y.
        let l = llt.L();
        let (mu, y) = symmetric_eigen(congruence(l, &ms).as_ref())?;
        let top = mu[n - 1];
        let mut lambda = Vec::with_capacity(count);
        let mut sel = Mat::<f64>::zeros(n, count);
        for j in 0..count {
            let c = n - 1 - j;
            if !(mu[c] > 1e-13 * top) {
                return Err(EigenError::MassNotDefinite(format!("mode {} has (near-)zero mass: 1/ω² = {:e}", j + 1, mu[c])));
            }
            lambda.push(1.0 / mu[c]);
            for i in 0..n {
                sel[(i, j)] = y[(i, c)];
            }
        }
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(l.transpose(), sel.as_mut(), par);
        (lambda, sel)
    } else {
        // K singular (free structure): M = LLᵀ, eigen of L⁻¹ K L⁻ᵀ.
        let llt = ms.llt(Side::Lower).map_err(|e| EigenError::MassNotDefinite(format!("{e:?}")))?;
        let l = llt.L();
        let (vals, vecs) = symmetric_eigen(congruence(l, &ks).as_ref())?;
        let top = vals[n - 1].abs();
        let mut lambda: Vec<f64> = vals[..count].to_vec();
        if let Some(&neg) = lambda.iter().find(|&&v| v < -1e-10 * top) {
            return Err(EigenError::StiffnessNotDefinite(format!("eigenvalue ω² = {neg:e} < 0")));
        }
        lambda.iter_mut().for_each(|v| *v = v.max(0.0));
        let mut phi = vecs.subcols(0, count).to_owned();
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(l.transpose(), phi.as_mut(), par);
        (lambda, phi)
    };
    let omega: Vec<f64> = lambda.iter().map(|l| l.sqrt()).collect();
    // Normalise, sign and residuals (dense).
    let mphi = &ms * &phi;
    for j in 0..count {
        let nm: f64 = (0..n).map(|i| phi[(i, j)] * mphi[(i, j)]).sum::<f64>().sqrt();
        let big = (0..n).max_by(|&a, &b| phi[(a, j)].abs().total_cmp(&phi[(b, j)].abs())).unwrap_or(0);
        let sign = if phi[(big, j)] < 0.0 { -1.0 } else { 1.0 };
        for i in 0..n {
            phi[(i, j)] *= sign / nm;
        }
    }
    let kphi = &ks * &phi;
    let mphi = &ms * &phi;
    let residual = (0..count)
        .map(|j| {
            let w2 = omega[j] * omega[j];
            let (mut r, mut kn) = (0.0, 0.0);
            for i in 0..n {
                let d = kphi[(i, j)] - w2 * mphi[(i, j)];
                r += d * d;
                kn += kphi[(i, j)] * kphi[(i, j)];
            }
            if kn > 0.0 { (r / kn).sqrt() } else { r.sqrt() }
        })
        .collect();
    Ok(Modes { omega, shapes: phi, residual, krylov_dim: 0 })
}
