//! The revised-form basis of Lemke's method: the stored columns of B⁻¹ and their updates.
//!
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
use crate::lcp::LcpMatrix;

/// "No position / no slot".
pub(super) const NONE: u32 = u32::MAX;

/// The revised-form state of Lemke's method on the scaled data Â = A / s_A, q̂ = q / s_q.
///
/// Variables are numbered w_i = i, z_j = n + j, z0 = 2n.
pub(super) struct Revised<'a> {
    pub(super) a: &'a dyn LcpMatrix,
    pub(super) n: usize,
    /// −1 / s_A: an entering z_j has the column −Â_{·j}.
    pub(super) neg_inv_sa: f64,
    /// Slot arena of the non-trivial columns of B⁻¹.
    pub(super) slots: Vec<Vec<f64>>,
    pub(super) free: Vec<u32>,
    /// slot of the column of B⁻¹ at each position, NONE when it is e_i.
    pub(super) slot_of_pos: Vec<u32>,
    /// The positions with a stored column (the set P), and each one's index in this list.
    pub(super) plist: Vec<u32>,
    pub(super) pidx: Vec<u32>,
    /// Basic variable at each position.
    pub(super) basic: Vec<usize>,
    /// Position of z_j (NONE when non-basic) and of z0.
    pub(super) pos_z: Vec<u32>,
    pub(super) pos_z0: u32,
    /// Values of the basic variables, B⁻¹ q̂, by position.
    pub(super) x: Vec<f64>,
    /// Entering column B⁻¹ d, the next one (see [`Revised::pivot`]), and the raw column d.
    pub(super) y: Vec<f64>,
    pub(super) ynext: Vec<f64>,
    pub(super) d: Vec<f64>,
    pub(super) ties: Vec<usize>,
    /// q̂, kept for the iterative refinement of x.
    pub(super) qhat: Vec<f64>,
    /// Work vector of the refinement.
    pub(super) r: Vec<f64>,
}

impl<'a> Revised<'a> {
    pub(super) fn new(a: &'a dyn LcpMatrix, qhat: Vec<f64>, sa: f64) -> Self {
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
    pub(super) fn add_column(&mut self, r: usize) {
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
    pub(super) fn remove_column(&mut self, j: usize) {
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
    pub(super) fn binv(&self, i: usize, c: usize) -> f64 {
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
    pub(super) fn entering_column(&mut self, v: usize) -> bool {
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
    pub(super) fn refine_x(&mut self) -> bool {
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
    /// d = −Â_{·j}: the raw column of an entering z_j.
    pub(super) fn load_column(&mut self, j: usize) {
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
    pub(super) fn pivot(&mut self, r: usize, v: usize, fuse: bool) -> Option<usize> {
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
    /// The current z (scaled back to the original units: z = ẑ · s_q / s_A), zero where non-basic.
    pub(super) fn current_z(&self, zscale: f64) -> Vec<f64> {
        let mut z = vec![0.0; self.n];
        for (j, &p) in self.pos_z.iter().enumerate() {
            if p != NONE {
                z[j] = self.x[p as usize] * zscale;
            }
        }
        z
    }

    /// The set α of basic z's, increasing.
    pub(super) fn basic_z(&self) -> Vec<usize> {
        (0..self.n).filter(|&j| self.pos_z[j] != NONE).collect()
    }
}

#[inline]
fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, &xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}
