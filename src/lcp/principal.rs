//! Principal-block solves: the LU of A_αα and its conditioning check, the final solve of a
//! complementary basis on the original data, and a safeguarded polish of a nearly-right basis.
//! Shared by Lemke (`lemke/`) and block pivoting (`pivoting.rs`); depends on the matrix trait and
//! on the certification helpers of `status.rs` only.
//!
//! Lemke's pivots run on an explicitly updated B⁻¹, whose round-off grows with the number of
//! pivots and the conditioning of the bases. On near-degenerate problems (a contact force grazing
//! zero, say) the last pivots can then pick a basis that is off by a few indices: the exact
//! re-solve shows a few z_i < 0 (i ∈ α) or w_i < 0 (i ∉ α). The polish repairs that by block
//! principal pivoting (Kostreva 1978; Júdice & Pires 1994; Cottle, Pang & Stone 1992, §4.1):
//! move the violating indices across, re-solve, and fall back to Murty's single least-index
//! exchange (Murty 1974) when full exchanges stop reducing the number of violations. It is
//! finite for P-matrices; for other matrices a round cap bounds it, and only a certified answer
//! is ever accepted.
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting;
use faer::linalg::solvers::PartialPivLu;
use faer::{Conj, Mat, MatMut};

use super::LcpMatrix;
use super::status::{Candidate, evaluate};

/// Pivot ratio below which A_FF counts as singular (the fast path then gives up).
const SINGULAR_RATIO: f64 = 1e-14;

/// The LU's U has no pivot below SINGULAR_RATIO of the largest (NaN counts as singular).
pub(crate) fn well_conditioned(u: faer::MatRef<'_, f64>) -> bool {
    let (lo, hi) = (0..u.nrows()).fold((f64::INFINITY, 0.0f64), |(l, h), i| (l.min(u[(i, i)].abs()), h.max(u[(i, i)].abs())));
    lo > SINGULAR_RATIO * hi || u.nrows() == 0
}

/// The workspace of solves with a [`PartialPivLu`] of one size, allocated once.
///
/// Why: faer's `Solve::solve_in_place` allocates its row-permutation scratch on every call; in a
/// pivot loop that is one allocation per pivot. This calls the same kernel
/// (`lu::partial_pivoting::solve::solve_in_place_with_conj`, same parallelism) with a stack
/// that lives as long as the solver, as faer's own low-level API intends.
pub(crate) struct LuScratch {
    n: usize,
    buf: MemBuffer,
}

impl LuScratch {
    /// For an n×n LU and one right-hand side.
    pub(crate) fn new(n: usize) -> Self {
        let req = partial_pivoting::solve::solve_in_place_scratch::<usize, f64>(n, 1, faer::get_global_parallelism());
        LuScratch { n, buf: MemBuffer::new(req) }
    }
    /// rhs ← A⁻¹ rhs (rhs n×1). Panics if the sizes differ from the LU's (a programming error).
    pub(crate) fn solve_in_place(&mut self, lu: &PartialPivLu<f64>, rhs: MatMut<'_, f64>) {
        assert!(lu.U().nrows() == self.n && rhs.nrows() == self.n && rhs.ncols() == 1, "LuScratch: sizes differ from the LU");
        let stack = MemStack::new(&mut self.buf);
        partial_pivoting::solve::solve_in_place_with_conj(lu.L(), lu.U(), lu.P(), Conj::No, rhs, faer::get_global_parallelism(), stack);
    }
}

/// Solves A_αα z_α = −q_α by LU with partial pivoting and `steps` of iterative refinement (the
/// residual recomputed from the original entries each step). Returns the full z (zero off α), or
/// None if the solve is not finite (singular A_αα).
pub(crate) fn solve_principal(a: &dyn LcpMatrix, q: &[f64], alpha: &[usize], steps: usize) -> Option<Vec<f64>> {
    let n = a.dim();
    let m = alpha.len();
    let mut z = vec![0.0; n];
    if m == 0 {
        return Some(z);
    }
    let mut sub = Mat::<f64>::zeros(m, m);
    let mut col = vec![0.0; n];
    for (jj, &j) in alpha.iter().enumerate() {
        a.column_into(j, &mut col);
        for (ii, &i) in alpha.iter().enumerate() {
            sub[(ii, jj)] = col[i];
        }
    }
    let lu = sub.partial_piv_lu();
    let mut scratch = LuScratch::new(m);
    let mut rhs = Mat::<f64>::from_fn(m, 1, |i, _| -q[alpha[i]]);
    scratch.solve_in_place(&lu, rhs.as_mut());
    let mut za: Vec<f64> = (0..m).map(|i| rhs[(i, 0)]).collect();
    if !za.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut res = Mat::<f64>::zeros(m, 1);
    for _ in 0..steps {
        // r = −q_α − A_αα z_α, then z_α += A_αα⁻¹ r (fixed-precision iterative refinement:
        // it brings the componentwise backward error of the LU solve down to round-off).
        for ii in 0..m {
            res[(ii, 0)] = -q[alpha[ii]];
        }
        for (jj, &zj) in za.iter().enumerate() {
            if zj != 0.0 {
                for ii in 0..m {
                    res[(ii, 0)] -= sub[(ii, jj)] * zj;
                }
            }
        }
        scratch.solve_in_place(&lu, res.as_mut());
        if !(0..m).all(|i| res[(i, 0)].is_finite()) {
            break;
        }
        for (ii, v) in za.iter_mut().enumerate() {
            *v += res[(ii, 0)];
        }
    }
    for (ii, &i) in alpha.iter().enumerate() {
        z[i] = za[ii];
    }
    Some(z)
}

