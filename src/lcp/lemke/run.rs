//! The pivot loop of Lemke's method on the revised basis: the lexicographic ratio test and the
//! complementary pivoting rule. Per pivot it allocates nothing: every buffer lives in [`Revised`].
use super::basis::{NONE, Revised};

/// Rows whose value after the pivot would be within `TIE_TOL · max(1, ‖B⁻¹q‖∞)` of zero tie at
/// the minimum ratio. Why: the data are scaled to max|A| = max|q| = 1, so B⁻¹q carries round-off
/// of a few ulps times the growth of B⁻¹; an exact (degenerate) tie must not be missed because of
/// it, while distinct ratios in real problems differ by far more.
const TIE_TOL: f64 = 1e-11;

/// Two entries of the lexicographic comparison `(B⁻¹)_{ic} / y_i` are equal within
/// `LEX_TOL · max(1, |min|)`. Why: exact zeros of B⁻¹ (the common tie) may carry round-off.
const LEX_TOL: f64 = 1e-11;

/// One step of iterative refinement of B⁻¹q̂ every this many pivots. Why: the explicit B⁻¹
/// updates accumulate round-off (≈ eps · cond(B) per pivot); on long runs with ill-conditioned
/// bases the drift in B⁻¹q̂ can exceed the small basic values that degenerate ratio decisions
/// hinge on. A refinement costs about one pivot (O(n·r)), so every 32 pivots it adds ~3 %.
const REFINE_EVERY: usize = 32;

/// How the pivoting ended.
pub(super) enum RunEnd {
    /// z0 left the basis: the z's basic at the end.
    Complementary,
    Ray,
    Limit,
    /// A non-finite value appeared in B⁻¹q or in an entering column.
    Breakdown,
}

impl Revised<'_> {
    /// Lexicographic minimum-ratio test over the rows with y_i > ptol. None: no blocking row.
    fn ratio_test(&mut self, ptol: f64) -> Option<usize> {
        let n = self.n;
        let (x, y) = (&self.x, &self.y);
        let mut best = f64::INFINITY;
        let mut found = false;
        let mut xmax = 0.0f64;
        for i in 0..n {
            xmax = xmax.max(x[i].abs());
            // `>` is false for NaN: a NaN entry never becomes a pivot (x, y are checked finite).
            if y[i] > ptol {
                // A slightly negative x_i is round-off of a degenerate zero.
                let t = x[i].max(0.0) / y[i];
                if t < best {
                    best = t;
                    found = true;
                }
            }
        }
        if !found {
            return None;
        }
        let tie_tol = TIE_TOL * xmax.max(1.0);
        self.ties.clear();
        for i in 0..n {
            if y[i] > ptol && x[i].max(0.0) - best * y[i] <= tie_tol {
                self.ties.push(i);
            }
        }
        if self.ties.is_empty() {
            // Unreachable with finite data (the minimiser ties with itself); stay NaN-safe.
            return None;
        }
        if self.ties.len() == 1 {
            return Some(self.ties[0]);
        }
        // Ties prefer the artificial variable: its leaving ends the run with a solution.
        if self.pos_z0 != NONE && self.ties.contains(&(self.pos_z0 as usize)) {
            return Some(self.pos_z0 as usize);
        }
        // Lexicographic tie-break on the rows of B⁻¹ / y_i, column by column.
        let mut ties = std::mem::take(&mut self.ties);
        for c in 0..n {
            if ties.len() <= 1 {
                break;
            }
            let mut vmin = f64::INFINITY;
            for &i in &ties {
                vmin = vmin.min(self.binv(i, c) / self.y[i]);
            }
            let tol = LEX_TOL * vmin.abs().max(1.0);
            let keep = |i: usize| self.binv(i, c) / self.y[i] - vmin <= tol;
            // NaN-safe: a comparison with NaN is false, so never let the list run empty.
            if ties.iter().any(|&i| keep(i)) {
                ties.retain(|&i| keep(i));
            }
        }
        // Exact arithmetic leaves one row (B⁻¹ is nonsingular); in floating point keep the
        // largest pivot among any survivors, the numerically safest.
        let mut r = ties[0];
        for &i in &ties {
            if self.y[i] > self.y[r] {
                r = i;
            }
        }
        self.ties = ties;
        Some(r)
    }

    pub(super) fn run(&mut self, ptol_rel: f64, limit: usize) -> (RunEnd, usize) {
        let n = self.n;
        // First pivot: z0 enters with column B⁻¹(−e) = −e; it leaves at the most negative q̂_i.
        // Lexicographic rule among equal minima: the largest index (then every other row of
        // [B⁻¹q, B⁻¹] stays lexicographically positive).
        let qmin = self.x.iter().fold(f64::INFINITY, |m, &v| m.min(v));
        let xmax = self.x.iter().fold(0.0f64, |m, &v| m.max(v.abs()));
        let tie_tol = TIE_TOL * xmax.max(1.0);
        let r0 = (0..n).rev().find(|&i| self.x[i] - qmin <= tie_tol).unwrap_or(0);
        self.y.fill(-1.0);
        let Some(leaving) = self.pivot(r0, 2 * n, false) else { return (RunEnd::Breakdown, 1) };
        let mut pivots = 1;
        let mut entering = n + leaving; // leaving = w_{r0}: z_{r0} enters.
        let mut column_ok = self.entering_column(entering);
        loop {
            if pivots >= limit {
                return (RunEnd::Limit, pivots);
            }
            if !column_ok {
                return (RunEnd::Breakdown, pivots);
            }
            let ymax = self.y.iter().fold(0.0f64, |m, &v| m.max(v.abs()));
            // Pivot threshold relative to the column's own size (the data are already scaled to
            // max|A| = max|q| = 1): entries below it are round-off of zeros, not pivots.
            let ptol = ptol_rel * ymax.max(1.0);
            let Some(r) = self.ratio_test(ptol) else { return (RunEnd::Ray, pivots) };
            // The complement of the leaving variable enters next; z0 leaving ends the run.
            let u = self.basic[r];
            let next = if u < n {
                Some(n + u)
            } else if u < 2 * n {
                Some(u - n)
            } else {
                None
            };
            let fuse = matches!(next, Some(v) if v >= n);
            if let Some(v) = next.filter(|_| fuse) {
                self.load_column(v - n);
            }
            if self.pivot(r, entering, fuse).is_none() {
                return (RunEnd::Breakdown, pivots + 1);
            }
            pivots += 1;
            let Some(next) = next else { return (RunEnd::Complementary, pivots) };
            if pivots % REFINE_EVERY == 0 && !self.refine_x() {
                return (RunEnd::Breakdown, pivots);
            }
            column_ok = if fuse {
                std::mem::swap(&mut self.y, &mut self.ynext);
                self.y.iter().all(|v| v.is_finite())
            } else {
                self.entering_column(next)
            };
            entering = next;
        }
    }
}
