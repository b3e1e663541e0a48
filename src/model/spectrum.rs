//! The highest undamped angular frequency ω_max of a model: the bound that explicit time
//! schemes must respect (ω_max·h below a scheme's limit, see `time::Scheme::stability_limit`).
//!
//! ω_max² is the largest eigenvalue of the pencil (K + Σ k_c s² e_d e_dᵀ, M): compliant contacts
//! are counted closed (their stiffness acts on the contact DOF), rigid ones not. When M is positive
//! definite there are no infinite eigenvalues. When some DOFs b are massless (a massless boundary,
//! src/formulation.md §4.1) their eigenvalues are infinite and no scheme resolves them: they are
//! quasi-static, so ω_max is that of the massive DOFs a after condensing b statically,
//! the pencil (K_aa − K_ab K_bb⁻¹ K_ba, M_aa), the finite eigenvalues of (K, M).
use super::{Compliance, Matrix, Model, ModelError};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

/// Up to this order the dense symmetric eigensolver is used (O(n³), a few ms); above, Lanczos.
const DENSE_MAX: usize = 400;
/// Lanczos steps at most (each costs one product by K, one solve with M, O(j·n) for the
/// re-orthogonalisation).
const LANCZOS_MAX_STEPS: usize = 200;
/// Relative accuracy of ω_max² asked of Lanczos (its residual bound). The Ritz value is a lower
/// bound; on clustered tops (a 2000-DOF chain) 200 steps leave ~1e-5, ample for a step limit.
const LANCZOS_TOL: f64 = 1e-10;

impl Model {
    /// ω_max [rad/s] of the model as solved (compliant contacts closed). Independent of the
    /// frequency and of the grid: compute once per structure.
    pub fn omega_max(&self) -> Result<f64, ModelError> {
        let n = self.n();
        // A compliant contact adds k_c B_iᵀ B_i to K.
        let springs: Vec<(&[(usize, f64)], f64)> = self
            .contacts
            .iter()
            .filter_map(|c| match c.compliance {
                Compliance::Compliant { stiffness } => Some((c.row.as_slice(), stiffness)),
                Compliance::Rigid => None,
            })
            .collect();
        let massless = self.massless_dofs();
        let lmax = if !massless.is_empty() {
            self.condensed_largest(&springs, &massless)?
        } else if n <= DENSE_MAX || !self.structure.mass.is_sparse() && n <= 2 * DENSE_MAX {
            let mut k = self.structure.stiffness.to_dense();
            for &(row, kc) in &springs {
                for &(a, ca) in row {
                    for &(b, cb) in row {
                        k[(a, b)] += kc * ca * cb;
                    }
                }
            }
            dense_largest(&self.structure.mass.to_dense(), &k)?
        } else {
            let mass = &self.structure.mass;
            let solve = mass_solver(mass)?;
            let mul_k = |x: &[f64], y: &mut [f64]| {
                self.structure.stiffness.mul_vec(x, y);
                for &(row, kc) in &springs {
                    let bx: f64 = row.iter().map(|&(d, c)| c * x[d]).sum();
                    for &(d, c) in row {
                        y[d] += kc * c * bx;
                    }
                }
            };
            lanczos_largest(n, mul_k, |x: &[f64], y: &mut [f64]| mass.mul_vec(x, y), solve)
        };
        if !(lmax.is_finite() && lmax >= 0.0) {
            return Err(ModelError::new(
                "structure.stiffness",
                format!("the largest eigenvalue of M⁻¹K is {lmax:e}; K must be finite and positive semidefinite"),
            ));
        }
        Ok(lmax.sqrt())
    }
}

impl Model {
    /// The largest finite eigenvalue with the massless DOFs condensed: Lanczos on the Schur
    /// complement K̃ = K_aa − K_ab K_bb⁻¹ K_ba (applied, never formed) against M_aa.
    fn condensed_largest(&self, springs: &[(&[(usize, f64)], f64)], massless: &[usize]) -> Result<f64, ModelError> {
        let n = self.n();
        let mut stiffness = self.structure.stiffness.clone();
        if !springs.is_empty() {
            let mut t = Vec::new();
            // k_c B_iᵀ B_i for each compliant contact row.
            for &(row, kc) in springs {
                for &(a, ca) in row {
                    row.iter().for_each(|&(b, cb)| t.push(faer::sparse::Triplet::new(a, b, kc * ca * cb)));
                }
            }
            let s = faer::sparse::SparseColMat::try_new_from_triplets(n, n, &t).expect("contact DOFs are in range");
            stiffness = stiffness.lincomb(1.0, &Matrix::Sparse(s), 1.0);
        }
        let massive: Vec<usize> = (0..n).filter(|d| massless.binary_search(d).is_err()).collect();
        let (k_aa, k_ab, k_bb) = (stiffness.block(&massive, &massive), stiffness.block(&massive, massless), stiffness.block(massless, massless));
        let solve_bb = solver(&k_bb, || ModelError::new("structure.stiffness", format!("is not positive definite on the massless DOFs {massless:?}")))?;
        let mass = self.structure.mass.block(&massive, &massive);
        let solve_m = mass_solver(&mass)?;
        let (na, nb) = (massive.len(), massless.len());
        let mut t = vec![0.0; nb];
        let mut u = vec![0.0; na];
        let mul_k = |x: &[f64], y: &mut [f64]| {
            k_aa.mul_vec(x, y);
            // y −= K_ab K_bb⁻¹ K_ba x (K_ba = K_abᵀ).
            t.iter_mut().for_each(|v| *v = 0.0);
            k_ab.for_each(|i, j, v| t[j] += v * x[i]);
            solve_bb(&mut t);
            k_ab.mul_vec(&t, &mut u);
            y.iter_mut().zip(&u).for_each(|(a, b)| *a -= b);
        };
        Ok(lanczos_largest(na, mul_k, |x: &[f64], y: &mut [f64]| mass.mul_vec(x, y), solve_m))
    }
}

