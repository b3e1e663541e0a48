//! A periodic LCP given as a time-stepping map, and one march over its period.
//!
//! The data say nothing of mechanics: a state s ∈ ℝᵈ, k steps, m complementarity pairs per step.
//! Step j (0 ≤ j < k) from state s_j:
//!
//! ```text
//! y_j     = Φ s_j + c_j                      (the step without contact: the predictor)
//! w_j     = r_j + H y_j + S z_j,  S = HΓ + D  (0 ≤ z_j ⊥ w_j ≥ 0, an m×m LCP)
//! s_{j+1} = y_j + Γ z_j
//! ```
//!
//! and the period closes, s_k = s_0. Stacking z_j (index j·m + c) gives an LCP of size k·m whose
//! matrix is dense; here it is the fixed point of the piecewise-affine period map P(s_0) = s_k,
//! which costs O(k·(d² + d·m + |a|³)) to evaluate (|a| the pairs active at a step). Each step's LCP has a unique answer when S is a
//! P-matrix ([`StepMapLcp::new`] checks it), so P is well defined and continuous.
use super::jacobian::{GEMM_MIN, PhiPowers, period_jacobian};
use super::step_lcp::{ActiveBlocks, MAX_PAIRS, check_p_matrix, members, solve_active, step_lcp};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// The data of a step map (see the module documentation), row-major.
#[derive(Clone, Debug, Default)]
pub struct StepMapData {
    /// Steps per period, state size, pairs per step.
    pub k: usize,
    pub d: usize,
    pub m: usize,
    /// Φ without its unit entries (d×d).
    pub phi: Vec<f64>,
    /// The unit entries of Φ as (row, column): y[row] += s[column], added exactly after the dense
    /// product. Why: a state of differences (x, ∇x, …) advances as x_(j+1) = x_j + ∇x_(j+1); a
    /// dense row 1 + O(h²) would round the O(h²) part to ε/h² relative, and a state of raw samples
    /// loses k²·ε over a period to the cancellation in 2x_j − x_(j−1).
    pub carry: Vec<(usize, usize)>,
    /// c_j, k×d.
    pub c: Vec<f64>,
    /// H, m×d.
    pub h: Vec<f64>,
    /// Γ, d×m.
    pub gamma: Vec<f64>,
    /// D: the m×m block added to HΓ, row-major (compliances on its diagonal, and a model's
    /// static flexibility between contacts, e.g. of condensed massless DOFs).
    pub flexibility: Vec<f64>,
    /// r_j, k×m.
    pub r: Vec<f64>,
}

/// A periodic LCP as a step map (see the module documentation), checked.
#[derive(Clone, Debug)]
pub struct StepMapLcp {
    pub(super) k: usize,
    pub(super) d: usize,
    pub(super) m: usize,
    /// Φ without its unit entries (d×d).
    pub(super) phi: Mat<f64>,
    /// The same, row-major: the march's products read rows.
    phi_rows: Vec<f64>,
    /// Row i of Φ, of every c_j and of Γ is row i mod `rows` ([`repeated_rows`]): the march
    /// forms the first `rows` of Φs + c_j and Γz and copies them.
    pub(super) rows: usize,
    /// The unit entries of Φ, (row, column).
    pub(super) carry: Vec<(usize, usize)>,
    /// c_j, k×d.
    pub(super) c: Vec<f64>,
    /// H, m×d.
    pub(super) h: Vec<f64>,
    /// Γ, d×m.
    pub(super) gamma: Vec<f64>,
    /// S = HΓ + D, m×m.
    pub(super) s: Vec<f64>,
    /// r_j, k×m.
    pub(super) r: Vec<f64>,
}

