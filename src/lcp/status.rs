//! How a solve ended, and the certification of an answer on the original data.
//!
//! Every solver reports an [`LcpSolution`]: a typed [`LcpOutcome`], the best iterate (z, w always
//! finite) and [`LcpInfo`]. An answer is `Solved` only when its residual ‖min(z, A z + q)‖∞,
//! computed from the original (unscaled) data, is within the certification tolerance. The helpers
//! here are shared by every solver; this file depends on the matrix trait only.
use serde::Serialize;

use super::LcpMatrix;

/// How a solve ended. Only `Solved` carries a certified answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LcpOutcome {
    /// z, w complementary, residual within the certification tolerance.
    Solved,
    /// Lemke's entering column has no blocking row: no solution reachable from the ray start
    /// (for a copositive-plus A: no solution at all).
    RayTermination,
    /// The pivot budget (proportional to the size) ran out.
    PivotLimit,
    /// A or q holds NaN or ±∞.
    NonFiniteData,
    /// A basis was found but its refined solution fails the residual check (ill-conditioning).
    Inaccurate,
}

impl LcpOutcome {
    pub fn name(self) -> &'static str {
        match self {
            LcpOutcome::Solved => "solved",
            LcpOutcome::RayTermination => "ray termination",
            LcpOutcome::PivotLimit => "pivot limit",
            LcpOutcome::NonFiniteData => "non-finite data",
            LcpOutcome::Inaccurate => "inaccurate",
        }
    }
}

/// Diagnostics of one solve.
#[derive(Clone, Debug, Default, Serialize)]
pub struct LcpInfo {
    pub pivots: usize,
    /// ‖min(z, A z + q)‖∞ on the original data.
    pub residual: f64,
    /// Siconos' ‖z − max(0, z − w)‖₂ / ‖q‖₂ (‖q‖₂ replaced by 1 when it is 0).
    pub relative_error: f64,
    pub time_s: f64,
    /// True when the warm-start guess was accepted without pivoting.
    pub warm_start_used: bool,
    /// What became of a warm start (set by the policy, [`crate::lcp::solve_circulant_lcp`]).
    #[serde(skip)]
    pub warm: WarmOutcome,
    /// The methods the policy ran, in order (empty when no policy ran).
    #[serde(skip)]
    pub path: Vec<LcpStep>,
    /// The closed orbit's initial state s_0 when shooting solved it (its step map's state), to
    /// warm-start the same orbit on another grid (behind one pointer: `SolveError::Lcp` carries
    /// this struct, and an error's size is bounded).
    #[serde(skip)]
    pub orbit_state: Option<std::sync::Arc<Vec<f64>>>,
}

/// What became of a warm-start guess.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WarmOutcome {
    /// No guess was offered.
    #[default]
    NotOffered,
    /// The guess was the answer (no pivot beyond checking it).
    Accepted,
    /// The solve started from the guess and repaired it in `pivots` pivots.
    Repaired { pivots: usize },
    /// The guess was discarded and the solve ran cold.
    Rejected,
}

impl WarmOutcome {
    /// "cold" (none offered), "accepted", "repaired" or "rejected".
    pub fn name(self) -> &'static str {
        match self {
            WarmOutcome::NotOffered => "cold",
            WarmOutcome::Accepted => "accepted",
            WarmOutcome::Repaired { .. } => "repaired",
            WarmOutcome::Rejected => "rejected",
        }
    }
}

/// One method run by the policy, and how it ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LcpStep {
    /// `Lemke` (dense lexicographic) or `Pivoting` (block pivoting with FFT products).
    pub method: super::LcpMethod,
    /// LCP size N.
    pub size: usize,
    /// Pivots (Lemke) or block exchanges plus finishing pivots (pivoting).
    pub pivots: usize,
    pub outcome: LcpOutcome,
    pub time_s: f64,
}

/// The outcome with the best iterate. z and w are always finite (zeros when nothing better).
#[derive(Clone, Debug)]
pub struct LcpSolution {
    pub outcome: LcpOutcome,
    pub z: Vec<f64>,
    pub w: Vec<f64>,
    pub info: LcpInfo,
}

/// ‖min(z, w)‖∞ and Siconos' relative error for a candidate z, with w = A z + q.
pub fn residuals(q: &[f64], z: &[f64], w: &[f64]) -> (f64, f64) {
    let mut inf = 0.0f64;
    let mut num = 0.0f64;
    for (&zi, &wi) in z.iter().zip(w) {
        let m = zi.min(wi);
        inf = inf.max(m.abs());
        let d = zi - (zi - wi).max(0.0);
        num += d * d;
    }
    let qn = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let rel = num.sqrt() / if qn > 0.0 { qn } else { 1.0 };
    if inf.is_nan() || rel.is_nan() { (f64::INFINITY, f64::INFINITY) } else { (inf, rel) }
}

