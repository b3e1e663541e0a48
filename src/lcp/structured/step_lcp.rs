//! One step's contact LCP w = r + S z (S m×m, a P-matrix), its active sets as bit masks, and the
//! check that S is a P-matrix.
use super::step_map::StepMapError;

/// Most pairs per step: a step's active set is one u64 bit mask (bit c: pair c active).
pub const MAX_PAIRS: usize = 64;

/// Up to this many mutually coupled pairs, S's P-property is checked on every principal minor
/// (2^m determinants); above, through its symmetric part being positive definite (sufficient,
/// and true of S = B W Bᵀ + D with W = N₀⁻¹ symmetric positive definite).
const ENUMERATE_MAX: usize = 12;

/// The pairs of a mask, in order, on the stack (this runs at every step of every march).
pub(super) fn members(mask: u64, m: usize) -> ([usize; MAX_PAIRS], usize) {
    let mut act = [0usize; MAX_PAIRS];
    let mut p = 0;
    for i in (0..m).filter(|&i| mask >> i & 1 == 1) {
        act[p] = i;
        p += 1;
    }
    (act, p)
}

/// S is a P-matrix: every principal minor positive. S is split into its groups of mutually
/// coupled pairs (strongly connected through non-zero entries): after ordering them S is block
/// triangular, so each principal minor is the product of the groups' and S is P iff each group's
/// block is. A group of up to [`ENUMERATE_MAX`] pairs has every minor checked, a larger one the
/// Cholesky factorisation of its symmetric part.
pub(super) fn check_p_matrix(s: &[f64], m: usize) -> Result<(), StepMapError> {
    let scale = s.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    // reach[i]: bit j when pair i's row reaches j through non-zero entries (Warshall's closure).
    let mut reach: Vec<u64> = (0..m).map(|i| (0..m).filter(|&j| j != i && s[i * m + j] != 0.0).fold(1u64 << i, |a, j| a | 1 << j)).collect();
    for via in 0..m {
        for i in 0..m {
            if reach[i] >> via & 1 == 1 {
                reach[i] |= reach[via];
            }
        }
    }
    let mut seen = 0u64;
    for i in 0..m {
        if seen >> i & 1 == 1 {
            continue;
        }
        let group: Vec<usize> = (0..m).filter(|&j| reach[i] >> j & 1 == 1 && reach[j] >> i & 1 == 1).collect();
        group.iter().for_each(|&j| seen |= 1 << j);
        if group.len() <= ENUMERATE_MAX {
            check_minors(s, m, &group, scale)?;
        } else {
            check_symmetric_part(s, m, &group, scale)?;
        }
    }
    Ok(())
}

/// Every principal minor of S on subsets of `group` positive.
fn check_minors(s: &[f64], m: usize, group: &[usize], scale: f64) -> Result<(), StepMapError> {
    for sub in 1u64..(1 << group.len()) {
        let rows: Vec<usize> = (0..group.len()).filter(|b| sub >> b & 1 == 1).map(|b| group[b]).collect();
        let mut a: Vec<f64> = rows.iter().flat_map(|&a| rows.iter().map(move |&b| s[a * m + b])).collect();
        let det = eliminate(&mut a, &mut vec![0.0; rows.len()], rows.len());
        // A minor at round-off of the entries' scale counts as zero: not a P-matrix.
        if !(det > 1e-13 * scale.powi(rows.len() as i32)) {
            return Err(StepMapError::NotP(rows, det));
        }
    }
    Ok(())
}

/// (S + Sᵀ)/2 on `group` positive definite (Cholesky, pivots above round-off of S's scale).
fn check_symmetric_part(s: &[f64], m: usize, group: &[usize], scale: f64) -> Result<(), StepMapError> {
    let p = group.len();
    let mut l: Vec<f64> = (0..p * p).map(|e| 0.5 * (s[group[e / p] * m + group[e % p]] + s[group[e % p] * m + group[e / p]])).collect();
    for c in 0..p {
        let pivot = l[c * p + c] - (0..c).map(|t| l[c * p + t] * l[c * p + t]).sum::<f64>();
        if !(pivot > 1e-13 * scale) {
            return Err(StepMapError::NotPositiveDefinite(group.to_vec(), pivot));
        }
        let root = pivot.sqrt();
        l[c * p + c] = root;
        for r in c + 1..p {
            l[r * p + c] = (l[r * p + c] - (0..c).map(|t| l[r * p + t] * l[c * p + t]).sum::<f64>()) / root;
        }
    }
    Ok(())
}

