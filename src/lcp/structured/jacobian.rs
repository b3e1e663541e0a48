//! The period Jacobian of a step map on the piece of given active sets, by runs.
//!
//! In augmented form ([s; 1] ↦ T [s; 1], the last column the derivative in a uniform offset δ of
//! every r_j) a step with active set a is
//!
//! ```text
//! T_a = [ (I − Γ_a S_aa⁻¹ H_a) Φ   −Γ_a S_aa⁻¹ 1_a ]
//!       [ 0                        1               ]
//! ```
//!
//! and the period's Jacobian is the product of the k steps' T. Along a period the active set
//! changes at a few hundred steps at most: a run of L steps with one set is T_a^L, formed by
//! repeated squaring (⌊log₂ L⌋ squarings and popcount(L) products with J), the empty set's from
//! cached powers Φ^(2^i). The work is O(runs · log k · d³), not O(k · d³).
use super::step_lcp::MAX_PAIRS;
use super::step_map::{DenseLu, StepMapLcp};
use faer::Mat;
use std::collections::HashMap;

/// Above this size a product goes to faer's gemm (cache blocking and SIMD, several times faster);
/// below, plain loops. Why not faer always: its kernels keep thread-local packing buffers that an
/// FMU unloaded by `dlclose` can never free (valgrind: definitely lost), and the FMU's models
/// are small.
pub(super) const GEMM_MIN: usize = 96;

/// a·b.
pub fn product(a: &Mat<f64>, b: &Mat<f64>) -> Mat<f64> {
    let (n, inner, m) = (a.nrows(), a.ncols(), b.ncols());
    let mut c = Mat::<f64>::zeros(n, m);
    if n.min(inner).min(m) >= GEMM_MIN {
        faer::linalg::matmul::matmul(c.as_mut(), faer::Accum::Replace, a.as_ref(), b.as_ref(), 1.0, faer::Par::Seq);
        return c;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU has AVX-512F (checked on the line above).
        unsafe { blocked_avx512(a, b, &mut c) };
        return c;
    } else if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked on the line above).
        unsafe { blocked_avx2(a, b, &mut c) };
        return c;
    }
    blocked(a, b, &mut c);
    c
}

/// [`blocked`] compiled for AVX-512 (the build targets baseline x86-64: SSE2 alone).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn blocked_avx512(a: &Mat<f64>, b: &Mat<f64>, c: &mut Mat<f64>) {
    blocked(a, b, c);
}

/// [`blocked`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn blocked_avx2(a: &Mat<f64>, b: &Mat<f64>, c: &mut Mat<f64>) {
    blocked(a, b, c);
}

/// Rows and columns of c held in registers by [`blocked`] (8 × 4 measured fastest at d + 1 = 41:
/// 2.0× the plain axpy loop under AVX2, 2.8× under AVX-512).
const BLOCK_ROWS: usize = 8;
const BLOCK_COLS: usize = 4;

/// c = a·b by blocks of c kept in registers, each entry summed over l in order from 0, as the
/// plain loop c_ij += a_il·b_lj does: the same operations in the same order, so the result is
/// bit-identical whatever the instruction set (Rust never fuses a·b + c). Why: the Jacobians'
/// (d+1)² products were a sixth of the real blade's 1e-3 sweep (issue 23), and the axpy loop
/// reloads and stores a column of c per term.
#[inline(always)]
fn blocked(a: &Mat<f64>, b: &Mat<f64>, c: &mut Mat<f64>) {
    let (n, inner, m) = (a.nrows(), a.ncols(), b.ncols());
    let (rows, cols) = (n / BLOCK_ROWS * BLOCK_ROWS, m / BLOCK_COLS * BLOCK_COLS);
    let entry = |i: usize, j: usize| (0..inner).fold(0.0, |s, l| s + a[(i, l)] * b[(l, j)]);
    let a_columns: Vec<&[f64]> = (0..inner).map(|l| a.col_as_slice(l)).collect();
    for j in (0..cols).step_by(BLOCK_COLS) {
        let columns: [&[f64]; BLOCK_COLS] = std::array::from_fn(|cc| b.col_as_slice(j + cc));
        for i in (0..rows).step_by(BLOCK_ROWS) {
            let mut acc = [[0.0f64; BLOCK_ROWS]; BLOCK_COLS];
            for (l, a_column) in a_columns.iter().enumerate() {
                let ail: &[f64; BLOCK_ROWS] = a_column[i..i + BLOCK_ROWS].try_into().expect("a block of rows");
                for (cc, acc) in acc.iter_mut().enumerate() {
                    let blj = columns[cc][l];
                    for x in 0..BLOCK_ROWS {
                        acc[x] += ail[x] * blj;
                    }
                }
            }
            for (cc, acc) in acc.iter().enumerate() {
                c.col_as_slice_mut(j + cc)[i..i + BLOCK_ROWS].copy_from_slice(acc);
            }
        }
        // The rows left (the augmented row at d + 1 = 41): BLOCK_COLS sums side by side, not one
        // entry's chain of dependent adds at a time (that tail took as long as the blocks).
        for i in rows..n {
            let mut acc = [0.0f64; BLOCK_COLS];
            for (l, a_column) in a_columns.iter().enumerate() {
                let ail = a_column[i];
                for (cc, acc) in acc.iter_mut().enumerate() {
                    *acc += ail * columns[cc][l];
                }
            }
            for (cc, acc) in acc.iter().enumerate() {
                c[(i, j + cc)] = *acc;
            }
        }
    }
    // The columns left: BLOCK_ROWS rows at a time, as the blocks.
    for j in cols..m {
        let column = b.col_as_slice(j);
        for i in (0..rows).step_by(BLOCK_ROWS) {
            let mut acc = [0.0f64; BLOCK_ROWS];
            for (l, a_column) in a_columns.iter().enumerate() {
                let ail: &[f64; BLOCK_ROWS] = a_column[i..i + BLOCK_ROWS].try_into().expect("a block of rows");
                let blj = column[l];
                for x in 0..BLOCK_ROWS {
                    acc[x] += ail[x] * blj;
                }
            }
            c.col_as_slice_mut(j)[i..i + BLOCK_ROWS].copy_from_slice(&acc);
        }
        for i in rows..n {
            c[(i, j)] = entry(i, j);
        }
    }
}

