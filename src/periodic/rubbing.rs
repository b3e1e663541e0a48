//! Rubbing in gross slip (src/formulation.md §9): contact a's counter-face slides along t at V,
//! faster than the structure moves along t, so the friction force is μ·λ_a along V and the
//! contact force on the structure is −(n − μ·sign(V)·t)ᵀ λ_a. The tangential rows are assembled
//! as extra rows of B and folded into the contacts' columns: the LCP keeps its k·m unknowns and
//! becomes non-symmetric (Ĝ_ab + c·Ĝ_a,t with c = −μ·sign(V)).
use super::{Assembly, PeriodFft, PeriodicProblem, SolveError, SolverSettings};
use crate::lcp::{BlockCirculant, LcpMethod, LcpSolution, progress};
use crate::model::{Compliance, Contact, Model};
use num_complex::Complex64 as C;
use std::borrow::Cow;

mod walk;

/// The tangential row of a rubbing contact after the fold: its response to each contact's
/// force (with the friction it carries) and its linear part, per harmonic.
#[derive(Clone, Debug)]
pub struct TangentialRow {
    /// [p][m]: t Ẑ_p⁻¹ (n_b − μ·sign(V_b)·t_b)ᵀ.
    pub g_hat: Vec<C>,
    /// [p]: t X̂lin_p.
    pub bxlin_hat: Vec<C>,
}

/// `model` with one extra contact row per rubbing contact (after the contacts); borrowed
/// unchanged without rubbing.
pub(super) fn with_rows(model: &Model) -> Cow<'_, Model> {
    if model.rubbing.is_empty() {
        return Cow::Borrowed(model);
    }
    let mut rows = model.clone();
    for r in &model.rubbing {
        rows.contacts.push(Contact { row: r.row.clone(), gap: 0.0, compliance: Compliance::Rigid, motion: Vec::new() });
    }
    Cow::Owned(rows)
}

/// Folds the tangential rows of `wide` (assembled with [`with_rows`]) into the contacts' columns.
pub(super) fn fold(model: &Model, wide: Assembly) -> Assembly {
    if model.rubbing.is_empty() {
        return wide;
    }
    let (mw, m, nh, nd) = (wide.m, model.contacts.len(), wide.k / 2 + 1, wide.dofs.len());
    // Column b of the folded problem: column b plus c_r times the column of each tangential row r on b.
    let column = |b: usize, entry: &dyn Fn(usize) -> C| -> C {
        model.rubbing.iter().enumerate().filter(|(_, r)| r.contact == b).fold(entry(b), |v, (r, rub)| v + entry(m + r) * rub.traction())
    };
    let g = |p: usize, a: usize, b: usize| column(b, &|c| wide.g_hat[(p * mw + a) * mw + c]);
    let mut g_hat = vec![C::ZERO; nh * m * m];
    let mut h_hat = vec![C::ZERO; nh * nd * m];
    for p in 0..nh {
        for b in 0..m {
            for a in 0..m {
                g_hat[(p * m + a) * m + b] = g(p, a, b);
            }
            for d in 0..nd {
                h_hat[(p * nd + d) * m + b] = column(b, &|c| wide.h_hat[(p * nd + d) * mw + c]);
            }
        }
    }
    let tangential = (0..model.rubbing.len())
        .map(|r| TangentialRow {
            g_hat: (0..nh).flat_map(|p| (0..m).map(move |b| (p, b))).map(|(p, b)| g(p, m + r, b)).collect(),
            bxlin_hat: (0..nh).map(|p| wide.bxlin_hat[p * mw + m + r]).collect(),
        })
        .collect();
    let bxlin_hat = (0..nh).flat_map(|p| (0..m).map(move |a| (p, a))).map(|(p, a)| wide.bxlin_hat[p * mw + a]).collect();
    Assembly { m, g_hat: g_hat.into(), h_hat, bxlin_hat, tangential, ..wide }
}

