//! A phase's exponential by its eigendecomposition Â = V Λ V⁻¹: e^{Âτ} = V e^{Λτ} V⁻¹ for any τ
//! from one decomposition (Moler & Van Loan, "Nineteen dubious ways to compute the exponential of
//! a matrix, twenty-five years later", SIAM Rev. 45, 2003, method 14), so a Newton iteration, a
//! sampled phase and an admissibility check no longer pay a Padé exponential (scaling and
//! squaring: ~20 products of the 2n_a × 2n_a matrix) per span, and a state costs O(n_a²).
//! Method 14's error grows with the condition number κ(V): e^{Âτ}'s rounding is about ε κ(V)
//! relative (ibid., §6), so a V with κ₁(V) > [`MAX_CONDITION`] (a defective or nearly defective
//! Â: repeated poles, a critically damped mode) is refused and the phase keeps the Padé path.
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;

/// The largest κ₁(V) = ‖V‖₁ ‖V⁻¹‖₁ taken: ε κ ≈ 2e-13 keeps the exponential's rounding below the
/// 1e-12 the polish's Newton converges to (the unit columns faer returns make κ within √(2n_a)
/// of its smallest over column scalings, van der Sluis 1969).
pub(super) const MAX_CONDITION: f64 = 1e3;

/// Â = V Λ V⁻¹ with V and V⁻¹ split in real and imaginary parts (two real products per use).
#[derive(Clone, Debug)]
pub(super) struct EigenFlow {
    lambda: Vec<C>,
    v_re: DMatrix<f64>,
    v_im: DMatrix<f64>,
    inv_re: DMatrix<f64>,
    inv_im: DMatrix<f64>,
    /// κ₁(V), printed by the tests (the decomposition's accuracy scales with it).
    #[cfg_attr(not(test), allow(dead_code))]
    pub condition: f64,
}

