//! Brute-force enumeration of complementary bases: an independent reference for small LCPs.
//!
//! For every α ⊆ {0…n−1} (2ⁿ of them) solve A_αα z_α = −q_α with z_ᾱ = 0 by its own Gaussian
//! elimination (partial pivoting; no code shared with the solvers), and keep z when z ≥ 0 and
//! w = A z + q ≥ 0 within the tolerance. This finds every solution that is a *complementary basic*
//! solution (A_αα nonsingular). Every solution Lemke's method certifies is one (its final basis is
//! nonsingular), and for nondegenerate data every solution is. A continuum of solutions shows up
//! as its basic vertices only, and in singular degenerate cases a solvable LCP can have no
//! complementary basic solution at all (e.g. A = [[0,0],[1,−1]], q = (0,−1), solved by (t, 0),
//! t ≥ 1): "none found" proves unsolvability only for nondegenerate data.

use super::LcpMatrix;

/// Pivots below `SINGULAR_REL · max|A_αα|` mark A_αα as singular: its basis is skipped.
/// Why: a numerically singular principal block has no well-defined basic solution.
const SINGULAR_REL: f64 = 1e-11;

/// All distinct complementary basic solutions z of w = A z + q, z ≥ 0, w ≥ 0, zᵀw = 0.
///
/// A candidate is accepted when z_α ≥ −tol·max(1, ‖z‖∞) and w_ᾱ ≥ −tol·max(1, ‖q‖∞, ‖A‖∞‖z‖∞)
/// (w = A z + q carries round-off proportional to ‖A‖‖z‖); such small negatives are set to 0 in
/// the result. Two solutions closer than tol·max(1, ‖z‖∞) (∞-norm)
/// count as one. Returns nothing for non-finite data. Meant for n ≤ 12 (2ⁿ small solves);
/// panics for n > 20.
pub fn solve_by_enumeration(a: &dyn LcpMatrix, q: &[f64], tol: f64) -> Vec<Vec<f64>> {
    let n = a.dim();
    assert!(n <= 20, "solve_by_enumeration: 2^{n} bases is too many (meant for n ≤ 12)");
    assert_eq!(q.len(), n, "solve_by_enumeration: q has {} entries for n = {n}", q.len());
    let full: Vec<f64> = (0..n * n).map(|k| a.entry(k / n, k % n)).collect();
    if !full.iter().chain(q).all(|v| v.is_finite()) {
        return Vec::new();
    }
    let qscale = q.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    // ‖A‖∞: the largest absolute row sum.
    let anorm = (0..n).map(|i| full[i * n..(i + 1) * n].iter().map(|v| v.abs()).sum::<f64>()).fold(0.0f64, f64::max);
    let mut found: Vec<Vec<f64>> = Vec::new();
    let mut alpha = Vec::with_capacity(n);
    let mut m = Vec::with_capacity(n * n);
    let mut rhs = Vec::with_capacity(n);
    for mask in 0u32..(1u32 << n) {
        alpha.clear();
        alpha.extend((0..n).filter(|&i| mask & (1 << i) != 0));
        let k = alpha.len();
        m.clear();
        for &i in &alpha {
            for &j in &alpha {
                m.push(full[i * n + j]);
            }
        }
        rhs.clear();
        rhs.extend(alpha.iter().map(|&i| -q[i]));
        if !gauss_solve(k, &mut m, &mut rhs) {
            continue;
        }
        let mut z = vec![0.0; n];
        for (t, &i) in alpha.iter().enumerate() {
            z[i] = rhs[t];
        }
        let zscale = z.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        if z.iter().any(|&v| v.is_nan() || v < -tol * zscale) {
            continue;
        }
        let w: Vec<f64> = (0..n).map(|i| q[i] + (0..n).map(|j| full[i * n + j] * z[j]).sum::<f64>()).collect();
        let wscale = qscale.max(anorm * zscale);
        if w.iter().any(|&v| v.is_nan() || v < -tol * wscale) {
            continue;
        }
        z.iter_mut().for_each(|v| *v = v.max(0.0));
        let dup = found.iter().any(|s| s.iter().zip(&z).all(|(a, b)| (a - b).abs() <= tol * zscale));
        if !dup {
            found.push(z);
        }
    }
    found
}

/// Solves the k×k system in place (row-major `m`, right-hand side → solution in `b`) by Gaussian
/// elimination with partial pivoting. False if singular (relative pivot test) or not finite.
fn gauss_solve(k: usize, m: &mut [f64], b: &mut [f64]) -> bool {
    let scale = m.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    if k == 0 {
        return true;
    }
    if scale.is_nan() || scale <= 0.0 {
        return false;
    }
    for c in 0..k {
        let mut p = c;
        for r in c + 1..k {
            if m[r * k + c].abs() > m[p * k + c].abs() {
                p = r;
            }
        }
        let pivot = m[p * k + c].abs();
        if pivot.is_nan() || pivot <= SINGULAR_REL * scale {
            return false;
        }
        if p != c {
            for j in 0..k {
                m.swap(p * k + j, c * k + j);
            }
            b.swap(p, c);
        }
        let piv = m[c * k + c];
        for r in c + 1..k {
            let f = m[r * k + c] / piv;
            if f != 0.0 {
                for j in c..k {
                    m[r * k + j] -= f * m[c * k + j];
                }
                b[r] -= f * b[c];
            }
        }
    }
    for c in (0..k).rev() {
        let s: f64 = (c + 1..k).map(|j| m[c * k + j] * b[j]).sum();
        b[c] = (b[c] - s) / m[c * k + c];
    }
    b.iter().all(|v| v.is_finite())
}