/// Why a step map was not accepted (the caller then solves the LCP another way).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StepMapError {
    #[error("{0}: sizes do not match k = {1}, d = {2}, m = {3}")]
    Size(&'static str, usize, usize, usize),
    #[error("{0} pairs per step; the step-map solver takes at most {MAX_PAIRS} (a step's active set is one 64-bit mask)")]
    TooManyPairs(usize),
    #[error("the step matrix S = HΓ + D is not a P-matrix (principal minor of rows {0:?} is {1:e}): a step's LCP may have no or several answers")]
    NotP(Vec<usize>, f64),
    #[error(
        "the step matrix S = HΓ + D could not be shown a P-matrix: its coupled pairs {0:?} (more than 12, checked through the symmetric part) have a symmetric part that is not positive definite (pivot {1:e})"
    )]
    NotPositiveDefinite(Vec<usize>, f64),
    #[error("the step map holds NaN or infinite values")]
    NonFinite,
}

impl StepMapLcp {
    /// Checks sizes, finiteness and that S = HΓ + D is a P-matrix.
    pub fn new(data: StepMapData) -> Result<Self, StepMapError> {
        let StepMapData { k, d, m, phi, carry, c, h, gamma, flexibility, r } = data;
        let size = |what, ok: bool| if ok { Ok(()) } else { Err(StepMapError::Size(what, k, d, m)) };
        size("phi", phi.len() == d * d)?;
        size("carry", carry.iter().all(|&(i, j)| i < d && j < d))?;
        size("c", c.len() == k * d)?;
        size("h", h.len() == m * d)?;
        size("gamma", gamma.len() == d * m)?;
        size("flexibility", flexibility.len() == m * m)?;
        size("r", r.len() == k * m)?;
        if m > MAX_PAIRS {
            return Err(StepMapError::TooManyPairs(m));
        }
        if !phi.iter().chain(&c).chain(&h).chain(&gamma).chain(&flexibility).chain(&r).all(|v| v.is_finite()) {
            return Err(StepMapError::NonFinite);
        }
        let mut s = vec![0.0; m * m];
        for a in 0..m {
            for b in 0..m {
                s[a * m + b] = (0..d).map(|i| h[a * d + i] * gamma[i * m + b]).sum::<f64>() + flexibility[a * m + b];
            }
        }
        check_p_matrix(&s, m)?;
        let rows = repeated_rows(d, m, &phi, &c, &gamma);
        let phi_rows = phi;
        let phi = Mat::from_fn(d, d, |i, j| phi_rows[i * d + j]);
        Ok(StepMapLcp { k, d, m, phi, phi_rows, rows, carry, c, h, gamma, s, r })
    }

    /// One march over the period from `s0` with every step's LCP solved (its active set tried
    /// first from `guess`, per step): (s_k, the active set of each step, z stacked j·m + c).
    /// `None` when a step breaks down. For analyses of the orbit (continuation, stability).
    pub fn march_period(&self, s0: &[f64], guess: Option<&[u64]>) -> Option<(Vec<f64>, Vec<u64>, Vec<f64>)> {
        let m = march(self, s0, 0.0, Contacts::Solve(guess.unwrap_or(&[])))?;
        Some((m.end, m.masks, m.z))
    }

    /// One march with each step's active set imposed (w_a = 0, z_a free in sign): the affine
    /// piece of P these sets belong to, so that its fixed point is (I − dP/ds0)⁻¹ P(0). `None`
    /// when the sets do not fit k or a step's block is singular. For continuation.
    pub fn march_frozen(&self, s0: &[f64], masks: &[u64]) -> Option<Vec<f64>> {
        if masks.len() != self.k || s0.len() != self.d {
            return None;
        }
        march(self, s0, 0.0, Contacts::Frozen(masks)).map(|m| m.end)
    }

    /// [dP/ds0 | dP/dδ] (d×(d+1), δ a uniform offset of every pair's r_j) on the piece of these
    /// active sets; at a closed orbit dP/ds0 is the discrete monodromy matrix, whose eigenvalues
    /// are the orbit's Floquet multipliers as k grows (src/formulation.md §7).
    pub fn period_jacobian(&self, masks: &[u64]) -> Mat<f64> {
        let mut j = Mat::zeros(self.d, self.d + 1);
        period_jacobian(self, masks, &PhiPowers::new(self), &mut j);
        j
    }