/// Gaussian elimination with partial pivoting of the n×n `a` (row-major), applied to `b` too and
/// finished by back substitution (b becomes a⁻¹b); returns det(a), 0 when a pivot is exactly 0.
pub(super) fn eliminate(a: &mut [f64], b: &mut [f64], n: usize) -> f64 {
    let (mut multipliers, mut pivots) = (vec![0.0; n * n], vec![0usize; n]);
    let det = factor(a, &mut multipliers, &mut pivots, n);
    if det != 0.0 {
        replay(a, &multipliers, &pivots, b);
    }
    det
}

/// The elimination of one principal block S_aa: its upper triangle, multipliers and row
/// exchanges ([`factor`]), and its determinant.
#[derive(Clone, Debug)]
struct Factored {
    mask: u64,
    upper: Vec<f64>,
    multipliers: Vec<f64>,
    pivots: [usize; MAX_PAIRS],
    det: f64,
}

/// Blocks S_aa factored on one step map (S is fixed there), by set: a step replays its block's
/// elimination on its right-hand side instead of eliminating again (the same operations on b in
/// the same order: the same bits). Consecutive steps mostly share their set, and a period's sets
/// recur over a solve's marches. Why: the elimination was 8 % of the real blade's 1e-3 sweep
/// (issue 23).
#[derive(Clone, Debug, Default)]
pub(super) struct ActiveBlocks {
    blocks: Vec<Factored>,
    by_mask: std::collections::HashMap<u64, usize>,
    /// The block the last step used.
    last: usize,
}

/// Sets an [`ActiveBlocks`] keeps at most (a long homotopy meets thousands).
const BLOCKS_KEPT: usize = 4096;

impl ActiveBlocks {
    /// The factored block of `mask` (non-empty), made and kept if not there.
    fn block(&mut self, s: &[f64], m: usize, mask: u64) -> &Factored {
        if self.blocks.get(self.last).is_some_and(|f| f.mask == mask) {
            return &self.blocks[self.last];
        }
        if let Some(&i) = self.by_mask.get(&mask) {
            self.last = i;
            return &self.blocks[i];
        }
        if self.blocks.len() == BLOCKS_KEPT {
            self.blocks.clear();
            self.by_mask.clear();
        }
        let (members, p) = members(mask, m);
        let act = &members[..p];
        let mut a: Vec<f64> = act.iter().flat_map(|&ai| act.iter().map(move |&aj| s[ai * m + aj])).collect();
        let mut multipliers = vec![0.0; p * p];
        let mut pivots = [0usize; MAX_PAIRS];
        let det = factor(&mut a, &mut multipliers, &mut pivots, p);
        self.last = self.blocks.len();
        self.by_mask.insert(mask, self.last);
        self.blocks.push(Factored { mask, upper: a, multipliers, pivots, det });
        &self.blocks[self.last]
    }
}

/// Gaussian elimination with partial pivoting of the n×n row-major `a`, recording each column's
/// pivot row and each row's multiplier (`multipliers[i·n + col]`); returns det(a), 0 when a pivot is exactly 0.
fn factor(a: &mut [f64], multipliers: &mut [f64], pivots: &mut [usize], n: usize) -> f64 {
    let mut det = 1.0;
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs())).unwrap_or(col);
        pivots[col] = piv;
        if !(a[piv * n + col].abs() > 0.0) {
            return 0.0;
        }
        if piv != col {
            for j in 0..n {
                a.swap(piv * n + j, col * n + j);
            }
            det = -det;
        }
        det *= a[col * n + col];
        for i in col + 1..n {
            let f = a[i * n + col] / a[col * n + col];
            multipliers[i * n + col] = f;
            for j in col..n {
                a[i * n + j] -= f * a[col * n + j];
            }
        }
    }
    det
}

