//! Floquet multipliers of a discrete orbit and the test functions of its bifurcations.
//!
//! The multipliers are the eigenvalues of the discrete monodromy dP/ds_0 (the period map's
//! Jacobian with the active sets frozen); they converge to the continuous orbit's as k grows
//! (src/formulation.md §7). The test functions change sign where a bifurcation lies between two points:
//! - period doubling: det(I + M) = Π(1 + μ) (complex pairs give |1 + μ|² > 0, so only a real
//!   multiplier through −1 changes its sign; Kuznetsov, "Elements of Applied Bifurcation
//!   Theory", §10.2);
//! - Neimark–Sacker: the number of non-real multipliers outside the unit circle.
use nalgebra::{DMatrix, Schur};
use num_complex::Complex64;

/// QR sweeps at most for the monodromy's Schur form (LAPACK's hseqr allows 30 per eigenvalue).
const SCHUR_SWEEPS: usize = 10_000;

/// The multipliers of a monodromy matrix, largest modulus first.
/// NaN where the Schur iteration does not converge in [`SCHUR_SWEEPS`] (nalgebra's own loop has
/// no bound: the real blade's exact walk hung at 2293.30 rad/s in it).
pub fn multipliers(monodromy: &DMatrix<f64>) -> Vec<Complex64> {
    let n = monodromy.nrows();
    let schur = monodromy.iter().all(|x| x.is_finite()).then(|| Schur::try_new(balanced(monodromy), f64::EPSILON, SCHUR_SWEEPS)).flatten();
    let Some(schur) = schur else {
        return vec![Complex64::new(f64::NAN, f64::NAN); n];
    };
    let mut mu: Vec<Complex64> = schur.complex_eigenvalues().iter().map(|c| Complex64::new(c.re, c.im)).collect();
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    mu
}

/// D⁻¹ M D with D diagonal, powers of 2, equalising each row's and column's off-diagonal norms
/// (Parlett & Reinsch, Numer. Math. 13, 1969; LAPACK's gebal): the eigenvalues are unchanged, but
/// a monodromy whose displacement and velocity rows differ by ω_max in scale loses up to 1e-6 of its
/// multipliers in an unbalanced QR (the real blade: 138 states, velocities 1e6 × displacements).
fn balanced(m: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    let mut b = m.clone();
    for _sweep in 0..64 {
        let mut changed = false;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in (0..n).filter(|&j| j != i) {
                c += b[(j, i)].abs();
                r += b[(i, j)].abs();
            }
            if c == 0.0 || r == 0.0 || !(c + r).is_finite() {
                continue;
            }
            let mut f = 1.0;
            let (mut cs, mut rs) = (c, r);
            while cs < rs / 2.0 {
                cs *= 2.0;
                rs /= 2.0;
                f *= 2.0;
            }
            while cs >= rs * 2.0 {
                cs /= 2.0;
                rs *= 2.0;
                f /= 2.0;
            }
            if (cs + rs) < 0.95 * (c + r) {
                // column i times f, row i divided by f: a similarity by diag(…, f, …).
                b.column_mut(i).scale_mut(f);
                b.row_mut(i).scale_mut(1.0 / f);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    b
}

/// Largest modulus (0 for an empty state).
/// NaN when a multiplier is (an unconverged Schur form): `f64::max` would drop it and read 0, stable.
pub fn largest(mu: &[Complex64]) -> f64 {
    mu.iter().fold(0.0, |a: f64, m| if m.norm().is_nan() { f64::NAN } else { a.max(m.norm()) })
}

/// Sign of det(I + M) = Π(1 + μ): flips where a real multiplier crosses −1.
pub fn doubling_sign(mu: &[Complex64]) -> bool {
    doubling_test(mu) > 0.0
}

/// det(I + M) = Π(1 + μ_i): zero where a multiplier passes −1 (a period doubling's test function).
pub fn doubling_test(mu: &[Complex64]) -> f64 {
    mu.iter().fold(Complex64::new(1.0, 0.0), |a, m| a * (1.0 + m)).re
}

/// Non-real multipliers outside the unit circle (pairs counted twice). A multiplier counts as
/// non-real when its imaginary part is above round-off of its modulus.
pub fn complex_outside(mu: &[Complex64]) -> usize {
    mu.iter().filter(|m| m.im.abs() > 1e-9 * m.norm() && m.norm() > 1.0).count()
}

/// A real multiplier within 0.1 of `at` (−1 or +1) on each side of it, one in `a` and one in
/// `b`: a period doubling (−1) or a fold (+1, Seydel 2010, §7.4) between two points, where its
/// test's sign change could not be located.
pub fn crosses(a: &[Complex64], b: &[Complex64], at: f64) -> bool {
    let near = |mu: &[Complex64], inside: bool| mu.iter().any(|m| m.im.abs() <= 1e-9 * m.norm() && (m.re - at).abs() < 0.1 && (m.re.abs() < 1.0) == inside);
    (near(a, true) && near(b, false)) || (near(a, false) && near(b, true))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A monodromy with a badly scaled similarity: the balanced eigenvalues equal those of the
    /// well-scaled matrix (a rotation-dilation block and a real pair, known in closed form).
    #[test]
    fn balancing_keeps_the_multipliers_of_a_badly_scaled_monodromy() {
        let (a, b) = (0.6_f64, 0.7_f64);
        let base = DMatrix::from_row_slice(4, 4, &[a, -b, 0.2, 0.0, b, a, 0.0, 0.1, 0.0, 0.0, -0.9, 0.3, 0.0, 0.0, 0.0, 0.4]);
        let d = [1.0, 1e6, 1e-3, 1e5];
        let scaled = DMatrix::from_fn(4, 4, |i, j| base[(i, j)] * d[i] / d[j]);
        let mu = multipliers(&scaled);
        let modulus = (a * a + b * b).sqrt();
        let expected = [modulus, modulus, 0.9, 0.4];
        for (m, e) in mu.iter().zip(expected) {
            assert!((m.norm() - e).abs() < 1e-13, "{m} against |μ| = {e}");
        }
    }
}