/// Powers of the contact-free step, augmented: diag(Φ, 1)^(2^i), i = 0..=log₂ k; with H·Φ (m×d,
/// row-major), which every step matrix reads ([`step_matrix`]).
pub(super) struct PhiPowers(Vec<Mat<f64>>, Vec<f64>);

impl PhiPowers {
    pub(super) fn new(sm: &StepMapLcp) -> Self {
        let (d, m) = (sm.d, sm.m);
        let mut first = Mat::zeros(d + 1, d + 1);
        first.as_mut().submatrix_mut(0, 0, d, d).copy_from(sm.phi.as_ref());
        for &(i, j) in &sm.carry {
            first[(i, j)] += 1.0;
        }
        first[(d, d)] = 1.0;
        // Row a of H times Φ, summed over i in order as each step matrix summed it.
        let h_phi = (0..m * d).map(|e| (0..d).map(|i| sm.h[e / d * d + i] * first[(i, e % d)]).sum()).collect();
        let mut p = vec![first];
        while 1usize << p.len() <= sm.k {
            let last = p.last().expect("one power");
            p.push(product(last, last));
        }
        PhiPowers(p, h_phi)
    }
}

/// T^n from the powers T^(2^i) (as many as n needs; n ≥ 1); returns it and the products formed.
fn from_powers(powers: &[Mat<f64>], n: usize) -> (Mat<f64>, usize) {
    let mut bits = (0..usize::BITS as usize).filter(|&i| n >> i & 1 == 1);
    let first = bits.next().expect("n ≥ 1");
    bits.fold((powers[first].clone(), 0), |(acc, formed), i| (product(&powers[i], &acc), formed + 1))
}

/// T^n (n ≥ 1) by repeated squaring; returns it and the products formed.
fn power(t: Mat<f64>, mut n: usize) -> (Mat<f64>, usize) {
    let mut formed = 0;
    let mut base = t;
    let mut acc: Option<Mat<f64>> = None;
    loop {
        if n & 1 == 1 {
            acc = Some(match acc {
                None => base.clone(),
                Some(a) => {
                    formed += 1;
                    product(&base, &a)
                }
            });
        }
        n >>= 1;
        if n == 0 {
            return (acc.expect("n ≥ 1"), formed);
        }
        base = product(&base, &base);
        formed += 1;
    }
}