/// Gaussian elimination's operations on `b` (n = b.len()) from a [`factor`]ed block (its upper
/// triangle, multipliers and pivot rows), then back substitution: b becomes a⁻¹b.
fn replay(upper: &[f64], multipliers: &[f64], pivots: &[usize], b: &mut [f64]) {
    let n = b.len();
    for col in 0..n {
        if pivots[col] != col {
            b.swap(pivots[col], col);
        }
        for i in col + 1..n {
            b[i] -= multipliers[i * n + col] * b[col];
        }
    }
    for i in (0..n).rev() {
        let t: f64 = (i + 1..n).map(|j| upper[i * n + j] * b[j]).sum();
        b[i] = (b[i] - t) / upper[i * n + i];
    }
}

/// Solves S_aa z_a = −r_a for the active set `mask` into `z` (zero off the set), from the step
/// map's factored blocks; false when the principal block is singular to working precision.
pub(super) fn solve_active(blocks: &mut ActiveBlocks, s: &[f64], m: usize, r: &[f64], mask: u64, z: &mut [f64]) -> bool {
    z.iter_mut().for_each(|v| *v = 0.0);
    let (members, p) = members(mask, m);
    let act = &members[..p];
    if p == 0 {
        return true;
    }
    let block = blocks.block(s, m, mask);
    if block.det == 0.0 {
        return false;
    }
    let mut b = [0.0; MAX_PAIRS];
    for (i, &ai) in act.iter().enumerate() {
        b[i] = -r[ai];
    }
    replay(&block.upper, &block.multipliers, &block.pivots[..p], &mut b[..p]);
    for (i, &ai) in act.iter().enumerate() {
        z[ai] = b[i];
    }
    z.iter().all(|v| v.is_finite())
}