    pub fn k(&self) -> usize {
        self.k
    }
    pub fn state_size(&self) -> usize {
        self.d
    }
    pub fn pairs(&self) -> usize {
        self.m
    }
    /// The step matrix S (m×m, row-major).
    pub fn step_matrix(&self) -> &[f64] {
        &self.s
    }
}

/// The least n dividing d such that row i of Φ (d×d), of every c_j (k×d) and of Γ (d×m) equals
/// row i mod n bit for bit; d when there is none. Why: a scheme's state of differences
/// (x, ∇x, …) advances every block by the same δ (src/periodic/state_space.rs), so its rows repeat
/// and half of the march's Φs (the real blade's d = 40) was computed twice.
fn repeated_rows(d: usize, m: usize, phi: &[f64], c: &[f64], gamma: &[f64]) -> usize {
    let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let repeats = |n: usize| {
        (n..d).all(|i| {
            let o = i % n;
            same(&phi[i * d..(i + 1) * d], &phi[o * d..(o + 1) * d])
                && same(&gamma[i * m..(i + 1) * m], &gamma[o * m..(o + 1) * m])
                && c.chunks_exact(d).all(|cj| cj[i].to_bits() == cj[o].to_bits())
        })
    };
    (1..d).find(|&n| d.is_multiple_of(n) && repeats(n)).unwrap_or(d)
}

/// What one march over the period gives.
pub(super) struct March {
    /// s_k = P(s_0).
    pub end: Vec<f64>,
    /// z_j, k×m.
    pub z: Vec<f64>,
    /// The active set of each step.
    pub masks: Vec<u64>,
    /// Step-LCP set changes summed over the period (the march's "pivots").
    pub changes: usize,
    /// The smallest w over the period (negative: a pair violated, only in a free march).
    pub min_w: f64,
}

/// How a march treats the contacts.
#[derive(Clone, Copy)]
pub(super) enum Contacts<'a> {
    /// z = 0 throughout (the contact-free orbit).
    Free,
    /// Each step's LCP solved, starting from these sets (per step).
    Solve(&'a [u64]),
    /// The active set of each step imposed (w_a = 0, z_a free in sign): an affine map.
    Frozen(&'a [u64]),
}

/// LU with partial pivoting of a small dense matrix, by plain loops (see
/// [`super::jacobian::product`] for why not faer's). A zero pivot is kept: the solutions are then not finite, which callers check.
pub struct DenseLu {
    n: usize,
    lu: Vec<f64>,
    perm: Vec<usize>,
}

impl DenseLu {
    pub fn new(a: &Mat<f64>) -> DenseLu {
        let n = a.nrows();
        let mut lu: Vec<f64> = (0..n * n).map(|e| a[(e / n, e % n)]).collect();
        let mut perm: Vec<usize> = (0..n).collect();
        for col in 0..n {
            let piv = (col..n).max_by(|&i, &j| lu[i * n + col].abs().total_cmp(&lu[j * n + col].abs())).unwrap_or(col);
            if piv != col {
                for j in 0..n {
                    lu.swap(piv * n + j, col * n + j);
                }
                perm.swap(piv, col);
            }
            let p = lu[col * n + col];
            for i in col + 1..n {
                let f = lu[i * n + col] / p;
                lu[i * n + col] = f;
                for j in col + 1..n {
                    lu[i * n + j] -= f * lu[col * n + j];
                }
            }
        }
        DenseLu { n, lu, perm }
    }

    /// a⁻¹ b.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut x: Vec<f64> = self.perm.iter().map(|&i| b[i]).collect();
        for i in 0..n {
            let t: f64 = (0..i).map(|j| self.lu[i * n + j] * x[j]).sum();
            x[i] -= t;
        }
        for i in (0..n).rev() {
            let t: f64 = (i + 1..n).map(|j| self.lu[i * n + j] * x[j]).sum();
            x[i] = (x[i] - t) / self.lu[i * n + i];
        }
        x
    }
}

/// Marches one period from `s0` with offset `shift` added to every r_j.
pub(super) fn march(sm: &StepMapLcp, s0: &[f64], shift: f64, contacts: Contacts<'_>) -> Option<March> {
    march_with(&mut ActiveBlocks::default(), sm, s0, shift, contacts)
}

