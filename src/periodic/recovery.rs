//! Recovery (src/formulation.md §3): X̂_p = X̂lin_p − (Ẑ_p⁻¹Bᵀ) ẑ_p at the output DOFs only, velocities and
//! accelerations by the symbols σ1, σ2; contact gaps from B X̂_p = B X̂lin_p − Ĝ_p ẑ_p.
use super::{Assembly, PeriodFft, PeriodicProblem, SolveError};
use crate::lcp::{AUTO_LEMKE_MAX, LcpMethod, LcpOutcome, LcpSolution, LcpStep, WarmOutcome};
use crate::response::{ContactResponse, LcpSummary, Response, WarmStartSummary};
use num_complex::Complex64 as C;
use std::collections::BTreeMap;

pub fn recover(problem: &PeriodicProblem, asm: &Assembly, fft: &PeriodFft, sol: &LcpSolution) -> Result<Response, SolveError> {
    let (k, m) = (asm.k, asm.m);
    let nh = k / 2 + 1;
    let nd = asm.dofs.len();
    let model = &problem.model();
    let period = problem.period();
    let time: Vec<f64> = (0..k).map(|j| j as f64 * period / k as f64).collect();

    // ẑ_p for each contact.
    let z_hat: Vec<Vec<C>> = (0..m)
        .map(|a| {
            let series: Vec<f64> = (0..k).map(|j| sol.z[j * m + a]).collect();
            fft.forward(&series)
        })
        .collect();

    let mut displacement = BTreeMap::new();
    let mut velocity = BTreeMap::new();
    let mut acceleration = BTreeMap::new();
    let mut linear_displacement = BTreeMap::new();
    let out = &problem.outputs();
    // X̂_p of every output row, harmonic by harmonic: Ĥ and X̂lin are stored harmonic-major, so
    // one sequential pass (row by row strided through megabytes at k = 4096, latency-bound).
    let x_hats = harmonic_rows(nh, nd, m, &asm.xlin_hat, &asm.h_hat, &z_hat);
    let mut tmp = vec![C::ZERO; nh];
    // Row r of the assembly is output label d (the output map's combination of model DOFs
    // already taken there).
    for (r, &d) in asm.dofs.iter().enumerate() {
        let x_hat = &x_hats[r];
        let xl_hat: Vec<C> = (0..nh).map(|p| asm.xlin_hat[p * nd + r]).collect();
        let key = d.to_string();
        if out.displacement.contains(&d) {
            displacement.insert(key.clone(), finite(fft.inverse(x_hat), "displacement", d)?);
            linear_displacement.insert(key.clone(), finite(fft.inverse(&xl_hat), "linear displacement", d)?);
        }
        if out.velocity.contains(&d) {
            for p in 0..nh {
                tmp[p] = asm.symbols.sigma1[p] * x_hat[p];
            }
            velocity.insert(key.clone(), finite(fft.inverse(&tmp), "velocity", d)?);
        }
        if out.acceleration.contains(&d) {
            for p in 0..nh {
                tmp[p] = asm.symbols.sigma2[p] * x_hat[p];
            }
            acceleration.insert(key, finite(fft.inverse(&tmp), "acceleration", d)?);
        }
    }

    let mut contacts = Vec::new();
    if out.contacts {
        let gaps = problem.gap_samples(k);
        let bx_hats = harmonic_rows(nh, m, m, &asm.bxlin_hat, &asm.g_hat, &z_hat);
        for (a, ca) in model.contacts.iter().enumerate() {
            let bx = fft.inverse(&bx_hats[a]);
            let gap: Vec<f64> = gaps[a].iter().zip(&bx).map(|(&g, &b)| g - b).collect();
            let force: Vec<f64> = (0..k).map(|j| sol.z[j * m + a]).collect();
            let gap = finite(gap, "contact gap", a)?;
            let normal_displacement = finite(bx, "contact normal displacement", a)?;
            let normal = problem.user_row(a).to_vec();
            let (dof, direction) = crate::model::label_of(&normal);
            // Row j of the LCP pairs force sample j with the gap at t_{j+s} (`PeriodicProblem::lcp`).
            let s = problem.pairing_of(ca).offset();
            let paired_gap = (0..k).map(|j| gap[(j + s) % k]).collect();
            contacts.push(ContactResponse {
                dof,
                direction,
                normal,
                normal_displacement,
                stiffness: match ca.compliance {
                    crate::model::Compliance::Rigid => None,
                    crate::model::Compliance::Compliant { stiffness } => Some(stiffness),
                },
                pairing: problem.pairing_of(ca).name().to_string(),
                force: finite(force, "contact force", a)?,
                gap,
                paired_gap,
            });
        }
    }

    let pairings: Vec<&str> = model.contacts.iter().map(|c| problem.pairing_of(c).name()).collect();
    let pairing = match pairings.first() {
        None => problem.discretization().pairing.unwrap_or(crate::time::Pairing::Same).name().to_string(),
        Some(first) if pairings.iter().all(|p| p == first) => first.to_string(),
        Some(_) => "mixed".to_string(),
    };
    let active_set = (0..sol.z.len()).filter(|&i| sol.z[i] > 0.0).collect();
    Ok(Response {
        period,
        steps: k,
        period_multiple: problem.period_multiple(),
        scheme: problem.discretization().scheme.name().to_string(),
        pairing,
        effects: model
            .effects()
            .names()
            .into_iter()
            .map(String::from)
            .chain(problem.output_map().into_iter().flat_map(|m| m.effects.iter().cloned()))
            .collect(),
        time,
        displacement,
        velocity,
        acceleration,
        contacts,
        friction: Vec::new(),
        lcp: LcpSummary {
            size: k * m,
            status: sol.outcome.name().to_string(),
            pivots: sol.info.pivots,
            residual: sol.info.residual,
            relative_error: sol.info.relative_error,
            warm_start_used: matches!(sol.info.warm, WarmOutcome::Accepted | WarmOutcome::Repaired { .. }),
            warm_start: WarmStartSummary { outcome: sol.info.warm.name().to_string(), pivots: sol.info.pivots },
            path: render_path(problem.solver_settings().method, &sol.info.path),
        },
        warnings: problem.warnings(),
        timing_s: Default::default(),
        accuracy: Default::default(),
        polish: None,
        scheme_choice: None,
        linear_displacement,
        active_set,
        orbit_state: sol.info.orbit_state.as_deref().cloned(),
    })
}

