//! A phase's exponential by its eigendecomposition Â = V Λ V⁻¹: e^{Âτ} = V e^{Λτ} V⁻¹ for any τ
//! from one decomposition (Moler & Van Loan, "Nineteen dubious ways to compute the exponential of
//! a matrix, twenty-five years later", SIAM Rev. 45, 2003, method 14), so a Newton iteration, a
//! sampled phase and an admissibility check no longer pay a Padé exponential (scaling and
//! squaring: ~20 products of the 2n_a × 2n_a matrix) per span, and a state costs O(n_a²).
//! Method 14's error grows with the condition number of the basis the state is resolved in, so V⁻¹
//! is not V's inverse computed as such: each conjugate pair's eigenvector v = p + iq is turned so
//! that p ⟂ q, and the real basis X of the unit vectors p/‖p‖, q/‖q‖ (and the real eigenvectors)
//! is inverted instead; V⁻¹'s rows follow from X⁻¹'s in closed form (see [`EigenFlow::new`]).
//! A balanced phase's pair is [φ; ±iωφ/s] (phase.rs): for a mode much slower than the balancing
//! rate s (a Craig–Bampton model: s ≈ 8.4e6 rad/s against ω₁ ≈ 2.3e3 rad/s) the two are ω/s from
//! parallel and κ₁(V) ≈ 1e6 (the Padé path for every flow: the polish's 150–230 s), while p and q
//! ([φ; 0] and [0; φ] undamped) are orthogonal and κ₁(X) is the mode shapes' own. e^{Âτ}'s
//! rounding is then about ε κ₁(X) relative (Moler & Van Loan, §6, for the real block-diagonal
//! form X diag(e^{B_j τ}) X⁻¹), so an X with κ₁(X) > [`MAX_CONDITION`] (a defective or nearly
//! defective Â: repeated poles, a critically damped mode) is refused and the phase keeps the Padé path.
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64 as C;

/// The largest κ₁(X) = ‖X‖₁ ‖X⁻¹‖₁ taken: ε κ ≈ 2e-12 keeps the exponential's rounding two decades
/// below the 1e-10 (of the state's scale) at which the polish's Newton takes its residual for
/// round-off (orbit.rs). The 1-norm of X's unit columns counts up to √(2n_a) each over the 2-norm
/// (van der Sluis 1969: within √(2n_a) of the smallest κ over column scalings); the Craig–Bampton
/// blade's 34 phases have κ₁(X) = 7.0e2–1.8e3 (κ₁(V) = 4e5–1.3e6).
pub(super) const MAX_CONDITION: f64 = 1e4;

/// Â = V Λ V⁻¹ with V and V⁻¹ split in real and imaginary parts (two real products per use).
#[derive(Clone, Debug)]
pub(super) struct EigenFlow {
    lambda: Vec<C>,
    v_re: DMatrix<f64>,
    v_im: DMatrix<f64>,
    inv_re: DMatrix<f64>,
    inv_im: DMatrix<f64>,
    /// κ₁(X) of the real basis (module doc), printed by the tests (the accuracy scales with it).
    #[cfg_attr(not(test), allow(dead_code))]
    pub condition: f64,
}

/// How far from exact conjugates (relative to |λ|) a pair of eigenvalues may be, and how far from
/// real (relative to its norm) a real eigenvalue's turned eigenvector: faer's real Schur form
/// gives both exactly; anything else is refused.
const PAIRING: f64 = 1e-10;