/// The [`LcpSolution`] contract: z and w finite. An overflowed iterate (A_FF⁻¹q beyond f64 on data
/// spanning hundreds of decades, found by tests/props.rs) becomes z = 0, w = q, never `Solved`.
pub(crate) fn finite_or_zero(mut sol: LcpSolution, q: &[f64]) -> LcpSolution {
    if sol.z.iter().chain(&sol.w).all(|v| v.is_finite()) {
        return sol;
    }
    sol.z = vec![0.0; q.len()];
    sol.w = q.to_vec();
    let (residual, relative_error) = residuals(q, &sol.z, &sol.w);
    sol.info.residual = residual;
    sol.info.relative_error = relative_error;
    if sol.outcome == LcpOutcome::Solved {
        sol.outcome = LcpOutcome::Inaccurate;
    }
    sol
}

/// Re-certifies a `Solved` answer with w = A z + q summed directly (`LcpMatrix::direct_mul_add`), when
/// the round-off of `mul_into` could exceed a hundredth of the certification tolerance.
///
/// Why: the FFT product of a block-circulant A has a normwise error, about
/// eps·log₂N·max|A|·‖z‖₁, not a componentwise one. On data spanning hundreds of decades that
/// swamps the small components of w: tests/props.rs found a 9×9 block-circulant LCP "solved" with
/// w₃ = −2.8e161 when summed exactly. The exact sum costs O(N·nnz(z)) at most; it runs only
/// when the bound says the fast product cannot be trusted to the tolerance, and on the rows where
/// the fast product's w could be wrong about the sign.
pub(crate) fn recheck_exactly(mut sol: LcpSolution, a: &dyn LcpMatrix, q: &[f64], certify_tol: f64) -> LcpSolution {
    if sol.outcome != LcpOutcome::Solved || q.is_empty() {
        return sol;
    }
    let n = q.len();
    let qmax = q.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let cert = certify_tol * qmax;
    let z1: f64 = sol.z.iter().map(|v| v.abs()).sum();
    let bound = 8.0 * f64::EPSILON * ((n as f64).log2() + 1.0) * a.max_abs().0 * z1;
    if bound <= 0.01 * cert {
        return sol;
    }
    // The fast product settles the rows with z_i = 0 and w_i ≥ bound: the exact w_i ≥ 0 there,
    // so they add nothing to the residual. The others (z_i > 0, or w_i near or below 0) are
    // summed exactly: about nnz(z) + the grazing rows, not all N (a third of the work at
    // k = 8192, 32 contacts).
    let mut w = vec![0.0; n];
    a.mul_into(&sol.z, &mut w);
    w.iter_mut().zip(q).for_each(|(wi, qi)| *wi += qi);
    let rows: Vec<bool> = sol.z.iter().zip(&w).map(|(&zi, &wi)| zi != 0.0 || !(wi >= bound)).collect();
    w.iter_mut().zip(q).zip(&rows).filter(|(_, r)| **r).for_each(|((wi, qi), _)| *wi = *qi);
    a.direct_mul_add(&sol.z, &rows, &mut w);
    let (residual, relative_error) = residuals(q, &sol.z, &w);
    // `!(… <= …)`: a NaN residual must fail the check
    if !(residual <= cert) || !w.iter().all(|v| v.is_finite()) {
        sol.outcome = LcpOutcome::Inaccurate;
    }
    sol.info.residual = residual;
    sol.info.relative_error = relative_error;
    if w.iter().all(|v| v.is_finite()) {
        sol.w = w;
    }
    sol
}

/// A candidate answer evaluated on the original data.
pub(crate) struct Candidate {
    pub z: Vec<f64>,
    pub w: Vec<f64>,
    pub residual: f64,
    pub relative_error: f64,
}

impl Candidate {
    /// z = w = 0 with infinite residuals: "nothing better".
    pub fn zeros(n: usize) -> Self {
        Candidate { z: vec![0.0; n], w: vec![0.0; n], residual: f64::INFINITY, relative_error: f64::INFINITY }
    }
}

/// Clips z_i ∈ [−clip, 0) to 0, computes w = A z + q and the residuals on the original data, then
/// clips w_i ∈ [−clip, 0) to 0 for the report. Why: a negative within the certification
/// tolerance is round-off of a zero; anything larger is left visible (and fails certification).
pub(crate) fn evaluate(a: &dyn LcpMatrix, q: &[f64], mut z: Vec<f64>, clip: f64) -> Candidate {
    let n = q.len();
    if !z.iter().all(|v| v.is_finite()) {
        return Candidate::zeros(n);
    }
    for v in z.iter_mut() {
        if *v < 0.0 && *v >= -clip {
            *v = 0.0;
        }
    }
    let mut w = vec![0.0; n];
    a.mul_into(&z, &mut w);
    for (wi, qi) in w.iter_mut().zip(q) {
        *wi += qi;
    }
    if !w.iter().all(|v| v.is_finite()) {
        return Candidate::zeros(n);
    }
    let (residual, relative_error) = residuals(q, &z, &w);
    for v in w.iter_mut() {
        if *v < 0.0 && *v >= -clip {
            *v = 0.0;
        }
    }
    Candidate { z, w, residual, relative_error }
}