/// The augmented step T_a ((d+1)×(d+1), see the module documentation) of a non-empty set.
pub(super) fn step_matrix(sm: &StepMapLcp, powers: &PhiPowers, mask: u64) -> Mat<f64> {
    let (d, m) = (sm.d, sm.m);
    let phi = &powers.0[0];
    let act: Vec<usize> = (0..m).filter(|&i| mask >> i & 1 == 1).collect();
    let p = act.len();
    debug_assert!(p <= MAX_PAIRS);
    let lu = DenseLu::new(&Mat::from_fn(p, p, |a, b| sm.s[act[a] * m + act[b]]));
    // Y = S_aa⁻¹ [H_a Φ | 1_a], column by column (p×(d+1)).
    let mut y = Mat::<f64>::zeros(p, d + 1);
    let mut rhs = vec![0.0; p];
    for col in 0..=d {
        for (r, &a) in act.iter().enumerate() {
            rhs[r] = if col == d { 1.0 } else { powers.1[a * d + col] };
        }
        for (r, v) in lu.solve(&rhs).into_iter().enumerate() {
            y[(r, col)] = v;
        }
    }
    // Γ_a Y's rows repeat as Γ's do (`StepMapLcp::rows`): the distinct ones, then subtracted.
    let n = sm.rows;
    let mut t = phi.clone();
    let mut term = vec![0.0; n];
    for col in 0..=d {
        for (i, v) in term.iter_mut().enumerate() {
            *v = act.iter().enumerate().map(|(r, &a)| sm.gamma[i * m + a] * y[(r, col)]).sum::<f64>();
        }
        for i in 0..d {
            t[(i, col)] -= term[i % n];
        }
    }
    t
}

/// [dP/ds0 | dP/dshift] (d×(d+1)) on the piece of these active sets: P is affine there, so the
/// Jacobian depends on the sets alone (dP/ds0 is the discrete monodromy matrix when the orbit
/// closes). Returns the (d+1)×(d+1) products it formed (the work, with the runs' steps).
pub(super) fn period_jacobian(sm: &StepMapLcp, masks: &[u64], powers: &PhiPowers, j: &mut Mat<f64>) -> usize {
    RunsJacobian::default().form(sm, masks, powers, j)
}

/// The period Jacobian by runs, keeping between calls on one step map what the next call can
/// reuse: each set's step matrix, each run's power T_a^L, and the product after each run of the
/// last call, so that a call whose sets first differ at run r starts from the product before r.
/// Why: Newton's Jacobians within one solve differ in a few steps (a warm start's sets, then the
/// answer's), and the same sets recur along a period (two lobes per revolution): on the real
/// blade (issue 23) most of a sweep point's Jacobian work was forming what the last call formed.
#[derive(Default)]
pub(super) struct RunsJacobian {
    steps: HashMap<u64, Mat<f64>>,
    powers: HashMap<(u64, usize), Mat<f64>>,
    /// The last call's runs (set, length) with the product of the runs up to each.
    prefix: Vec<((u64, usize), Mat<f64>)>,
}

/// Run powers kept at most (each (d+1)² numbers): a long homotopy meets thousands of runs.
const KEPT_POWERS: usize = 2048;

impl RunsJacobian {
    /// [`period_jacobian`], reusing this cache's products (`sm` and `powers` the same at every call).
    pub(super) fn form(&mut self, sm: &StepMapLcp, masks: &[u64], powers: &PhiPowers, j: &mut Mat<f64>) -> usize {
        // Small states keep the step-by-step product (k products of d³ are cheap there): the runs'
        // squaring rounds differently, and the discrete walk's kink tests on NLvib 03 at k = 4096
        // (tests/continuation.rs, nlvib03_branch_events_amplitudes_stability) lose the branch with it.
        if sm.d <= STEPWISE_MAX_D {
            *j = by_steps(sm, masks, powers);
            return masks.len();
        }
        let d = sm.d;
        let mut runs = Vec::new();
        let mut start = 0;
        while start < masks.len() {
            let len = masks[start..].iter().take_while(|&&m| m == masks[start]).count();
            runs.push((masks[start], len));
            start += len;
        }
        let same = self.prefix.iter().zip(&runs).take_while(|(kept, run)| kept.0 == **run).count();
        self.prefix.truncate(same);
        if self.powers.len() > KEPT_POWERS {
            self.powers.clear();
        }
        let mut formed = 0;
        for &(mask, len) in &runs[same..] {
            if !self.powers.contains_key(&(mask, len)) {
                let (p, n) = if mask == 0 {
                    from_powers(&powers.0, len)
                } else {
                    let t = self.steps.entry(mask).or_insert_with(|| step_matrix(sm, powers, mask));
                    power(t.clone(), len)
                };
                formed += n;
                self.powers.insert((mask, len), p);
            }
            let p = &self.powers[&(mask, len)];
            let acc = match self.prefix.last() {
                Some((_, before)) => {
                    formed += 1;
                    product(p, before)
                }
                None => p.clone(),
            };
            self.prefix.push(((mask, len), acc));
        }
        *j = match self.prefix.last() {
            Some((_, acc)) => acc.as_ref().submatrix(0, 0, d, d + 1).to_owned(),
            None => Mat::<f64>::identity(d + 1, d + 1).as_ref().submatrix(0, 0, d, d + 1).to_owned(),
        };
        formed
    }
}