impl EigenFlow {
    /// The decomposition of `a`; `None` when faer's eigensolver fails, the eigenvalues do not
    /// come in conjugate pairs, X is singular, or κ₁(X) > [`MAX_CONDITION`].
    ///
    /// With v = p + iq turned so that pᵀq = 0 (by e^{−i arg(vᵀv)/2}), p̂ = p/‖p‖, q̂ = q/‖q‖ and
    /// ρ = ‖q‖/‖p‖, the eigenvector is p̂ + iρq̂ (that column of V, its conjugate the twin's), and a
    /// real y = c_p p̂ + c_q q̂ + … (c = X⁻¹y) has γ = (c_p − i c_q/ρ)/2 on it and γ̄ on the twin:
    /// V⁻¹'s rows are (X⁻¹_p − i X⁻¹_q/ρ)/2 and their conjugates, and a real eigenvector's row is X⁻¹'s.
    pub fn new(a: &DMatrix<f64>) -> Option<Self> {
        let n = a.nrows();
        if n == 0 || !a.iter().all(|x| x.is_finite()) {
            return None;
        }
        let eig = faer::Mat::from_fn(n, n, |i, j| a[(i, j)]).eigen().ok()?;
        let (u, s) = (eig.U(), eig.S().column_vector());
        let mut lambda: Vec<C> = (0..n).map(|i| s[i]).collect();
        let column = |j: usize| DVector::from_fn(n, |i, _| u[(i, j)]);
        // Each mode: (its index, its twin's) for a pair, (index, index) for a real eigenvalue.
        let mut twin = vec![usize::MAX; n];
        for j in 0..n {
            if twin[j] != usize::MAX || lambda[j].im < 0.0 {
                continue;
            }
            if lambda[j].im == 0.0 {
                twin[j] = j;
                continue;
            }
            let k = (0..n)
                .filter(|&k| twin[k] == usize::MAX && lambda[k].im < 0.0)
                .min_by(|&a, &b| (lambda[a] - lambda[j].conj()).norm().total_cmp(&(lambda[b] - lambda[j].conj()).norm()))?;
            if (lambda[k] - lambda[j].conj()).norm() > PAIRING * lambda[j].norm() {
                return None;
            }
            lambda[k] = lambda[j].conj();
            (twin[j], twin[k]) = (k, j);
        }
        if twin.contains(&usize::MAX) {
            return None;
        }
        // The real basis X (unit columns: p̂ at j, q̂ at the twin; a real eigenvector at j) and ρ.
        let mut x = DMatrix::zeros(n, n);
        let mut rho = vec![0.0; n];
        for j in (0..n).filter(|&j| lambda[j].im >= 0.0) {
            let v = column(j);
            if twin[j] == j {
                let big = v.iter().copied().max_by(|a, b| a.norm().total_cmp(&b.norm()))?;
                let r = v.map(|z| (z * big.conj() / big.norm()).re);
                let im = v.map(|z| (z * big.conj() / big.norm()).im);
                if !(im.norm() <= PAIRING * r.norm()) {
                    return None;
                }
                x.set_column(j, &(&r / r.norm()));
                continue;
            }
            let turn = C::from_polar(1.0, -0.5 * v.iter().map(|z| z * z).sum::<C>().arg());
            let (p, q) = (v.map(|z| (z * turn).re), v.map(|z| (z * turn).im));
            let (np, nq) = (p.norm(), q.norm());
            if !(np > 0.0 && nq > 0.0) {
                return None;
            }
            x.set_column(j, &(&p / np));
            x.set_column(twin[j], &(&q / nq));
            rho[j] = nq / np;
        }
        let x_inv = x.clone().try_inverse()?;
        let norm1 = |m: &DMatrix<f64>| m.column_iter().map(|c| c.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
        let condition = norm1(&x) * norm1(&x_inv);
        if !(condition <= MAX_CONDITION) {
            return None;
        }
        let (mut v_re, mut v_im) = (x.clone(), DMatrix::zeros(n, n));
        let (mut inv_re, mut inv_im) = (x_inv.clone(), DMatrix::zeros(n, n));
        for j in (0..n).filter(|&j| lambda[j].im > 0.0) {
            let k = twin[j];
            let (p, q) = (x.column(j).into_owned(), x.column(k).into_owned());
            let (rp, rq) = (x_inv.row(j).into_owned(), x_inv.row(k).into_owned());
            // v_j = p̂ + iρq̂, v_k = p̂ − iρq̂; rows (X⁻¹_p ∓ i X⁻¹_q/ρ)/2.
            v_re.set_column(k, &p);
            v_im.set_column(j, &(&q * rho[j]));
            v_im.set_column(k, &(&q * -rho[j]));
            inv_re.set_row(j, &(&rp * 0.5));
            inv_re.set_row(k, &(&rp * 0.5));
            inv_im.set_row(j, &(&rq * (-0.5 / rho[j])));
            inv_im.set_row(k, &(&rq * (0.5 / rho[j])));
        }
        // Refuse a decomposition whose residual ‖ÂV − VΛ‖₁ is not at round-off of ‖Â‖₁‖V‖₁.
        let v = v_re.zip_map(&v_im, C::new);
        let vl = DMatrix::from_fn(n, n, |i, j| v[(i, j)] * lambda[j]);
        let av = a.map(|x| C::new(x, 0.0)) * &v;
        let norm_c = |m: &DMatrix<C>| m.column_iter().map(|c| c.iter().map(|z| z.norm()).sum::<f64>()).fold(0.0, f64::max);
        let residual = norm_c(&(av - vl));
        if !(residual <= 1e-12 * norm1(a).max(f64::MIN_POSITIVE) * norm_c(&v)) {
            return None;
        }
        Some(EigenFlow { lambda, v_re, v_im, inv_re, inv_im, condition })
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

    /// An integer matrix product, exact (i128).
    fn product(a: &[Vec<i128>], b: &[Vec<i128>]) -> Vec<Vec<i128>> {
        (0..a.len()).map(|i| (0..b[0].len()).map(|j| (0..b.len()).map(|k| a[i][k] * b[k][j]).sum()).collect()).collect()
    }

    /// Φ diag(d) Φ⁻¹ · 2^shift in f64, summed in i128 and asserted representable: exact.
    fn similar(phi: &[Vec<i128>], d: &[i128], phi_inv: &[Vec<i128>], shift: i32) -> DMatrix<f64> {
        let scaled: Vec<Vec<i128>> = phi.iter().map(|r| r.iter().zip(d).map(|(p, d)| p * d).collect()).collect();
        let g = product(&scaled, phi_inv);
        DMatrix::from_fn(phi.len(), phi.len(), |i, j| {
            let x = g[i][j] as f64;
            assert_eq!(x as i128, g[i][j], "entry ({i}, {j}) not exact in f64");
            x * 2f64.powi(shift)
        })
    }

    /// A chain with known modes (M = Φ⁻ᵀΦ⁻¹, K = Φ⁻ᵀ diag(ω²) Φ⁻¹, C = Φ⁻ᵀ diag(2ζω) Φ⁻¹: then
    /// M⁻¹K = Φ diag(ω²) Φ⁻¹ and q = Φη decouples into damped oscillators) against the oscillators'
    /// closed-form flows, at a Craig–Bampton spread of rates (s/ω_min = 2^12 and 2^16; the blade's
    /// 8.4e6 / 2.3e3 = 3.6e3) with a non-orthogonal, ill-conditioned Φ (unit bidiagonal factors,
    /// κ₁ ≈ 2e3: non-normal M⁻¹K). Â is formed exactly (integer Φ, Φ⁻¹; powers-of-two ω, ζ, s)
    /// so the reference is e^{Âτ} of the very matrix decomposed. The bound, first order, each term
    /// times 2·2n (2n = the state's size; a backward-stable eigensolver's error is a modest multiple
    /// of 2nε‖Â‖): ε κ₁(X) for the basis (module doc; X's closed form diag(Φ̂, Φ̂)); the slowest
    /// rate's error ε(s/ω_min)²/2 relative, times ω_min τ as a phase — Â's backward error ε‖Â‖ ≈ εs on
    /// the block −M⁻¹K/s moves ω_min² by εs², i.e. the eigenvalue's condition s/2ω_min of the balanced
    /// pair [φ; ±iωφ/s] (Wilkinson); any backward-stable exponential, Padé included, carries it (Φ's
    /// non-normality left out: a normal-case figure, its constant measured 3.1–3.5 of the 12 allowed);
    /// and the reference's own sums, ε n ‖|Φ||B||Φ⁻¹|‖₁ / ‖E‖₁.
    #[test]
    fn eigen_exponential_matches_closed_form_damped_oscillators_at_a_craig_bampton_spread() {
        let n = 6;
        // Φ = L U with L = I + 2·(sub-diagonal), U = I + (super-diagonal): both inverses in closed
        // form, L⁻¹ = Σ (−2)^k N^k, U⁻¹ = Σ (−1)^k (Nᵀ)^k; κ₁ of Φ's unit columns 1.7e3 (the blade's X: 7e2–1.8e3).
        let l = |a: i128, lower: bool| -> Vec<Vec<i128>> {
            (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| {
                            if i == j {
                                1
                            } else if (lower && i == j + 1) || (!lower && j == i + 1) {
                                a
                            } else {
                                0
                            }
                        })
                        .collect()
                })
                .collect()
        };
        let power_series = |a: i128, lower: bool| -> Vec<Vec<i128>> {
            (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| {
                            if lower && i >= j {
                                (-a).pow((i - j) as u32)
                            } else if !lower && j >= i {
                                (-a).pow((j - i) as u32)
                            } else {
                                0
                            }
                        })
                        .collect()
                })
                .collect()
        };
        let phi = product(&l(2, true), &l(1, false));
        let phi_inv = product(&power_series(1, false), &power_series(2, true));
        let identity = product(&phi, &phi_inv);
        assert!((0..n).all(|i| (0..n).all(|j| identity[i][j] == i128::from(i == j))), "Φ⁻¹ is Φ's inverse");
        let as_f64 = |m: &[Vec<i128>]| DMatrix::from_fn(n, n, |i, j| m[i][j] as f64);
        let (phi_f, phi_inv_f) = (as_f64(&phi), as_f64(&phi_inv));
        // The undamped real basis is diag(Φ̂, Φ̂) (Φ̂: Φ's unit columns; module doc): κ₁ = κ₁(Φ̂).
        let column_norms = DVector::from_fn(n, |j, _| phi_f.column(j).norm());
        let unit = &phi_f * DMatrix::from_diagonal(&column_norms.map(|c| 1.0 / c));
        let unit_inv = DMatrix::from_diagonal(&column_norms) * &phi_inv_f;
        let norm1 = |m: &DMatrix<f64>| m.column_iter().map(|c| c.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
        let basis = norm1(&unit) * norm1(&unit_inv);
        let eps = f64::EPSILON;
        let mut worst: f64 = 0.0;
        for top in [12, 16] {
            // ω_j = 2^{e_j} from 1 to 2^top rad/s, ζ = 2^{-7} (2ζω_j = 2^{e_j − 6}), s = 2^top.
            let e: Vec<i32> = (0..n).map(|j| (j as i32 * top) / (n as i32 - 1)).collect();
            let (omega, s) = (e.iter().map(|&e| 2f64.powi(e)).collect::<Vec<_>>(), 2f64.powi(top));
            let zeta = 2f64.powi(-7);
            let mut a = DMatrix::zeros(2 * n, 2 * n);
            a.view_mut((0, n), (n, n)).fill_with_identity();
            a.view_mut((0, n), (n, n)).scale_mut(s);
            let stiffness: Vec<i128> = e.iter().map(|&e| 1i128 << (2 * e)).collect();
            let damping: Vec<i128> = e.iter().map(|&e| 1i128 << e).collect();
            a.view_mut((n, 0), (n, n)).copy_from(&(-similar(&phi, &stiffness, &phi_inv, -top)));
            a.view_mut((n, n), (n, n)).copy_from(&(-similar(&phi, &damping, &phi_inv, -6)));
            let f = EigenFlow::new(&a).expect("distinct, underdamped modes; κ₁(X) within MAX_CONDITION");
            // Damping (ζ = 2^-7) and the stiff modes' velocity parts move X off diag(Φ̂, Φ̂) a little.
            assert!(f.condition <= 2.0 * basis, "κ₁(X) = {:.2e} against the mode shapes' {basis:.2e}", f.condition);
            for tau in [1.0 / omega[n - 1], 1.0 / omega[0]] {
                // The oscillators' flows in [η; η̇] (σ = ζω, ω_d = ω√(1−ζ²)), then y = [Φη; Φη̇/s].
                let mut b = [DVector::zeros(n), DVector::zeros(n), DVector::zeros(n), DVector::zeros(n)];
                for (j, &w) in omega.iter().enumerate() {
                    let (sigma, wd) = (zeta * w, w * (1.0 - zeta * zeta).sqrt());
                    let (decay, (sin, cos)) = ((-sigma * tau).exp(), (wd * tau).sin_cos());
                    b[0][j] = decay * (cos + sigma / wd * sin);
                    b[1][j] = s * decay * sin / wd;
                    b[2][j] = -decay * w * w * sin / wd / s;
                    b[3][j] = decay * (cos - sigma / wd * sin);
                }
                let block = |d: &DVector<f64>| &phi_f * DMatrix::from_diagonal(d) * &phi_inv_f;
                let abs_block = |d: &DVector<f64>| phi_f.abs() * DMatrix::from_diagonal(&d.abs()) * phi_inv_f.abs();
                let mut exact = DMatrix::zeros(2 * n, 2 * n);
                let mut magnitude = DMatrix::zeros(2 * n, 2 * n);
                for (k, (r, c)) in [(0, 0), (0, n), (n, 0), (n, n)].into_iter().enumerate() {
                    exact.view_mut((r, c), (n, n)).copy_from(&block(&b[k]));
                    magnitude.view_mut((r, c), (n, n)).copy_from(&abs_block(&b[k]));
                }
                let scale = norm1(&exact);
                let slowest_phase = (s / omega[0]).powi(2) * omega[0] * tau / 2.0;
                let bound = 2.0 * (2 * n) as f64 * eps * (basis + slowest_phase + n as f64 * norm1(&magnitude) / scale);
                let err = relative(&f.exp(tau), &exact);
                let u = DVector::from_fn(2 * n, |i, _| (i as f64 + 0.5).sin());
                let applied = (f.apply(tau, &u) - &exact * &u).amax() / (&exact * &u).amax();
                println!(
                    "s/ω_min = 2^{top}, ω_min τ = {:.0e}, ω_max τ = {:.0e}: κ₁(X) = {:.2e} (Φ̂: {basis:.2e}), error {err:.2e} = {:.1} ε(s/ω_min)² (apply {applied:.2e}), bound {bound:.2e}",
                    omega[0] * tau,
                    omega[n - 1] * tau,
                    f.condition,
                    err / (eps * (s / omega[0]).powi(2))
                );
                worst = worst.max(err.max(applied) / bound);
            }
        }
        assert!(worst <= 1.0, "the error exceeds its bound {worst:.2}×");
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