/// Gross slip holds only while the structure's tangential speed stays below |V|: checked at the
/// solution (the spectral derivative of the tangential displacement at the instants); a typed
/// outcome when it does not, never an answer. `forces`: the contacts' forces, `[j·m + a]`.
pub(super) fn check_gross_slip(problem: &PeriodicProblem, asm: &Assembly, fft: &PeriodFft, forces: &[f64]) -> Result<(), SolveError> {
    let model = problem.model();
    let (k, m, nh) = (asm.k, asm.m, asm.k / 2 + 1);
    let lambda: Vec<Vec<C>> = (0..m).map(|b| fft.forward(&(0..k).map(|j| forces[j * m + b]).collect::<Vec<_>>())).collect();
    let omega = 2.0 * std::f64::consts::PI / problem.period();
    for (r, (rub, row)) in model.rubbing.iter().zip(&asm.tangential).enumerate() {
        // The Nyquist harmonic of an even grid has no odd derivative on the samples: dropped.
        let velocity_hat: Vec<C> = (0..nh)
            .map(|p| {
                let u = row.bxlin_hat[p] - (0..m).map(|b| row.g_hat[p * m + b] * lambda[b][p]).sum::<C>();
                if 2 * p == k { C::ZERO } else { C::new(0.0, omega * p as f64) * u }
            })
            .collect();
        let fastest = fft.inverse(&velocity_hat).iter().fold(0.0_f64, |v, s| v.max(s.abs()));
        if !fastest.is_finite() {
            return Err(SolveError::NonFinite(format!("friction[{r}] (rubbing): the tangential velocity")));
        }
        if fastest >= rub.sliding_velocity.abs() {
            return Err(SolveError::Invalid(format!(
                "friction[{r}].sliding_velocity: is {}, but the structure slides along it at up to {fastest:.4e} at the solution: gross slip (the friction force μ·λ_n along the counter-face's motion) does not hold; rubbing with stick/slip is not yet solved: give a faster counter-face or solve without friction",
                rub.sliding_velocity
            )));
        }
    }
    Ok(())
}

/// Steps of the μ-homotopy: the first step's share of μ, and the smallest before giving up.
const HOMOTOPY_FIRST_STEP: f64 = 0.25;
const HOMOTOPY_MIN_STEP: f64 = 1.0 / 256.0;

/// The period's LCP of a rubbing model (`auto` or `shooting`). Where shooting misses and no
/// affordable dense fallback follows (`shooting` alone, or `auto` on an LCP whose dense Lemke is
/// refused by its projected cost), the μ-homotopy ([`friction_homotopy`]) gives shooting a warm
/// start. Why: near the real blade's μ = 0.15 resonance cold shooting's offset homotopy follows a
/// path that folds and ends at a kink (validation/RECORD.md "Friction"), where μ = 0 solves at once. Where that
/// misses too, a lone solve (`auto`; a sweep's tries are `shooting`) walks up in ω from below
/// ([`walk::walk_up`]). Returns the solution and, after the walk, a note for `lcp.path`.
pub(super) fn solve_lcp(
    problem: &PeriodicProblem,
    fft: &PeriodFft,
    a: &BlockCirculant,
    q: &[f64],
    warm: Option<&[usize]>,
) -> Result<(LcpSolution, Option<String>), SolveError> {
    let settings = problem.solver_settings();
    let rubbing = problem.model().rubbing.iter().any(|r| r.coefficient > 0.0);
    // A warm-only try (a guarded sweep's quick one, and the homotopy's own steps) stays one try;
    // an affordable dense Lemke is the surer fallback.
    let dense_next = settings.method == LcpMethod::Auto && crate::lcp::dense_fallback_allowed(q.len()).is_ok();
    if !rubbing || settings.shooting_warm_only || dense_next || !matches!(settings.method, LcpMethod::Auto | LcpMethod::Shooting) {
        return problem.solve_lcp(a, q, warm).map(|sol| (sol, None));
    }
    let missed = match problem.solve_lcp(a, q, warm) {
        Ok(sol) => return Ok((sol, None)),
        Err(e) => e,
    };
    // Shooting at full μ from a homotopy's or the walk's final active sets (Newton from them).
    let from_set = |set: Vec<usize>| {
        let mut p = problem.clone();
        p.set_solver_settings(SolverSettings { method: LcpMethod::Shooting, ..settings.clone() })?;
        p.solve_lcp(a, q, Some(&set))
    };
    progress(&format!("shooting missed ({missed}); μ-homotopy from μ = 0 next"));
    let why = match friction_homotopy(problem, fft).and_then(&from_set) {
        Ok(sol) => return Ok((sol, None)),
        Err(e) => format!("the μ-homotopy from μ = 0 missed too ({e})"),
    };
    if settings.method != LcpMethod::Auto {
        return Err(annotate(missed, &why));
    }
    progress(&format!("{why}; a frequency walk from below next"));
    match walk::walk_up(problem) {
        Ok((set, note)) => {
            from_set(set).map(|sol| (sol, Some(note))).map_err(|e| annotate(missed, &format!("{why}; shooting from the frequency walk's orbit missed ({e})")))
        }
        Err(walked) => Err(annotate(missed, &format!("{why}; {walked}"))),
    }
}

