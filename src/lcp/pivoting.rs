//! Block principal pivoting (Júdice & Pires 1994, after Kostreva 1978) with Murty's
//! single-pivot fallback: the fast path for large LCPs.
//!
//! Each iteration solves A_FF z_F = −q_F on the current active set F only (dense LU of |F|²),
//! and gets w = A z + q by one product (an FFT away for a block-circulant A). Memory is
//! O(|F|²) plus A's own storage. Finite for P-matrices; for others it may cycle, which the
//! iteration cap turns into a typed failure so that the caller falls back to Lemke.
//!
//! Measured on the rigid stop with forward-paired cds (k = 1024): two full exchanges bring the
//! active set within two indices, then the front walks two instants per iteration (the odd–even
//! coupling of central differences): O(k) LUs. So once full exchanges stop reducing the number
//! of infeasible indices, Lemke takes over from the best basis (`lemke::warm`), one cheap pivot
//! per wrong index.
use super::lemke::warm;
use super::principal::well_conditioned;
use super::status::{finite_or_zero, recheck_exactly, residuals};
use super::{LcpInfo, LcpMatrix, LcpOutcome, LcpSolution};
use faer::Mat;
use faer::linalg::solvers::PartialPivLu;
use faer::linalg::solvers::Solve;
use std::time::Instant;

/// Settings with defaults; see [`PivotingSettings::default`].
#[derive(Clone, Debug)]
pub struct PivotingSettings {
    /// Iteration cap (each iteration is one LU of the active block).
    pub max_iterations: usize,
    /// Full exchanges allowed without progress before switching to single pivots (Júdice–Pires' p̄).
    pub max_stalls: usize,
    /// Feasibility tolerance relative to max(1, ‖q‖∞).
    pub feasibility_tol: f64,
    /// Certification: solved iff ‖min(z, w)‖∞ ≤ certify_tol · max(1, ‖q‖∞).
    pub certify_tol: f64,
    /// Initial active set (indices with z > 0); default {i : q_i < 0}.
    pub warm_start: Option<Vec<usize>>,
    /// Pivot budget of the finishing Lemke run from the best basis.
    pub max_lemke_pivots: usize,
}

impl Default for PivotingSettings {
    fn default() -> Self {
        PivotingSettings { max_iterations: 50, max_stalls: 2, feasibility_tol: 1e-11, certify_tol: 1e-9, warm_start: None, max_lemke_pivots: 2000 }
    }
}

pub struct BlockPivoting {
    pub settings: PivotingSettings,
}

impl BlockPivoting {
    pub fn new(settings: PivotingSettings) -> Self {
        BlockPivoting { settings }
    }

    /// Full exchanges while they reduce the number of infeasible indices; then Lemke from the
    /// best basis found (`lemke::warm`), which repairs the last few indices pivot by pivot.
    /// z and w are always finite: an iterate that overflowed is reported as z = 0, w = q. A
    /// `Solved` answer is certified with w = A z + q formed exactly when a fast (FFT) product's
    /// round-off could hide a violation.
    pub fn solve(&self, a: &dyn LcpMatrix, q: &[f64]) -> LcpSolution {
        let sol = finite_or_zero(self.solve_unchecked(a, q), q);
        recheck_exactly(sol, a, q, self.settings.certify_tol)
    }