/// Up to this state size the period Jacobian is formed step by step: NLvib 03's small state
/// keeps it (see above). Not above: at 64 the k products made the rigid coarse blade's (d = 46)
/// 100-point sweep 6× costlier (9.4 s of CPU against 1.4 s by runs, issue 23).
const STEPWISE_MAX_D: usize = 16;

/// The same Jacobian step by step (k products): the reference of the runs' product.
#[cfg(test)]
pub(super) fn period_jacobian_by_steps(sm: &StepMapLcp, masks: &[u64]) -> Mat<f64> {
    by_steps(sm, masks, &PhiPowers::new(sm))
}

fn by_steps(sm: &StepMapLcp, masks: &[u64], powers: &PhiPowers) -> Mat<f64> {
    let d = sm.d;
    let mut acc = Mat::<f64>::identity(d + 1, d + 1);
    // A run of steps with one set shares its T_a: formed once per run (the same numbers).
    let mut run: Option<(u64, Mat<f64>)> = None;
    for &mask in masks {
        if run.as_ref().is_none_or(|(m, _)| *m != mask) {
            run = Some((mask, if mask == 0 { powers.0[0].clone() } else { step_matrix(sm, powers, mask) }));
        }
        let (_, t) = run.as_ref().expect("set above");
        acc = product(t, &acc);
    }
    acc.as_ref().submatrix(0, 0, d, d + 1).to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lcp::structured::StepMapData;

    /// Uniform draws in [−½, ½) from a linear congruential generator seeded with `seed`.
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// The blocked product (register blocks, AVX2/AVX-512 where the CPU has them) equals the
    /// textbook triple loop bit for bit, on sizes with and without remainder rows and columns.
    #[test]
    fn the_blocked_product_equals_the_triple_loop_bit_for_bit() {
        let mut draw = uniform(5);
        for (n, inner, m) in [(41, 41, 41), (1, 1, 1), (8, 3, 4), (13, 7, 9), (95, 40, 17)] {
            let a = Mat::from_fn(n, inner, |_, _| draw());
            let b = Mat::from_fn(inner, m, |_, _| draw());
            let c = product(&a, &b);
            for i in 0..n {
                for j in 0..m {
                    let mut sum = 0.0;
                    for l in 0..inner {
                        sum += a[(i, l)] * b[(l, j)];
                    }
                    assert_eq!(c[(i, j)].to_bits(), sum.to_bits(), "({n}×{inner})·({inner}×{m}) at ({i}, {j})");
                }
            }
        }
    }

    /// The runs' product (squaring, cached powers of Φ, faer's gemm at d = 120 > GEMM_MIN) equals
    /// the step-by-step product to round-off, on sets with runs of every length and an empty run
    /// at both ends.
    #[test]
    fn the_runs_product_equals_the_step_by_step_product() {
        let mut draw = uniform(11);
        for (d, m, k) in [(7, 3, 300), (40, 6, 1000), (120, 5, 1000)] {
            // Φ near the identity (a damped step) with a carry on its diagonal, as the schemes'.
            let phi: Vec<f64> = (0..d * d).map(|e| if e / d == e % d { -0.002 } else { 0.02 / d as f64 } * (1.0 + draw())).collect();
            let h: Vec<f64> = (0..m * d).map(|_| draw()).collect();
            let gamma: Vec<f64> = (0..d * m).map(|_| 0.1 * draw()).collect();
            let sm = StepMapLcp::new(StepMapData {
                k,
                d,
                m,
                phi,
                carry: (0..d).map(|i| (i, i)).collect(),
                c: vec![0.0; k * d],
                h,
                gamma,
                // A large compliance keeps S = HΓ + D positive definite.
                flexibility: (0..m * m).map(|i| if i % (m + 1) == 0 { 10.0 } else { 0.0 }).collect(),
                r: vec![0.0; k * m],
            })
            .unwrap();
            let mut masks = vec![0u64; k];
            let mut j = 17;
            let mut len = 1;
            while j < k - 40 {
                let mask = 1 + j as u64 % ((1 << m) - 1);
                masks[j..(j + len).min(k - 40)].iter_mut().for_each(|v| *v = mask);
                j += len + 3;
                len = len * 2 + 1;
            }
            let by_runs = sm.period_jacobian(&masks);
            let by_steps = period_jacobian_by_steps(&sm, &masks);
            let scale = by_steps.norm_max();
            let error = (&by_runs - &by_steps).norm_max();
            eprintln!("d = {d}, k = {k}: ‖J‖ = {scale:.3e}, runs − steps = {error:.3e}");
            assert!(scale > 1e-3 && error <= 1e-11 * scale, "d = {d}: {error:e} of {scale:e}");
        }
    }
}
