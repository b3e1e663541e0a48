//! Lexicographic Lemke's algorithm (complementary pivoting, covering vector e = 1), in revised form.
//!
//! Sources: C. E. Lemke, "Bimatrix equilibrium points and mathematical programming" (1965);
//! R. W. Cottle, J.-S. Pang, R. E. Stone, *The Linear Complementarity Problem* (1992), ch. 4
//! (Lemke's method, lexicographic degeneracy resolution); K. G. Murty, *Linear Complementarity,
//! Linear and Nonlinear Programming* (1988), ch. 2 (complementary pivot algorithm) and ch. 6
//! (its exponential worst case).
//!
//! # The algorithm
//! Augment the LCP with an artificial variable z0 ≥ 0 and the covering vector e = 1:
//! `w − A z − e z0 = q`. Start from the basis of all w (infeasible when some q_i < 0), let z0
//! enter and leave at the row of the most negative q_i: the basis becomes feasible and almost
//! complementary. Then repeatedly let the complement of the variable that just left enter, with
//! a ratio test choosing the leaving row, until z0 leaves (solution), no row blocks (ray
//! termination) or the pivot budget is spent. Degeneracy is resolved lexicographically: the
//! ratio test compares rows of `[B⁻¹q, B⁻¹] / y_i` lexicographically, which is the exact limit of
//! the perturbation `q + (ε, ε², …, εⁿ)` and guarantees termination (no cycling). When z0 is among
//! the rows tied at the minimum ratio it leaves: that ends the run with a solution at once.
//!
//! The pivots run on a revised form (no tableau; see `basis.rs`), driven by `run.rs`.
//!
//! # Final answer
//! The pivots only identify the final complementary basis: the set α of basic z's. The answer is
//! recomputed from the original (unscaled) data as `A_αα z_α = −q_α` by LU with partial pivoting
//! (faer) plus iterative refinement, `w = A z + q`, and certified by the residual
//! `‖min(z, w)‖∞ ≤ certify_tol · max(1, ‖q‖∞)` on the original data. If it does not certify,
//! the basis is polished by safeguarded principal pivoting (see `principal.rs`): the round-off of
//! thousands of explicit B⁻¹ updates can leave it off by a few near-degenerate indices.
//!
//! # Files
//! - `mod.rs`: settings and the driver [`Lemke::solve`] (trivial cases, warm start, scaling, the
//!   final re-solve and polish);
//! - `basis.rs`: the revised-form basis (stored columns of B⁻¹, entering column, pivot update);
//! - `run.rs`: the lexicographic ratio test and the pivot loop;
//! - `warm.rs`: Lemke from an arbitrary complementary basis (the finishing step of block pivoting).
mod basis;
mod run;
pub(crate) mod warm;

use std::time::Instant;

use super::principal::{polish, solve_principal};
use super::status::{Candidate, evaluate};
use super::{LcpInfo, LcpMatrix, LcpOutcome, LcpSolution};
use basis::Revised;
use run::RunEnd;

/// Settings with defaults; see [`LemkeSettings::default`].
#[derive(Clone, Debug)]
pub struct LemkeSettings {
    /// Pivot tolerance relative to max|A|, max|q|.
    pub pivot_tol: f64,
    /// The pivot limit is `max_pivots_per_dim · n + 100`.
    pub max_pivots_per_dim: usize,
    /// Steps of iterative refinement of the final basis solve.
    pub refinement_steps: usize,
    /// Certification: solved iff ‖min(z, w)‖∞ ≤ certify_tol · max(1, ‖q‖∞).
    pub certify_tol: f64,
    /// Optional warm start: indices expected to have z > 0.
    pub warm_start: Option<Vec<usize>>,
    /// A cap on the pivots below `max_pivots_per_dim · n + 100` (`None`: that limit alone). Why:
    /// an error estimate's dense fallback is bounded by its CPU budget (on the non-symmetric
    /// rubbing LCP, Lemke ran minutes towards its 20·N limit at N = 4352).
    pub max_pivots: Option<usize>,
}

impl Default for LemkeSettings {
    fn default() -> Self {
        LemkeSettings { pivot_tol: 1e-12, max_pivots_per_dim: 20, refinement_steps: 3, certify_tol: 1e-9, warm_start: None, max_pivots: None }
    }
}

/// Rounds of the final-basis polish (each one an LU of A_αα). Why: it is meant to repair a basis
/// off by a few indices, not to solve the LCP; a cap keeps its cost bounded.
const POLISH_ROUNDS: usize = 8;

pub struct Lemke {
    pub settings: LemkeSettings,
}