/// [`march`] with the step map's factored blocks, kept across a solve's marches.
pub(super) fn march_with(blocks: &mut ActiveBlocks, sm: &StepMapLcp, s0: &[f64], shift: f64, contacts: Contacts<'_>) -> Option<March> {
    let (k, d, m) = (sm.k, sm.d, sm.m);
    let mut s = s0.to_vec();
    let mut y = vec![0.0; d];
    let mut r = vec![0.0; m];
    let mut zs = vec![0.0; m];
    let mut ws = vec![0.0; m];
    let mut out = March { end: Vec::new(), z: vec![0.0; k * m], masks: vec![0; k], changes: 0, min_w: f64::INFINITY };
    let mut previous = 0u64;
    // A large state's products go to faer's matrix–vector kernels (SIMD chosen at run time: 3×
    // faster at d = 200, where the march is a third of a k = 8192 solve); a small one's stay
    // plain loops (see `GEMM_MIN`).
    let gemv = d >= GEMM_MIN;
    let h_rows = MatRef::from_row_major_slice(&sm.h, m, d);
    // The distinct rows of Φs + c_j and Γz (the others repeat them: `repeated_rows`).
    let n = sm.rows;
    let mut gz = vec![0.0; n];
    for step in 0..k {
        if gemv {
            y.copy_from_slice(&sm.c[step * d..(step + 1) * d]);
            let x = MatRef::from_column_major_slice(&s, d, 1);
            matmul(MatMut::from_column_major_slice_mut(&mut y, d, 1), Accum::Add, sm.phi.as_ref(), x, 1.0, Par::Seq);
        } else {
            rows_dot(&sm.phi_rows[..n * d], &s, &mut y[..n]);
            y[..n].iter_mut().zip(&sm.c[step * d..step * d + n]).for_each(|(v, &c)| *v += c);
            for block in 1..d / n {
                y.copy_within(0..n, block * n);
            }
        }
        for &(i, l) in &sm.carry {
            y[i] += s[l];
        }
        if gemv {
            r.iter_mut().zip(&sm.r[step * m..(step + 1) * m]).for_each(|(ra, &rj)| *ra = rj + shift);
            let x = MatRef::from_column_major_slice(&y, d, 1);
            matmul(MatMut::from_column_major_slice_mut(&mut r, m, 1), Accum::Add, h_rows, x, 1.0, Par::Seq);
        } else {
            rows_dot(&sm.h, &y, &mut r);
            r.iter_mut().zip(&sm.r[step * m..(step + 1) * m]).for_each(|(v, &rj)| *v += rj + shift);
        }
        let mask = match contacts {
            Contacts::Free => {
                out.min_w = r.iter().fold(out.min_w, |a, &v| a.min(v));
                zs.iter_mut().for_each(|v| *v = 0.0);
                0
            }
            Contacts::Solve(guess) => {
                // The same step's set at the previous march, else the previous step's.
                let (mask, changes) = step_lcp(blocks, &sm.s, m, &r, guess.get(step).copied().unwrap_or(previous), &mut zs, &mut ws)?;
                out.changes += changes;
                mask
            }
            Contacts::Frozen(sets) => {
                let mask = sets[step];
                if !solve_active(blocks, &sm.s, m, &r, mask, &mut zs) {
                    return None;
                }
                mask
            }
        };
        out.masks[step] = mask;
        previous = mask;
        out.z[step * m..(step + 1) * m].copy_from_slice(&zs);
        s.copy_from_slice(&y);
        if mask != 0 {
            let (act, p) = members(mask, m);
            for (i, g) in gz.iter_mut().enumerate() {
                *g = act[..p].iter().map(|&a| sm.gamma[i * m + a] * zs[a]).sum::<f64>();
            }
            for (i, v) in s.iter_mut().enumerate() {
                *v += gz[i % n];
            }
        }
    }
    if !s.iter().all(|v| v.is_finite()) {
        return None;
    }
    out.end = s;
    Some(out)
}