impl EigenFlow {
    /// The decomposition of `a`; `None` when faer's eigensolver fails, V is singular, or
    /// κ₁(V) > [`MAX_CONDITION`].
    pub fn new(a: &DMatrix<f64>) -> Option<Self> {
        let n = a.nrows();
        if n == 0 || !a.iter().all(|x| x.is_finite()) {
            return None;
        }
        let eig = faer::Mat::from_fn(n, n, |i, j| a[(i, j)]).eigen().ok()?;
        let (u, s) = (eig.U(), eig.S().column_vector());
        let v = DMatrix::from_fn(n, n, |i, j| u[(i, j)]);
        let lambda: Vec<C> = (0..n).map(|i| s[i]).collect();
        let inv = v.clone().try_inverse()?;
        let norm1 = |m: &DMatrix<C>| m.column_iter().map(|c| c.iter().map(|z| z.norm()).sum::<f64>()).fold(0.0, f64::max);
        let condition = norm1(&v) * norm1(&inv);
        // Also refuse a decomposition whose residual ‖ÂV − VΛ‖₁ is not at round-off of ‖Â‖₁‖V‖₁.
        let vl = DMatrix::from_fn(n, n, |i, j| v[(i, j)] * lambda[j]);
        let av = a.map(|x| C::new(x, 0.0)) * &v;
        let norm_a = a.column_iter().map(|c| c.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
        let residual = norm1(&(av - vl));
        if !(condition <= MAX_CONDITION) || !(residual <= 1e-12 * norm_a.max(f64::MIN_POSITIVE) * norm1(&v)) {
            return None;
        }
        Some(EigenFlow { lambda, v_re: v.map(|z| z.re), v_im: v.map(|z| z.im), inv_re: inv.map(|z| z.re), inv_im: inv.map(|z| z.im), condition })
    }

    /// e^{Âτ} = Re(V e^{Λτ} V⁻¹) = Re(V e^{Λτ}) Re V⁻¹ − Im(V e^{Λτ}) Im V⁻¹.
    pub fn exp(&self, tau: f64) -> DMatrix<f64> {
        let (mut re, mut im) = (self.v_re.clone(), self.v_im.clone());
        for (j, l) in self.lambda.iter().enumerate() {
            let e = (l * tau).exp();
            for i in 0..re.nrows() {
                let z = C::new(re[(i, j)], im[(i, j)]) * e;
                re[(i, j)] = z.re;
                im[(i, j)] = z.im;
            }
        }
        re * &self.inv_re - im * &self.inv_im
    }

    /// The eigenvalues λ_j and the columns of V scaled by the modal coordinates c = V⁻¹ u:
    /// e^{Âτ} u = Re Σ_j (V_j c_j) e^{λ_j τ} (the phase's transient as exponentials, for the
    /// admissibility check's closed-form signals).
    pub fn modal(&self, u: &DVector<f64>) -> (Vec<C>, DMatrix<C>) {
        let (re, im) = (&self.inv_re * u, &self.inv_im * u);
        let q = DMatrix::from_fn(self.v_re.nrows(), self.lambda.len(), |i, j| C::new(self.v_re[(i, j)], self.v_im[(i, j)]) * C::new(re[j], im[j]));
        (self.lambda.clone(), q)
    }

    /// The eigenvalues λ_j.
    pub fn eigenvalues(&self) -> &[C] {
        &self.lambda
    }

    /// The modal coordinates c = V⁻¹ u.
    pub fn coordinates(&self, u: &DVector<f64>) -> Vec<C> {
        let (re, im) = (&self.inv_re * u, &self.inv_im * u);
        re.iter().zip(im.iter()).map(|(a, b)| C::new(*a, *b)).collect()
    }

    /// r V₁ for the rows `r` on V's first r.ncols() rows.
    pub fn rows_on_modes(&self, r: &DMatrix<f64>) -> DMatrix<C> {
        let k = r.ncols();
        let (re, im) = (r * self.v_re.rows(0, k), r * self.v_im.rows(0, k));
        re.zip_map(&im, C::new)
    }

    /// e^{Âτ} u in O(n_a²): V (e^{Λτ} ⊙ V⁻¹ u).
    pub fn apply(&self, tau: f64, u: &DVector<f64>) -> DVector<f64> {
        let (w_re, w_im) = (&self.inv_re * u, &self.inv_im * u);
        let (mut a, mut b) = (w_re, w_im);
        for (j, l) in self.lambda.iter().enumerate() {
            let z = C::new(a[j], b[j]) * (l * tau).exp();
            a[j] = z.re;
            b[j] = z.im;
        }
        &self.v_re * a - &self.v_im * b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ‖X − Y‖₁ / ‖Y‖₁.
    fn relative(x: &DMatrix<f64>, y: &DMatrix<f64>) -> f64 {
        let norm1 = |m: &DMatrix<f64>| m.column_iter().map(|c| c.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
        norm1(&(x - y)) / norm1(y)
    }

    /// A phase's balanced first-order matrix (phase.rs): [0, s I; −M⁻¹K/s, −M⁻¹C] for a chain of
    /// `n` masses with springs to ground and neighbours and dampers on some springs only (damping
    /// not proportional: Â is not normal), s = √‖M⁻¹K‖∞.
    fn chain(n: usize) -> DMatrix<f64> {
        let mut seed = 7u64;
        let mut rand = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let masses: Vec<f64> = (0..n).map(|_| 0.5 + rand()).collect();
        let (mut k, mut c) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        for i in 0..n {
            let (ki, ci) = (1e4 * (1.0 + 10.0 * rand()), if i % 3 == 0 { 5.0 * rand() } else { 0.0 });
            k[(i, i)] += ki;
            c[(i, i)] += ci;
            if i + 1 < n {
                let (kc, cc) = (1e5 * (1.0 + rand()), if i % 2 == 0 { 2.0 * rand() } else { 0.0 });
                for (a, b, sign) in [(i, i, 1.0), (i + 1, i + 1, 1.0), (i, i + 1, -1.0), (i + 1, i, -1.0)] {
                    k[(a, b)] += sign * kc;
                    c[(a, b)] += sign * cc;
                }
            }
        }
        let m_inv = DMatrix::from_diagonal(&DVector::from_iterator(n, masses.iter().map(|m| 1.0 / m)));
        let mk = -(&m_inv * k);
        let s = mk.row_iter().map(|r| r.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max).sqrt();
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        a.view_mut((0, n), (n, n)).fill_with_identity();
        a.view_mut((0, n), (n, n)).scale_mut(s);
        a.view_mut((n, 0), (n, n)).copy_from(&(mk / s));
        a.view_mut((n, n), (n, n)).copy_from(&(-(&m_inv * c)));
        a
    }

    #[test]
    fn eigen_exponential_matches_pade_on_a_damped_chain() {
        let a = chain(20);
        let f = EigenFlow::new(&a).expect("a damped chain's Â is diagonalisable and well conditioned");
        let speed = a.column_iter().map(|c| c.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
        // Spans from a tenth to a thousand radians of the fastest mode (a short flow to a whole phase).
        for tau in [0.1, 1.0, 10.0, 100.0, 1000.0].map(|r| r / speed) {
            let (e, pade) = (f.exp(tau), (&a * tau).exp());
            let err = relative(&e, &pade);
            println!("chain, ‖Â‖τ = {:.1}: κ(V) = {:.2e}, relative difference to Padé {err:.2e}", speed * tau, f.condition);
            assert!(err < 1e-12, "exp at τ = {tau:e}: {err:e}");
            let u = DVector::from_fn(a.nrows(), |i, _| (i as f64).sin());
            let d = (f.apply(tau, &u) - &pade * &u).amax() / (&pade * &u).amax();
            assert!(d < 1e-12, "apply at τ = {tau:e}: {d:e}");
        }
    }

    #[test]
    fn eigen_exponential_matches_pade_on_a_non_normal_matrix() {
        // Upper triangular with couplings 3–8× its eigenvalues' spread: far from normal
        // (‖ÂÂᵀ − ÂᵀÂ‖_F = 0.76 ‖Â‖_F²), κ₁(V) = 3.0e2 < MAX_CONDITION with faer's unit columns.
        let a = DMatrix::from_row_slice(3, 3, &[-1.0, 8.0, 0.5, 0.0, -2.0, 5.0, 0.0, 0.0, -3.5]);
        let f = EigenFlow::new(&a).expect("distinct eigenvalues, moderate κ");
        for tau in [0.01, 0.5, 3.0] {
            let err = relative(&f.exp(tau), &(&a * tau).exp());
            println!("non-normal: κ(V) = {:.2e}, τ = {tau}: relative difference to Padé {err:.2e}", f.condition);
            assert!(err < 1e-12, "τ = {tau}: {err:e}");
        }
    }

    #[test]
    fn a_defective_matrix_is_refused() {
        // A Jordan block (a critically damped mode): no basis of eigenvectors.
        let a = DMatrix::from_row_slice(2, 2, &[-1.0, 1.0, 0.0, -1.0]);
        assert!(EigenFlow::new(&a).is_none());
        // Nearly defective: eigenvalues 1e-9 apart, κ(V) ≈ 1e9.
        let b = DMatrix::from_row_slice(2, 2, &[-1.0, 1.0, 0.0, -1.0 - 1e-9]);
        assert!(EigenFlow::new(&b).is_none());
    }
}