impl Lemke {
    pub fn new(settings: LemkeSettings) -> Self {
        Lemke { settings }
    }

    /// Solves w = A z + q, z ≥ 0, w ≥ 0, zᵀw = 0. See the module documentation.
    ///
    /// Panics if `q.len() != a.dim()` (a programming error).
    pub fn solve(&self, a: &dyn LcpMatrix, q: &[f64]) -> LcpSolution {
        let start = Instant::now();
        let n = a.dim();
        assert_eq!(q.len(), n, "Lemke::solve: q has {} entries for a {n}×{n} matrix", q.len());
        let s = &self.settings;
        let done = |outcome, c: Candidate, pivots, warm| LcpSolution {
            outcome,
            z: c.z,
            w: c.w,
            info: LcpInfo {
                pivots,
                residual: c.residual,
                relative_error: c.relative_error,
                time_s: start.elapsed().as_secs_f64(),
                warm_start_used: warm,
                ..LcpInfo::default()
            },
        };

        let (amax, a_finite) = a.max_abs();
        if !a_finite || !amax.is_finite() || !q.iter().all(|v| v.is_finite()) {
            return done(LcpOutcome::NonFiniteData, Candidate::zeros(n), 0, false);
        }
        let qmax = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // The certification threshold, and the clipping threshold for round-off negatives.
        let cert = s.certify_tol * qmax.max(1.0);
        let certified = |c: &Candidate| c.residual <= cert;

        // q ≥ 0: z = 0, w = q is a solution (no pivot).
        if q.iter().all(|&v| v >= 0.0) {
            let c = Candidate { z: vec![0.0; n], w: q.to_vec(), residual: 0.0, relative_error: 0.0 };
            return done(LcpOutcome::Solved, c, 0, false);
        }

        // Warm start: the guessed active set α, accepted only if its solution certifies.
        if let Some(active) = &s.warm_start {
            let mut alpha: Vec<usize> = active.clone();
            alpha.sort_unstable();
            alpha.dedup();
            if alpha.iter().all(|&i| i < n)
                && let Some(z) = solve_principal(a, q, &alpha, s.refinement_steps)
            {
                let c = evaluate(a, q, z, cert);
                if certified(&c) {
                    return done(LcpOutcome::Solved, c, 0, true);
                }
            }
        }

        // Cold run on the scaled data Â = A / s_A, q̂ = q / s_q (so that the absolute pivot and tie
        // tolerances are relative to max|A| and max|q|); then ẑ = z · s_A / s_q.
        let sa = if amax > 0.0 { amax } else { 1.0 };
        let sq = qmax; // > 0 here since some q_i < 0
        let qhat: Vec<f64> = q.iter().map(|v| v / sq).collect();
        let mut rev = Revised::new(a, qhat, sa);
        let limit = s.max_pivots_per_dim.saturating_mul(n).saturating_add(100).min(s.max_pivots.unwrap_or(usize::MAX));
        let (end, pivots) = rev.run(s.pivot_tol, limit);
        let tableau_z = rev.current_z(sq / sa);
        let alpha = rev.basic_z();
        drop(rev);

        match end {
            RunEnd::Complementary => {
                // Re-solve the final basis on the original data. If that does not certify, the
                // basis may be off by a few near-degenerate indices: polish it. The tableau values
                // are the last resort (they only matter if the re-solve breaks down).
                let resolved = solve_principal(a, q, &alpha, s.refinement_steps).map(|z| evaluate(a, q, z, cert));
                let best = match resolved {
                    Some(c) if certified(&c) => c,
                    other => {
                        let polished = other.as_ref().and_then(|c| polish(a, q, &alpha, c, s.refinement_steps, cert, POLISH_ROUNDS));
                        match polished {
                            Some(c) => c,
                            None => {
                                let t = evaluate(a, q, tableau_z, cert);
                                match other {
                                    Some(c) if c.residual <= t.residual => c,
                                    _ => t,
                                }
                            }
                        }
                    }
                };
                let outcome = if certified(&best) { LcpOutcome::Solved } else { LcpOutcome::Inaccurate };
                done(outcome, best, pivots, false)
            }
            RunEnd::Ray => done(LcpOutcome::RayTermination, evaluate(a, q, tableau_z, cert), pivots, false),
            RunEnd::Limit => done(LcpOutcome::PivotLimit, evaluate(a, q, tableau_z, cert), pivots, false),
            RunEnd::Breakdown => {
                let tz: Vec<f64> = if tableau_z.iter().all(|v| v.is_finite()) { tableau_z } else { vec![0.0; n] };
                done(LcpOutcome::Inaccurate, evaluate(a, q, tz, cert), pivots, false)
            }
        }
    }
}