/// Largest eigenvalue of (K, M), both dense: M = L Lᵀ, eigenvalues of L⁻¹ K L⁻ᵀ.
fn dense_largest(mass: &Mat<f64>, stiffness: &Mat<f64>) -> Result<f64, ModelError> {
    let llt = mass.llt(Side::Lower).map_err(|_| ModelError::new("structure.mass", "is not positive definite (every DOF must carry mass)"))?;
    let l = llt.L();
    let mut x = stiffness.clone();
    l.solve_lower_triangular_in_place(x.as_mut());
    let mut s = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(s.as_mut());
    let n = s.nrows();
    let sym = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (s[(i, j)] + s[(j, i)]));
    let ev =
        sym.self_adjoint_eigenvalues(Side::Lower).map_err(|e| ModelError::new("structure.stiffness", format!("the eigenvalues of M⁻¹K failed ({e:?})")))?;
    Ok(ev.iter().copied().fold(f64::NEG_INFINITY, f64::max))
}

/// x ↦ M⁻¹ x by a Cholesky factorisation of M (dense or sparse).
fn mass_solver(mass: &Matrix) -> Result<impl Fn(&mut [f64]), ModelError> {
    solver(mass, || ModelError::new("structure.mass", "is not positive definite (every DOF must carry mass)"))
}

/// x ↦ A⁻¹ x by a Cholesky factorisation of A (dense or sparse), `bad()` when it fails.
fn solver(mass: &Matrix, bad: impl Fn() -> ModelError) -> Result<impl Fn(&mut [f64]), ModelError> {
    enum Factor {
        Dense(faer::linalg::solvers::Llt<f64>),
        Sparse(faer::sparse::linalg::solvers::Llt<usize, f64>),
    }
    let f = match mass {
        Matrix::Dense(m) => Factor::Dense(m.llt(Side::Lower).map_err(|_| bad())?),
        Matrix::Sparse(s) => Factor::Sparse(s.sp_cholesky(Side::Lower).map_err(|_| bad())?),
    };
    Ok(move |x: &mut [f64]| {
        let n = x.len();
        let mut col = Mat::<f64>::from_fn(n, 1, |i, _| x[i]);
        match &f {
            Factor::Dense(l) => l.solve_in_place(col.as_mut()),
            Factor::Sparse(l) => l.solve_in_place(col.as_mut()),
        }
        x.iter_mut().enumerate().for_each(|(i, v)| *v = col[(i, 0)]);
    })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Largest eigenvalue of the symmetric-definite pencil (A, B) by Lanczos on B⁻¹A in the
/// B-inner product, fully re-orthogonalised. Stops when the Ritz residual β_j·|s_j| is below
/// [`LANCZOS_TOL`] of the Ritz value, or on an invariant subspace.
pub(crate) fn lanczos_largest(
    n: usize,
    mut mul_a: impl FnMut(&[f64], &mut [f64]),
    mut mul_b: impl FnMut(&[f64], &mut [f64]),
    solve_b: impl Fn(&mut [f64]),
) -> f64 {
    // Deterministic start with a component on every eigenvector (splitmix-like hash).
    let mut q: Vec<f64> = (0..n as u64)
        .map(|i| {
            let z = (i.wrapping_add(1)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let z = (z ^ (z >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            1.0 + (z >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect();
    let mut bq = vec![0.0; n];
    mul_b(&q, &mut bq);
    let s = dot(&q, &bq).sqrt();
    q.iter_mut().for_each(|v| *v /= s);
    bq.iter_mut().for_each(|v| *v /= s);
    let (mut qs, mut bqs) = (vec![q], vec![bq]);
    let (mut alpha, mut beta) = (Vec::new(), Vec::<f64>::new());
    let mut w = vec![0.0; n];
    let mut best = f64::NEG_INFINITY;
    for j in 0..LANCZOS_MAX_STEPS.min(n) {
        mul_a(&qs[j], &mut w);
        alpha.push(dot(&qs[j], &w));
        solve_b(&mut w);
        for _ in 0..2 {
            for (qi, bqi) in qs.iter().zip(&bqs) {
                let c = dot(bqi, &w);
                w.iter_mut().zip(qi).for_each(|(v, x)| *v -= c * x);
            }
        }
        let mut bw = vec![0.0; n];
        mul_b(&w, &mut bw);
        let b = dot(&w, &bw).max(0.0).sqrt();
        let t = Mat::<f64>::from_fn(j + 1, j + 1, |r, c| {
            if r == c {
                alpha[r]
            } else if r == c + 1 || c == r + 1 {
                beta[r.min(c)]
            } else {
                0.0
            }
        });
        let Ok(eig) = t.self_adjoint_eigen(Side::Lower) else { break };
        let (vals, vecs) = (eig.S().column_vector(), eig.U());
        let top = (0..=j).max_by(|&a, &c| vals[a].total_cmp(&vals[c])).unwrap_or(0);
        best = vals[top];
        if b * vecs[(j, top)].abs() <= LANCZOS_TOL * best.abs() || b <= f64::EPSILON * best.abs() {
            break;
        }
        beta.push(b);
        w.iter_mut().for_each(|v| *v /= b);
        bw.iter_mut().for_each(|v| *v /= b);
        qs.push(std::mem::replace(&mut w, vec![0.0; n]));
        bqs.push(bw);
    }
    best
}
