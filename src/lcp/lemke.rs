//! Lexicographic Lemke's algorithm (complementary pivoting, covering vector e = 1), in revised form.
//!
//! Sources: C. E. Lemke, "Bimatrix equilibrium points and mathematical programming" (1965);
//! R. W. Cottle, J.-S. Pang, R. E. Stone, *The Linear Complementarity Problem* (1992), ch. 4
//! (Lemke's method, lexicographic degeneracy resolution); K. G. Murty, *Linear Complementarity,
//! Linear and Nonlinear Programming* (1988), ch. 2 (complementary pivot algorithm) and ch. 6
//! (its exponential worst case).
//!
//! # The algorithm
//! Augment the LCP with an artificial variable z0 ≥ 0 and the covering vector e = 1:
//! `w − A z − e z0 = q`. Start from the basis of all w (infeasible when some q_i < 0), let z0
//! enter and leave at the row of the most negative q_i: the basis becomes feasible and almost
//! complementary. Then repeatedly let the complement of the variable that just left enter, with
//! a ratio test choosing the leaving row, until z0 leaves (solution), no row blocks (ray
//! termination) or the pivot budget is spent. Degeneracy is resolved lexicographically: the
//! ratio test compares rows of `[B⁻¹q, B⁻¹] / y_i` lexicographically, which is the exact limit of
//! the perturbation `q + (ε, ε², …, εⁿ)` and guarantees termination (no cycling). When z0 is among
//! the rows tied at the minimum ratio it leaves: that ends the run with a solution at once.
//!
//! # Revised form
//! No n×2n tableau is stored. The basis matrix B has a column per position i = 0…n−1: e_i while
//! w_i is basic (w_i is always kept at its own position i), or the column of the non-w basic
//! variable (−A_{·j} for z_j, −e for z0) hosted at a position i whose w_i is non-basic. So B is
//! the identity with the columns in the set P of "hosting" positions replaced, and therefore
//! `B⁻¹ = [[B_PP⁻¹, 0], [−B_NP B_PP⁻¹, I]]` (P first) is also the identity except in the columns
//! P. Only those columns of B⁻¹ are stored (dense n-vectors in a slot arena, reused through a free
//! list). With r = |P|:
//! - entering column: `B⁻¹ d = d − Σ_{p∈P} d_p e_p + Σ_{p∈P} d_p g_p` (g_p: column p of B⁻¹), O(n·r);
//!   columns of A come from [`LcpMatrix::column_into`] (O(n) for a block-circulant A);
//! - pivot on row r with entering column y: every stored column g gets
//!   `g ← g − (g_r / y_r)(y − e_r)`, O(n·r); the trivial columns e_i (i ∉ P, i ≠ r) are unchanged;
//! - when w_j enters at a row r ≠ j, the variable hosted at position j moves to position r
//!   (a swap of rows r and j of B⁻¹ and of B⁻¹q, O(r)); column j of B⁻¹ is then exactly e_j and
//!   its slot is freed.
//!
//! Rows of B⁻¹, needed only by the lexicographic tie-break (rare), are read entry by entry.
//! Every 32 pivots B⁻¹q̂ gets one step of iterative refinement against the original columns
//! (`x += B⁻¹(q̂ − B x)`, O(n·r)), which keeps round-off drift out of the ratio decisions.
//!
//! # Final answer
//! The pivots only identify the final complementary basis: the set α of basic z's. The answer is
//! recomputed from the original (unscaled) data as `A_αα z_α = −q_α` by LU with partial pivoting
//! (faer) plus iterative refinement, `w = A z + q`, and certified by the residual
//! `‖min(z, w)‖∞ ≤ certify_tol · max(1, ‖q‖∞)` on the original data. If it does not certify,
//! the basis is polished by safeguarded principal pivoting (see `refine.rs`): the round-off of
//! thousands of explicit B⁻¹ updates can leave it off by a few near-degenerate indices.
use std::time::Instant;

use super::refine::{Candidate, evaluate, polish, solve_principal};
use super::{LcpInfo, LcpMatrix, LcpOutcome, LcpSolution};

