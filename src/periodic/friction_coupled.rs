//! Coupled normal–tangential friction (src/formulation.md §9): a friction row whose slip force is
//! μ·λ_n of a unilateral contact at the same instant. The friction LCP keeps its rows
//! (`friction.rs`); the coupling is one more column term (f = z₁ − μλ_n) and one more entry in the
//! slack rows (w₂ = 2μλ_n − z₁), so no unknown is added. The matrix is then neither positive
//! semi-definite nor a P-matrix in general, and Lemke may end on a ray: that is diagnosed here,
//! never reported as an answer.
use super::{Assembly, PeriodicProblem, SolveError};
use crate::lcp::{LcpOutcome, LcpSolution};
use crate::model::{Compliance, Model};

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
