//! Coupled normal–tangential friction (src/formulation.md §9): a friction row whose slip force is
//! μ·λ_n of a unilateral contact at the same instant. The friction LCP keeps its rows
//! (`friction.rs`); the coupling is one more column term (f = z₁ − μλ_n) and one more entry in the
//! slack rows (w₂ = 2μλ_n − z₁), so no unknown is added. The matrix is then neither positive
//! semi-definite nor a P-matrix in general, and Lemke may end on a ray: that is diagnosed here,
//! never reported as an answer.
use super::friction::{FrictionGrid, Layout, friction_lcp};
use super::{Assembly, PeriodFft, PeriodicProblem, SolveError};
use crate::lcp::{DenseMatrix, LcpOutcome, LcpSolution, Lemke, LemkeSettings, solve_from_basis};
use crate::model::{Compliance, Model};
use crate::time::Discretization;

/// Fewest instants of the coarsest grid of the k-continuation ([`continued`]). Why: measured on
/// the random family of validation/RECORD.md "Friction" (seed 2031, member 3), bds1 at k = 128 and 256 holds
/// only the orbit pressed all period, while k ≥ 512 also holds a lift-off orbit (a second exact
/// periodic orbit of the event-driven simulation) that cold Lemke ends on.
const CONTINUATION_COARSEST: usize = 128;

/// Per friction contact: (its contact, μ) when coupled, `None` under a constant load.
pub(super) fn couplings(model: &Model) -> Vec<Option<(usize, f64)>> {
    model.frictions.iter().map(|f| f.contact.map(|c| (c, f.coefficient))).collect()
}

/// The wedging number κ = μ·|G_nt| / G_nn of friction `t` pressed by contact `c`: G_nn is the
/// contact's static flexibility (Ĝ₀ = B K⁻¹ Bᵀ plus 1/k_c of a compliant contact), G_nt the
/// normal displacement per unit friction force. While slipping, the gap answers λ_n with
/// G_nn ± μ·G_nt: for κ ≥ 1 one slip direction closes the contact harder the harder it presses
/// (a jam, the quasi-static face of Painlevé's paradox; Klarbring, Int. J. Eng. Sci. 28 (1990)).
fn wedging(model: &Model, asm: &Assembly, t: usize, c: usize) -> (f64, f64, f64) {
    let (m, a) = (asm.m, model.contacts.len() + t);
    let soft = match model.contacts[c].compliance {
        Compliance::Compliant { stiffness } => 1.0 / stiffness,
        Compliance::Rigid => 0.0,
    };
    let g_nn = asm.g_hat[c * m + c].re + soft;
    let g_nt = asm.g_hat[c * m + a].re;
    (model.frictions[t].coefficient * g_nt.abs() / g_nn, g_nn, g_nt)
}

/// The typed outcome of a coupled friction LCP that Lemke did not solve, with its diagnosis.
pub(super) fn no_solution(problem: &PeriodicProblem, asm: &Assembly, sol: LcpSolution) -> SolveError {
    let model = problem.model();
    let why = match sol.outcome {
        LcpOutcome::RayTermination => "Lemke's path left on a ray: no solution is reachable from this start, and none may exist",
        LcpOutcome::PivotLimit => "Lemke's pivot budget ran out (a degenerate or cycling path)",
        LcpOutcome::NonFiniteData => "the assembled LCP holds NaN or infinite values",
        _ => "the final basis is too ill-conditioned to certify the residual",
    };
    let numbers: Vec<String> = model
        .frictions
        .iter()
        .enumerate()
        .filter_map(|(t, f)| f.contact.map(|c| (t, c)))
        .map(|(t, c)| {
            let (kappa, g_nn, g_nt) = wedging(model, asm, t, c);
            format!("friction[{t}] on contact[{c}]: κ = μ·|G_nt|/G_nn = {kappa:.3} (static flexibilities G_nn = {g_nn:.4e}, G_nt = {g_nt:.4e})")
        })
        .collect();
    let hint = format!(
        "coupled normal–tangential friction: {why}. The coupled LCP (src/formulation.md §9) mixes displacement-level contact rows with velocity-level friction rows and adds −μ times each friction column to its contact's column: its matrix is neither positive semi-definite nor a P-matrix, so no theorem promises a periodic solution. {}. κ ≥ 1 means that slipping against the coupling presses the contact shut harder than its normal flexibility opens it (a jam: Painlevé-like, in the LCP's static part): the periodic LCP may have no solution or several, while the continuous orbit can still exist (a mass on both directions keeps the dynamics well posed; measured on a mass on a plane: Lemke solved up to κ = 0.97 and ended on a ray from κ = 1.06, where the exact event-driven orbit exists). κ < 1 rules the jam out: a failure there is a dynamic one (a resonance of the discrete operator, degeneracy). Remedies: lower the coefficient or the tangential–normal coupling until κ < 1, make the contact compliant or softer (stiffness = …), add damping, or change discretization.steps",
        numbers.join("; ")
    );
    SolveError::Lcp { outcome: sol.outcome, info: sol.info, hint }
}