/// `out[i]` = row i of the row-major `a` (out.len() rows of x.len()) times `x`, each row summed
/// as [`dot`] sums it (bit for bit), four rows at a time. Why: one row's four running sums wait
/// on the adder's latency; four rows' sixteen are independent (the march's d² per step).
fn rows_dot(a: &[f64], x: &[f64], out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked on the line above).
        unsafe { rows_dot_avx2(a, x, out) };
        return;
    }
    rows_dot_in_order(a, x, out);
}

/// [`rows_dot_in_order`] in AVX2 registers, eight rows at a time: a row's four running sums are
/// one register (lane l sums the terms l, l + 4, …), multiplied then added as there (no fused
/// multiply-add), so the same bits; the rows left over go to [`rows_dot_in_order`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn rows_dot_avx2(a: &[f64], x: &[f64], out: &mut [f64]) {
    use std::arch::x86_64::{__m256d, _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_storeu_pd};
    const ROWS: usize = 8;
    let (n, rows) = (x.len(), out.len());
    let full = n - n % 4;
    assert!(a.len() >= rows * n);
    let blocked = rows / ROWS * ROWS;
    for i in (0..blocked).step_by(ROWS) {
        let mut acc: [__m256d; ROWS] = [_mm256_setzero_pd(); ROWS];
        for j in (0..full).step_by(4) {
            // SAFETY: j + 4 ≤ full ≤ n = x.len(), and (i + r)·n + j + 4 ≤ rows·n ≤ a.len().
            unsafe {
                let xs = _mm256_loadu_pd(x.as_ptr().add(j));
                for (r, acc) in acc.iter_mut().enumerate() {
                    *acc = _mm256_add_pd(*acc, _mm256_mul_pd(_mm256_loadu_pd(a.as_ptr().add((i + r) * n + j)), xs));
                }
            }
        }
        for (r, acc) in acc.iter().enumerate() {
            let mut l = [0.0; 4];
            // SAFETY: l holds four f64.
            unsafe { _mm256_storeu_pd(l.as_mut_ptr(), *acc) };
            let row = &a[(i + r) * n..(i + r + 1) * n];
            let tail: f64 = row[full..].iter().zip(&x[full..]).map(|(x, y)| x * y).sum();
            out[i + r] = (l[0] + l[1]) + (l[2] + l[3]) + tail;
        }
    }
    rows_dot_in_order(&a[blocked * n..], x, &mut out[blocked..]);
}