/// Row r of Ŷ_p = Ŷlin_p − Â_p ẑ_p for every harmonic p (`lin` n per harmonic, `a` n×m per
/// harmonic, both harmonic-major): one pass in storage order; each value's terms are subtracted
/// in the order b = 0..m, as row by row.
fn harmonic_rows(nh: usize, n: usize, m: usize, lin: &[C], a: &[C], z_hat: &[Vec<C>]) -> Vec<Vec<C>> {
    let mut rows = vec![vec![C::ZERO; nh]; n];
    for p in 0..nh {
        for (r, row) in rows.iter_mut().enumerate() {
            let mut v = lin[p * n + r];
            for (b, zb) in z_hat.iter().enumerate() {
                v -= a[(p * n + r) * m + b] * zb[p];
            }
            row[p] = v;
        }
    }
    rows
}

fn finite(v: Vec<f64>, what: &str, index: usize) -> Result<Vec<f64>, SolveError> {
    if v.iter().all(|x| x.is_finite()) { Ok(v) } else { Err(SolveError::NonFinite(format!("{what} {index}"))) }
}

/// The policy's path in one line: the method asked for (with `auto`'s size rule), then each
/// method run with its pivots, time and outcome, fallbacks after a ';'.
pub fn render_path(method: LcpMethod, path: &[LcpStep]) -> String {
    let Some(first) = path.first() else { return "no LCP (no contact, or no force needed)".to_string() };
    let n = first.size;
    let head = match method {
        LcpMethod::Auto if first.method == LcpMethod::Shooting => format!("auto (N = {n}, a time-stepping map: shooting first)"),
        LcpMethod::Auto if n <= AUTO_LEMKE_MAX => format!("auto (N = {n} ≤ {AUTO_LEMKE_MAX}: dense Lemke)"),
        LcpMethod::Auto => format!("auto (N = {n} > {AUTO_LEMKE_MAX}: block pivoting first)"),
        m => format!("{} (N = {n})", m.name()),
    };
    let steps: Vec<String> = path
        .iter()
        .map(|s| {
            let (what, count) = match s.method {
                LcpMethod::Shooting => ("shooting (Newton on the period map, certified on the LCP)", "Newton iterations"),
                LcpMethod::Pivoting => ("block pivoting", "pivots"),
                _ => ("dense lexicographic Lemke", "pivots"),
            };
            // Shooting counts Newton iterations: its limit is an iteration limit, not a pivot limit.
            let outcome = match (s.method, s.outcome) {
                (LcpMethod::Shooting, LcpOutcome::PivotLimit) => "iteration limit",
                (_, o) => o.name(),
            };
            format!("{what}, {} {count}, {:.3} s → {outcome}", s.pivots, s.time_s)
        })
        .collect();
    format!("{head}: {}", steps.join("; fallback: "))
}