/// Settings with defaults; see [`LemkeSettings::default`].
#[derive(Clone, Debug)]
pub struct LemkeSettings {
    /// Pivot tolerance relative to max|A|, max|q|.
    pub pivot_tol: f64,
    /// The pivot limit is `max_pivots_per_dim · n + 100`.
    pub max_pivots_per_dim: usize,
    /// Steps of iterative refinement of the final basis solve.
    pub refinement_steps: usize,
    /// Certification: solved iff ‖min(z, w)‖∞ ≤ certify_tol · max(1, ‖q‖∞).
    pub certify_tol: f64,
    /// Optional warm start: indices expected to have z > 0.
    pub warm_start: Option<Vec<usize>>,
}

impl Default for LemkeSettings {
    fn default() -> Self {
        LemkeSettings { pivot_tol: 1e-12, max_pivots_per_dim: 20, refinement_steps: 3, certify_tol: 1e-9, warm_start: None }
    }
}

/// Rows whose value after the pivot would be within `TIE_TOL · max(1, ‖B⁻¹q‖∞)` of zero tie at
/// the minimum ratio. Why: the data are scaled to max|A| = max|q| = 1, so B⁻¹q carries round-off
/// of a few ulps times the growth of B⁻¹; an exact (degenerate) tie must not be missed because of
/// it, while distinct ratios in real problems differ by far more.
const TIE_TOL: f64 = 1e-11;

/// Two entries of the lexicographic comparison `(B⁻¹)_{ic} / y_i` are equal within
/// `LEX_TOL · max(1, |min|)`. Why: exact zeros of B⁻¹ (the common tie) may carry round-off.
const LEX_TOL: f64 = 1e-11;

/// Rounds of the final-basis polish (each one an LU of A_αα). Why: it is meant to repair a basis
/// off by a few indices, not to solve the LCP; a cap keeps its cost bounded.
const POLISH_ROUNDS: usize = 8;

/// One step of iterative refinement of B⁻¹q̂ every this many pivots. Why: the explicit B⁻¹
/// updates accumulate round-off (≈ eps · cond(B) per pivot); on long runs with ill-conditioned
/// bases the drift in B⁻¹q̂ can exceed the small basic values that degenerate ratio decisions
/// hinge on. A refinement costs about one pivot (O(n·r)), so every 32 pivots it adds ~3 %.
const REFINE_EVERY: usize = 32;

const NONE: u32 = u32::MAX;

pub struct Lemke {
    pub settings: LemkeSettings,
}

/// How the pivoting ended.
enum RunEnd {
    /// z0 left the basis: the z's basic at the end.
    Complementary,
    Ray,
    Limit,
    /// A non-finite value appeared in B⁻¹q or in an entering column.
    Breakdown,
}

/// The revised-form state of Lemke's method on the scaled data Â = A / s_A, q̂ = q / s_q.
///
/// Variables are numbered w_i = i, z_j = n + j, z0 = 2n.
struct Revised<'a> {
    a: &'a dyn LcpMatrix,
    n: usize,
    /// −1 / s_A: an entering z_j has the column −Â_{·j}.
    neg_inv_sa: f64,
    /// Slot arena of the non-trivial columns of B⁻¹.
    slots: Vec<Vec<f64>>,
    free: Vec<u32>,
    /// slot of the column of B⁻¹ at each position, NONE when it is e_i.
    slot_of_pos: Vec<u32>,
    /// The positions with a stored column (the set P), and each one's index in this list.
    plist: Vec<u32>,
    pidx: Vec<u32>,
    /// Basic variable at each position.
    basic: Vec<usize>,
    /// Position of z_j (NONE when non-basic) and of z0.
    pos_z: Vec<u32>,
    pos_z0: u32,
    /// Values of the basic variables, B⁻¹ q̂, by position.
    x: Vec<f64>,
    /// Entering column B⁻¹ d, the next one (see [`Revised::pivot`]), and the raw column d.
    y: Vec<f64>,
    ynext: Vec<f64>,
    d: Vec<f64>,
    ties: Vec<usize>,
    /// q̂, kept for the iterative refinement of x.
    qhat: Vec<f64>,
    /// Work vector of the refinement.
    r: Vec<f64>,
}