#[inline(always)]
fn rows_dot_in_order(a: &[f64], x: &[f64], out: &mut [f64]) {
    let (n, rows) = (x.len(), out.len());
    let full = n - n % 4;
    let mut blocks = out.chunks_exact_mut(4);
    for (b, o) in blocks.by_ref().enumerate() {
        let rows: [&[f64]; 4] = std::array::from_fn(|r| &a[(4 * b + r) * n..(4 * b + r + 1) * n]);
        let mut acc = [[0.0f64; 4]; 4];
        for j in (0..full).step_by(4) {
            let xs: &[f64; 4] = x[j..j + 4].try_into().unwrap_or(&[0.0; 4]);
            for (acc, row) in acc.iter_mut().zip(&rows) {
                let ys: &[f64; 4] = row[j..j + 4].try_into().unwrap_or(&[0.0; 4]);
                for l in 0..4 {
                    acc[l] += ys[l] * xs[l];
                }
            }
        }
        for ((o, acc), row) in o.iter_mut().zip(&acc).zip(&rows) {
            let tail: f64 = row[full..].iter().zip(&x[full..]).map(|(x, y)| x * y).sum();
            *o = (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail;
        }
    }
    let done = rows - blocks.into_remainder().len();
    for (i, o) in out.iter_mut().enumerate().skip(done) {
        *o = dot(&a[i * n..(i + 1) * n], x);
    }
}

/// Σ a_i b_i in four running sums (the march's inner product: d² per step).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ac.remainder().iter().zip(bc.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in ac.zip(bc) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The march's blocked products equal the row-by-row [`dot`] bit for bit, on every path
    /// (AVX2 when the CPU has it, the in-order loop), with rows left over after the blocks of 8
    /// and 4 and rows whose length is not a multiple of 4; values of mixed sign and scale, so a
    /// change of summation order would show in the last bits.
    #[test]
    fn the_blocked_row_products_equal_the_row_by_row_dot_bit_for_bit() {
        let mut seed = 11u64;
        let mut draw = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi((seed % 7) as i32 - 3)
        };
        for (rows, n) in [(40, 40), (17, 40), (13, 41), (3, 7), (8, 4), (0, 5), (21, 2)] {
            let a: Vec<f64> = (0..rows * n).map(|_| draw()).collect();
            let x: Vec<f64> = (0..n).map(|_| draw()).collect();
            let reference: Vec<u64> = (0..rows).map(|i| dot(&a[i * n..(i + 1) * n], &x).to_bits()).collect();
            let (mut fast, mut in_order) = (vec![0.0; rows], vec![0.0; rows]);
            rows_dot(&a, &x, &mut fast);
            rows_dot_in_order(&a, &x, &mut in_order);
            assert_eq!(fast.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), reference, "rows_dot, {rows}×{n}");
            assert_eq!(in_order.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), reference, "in order, {rows}×{n}");
        }
    }

    /// A state of differences (two blocks whose rows of Φ, c_j and Γ repeat, as the schemes'):
    /// [`repeated_rows`] finds the block, and a march on its distinct rows gives the bits of the
    /// march on every row (the same map with `rows` = d), in z, the sets and the end state.
    #[test]
    fn a_march_on_the_distinct_rows_equals_the_march_on_every_row_bit_for_bit() {
        let (k, n, m) = (200, 5, 3);
        let d = 2 * n;
        let mut seed = 17u64;
        let mut draw = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let block: Vec<f64> = (0..n * d).map(|_| 0.01 * draw()).collect();
        let phi: Vec<f64> = (0..d * d).map(|e| block[(e / d % n) * d + e % d]).collect();
        let c_rows: Vec<f64> = (0..k * n).map(|_| draw()).collect();
        let c: Vec<f64> = (0..k * d).map(|e| c_rows[e / d * n + e % d % n]).collect();
        let g: Vec<f64> = (0..n * m).map(|_| 0.1 * draw()).collect();
        let gamma: Vec<f64> = (0..d * m).map(|e| g[(e / m % n) * m + e % m]).collect();
        let data = StepMapData {
            k,
            d,
            m,
            phi,
            carry: (0..2).flat_map(|b| (b..2).flat_map(move |i| (0..n).map(move |r| (b * n + r, i * n + r)))).collect(),
            c,
            h: (0..m * d).map(|_| draw()).collect(),
            gamma,
            flexibility: (0..m * m).map(|e| if e % (m + 1) == 0 { 2.0 } else { 0.0 }).collect(),
            r: (0..k * m).map(|_| 0.3 * draw()).collect(),
        };
        let sm = StepMapLcp::new(data).unwrap();
        assert_eq!(sm.rows, n);
        let mut every = sm.clone();
        every.rows = d;
        let s0: Vec<f64> = (0..d).map(|_| draw()).collect();
        let (a, b) = (march(&sm, &s0, 0.0, Contacts::Solve(&[])).unwrap(), march(&every, &s0, 0.0, Contacts::Solve(&[])).unwrap());
        assert!(a.masks.iter().any(|&s| s != 0), "no pair is ever active");
        assert_eq!(a.masks, b.masks);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.z), bits(&b.z));
        assert_eq!(bits(&a.end), bits(&b.end));
        // The step matrices of the Jacobian read the same rows: equal to every row's.
        let powers = PhiPowers::new(&sm);
        for mask in 1u64..(1 << m) {
            let (x, y) = (super::super::jacobian::step_matrix(&sm, &powers, mask), super::super::jacobian::step_matrix(&every, &powers, mask));
            assert!((0..=d).all(|i| (0..=d).all(|j| x[(i, j)].to_bits() == y[(i, j)].to_bits())), "set {mask:b}");
        }
    }
}
