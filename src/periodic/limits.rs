//! Scheme limits known before solving: the stability of the time scheme
//! ([`Scheme::stability_limit`], ω_max·h below a bound) and the choice of k for `steps = "auto"`.
//!
//! Why refuse rather than try: past its limit a scheme's recurrence is unstable, its periodic
//! operator has near-singular harmonics and the LCP is ill-posed (the coarse rigid blade at
//! ω = 2300 rad/s, k = 512 under cds: ω_max·h ≈ 3.2, Lemke wanders for 31 477 pivots; src/formulation.md §7).
use super::SolveError;
use crate::model::Model;
use crate::time::{Discretization, Scheme};

/// `steps = "auto"` keeps ω_max·h at most this fraction of the scheme's limit.
pub const AUTO_MARGIN: f64 = 0.9;
/// The fewest steps `steps = "auto"` chooses (the scenes' default steps).
pub const AUTO_FLOOR: usize = 256;

/// h = T/k at frequency ω.
fn step(frequency: f64, k: usize) -> f64 {
    2.0 * std::f64::consts::PI / (frequency * k as f64)
}

/// The smallest k with ω_max·h ≤ `fraction`·limit (strictly below the limit when `fraction` is
/// 1), `None` without a limit.
pub fn smallest_stable_steps(scheme: Scheme, omega_max: f64, frequency: f64, fraction: f64) -> Option<usize> {
    let limit = scheme.stability_limit()? * fraction;
    // ω_max·T/k < limit  ⇔  k > ω_max·T/limit.
    let bound = omega_max * 2.0 * std::f64::consts::PI / (frequency * limit);
    let k = if fraction < 1.0 { bound.ceil() } else { bound.floor() + 1.0 };
    Some(k.max(1.0) as usize)
}

/// Refuses a scheme past its stability limit, naming ω_max, h, ω_max·h, the limit, the smallest
/// k that satisfies it and the schemes that would work at this k.
pub(crate) fn check_stability(model: &Model, disc: &Discretization, omega_max: f64) -> Result<(), SolveError> {
    let Some(limit) = disc.scheme.stability_limit() else { return Ok(()) };
    let (k, w) = (disc.steps, model.frequency);
    let h = step(w, k);
    let wh = omega_max * h;
    if wh < limit {
        return Ok(());
    }
    let k_min = smallest_stable_steps(disc.scheme, omega_max, w, 1.0).unwrap_or(k);
    let fits: Vec<String> = Scheme::ALL
        .into_iter()
        .filter_map(|s| match s.stability_limit() {
            None => Some(s.name().to_string()),
            Some(l) if wh < l => Some(format!("{s} (ω_max·h = {wh:.3} < {l:.3})")),
            Some(_) => None,
        })
        .collect();
    Err(SolveError::Limit(format!(
        "discretization.steps: {scheme} is stable only for ω_max·h < {limit:.3}, but ω_max = {omega_max:.4e} rad/s (the model as solved, compliant contacts closed) and h = T/k = {h:.4e} s (ω = {w} rad/s, k = {k}) give ω_max·h = {wh:.3}; \
         use steps ≥ {k_min} with {scheme} at this frequency (or steps = \"auto\"), or at k = {k} one of: {}",
        fits.join(", "),
        scheme = disc.scheme,
    )))
}

/// `steps = "auto"`: the smallest power of two (FFT-friendly) that keeps ω_max·h ≤
/// [`AUTO_MARGIN`]·limit at `frequency`, resolves the highest forced harmonic (k ≥ 2·harmonic + 2)
/// and is at least [`AUTO_FLOOR`]. Returns k and the note reported with the result.
pub fn auto_steps(model: &Model, scheme: Scheme, omega_max: f64, frequency: f64) -> (usize, String) {
    let resolution = 2 * model.highest_harmonic() as usize + 2;
    let stable = smallest_stable_steps(scheme, omega_max, frequency, AUTO_MARGIN).unwrap_or(0);
    let k = AUTO_FLOOR.max(resolution).max(stable).next_power_of_two();
    let wh = omega_max * step(frequency, k);
    let why = match scheme.stability_limit() {
        Some(l) => format!("ω_max·h = {wh:.3} ≤ {:.3} = {AUTO_MARGIN}·{l:.3}", AUTO_MARGIN * l),
        None => format!("no stability limit, ω_max·h = {wh:.3}; the floor {AUTO_FLOOR}"),
    };
    (k, format!("steps = \"auto\": k = {k} ({scheme}, ω = {frequency} rad/s, ω_max = {omega_max:.4e} rad/s, {why}; a power of two)"))
}