impl<'a> Revised<'a> {
    fn new(a: &'a dyn LcpMatrix, qhat: Vec<f64>, sa: f64) -> Self {
        let n = a.dim();
        Revised {
            a,
            n,
            neg_inv_sa: -1.0 / sa,
            slots: Vec::new(),
            free: Vec::new(),
            slot_of_pos: vec![NONE; n],
            plist: Vec::with_capacity(n),
            pidx: vec![NONE; n],
            basic: (0..n).collect(),
            pos_z: vec![NONE; n],
            pos_z0: NONE,
            x: qhat.clone(),
            qhat,
            r: vec![0.0; n],
            y: vec![0.0; n],
            ynext: vec![0.0; n],
            d: vec![0.0; n],
            ties: Vec::with_capacity(n),
        }
    }

    /// Makes position r a stored column, equal to e_r.
    fn add_column(&mut self, r: usize) {
        let n = self.n;
        let s = match self.free.pop() {
            Some(s) => {
                self.slots[s as usize].fill(0.0);
                s
            }
            None => {
                // Allocated at most once per slot over the whole run (slots are reused), so the
                // total is O(n · max r), negligible next to the O(n · r) cost of every pivot.
                self.slots.push(vec![0.0; n]);
                (self.slots.len() - 1) as u32
            }
        };
        self.slots[s as usize][r] = 1.0;
        self.slot_of_pos[r] = s;
        self.pidx[r] = self.plist.len() as u32;
        self.plist.push(r as u32);
    }

    /// Position j's column of B⁻¹ is e_j again: frees its slot.
    fn remove_column(&mut self, j: usize) {
        let s = self.slot_of_pos[j];
        debug_assert!(s != NONE);
        self.free.push(s);
        self.slot_of_pos[j] = NONE;
        let k = self.pidx[j] as usize;
        self.plist.swap_remove(k);
        if k < self.plist.len() {
            let moved = self.plist[k] as usize;
            self.pidx[moved] = k as u32;
        }
        self.pidx[j] = NONE;
    }

    /// Entry (i, c) of B⁻¹.
    #[inline]
    fn binv(&self, i: usize, c: usize) -> f64 {
        let s = self.slot_of_pos[c];
        if s != NONE {
            self.slots[s as usize][i]
        } else if i == c {
            1.0
        } else {
            0.0
        }
    }

    /// y = B⁻¹ d for the entering variable v (z_j or w_j; z0 enters only at the start).
    /// Returns false if the column is not finite.
    fn entering_column(&mut self, v: usize) -> bool {
        let n = self.n;
        if v < n {
            // d = e_j: y is column j of B⁻¹ (j ∈ P because w_j is non-basic).
            let s = self.slot_of_pos[v];
            debug_assert!(s != NONE);
            self.y.copy_from_slice(&self.slots[s as usize]);
        } else {
            self.load_column(v - n);
            self.y.copy_from_slice(&self.d);
            for &p in &self.plist {
                self.y[p as usize] = 0.0;
            }
            for &p in &self.plist {
                let dp = self.d[p as usize];
                if dp != 0.0 {
                    axpy(&mut self.y, dp, &self.slots[self.slot_of_pos[p as usize] as usize]);
                }
            }
        }
        self.y.iter().all(|v| v.is_finite())
    }

    /// One step of iterative refinement of x = B⁻¹q̂: x += B⁻¹(q̂ − B x), with B x formed from the
    /// original columns. O(n·r). Returns false if x became non-finite.
    fn refine_x(&mut self) -> bool {
        let n = self.n;
        self.r.copy_from_slice(&self.qhat);
        for i in 0..n {
            if self.slot_of_pos[i] == NONE {
                // w_i basic at position i: B column e_i.
                self.r[i] -= self.x[i];
            }
        }
        for k in 0..self.plist.len() {
            let p = self.plist[k] as usize;
            let v = self.basic[p];
            let xp = self.x[p];
            if v >= 2 * n {
                // z0: B column −e.
                self.r.iter_mut().for_each(|ri| *ri += xp);
            } else if v >= n {
                // z_j: B column −Â_{·j}.
                self.a.column_into(v - n, &mut self.d);
                axpy(&mut self.r, -xp * self.neg_inv_sa, &self.d);
            } else {
                // w_j is never hosted at a position of P.
                debug_assert!(false);
            }
        }
        // x += B⁻¹ r = r − Σ_p r_p e_p + Σ_p r_p g_p
        for i in 0..n {
            if self.slot_of_pos[i] == NONE {
                self.x[i] += self.r[i];
            }
        }
        for &p in &self.plist {
            let rp = self.r[p as usize];
            if rp != 0.0 {
                axpy(&mut self.x, rp, &self.slots[self.slot_of_pos[p as usize] as usize]);
            }
        }
        self.x.iter().all(|v| v.is_finite())
    }

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

