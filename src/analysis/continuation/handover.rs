//! The hand-over from the exact walk to the discrete one (issue 24): the discrete walk's first
//! orbit, at the λ where the exact walk stopped, must be the same orbit up to the scheme's error,
//! or the discrete walk would report another branch (the coarse blade, rigid: the contact-free
//! orbit past 2397.64 rad/s) as the followed one.

use super::BranchPoint;

/// Largest relative difference of the outputs' amplitudes between the last exact orbit and the
/// discrete walk's first (same λ) for the two to be one orbit: the scheme's O(h^p) error at the
/// grids used is ≤ 1e-2 (validation/RECORD.md, the coarse blade's exact vs k = 1024 amplitudes); a change of
/// branch is O(1).
pub(super) const HANDOVER_JUMP: f64 = 5e-2;

/// Why the discrete walk's first orbit `first` is not the exact walk's last one `last` (another
/// branch), or None when they agree within [`HANDOVER_JUMP`].
pub(super) fn left_branch(last: &BranchPoint, first: &BranchPoint, name: &str) -> Option<String> {
    let relative = jump(last, first)?;
    let contact_free = !first.masks.is_empty() && first.masks.iter().all(|&m| m == 0);
    let what = if contact_free { "a contact-free orbit" } else { "another orbit" };
    Some(format!(
        "the discrete walk's orbit at {name} = {} is {what}, not the exact one's (amplitudes differ by {:.1}% > {:.0}%): refused, it would follow another branch; remedy: a finer --steps, or continue from past {name} = {} with a fresh solve",
        first.parameter,
        100.0 * relative,
        100.0 * HANDOVER_JUMP,
        last.parameter,
    ))
}

/// The largest relative difference of the outputs' amplitudes between two orbits at one λ when
/// they are not one orbit (above [`HANDOVER_JUMP`]; infinite for different outputs), else None.
pub(super) fn jump(a: &BranchPoint, b: &BranchPoint) -> Option<f64> {
    let scale = a.amplitude.iter().chain(&b.amplitude).fold(0.0_f64, |m, x| m.max(x.abs()));
    let jump = a.amplitude.iter().zip(&b.amplitude).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    let relative = if scale > 0.0 { jump / scale } else { 0.0 };
    if relative.is_finite() && relative <= HANDOVER_JUMP && a.amplitude.len() == b.amplitude.len() {
        return None;
    }
    Some(relative)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(parameter: f64, amplitude: Vec<f64>, masks: Vec<u64>) -> BranchPoint {
        BranchPoint { masks, ..BranchPoint::discrete(parameter, amplitude) }
    }

    /// A linear oscillator's amplitude F/|k − mω²| (closed form) against itself within the scheme's
    /// error is kept; the stop's held orbit (amplitude capped at the gap g) against the free one is refused.
    #[test]
    fn handover_keeps_the_branch_and_refuses_another() {
        let (k, m, f, w): (f64, f64, f64, f64) = (1.0e4, 1.0, 50.0, 90.0);
        let free = f / (k - m * w * w).abs();
        let exact = point(w, vec![free], Vec::new());
        assert!(left_branch(&exact, &point(w, vec![free * (1.0 + 1e-3)], vec![0]), "frequency").is_none());
        let gap = 0.25 * free;
        let held = point(w, vec![gap], Vec::new());
        let why = left_branch(&held, &point(w, vec![free], vec![0, 0]), "frequency").expect("refused");
        assert!(why.contains("contact-free") && why.contains("refused"), "{why}");
    }
}