/// Solves the coupled friction LCP (`a`, `q`) at k instants by k-continuation: cold Lemke at the
/// coarsest grid k0 = k/2ⁿ ≥ [`CONTINUATION_COARSEST`], then at each doubling Lemke from the
/// complementary basis of the coarser solution's active set, each instant's unknowns copied to its
/// two children. Why: the coupled LCP is not a P-matrix and can hold several periodic orbits
/// (validation/RECORD.md "Friction": two exact orbits of one member); cold Lemke ends on any of them, which can
/// change with k, while the continuation follows one orbit over the grids, the one the coarse
/// grid (with bds1's larger numerical damping) holds. A failed warm start falls back to cold
/// Lemke at that grid, and the note (for `lcp.path`) says so. Returns the solution at k and the
/// note; without a coarser grid, cold Lemke and an empty note.
pub(super) fn continued(problem: &PeriodicProblem, (a_k, q_k): (&DenseMatrix, &[f64]), settings: &LemkeSettings) -> Result<(LcpSolution, String), SolveError> {
    let disc = problem.discretization();
    let mut grids = vec![disc.steps];
    while let Some(&s) = grids.last()
        && s.is_multiple_of(2)
        && s / 2 >= CONTINUATION_COARSEST
    {
        grids.push(s / 2);
    }
    let cold = |a: &DenseMatrix, q: &[f64]| Lemke::new(settings.clone()).solve(a, q);
    if grids.len() == 1 {
        return Ok((cold(a_k, q_k), String::new()));
    }
    grids.reverse();
    let (model, mut steps_done) = (problem.model(), Vec::new());
    let (mc, mf) = (model.contacts.len(), model.frictions.len());
    let mut coarse: Option<(LcpSolution, usize)> = None;
    for &steps in &grids {
        let fine = steps == disc.steps;
        let owned;
        let (a, q, k) = if fine {
            (a_k, q_k, problem.instants())
        } else {
            match coarse_lcp(problem, steps) {
                Ok(lcp) => owned = lcp,
                // A grid the problem refuses (size, stability): the fine grid cold, said in the note.
                Err(e) => return Ok((cold(a_k, q_k), format!("; k-continuation abandoned at {steps} steps ({e}), so cold Lemke at k = {}", disc.steps))),
            }
            (&owned.0, owned.1.as_slice(), owned.2)
        };
        let warm = coarse.take().map(|(c, kc)| {
            let active = prolonged(&c.z, &Layout { k: kc, mc, mf }, &Layout { k, mc, mf });
            solve_from_basis(a, q, &active, None, q.len(), settings.certify_tol)
        });
        let sol = match warm {
            Some(sol) if sol.outcome == LcpOutcome::Solved => {
                steps_done.push(format!("warm at {k} ({} pivots)", sol.info.pivots));
                sol
            }
            other => {
                let sol = cold(a, q);
                let why = other.map_or(String::new(), |w| format!(" (the warm start ended {})", w.outcome.name()));
                steps_done.push(format!("cold at {k}{why} ({} pivots)", sol.info.pivots));
                sol
            }
        };
        if sol.outcome != LcpOutcome::Solved && !fine {
            // The coarse grid has no solution Lemke reaches: the fine grid cold, said in the note.
            let note =
                format!("; k-continuation abandoned: Lemke {} ended {}, so cold Lemke at k = {}", steps_done.join(", then "), sol.outcome.name(), disc.steps);
            return Ok((cold(a_k, q_k), note));
        }
        coarse = Some((sol, k));
    }
    let (sol, _) = coarse.expect("the fine grid was solved");
    let note = format!(
        "; k-continuation: Lemke {} from the prolonged active set (the orbit continued from the coarsest grid; the coupled LCP can hold several periodic orbits)",
        steps_done.join(", then ")
    );
    Ok((sol, note))
}

/// The dense LCP of `problem` on `steps` steps per forcing period, with its instants.
fn coarse_lcp(problem: &PeriodicProblem, steps: usize) -> Result<(DenseMatrix, Vec<f64>, usize), SolveError> {
    let mut p = problem.clone();
    p.set_discretization(Discretization { steps, ..problem.discretization() })?;
    let fft = PeriodFft::new(p.instants());
    let asm = p.assemble(&fft)?;
    let grid = FrictionGrid::new(p.discretization().scheme, asm.k, p.period())?;
    let (a, q) = friction_lcp(&p, &asm, &fft, &grid);
    Ok((a, q, asm.k))
}

/// The complementary basis at k instants from a solution `z` at k/2: fine instants 2j − 1 and 2j
/// take coarse instant j's unknowns (bds1's sample j closes the step (t_{j−1}, t_j]).
fn prolonged(z: &[f64], coarse: &Layout, fine: &Layout) -> Vec<bool> {
    let mut active = vec![false; fine.k * (fine.mc + 2 * fine.mf)];
    for jf in 0..fine.k {
        let jc = jf.div_ceil(2) % coarse.k;
        for r in 0..fine.mc + fine.mf {
            active[fine.row(r, jf)] = z[coarse.row(r, jc)] > 0.0;
        }
        for t in 0..fine.mf {
            active[fine.slack(t, jf)] = z[coarse.slack(t, jc)] > 0.0;
        }
    }
    active
}