/// The answer of one step's LCP w = S z + r by Murty's least-index principal pivoting started
/// from `guess` (the same step's set at the previous march, or the previous step's): finite for a
/// P-matrix from any start (Murty 1974), and a right guess costs one solve of its block, so the
/// work per step is O(|a|³) per set change, not the 2^m of an enumeration. Returns the active set,
/// z and the number of set changes; `None` when a block is singular or the changes pass a bound
/// far above any seen (a P-matrix lost to round-off).
/// `blocks`: the step map's factored blocks ([`ActiveBlocks`]).
pub(super) fn step_lcp(blocks: &mut ActiveBlocks, s: &[f64], m: usize, r: &[f64], guess: u64, z: &mut [f64], w: &mut [f64]) -> Option<(u64, usize)> {
    // Round-off of a zero: a sign within this of zero counts as zero.
    let tol = 1e-14 * r.iter().fold(f64::MIN_POSITIVE, |a, v| a.max(v.abs()));
    let valid = if m == MAX_PAIRS { u64::MAX } else { (1u64 << m) - 1 };
    let mut mask = guess & valid;
    let most = 1usize << m.min(20);
    for changes in 0..=most {
        if !solve_active(blocks, s, m, r, mask, z) {
            return None;
        }
        // z is zero off the set: its non-zero entries, in order, are summed as a scan of all m
        // would (most steps have none, and the scan was m² tests per step).
        let (members, p) = members(mask, m);
        let mut nonzero = [0usize; MAX_PAIRS];
        let mut n = 0;
        for &j in members[..p].iter().filter(|&&j| z[j] != 0.0) {
            nonzero[n] = j;
            n += 1;
        }
        for i in 0..m {
            w[i] = r[i] + nonzero[..n].iter().map(|&j| s[i * m + j] * z[j]).sum::<f64>();
        }
        match (0..m).find(|&i| if mask >> i & 1 == 1 { z[i] < -tol } else { w[i] < -tol }) {
            None => {
                for i in 0..m {
                    if mask >> i & 1 == 1 {
                        z[i] = z[i].max(0.0);
                        w[i] = 0.0;
                    } else {
                        w[i] = w[i].max(0.0);
                    }
                }
                return Some((mask, changes));
            }
            Some(i) => mask ^= 1 << i,
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 40-pair SPD S (past the old 10 and the enumeration's 12): the pivoting's answer is
    /// complementary, and the same from a cold and from a wrong guess.
    #[test]
    fn the_step_lcp_solves_forty_pairs_from_any_guess() {
        let m = 40;
        let mut seed = 7u64;
        let mut draw = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let g: Vec<f64> = (0..m * m).map(|_| draw()).collect();
        // S = G Gᵀ + I: symmetric positive definite, hence P.
        let s: Vec<f64> =
            (0..m * m).map(|e| (0..m).map(|t| g[e / m * m + t] * g[e % m * m + t]).sum::<f64>() + if e / m == e % m { 1.0 } else { 0.0 }).collect();
        assert!(check_p_matrix(&s, m).is_ok());
        let r: Vec<f64> = (0..m).map(|_| draw()).collect();
        let (mut z, mut w) = (vec![0.0; m], vec![0.0; m]);
        let (cold, _) = step_lcp(&mut ActiveBlocks::default(), &s, m, &r, 0, &mut z, &mut w).unwrap();
        for i in 0..m {
            let wi = r[i] + (0..m).map(|j| s[i * m + j] * z[j]).sum::<f64>();
            assert!(z[i] >= 0.0 && wi >= -1e-12 && (z[i] * wi).abs() <= 1e-12, "pair {i}: z = {}, w = {wi}", z[i]);
        }
        let z_cold = z.clone();
        let (warm, _) = step_lcp(&mut ActiveBlocks::default(), &s, m, &r, !cold & ((1 << m) - 1), &mut z, &mut w).unwrap();
        assert_eq!(warm, cold);
        assert!(z.iter().zip(&z_cold).all(|(a, b)| (a - b).abs() <= 1e-12));
        // A non-symmetric coupled group of 13 pairs whose symmetric part is indefinite is refused.
        let mut bad = vec![0.0; 13 * 13];
        for i in 0..13 {
            bad[i * 13 + i] = 1.0;
            bad[i * 13 + (i + 1) % 13] = 3.0;
        }
        assert!(matches!(check_p_matrix(&bad, 13), Err(StepMapError::NotPositiveDefinite(..))));
    }

    /// A block's kept elimination replayed on new right-hand sides gives the bits a fresh
    /// elimination gives, for every set of a 6-pair S (sizes 1–6, row exchanges included), each
    /// set solved twice in a mixed order so that most solves replay a kept block.
    #[test]
    fn a_kept_block_replays_the_elimination_bit_for_bit() {
        let m = 6;
        let mut seed = 3u64;
        let mut draw = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        // Non-symmetric with small diagonal entries: partial pivoting exchanges rows.
        let entries: Vec<f64> = (0..m * m).map(|e| draw() + if e / m == e % m { 0.01 } else { 0.0 }).collect();
        let s = entries.as_slice();
        let mut blocks = ActiveBlocks::default();
        for round in 0..2 {
            for mask in 1u64..(1 << m) {
                let mask = if round == 0 { mask } else { (1 << m) - mask };
                let r: Vec<f64> = (0..m).map(|_| draw()).collect();
                let (members, p) = members(mask, m);
                let act = &members[..p];
                let mut a: Vec<f64> = act.iter().flat_map(|&i| act.iter().map(move |&j| s[i * m + j])).collect();
                let mut b: Vec<f64> = act.iter().map(|&i| -r[i]).collect();
                let det = eliminate(&mut a, &mut b, p);
                let mut z = vec![0.0; m];
                let solved = solve_active(&mut blocks, s, m, &r, mask, &mut z);
                assert_eq!(solved, det != 0.0 && b.iter().all(|v| v.is_finite()), "set {mask:b}");
                for (i, &ai) in act.iter().enumerate() {
                    assert_eq!(z[ai].to_bits(), b[i].to_bits(), "set {mask:b}, pair {ai}");
                }
            }
        }
    }
}