/// Polishes the basis α by safeguarded block principal pivoting, starting from its evaluated
/// candidate `start`. Returns the first certified candidate (residual ≤ cert), or None.
pub(crate) fn polish(a: &dyn LcpMatrix, q: &[f64], alpha: &[usize], start: &Candidate, steps: usize, cert: f64, max_rounds: usize) -> Option<Candidate> {
    let n = a.dim();
    let mut in_alpha = vec![false; n];
    alpha.iter().for_each(|&i| in_alpha[i] = true);
    // Violations: z_i < −cert on α, w_i < −cert off α (round-off negatives were clipped already).
    let violations =
        |c: &Candidate, in_alpha: &[bool]| -> Vec<usize> { (0..n).filter(|&i| if in_alpha[i] { c.z[i] < -cert } else { c.w[i] < -cert }).collect() };
    let mut viol = violations(start, &in_alpha);
    let mut best_count = viol.len();
    let mut stalls = 0;
    for _ in 0..max_rounds {
        if viol.is_empty() {
            // Sign-feasible but not certified: the solve itself is the problem, not the basis.
            return None;
        }
        // Full exchange while it makes progress; after 3 rounds without progress, Murty's
        // least-index rule (one exchange, the smallest violating index), finite for P-matrices.
        if stalls >= 3 {
            let i = viol[0];
            in_alpha[i] = !in_alpha[i];
        } else {
            viol.iter().for_each(|&i| in_alpha[i] = !in_alpha[i]);
        }
        let alpha: Vec<usize> = (0..n).filter(|&i| in_alpha[i]).collect();
        let c = evaluate(a, q, solve_principal(a, q, &alpha, steps)?, cert);
        if c.residual <= cert {
            return Some(c);
        }
        viol = violations(&c, &in_alpha);
        if viol.len() < best_count {
            best_count = viol.len();
            stalls = 0;
        } else {
            stalls += 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lcp::{DenseMatrix, solve_by_enumeration};

    /// A P-matrix LCP (tridiagonal SPD) started from a basis off by two indices: the polish must
    /// recover the unique solution (found independently by enumeration).
    #[test]
    fn polish_repairs_a_nearly_right_basis() {
        let n = 12;
        let a = DenseMatrix::from_fn(n, |i, j| {
            if i == j {
                2.0
            } else if i.abs_diff(j) == 1 {
                -1.0
            } else {
                0.0
            }
        });
        let q: Vec<f64> = (0..n).map(|i| 0.3 - (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos()).collect();
        let sols = solve_by_enumeration(&a, &q, 1e-12);
        assert_eq!(sols.len(), 1);
        let exact = &sols[0];
        let active: Vec<usize> = (0..n).filter(|&i| exact[i] > 0.0).collect();
        assert!(active.len() >= 3 && active.len() < n, "{active:?}");
        // Drop the first active index, add the first inactive one.
        let outside = (0..n).find(|i| !active.contains(i)).unwrap();
        let mut wrong: Vec<usize> = active[1..].to_vec();
        wrong.push(outside);
        wrong.sort_unstable();
        let cert = 1e-12;
        let start = evaluate(&a, &q, solve_principal(&a, &q, &wrong, 2).unwrap(), cert);
        assert!(start.residual > 1e-3, "the wrong basis must not certify");
        let fixed = polish(&a, &q, &wrong, &start, 2, cert, 8).expect("polish");
        assert!(fixed.residual <= cert);
        let err = fixed.z.iter().zip(exact).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(err <= 1e-12, "{:?} vs {exact:?}", fixed.z);
        // A basis that is right already needs no polish: polish answers None (nothing violated).
        let right = evaluate(&a, &q, solve_principal(&a, &q, &active, 2).unwrap(), cert);
        assert!(right.residual <= cert);
        assert!(polish(&a, &q, &active, &right, 2, cert, 8).is_none());
    }
}