    fn solve_unchecked(&self, a: &dyn LcpMatrix, q: &[f64]) -> LcpSolution {
        let start = Instant::now();
        let n = a.dim();
        let s = &self.settings;
        let fail = |outcome, iterations, z: Vec<f64>, w: Vec<f64>| {
            let (residual, relative_error) = residuals(q, &z, &w);
            LcpSolution {
                outcome,
                z,
                w,
                info: LcpInfo {
                    pivots: iterations,
                    residual,
                    relative_error,
                    time_s: start.elapsed().as_secs_f64(),
                    warm_start_used: false,
                    ..LcpInfo::default()
                },
            }
        };
        let (_, finite) = a.max_abs();
        if !finite || q.iter().any(|v| !v.is_finite()) {
            return fail(LcpOutcome::NonFiniteData, 0, vec![0.0; n], vec![0.0; n]);
        }
        let qmax = q.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        let tol = s.feasibility_tol * qmax;
        let mut active = vec![false; n];
        match &s.warm_start {
            Some(f) => f.iter().filter(|&&i| i < n).for_each(|&i| active[i] = true),
            None => q.iter().enumerate().filter(|(_, v)| **v < 0.0).for_each(|(i, _)| active[i] = true),
        }
        let mut z = vec![0.0; n];
        let mut w = vec![0.0; n];
        let mut best: Option<(usize, Vec<bool>, Option<PartialPivLu<f64>>)> = None;
        let mut stalls = 0;
        let mut col = vec![0.0; n];
        // The active indices and the infeasible ones, refilled every iteration (no allocation).
        let mut f: Vec<usize> = Vec::with_capacity(n);
        let mut infeasible: Vec<usize> = Vec::with_capacity(n);
        let mut iterations = 0;
        for iteration in 1..=s.max_iterations {
            iterations = iteration;
            f.clear();
            f.extend((0..n).filter(|&i| active[i]));
            z.iter_mut().for_each(|v| *v = 0.0);
            let mut lu = None;
            if !f.is_empty() {
                let r = f.len();
                // A_FF lives only until it is factorised: memory is the LU's.
                let factor = {
                    let mut aff = Mat::<f64>::zeros(r, r);
                    for (cj, &j) in f.iter().enumerate() {
                        a.column_into(j, &mut col);
                        for (ci, &i) in f.iter().enumerate() {
                            aff[(ci, cj)] = col[i];
                        }
                    }
                    aff.partial_piv_lu()
                };
                if !well_conditioned(factor.U()) {
                    break;
                }
                let rhs = Mat::from_fn(r, 1, |i, _| -q[f[i]]);
                let zf = factor.solve(&rhs);
                for (ci, &i) in f.iter().enumerate() {
                    z[i] = zf[(ci, 0)];
                }
                lu = Some(factor);
            }
            a.mul_into(&z, &mut w);
            w.iter_mut().zip(q).for_each(|(wi, qi)| *wi += qi);
            // Infeasible: active with z < 0, or inactive with w < 0 (NaN counts as infeasible).
            // `!(x >= -tol)` is true for NaN on purpose
            let is_infeasible = |i: usize| if active[i] { !(z[i] >= -tol) } else { !(w[i] >= -tol) };
            infeasible.clear();
            infeasible.extend((0..n).filter(|&i| is_infeasible(i)));
            if infeasible.is_empty() {
                // Iterative refinement of z_F with the same LU (A_FF z_F = −q_F, residual −w_F):
                // an ill-conditioned A_FF otherwise leaves z off by cond·eps.
                if let Some(factor) = &lu {
                    for _ in 0..2 {
                        let rhs = Mat::from_fn(f.len(), 1, |c, _| -w[f[c]]);
                        let dz = factor.solve(&rhs);
                        if !(0..f.len()).all(|c| dz[(c, 0)].is_finite()) {
                            break;
                        }
                        for (c, &i) in f.iter().enumerate() {
                            z[i] += dz[(c, 0)];
                        }
                        a.mul_into(&z, &mut w);
                        w.iter_mut().zip(q).for_each(|(wi, qi)| *wi += qi);
                    }
                }
                // Active w and inactive z are zero by construction; clip round-off and certify.
                for i in 0..n {
                    if active[i] {
                        z[i] = z[i].max(0.0);
                    }
                }
                a.mul_into(&z, &mut w);
                w.iter_mut().zip(q).for_each(|(wi, qi)| *wi += qi);
                let (residual, relative_error) = residuals(q, &z, &w);
                let outcome = if residual <= s.certify_tol * qmax { LcpOutcome::Solved } else { LcpOutcome::Inaccurate };
                return LcpSolution {
                    outcome,
                    z,
                    w,
                    info: LcpInfo {
                        pivots: iteration,
                        residual,
                        relative_error,
                        time_s: start.elapsed().as_secs_f64(),
                        warm_start_used: s.warm_start.is_some() && iteration == 1,
                        ..LcpInfo::default()
                    },
                };
            }
            if best.as_ref().is_none_or(|b| infeasible.len() < b.0) {
                best = Some((infeasible.len(), active.clone(), lu));
                stalls = 0;
            } else {
                stalls += 1;
                if stalls > s.max_stalls {
                    break;
                }
            }
            infeasible.iter().for_each(|&i| active[i] = !active[i]);
        }
        let Some((_, basis, lu)) = best else {
            return fail(LcpOutcome::Inaccurate, 0, vec![0.0; n], q.to_vec());
        };
        let exchanges = iterations;
        let mut sol = warm::solve_from_basis(a, q, &basis, lu, s.max_lemke_pivots, s.certify_tol);
        // Pivots: the block exchanges (one LU each) plus Lemke's single pivots.
        sol.info.pivots += exchanges;
        sol.info.time_s = start.elapsed().as_secs_f64();
        sol.info.warm_start_used = s.warm_start.is_some();
        sol
    }
}
