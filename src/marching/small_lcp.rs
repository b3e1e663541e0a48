//! A small dense LCP solver for the per-step contact problem of the marcher:
//! find z ≥ 0 with w = G z + q ≥ 0 and zᵀw = 0, for m ≲ 10 contacts.
//!
//! Murty's least-index principal pivoting (finite for a P-matrix, which G = B Ŵ Bᵀ is when Ŵ is
//! symmetric positive definite and B has independent rows), with an exhaustive enumeration of
//! the 2^m complementary bases as a fallback. Independent of the crate's `lcp` module on purpose.

/// Solves a dense linear system by Gaussian elimination with partial pivoting; `None` if singular.
pub(crate) fn solve_dense(a: &mut [f64], b: &mut [f64], n: usize) -> Option<()> {
    for col in 0..n {
        let mut piv = col;
        for r in col + 1..n {
            if a[r * n + col].abs() > a[piv * n + col].abs() {
                piv = r;
            }
        }
        let p = a[piv * n + col];
        if p == 0.0 || !p.is_finite() {
            return None;
        }
        if piv != col {
            for k in 0..n {
                a.swap(col * n + k, piv * n + k);
            }
            b.swap(col, piv);
        }
        for r in col + 1..n {
            let f = a[r * n + col] / a[col * n + col];
            if f != 0.0 {
                for k in col..n {
                    a[r * n + k] -= f * a[col * n + k];
                }
                b[r] -= f * b[col];
            }
        }
    }
    for r in (0..n).rev() {
        let mut s = b[r];
        for k in r + 1..n {
            s -= a[r * n + k] * b[k];
        }
        b[r] = s / a[r * n + r];
    }
    b.iter().all(|v| v.is_finite()).then_some(())
}

/// z for the complementary basis `active` (z_i free for active i, w_i free otherwise), and w.
fn basis_solution(g: &[f64], q: &[f64], m: usize, active: &[bool]) -> Option<(Vec<f64>, Vec<f64>)> {
    let idx: Vec<usize> = (0..m).filter(|&i| active[i]).collect();
    let k = idx.len();
    let mut z = vec![0.0; m];
    if k > 0 {
        let mut a = vec![0.0; k * k];
        let mut b = vec![0.0; k];
        for (r, &i) in idx.iter().enumerate() {
            for (c, &j) in idx.iter().enumerate() {
                a[r * k + c] = g[i * m + j];
            }
            b[r] = -q[i];
        }
        solve_dense(&mut a, &mut b, k)?;
        for (r, &i) in idx.iter().enumerate() {
            z[i] = b[r];
        }
    }
    let w: Vec<f64> = (0..m).map(|i| q[i] + (0..m).map(|j| g[i * m + j] * z[j]).sum::<f64>()).collect();
    Some((z, w))
}

/// The step LCP has no complementary solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the {contacts}-contact step LCP has no complementary solution (G is not a P-matrix?)")]
pub struct StepLcpError {
    pub contacts: usize,
}

/// Returns z (clamped ≥ 0) or an error when no complementary solution is found.
pub(crate) fn solve_small_lcp(g: &[f64], q: &[f64], m: usize) -> Result<Vec<f64>, StepLcpError> {
    if q.iter().all(|&v| v >= 0.0) {
        return Ok(vec![0.0; m]);
    }
    let gs = g.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let qs = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let tol = 1e-12 * qs;
    let ztol = 1e-12 * qs / gs.max(f64::MIN_POSITIVE);
    // Murty's least-index principal pivoting.
    let mut active = vec![false; m];
    for _ in 0..(50 * m * m + 100) {
        let Some((z, w)) = basis_solution(g, q, m, &active) else { break };
        match (0..m).find(|&i| (active[i] && z[i] < -ztol) || (!active[i] && w[i] < -tol)) {
            None => return Ok(z.into_iter().map(|v| v.max(0.0)).collect()),
            Some(i) => active[i] = !active[i],
        }
    }
    // Fallback: enumeration of all complementary bases.
    if m <= 16 {
        for mask in 0u32..(1u32 << m) {
            let active: Vec<bool> = (0..m).map(|i| mask & (1 << i) != 0).collect();
            if let Some((z, w)) = basis_solution(g, q, m, &active)
                && z.iter().all(|&v| v >= -ztol)
                && w.iter().all(|&v| v >= -tol)
            {
                return Ok(z.into_iter().map(|v| v.max(0.0)).collect());
            }
        }
    }
    Err(StepLcpError { contacts: m })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random SPD G (a P-matrix) and random q: the answer is complementary.
    #[test]
    fn small_lcp_spd_is_complementary() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for m in 1..=8 {
            for _ in 0..50 {
                let a: Vec<f64> = (0..m * m).map(|_| rnd()).collect();
                let mut g = vec![0.0; m * m];
                for i in 0..m {
                    for j in 0..m {
                        g[i * m + j] = (0..m).map(|k| a[i * m + k] * a[j * m + k]).sum::<f64>() + if i == j { 0.1 } else { 0.0 };
                    }
                }
                let q: Vec<f64> = (0..m).map(|_| rnd()).collect();
                let z = solve_small_lcp(&g, &q, m).unwrap();
                for i in 0..m {
                    let w = q[i] + (0..m).map(|j| g[i * m + j] * z[j]).sum::<f64>();
                    assert!(z[i] >= 0.0 && w >= -1e-10 && (z[i] * w).abs() < 1e-10, "m {m} i {i} z {} w {w}", z[i]);
                }
            }
        }
    }
}
