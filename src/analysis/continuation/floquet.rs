//! Floquet multipliers of a discrete orbit and the test functions of its bifurcations.
//!
//! The multipliers are the eigenvalues of the discrete monodromy dP/ds_0 (the period map's
//! Jacobian with the active sets frozen); they converge to the continuous orbit's as k grows
//! (src/formulation.md §7). The test functions change sign where a bifurcation lies between two points:
//! - period doubling: det(I + M) = Π(1 + μ) (complex pairs give |1 + μ|² > 0, so only a real
//!   multiplier through −1 changes its sign; Kuznetsov, "Elements of Applied Bifurcation
//!   Theory", §10.2);
//! - Neimark–Sacker: the number of non-real multipliers outside the unit circle.
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The multipliers of a monodromy matrix, largest modulus first.
pub fn multipliers(monodromy: &DMatrix<f64>) -> Vec<Complex64> {
    let mut mu: Vec<Complex64> = monodromy.clone().complex_eigenvalues().iter().map(|c| Complex64::new(c.re, c.im)).collect();
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    mu
}

/// Largest modulus (0 for an empty state).
pub fn largest(mu: &[Complex64]) -> f64 {
    mu.iter().fold(0.0, |a, m| a.max(m.norm()))
}

/// Sign of det(I + M) = Π(1 + μ): flips where a real multiplier crosses −1.
pub fn doubling_sign(mu: &[Complex64]) -> bool {
    mu.iter().fold(Complex64::new(1.0, 0.0), |a, m| a * (1.0 + m)).re > 0.0
}

/// Non-real multipliers outside the unit circle (pairs counted twice). A multiplier counts as
/// non-real when its imaginary part is above round-off of its modulus.
pub fn complex_outside(mu: &[Complex64]) -> usize {
    mu.iter().filter(|m| m.im.abs() > 1e-9 * m.norm() && m.norm() > 1.0).count()
}

/// What an event's multipliers say in its detail: the pair of a Neimark–Sacker, the multiplier
/// nearest −1 of a period doubling; nothing for the other kinds.
pub fn event_detail(kind: super::EventKind, mu: &[Complex64]) -> String {
    match kind {
        super::EventKind::NeimarkSacker => {
            let m = mu.iter().find(|m| m.im.abs() > 1e-9 * m.norm()).copied().unwrap_or_default();
            format!("pair {:.6} ± {:.6}i, |μ| = {:.9}", m.re, m.im.abs(), m.norm())
        }
        super::EventKind::PeriodDoubling => {
            let m = mu.iter().min_by(|x, y| (*x + 1.0).norm().total_cmp(&(*y + 1.0).norm())).copied().unwrap_or_default();
            format!("multiplier {:.9}", m.re)
        }
        _ => String::new(),
    }
}