    /// d = −Â_{·j}: the raw column of an entering z_j.
    fn load_column(&mut self, j: usize) {
        self.a.column_into(j, &mut self.d);
        let f = self.neg_inv_sa;
        self.d.iter_mut().for_each(|v| *v *= f);
    }

    /// Pivot: v enters at row r (with its column B⁻¹d in self.y); returns the leaving variable,
    /// or None if B⁻¹q became non-finite.
    ///
    /// With `fuse`, self.d holds the raw column d' of the variable that enters next, and the new
    /// B⁻¹d' is accumulated into self.ynext column by column, right after each column's update,
    /// while it is still in cache: B⁻¹ is streamed from memory once per pivot instead of twice.
    fn pivot(&mut self, r: usize, v: usize, fuse: bool) -> Option<usize> {
        let n = self.n;
        let piv = self.y[r];
        if self.slot_of_pos[r] == NONE {
            // w_r leaves: position r starts hosting a non-w variable.
            self.add_column(r);
        }
        // w_j entering: rows r and j of B⁻¹ are swapped afterwards and column j becomes e_j.
        let drop = if v < n { v } else { usize::MAX };
        let swap = v < n && v != r;
        let Revised { slots, plist, slot_of_pos, y, ynext, d, .. } = self;
        if fuse {
            // B⁻¹_new d' = d' − Σ_{p∈P_new} d'_p e_p + Σ_{p∈P_new} d'_p g_p, P_new = P \ {drop}.
            ynext.copy_from_slice(d);
            for &p in plist.iter() {
                if p as usize != drop {
                    ynext[p as usize] = 0.0;
                }
            }
        }
        for &p in plist.iter() {
            let col = &mut slots[slot_of_pos[p as usize] as usize];
            let f = col[r] / piv;
            if f != 0.0 {
                axpy(col, -f, y);
            }
            col[r] = f;
            if swap {
                col.swap(r, drop);
            }
            if fuse && p as usize != drop {
                let dp = d[p as usize];
                if dp != 0.0 {
                    axpy(ynext, dp, col);
                }
            }
        }
        let f = self.x[r] / piv;
        if f != 0.0 {
            axpy(&mut self.x, -f, &self.y);
        }
        self.x[r] = f;

        let u = self.basic[r];
        if u >= 2 * n {
            self.pos_z0 = NONE;
        } else if u >= n {
            self.pos_z[u - n] = NONE;
        }
        self.basic[r] = v;
        if v < n {
            // w_j enters: it belongs at position j; the variable hosted there moves to r.
            let j = v;
            if j != r {
                self.x.swap(r, j);
                self.basic.swap(r, j);
                let moved = self.basic[r];
                if moved < 2 * n {
                    self.pos_z[moved - n] = r as u32;
                } else {
                    self.pos_z0 = r as u32;
                }
            }
            // Column j of B⁻¹ is now e_j.
            self.remove_column(j);
        } else if v < 2 * n {
            self.pos_z[v - n] = r as u32;
        } else {
            self.pos_z0 = r as u32;
        }
        if self.x.iter().all(|v| v.is_finite()) { Some(u) } else { None }
    }

    /// Runs Lemke's method; returns how it ended and the number of pivots.
    fn run(&mut self, ptol_rel: f64, limit: usize) -> (RunEnd, usize) {
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

    /// The current z (scaled back to the original units: z = ẑ · s_q / s_A), zero where non-basic.
    fn current_z(&self, zscale: f64) -> Vec<f64> {
        let mut z = vec![0.0; self.n];
        for (j, &p) in self.pos_z.iter().enumerate() {
            if p != NONE {
                z[j] = self.x[p as usize] * zscale;
            }
        }
        z
    }

    /// The set α of basic z's, increasing.
    fn basic_z(&self) -> Vec<usize> {
        (0..self.n).filter(|&j| self.pos_z[j] != NONE).collect()
    }
}

#[inline]
fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, &xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

impl Lemke {
    pub fn new(settings: LemkeSettings) -> Self {
        Lemke { settings }
    }