/// The μ-homotopy: solves the model without friction (the symmetric LCP, one answer), then
/// raises every rubbing μ by steps to its value, each step shooting from the last step's active
/// sets (Newton from them alone); a missed step is halved. Returns the active set at full μ.
fn friction_homotopy(problem: &PeriodicProblem, fft: &PeriodFft) -> Result<Vec<usize>, SolveError> {
    let model = problem.model();
    let at = |share: f64, warm: Option<&[usize]>| -> Result<Vec<usize>, SolveError> {
        let mut scaled = model.clone();
        for r in &mut scaled.rubbing {
            r.coefficient *= share;
        }
        if share == 0.0 {
            scaled.rubbing.clear();
        }
        let mut p = problem.with_model(scaled, problem.discretization())?;
        let method = if warm.is_some() { LcpMethod::Shooting } else { problem.solver_settings().method };
        p.set_solver_settings(SolverSettings { method, shooting_warm_only: warm.is_some(), ..problem.solver_settings().clone() })?;
        Ok(p.solve_with(fft, warm)?.active_set)
    };
    let mut set = at(0.0, None)?;
    let (mut share, mut step) = (0.0, HOMOTOPY_FIRST_STEP);
    let mu = model.rubbing.iter().fold(0.0f64, |v, r| v.max(r.coefficient));
    while share < 1.0 {
        let next = (share + step).min(1.0);
        match at(next, Some(&set)) {
            Ok(s) => {
                progress(&format!("μ-homotopy: μ = {:.4} of {mu} solved (step {step:.4})", next * mu));
                (set, share, step) = (s, next, (1.5 * step).min(HOMOTOPY_FIRST_STEP));
            }
            Err(e) if step <= HOMOTOPY_MIN_STEP => {
                let why = format!("the μ-homotopy stalled at μ = {:.4} of {mu} (a step of {step:.2e}·μ missed; the branch may fold in μ)", share * mu);
                return Err(annotate(e, &why));
            }
            Err(_) => step /= 2.0,
        }
    }
    Ok(set)
}

/// `e` with `why` after its remedies (an LCP failure keeps its outcome and figures).
fn annotate(e: SolveError, why: &str) -> SolveError {
    match e {
        SolveError::Lcp { outcome, info, hint } => SolveError::Lcp { outcome, info, hint: format!("{hint}; {why}") },
        SolveError::Limit(m) => SolveError::Limit(format!("{m}; {why}")),
        SolveError::Invalid(m) => SolveError::Invalid(format!("{m}; {why}")),
        other => other,
    }
}