    /// Solves w = A z + q, z ≥ 0, w ≥ 0, zᵀw = 0. See the module documentation.
    ///
    /// Panics if `q.len() != a.dim()` (a programming error).
    pub fn solve(&self, a: &dyn LcpMatrix, q: &[f64]) -> LcpSolution {
        let start = Instant::now();
        let n = a.dim();
        assert_eq!(q.len(), n, "Lemke::solve: q has {} entries for a {n}×{n} matrix", q.len());
        let s = &self.settings;
        let done = |outcome, c: Candidate, pivots, warm| LcpSolution {
            outcome,
            z: c.z,
            w: c.w,
            info: LcpInfo { pivots, residual: c.residual, relative_error: c.relative_error, time_s: start.elapsed().as_secs_f64(), warm_start_used: warm },
        };

        let (amax, a_finite) = a.max_abs();
        if !a_finite || !amax.is_finite() || !q.iter().all(|v| v.is_finite()) {
            return done(LcpOutcome::NonFiniteData, Candidate::zeros(n), 0, false);
        }
        let qmax = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // The certification threshold, and the clipping threshold for round-off negatives.
        let cert = s.certify_tol * qmax.max(1.0);
        let certified = |c: &Candidate| c.residual <= cert;

        // q ≥ 0: z = 0, w = q is a solution (no pivot).
        if q.iter().all(|&v| v >= 0.0) {
            let c = Candidate { z: vec![0.0; n], w: q.to_vec(), residual: 0.0, relative_error: 0.0 };
            return done(LcpOutcome::Solved, c, 0, false);
        }

        // Warm start: the guessed active set α, accepted only if its solution certifies.
        if let Some(active) = &s.warm_start {
            let mut alpha: Vec<usize> = active.clone();
            alpha.sort_unstable();
            alpha.dedup();
            if alpha.iter().all(|&i| i < n) {
                if let Some(z) = solve_principal(a, q, &alpha, s.refinement_steps) {
                    let c = evaluate(a, q, z, cert);
                    if certified(&c) {
                        return done(LcpOutcome::Solved, c, 0, true);
                    }
                }
            }
        }

        // Cold run on the scaled data Â = A / s_A, q̂ = q / s_q (so that the absolute pivot and tie
        // tolerances are relative to max|A| and max|q|); then ẑ = z · s_A / s_q.
        let sa = if amax > 0.0 { amax } else { 1.0 };
        let sq = qmax; // > 0 here since some q_i < 0
        let qhat: Vec<f64> = q.iter().map(|v| v / sq).collect();
        let mut rev = Revised::new(a, qhat, sa);
        let limit = s.max_pivots_per_dim.saturating_mul(n).saturating_add(100);
        let (end, pivots) = rev.run(s.pivot_tol, limit);
        let tableau_z = rev.current_z(sq / sa);
        let alpha = rev.basic_z();
        drop(rev);

        match end {
            RunEnd::Complementary => {
                // Re-solve the final basis on the original data. If that does not certify, the
                // basis may be off by a few near-degenerate indices: polish it. The tableau values
                // are the last resort (they only matter if the re-solve breaks down).
                let resolved = solve_principal(a, q, &alpha, s.refinement_steps).map(|z| evaluate(a, q, z, cert));
                let best = match resolved {
                    Some(c) if certified(&c) => c,
                    other => {
                        let polished = other.as_ref().and_then(|c| polish(a, q, &alpha, c, s.refinement_steps, cert, POLISH_ROUNDS));
                        match polished {
                            Some(c) => c,
                            None => {
                                let t = evaluate(a, q, tableau_z, cert);
                                match other {
                                    Some(c) if c.residual <= t.residual => c,
                                    _ => t,
                                }
                            }
                        }
                    }
                };
                let outcome = if certified(&best) { LcpOutcome::Solved } else { LcpOutcome::Inaccurate };
                done(outcome, best, pivots, false)
            }
            RunEnd::Ray => done(LcpOutcome::RayTermination, evaluate(a, q, tableau_z, cert), pivots, false),
            RunEnd::Limit => done(LcpOutcome::PivotLimit, evaluate(a, q, tableau_z, cert), pivots, false),
            RunEnd::Breakdown => {
                let tz: Vec<f64> = if tableau_z.iter().all(|v| v.is_finite()) { tableau_z } else { vec![0.0; n] };
                done(LcpOutcome::Inaccurate, evaluate(a, q, tz, cert), pivots, false)
            }
        }
    }
}
