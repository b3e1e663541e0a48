//! A periodic LCP given as a time-stepping map, and one march over its period.
//!
//! The data say nothing of mechanics: a state s ∈ ℝᵈ, k steps, m complementarity pairs per step.
//! Step j (0 ≤ j < k) from state s_j:
//!
//! ```text
//! y_j     = Φ s_j + c_j                      (the step without contact: the predictor)
//! w_j     = r_j + H y_j + S z_j,  S = HΓ + D  (0 ≤ z_j ⊥ w_j ≥ 0, an m×m LCP)
//! s_{j+1} = y_j + Γ z_j
//! ```
//!
//! and the period closes, s_k = s_0. Stacking z_j (index j·m + c) gives an LCP of size k·m whose
//! matrix is dense; here it is the fixed point of the piecewise-affine period map P(s_0) = s_k,
//! which costs O(k·(d² + m³)) to evaluate. Each step's LCP has a unique answer when S is a
//! P-matrix ([`StepMapLcp::new`] checks it), so P is well defined and continuous.
use faer::Mat;

/// Most pairs per step: the step LCP is solved by Murty's least-index principal pivoting over
/// active sets held as bit masks, and S's P-property is checked on all 2^m principal minors.
pub const MAX_PAIRS: usize = 10;

/// The data of a step map (see the module documentation), row-major.
#[derive(Clone, Debug, Default)]
pub struct StepMapData {
    /// Steps per period, state size, pairs per step.
    pub k: usize,
    pub d: usize,
    pub m: usize,
    /// Φ without its unit entries (d×d).
    pub phi: Vec<f64>,
    /// The unit entries of Φ as (row, column): y[row] += s[column], added exactly after the dense
    /// product. Why: a state of differences (x, ∇x, …) advances as x_(j+1) = x_j + ∇x_(j+1); a
    /// dense row 1 + O(h²) would round the O(h²) part to ε/h² relative, and a state of raw samples
    /// loses k²·ε over a period to the cancellation in 2x_j − x_(j−1).
    pub carry: Vec<(usize, usize)>,
    /// c_j, k×d.
    pub c: Vec<f64>,
    /// H, m×d.
    pub h: Vec<f64>,
    /// Γ, d×m.
    pub gamma: Vec<f64>,
    /// D: the m×m block added to HΓ, row-major (compliances on its diagonal, and a model's
    /// static flexibility between contacts, e.g. of condensed massless DOFs).
    pub flexibility: Vec<f64>,
    /// r_j, k×m.
    pub r: Vec<f64>,
}

/// A periodic LCP as a step map (see the module documentation), checked.
#[derive(Clone, Debug)]
pub struct StepMapLcp {
    pub(super) k: usize,
    pub(super) d: usize,
    pub(super) m: usize,
    /// Φ without its unit entries (d×d).
    pub(super) phi: Mat<f64>,
    /// The unit entries of Φ, (row, column).
    pub(super) carry: Vec<(usize, usize)>,
    /// c_j, k×d.
    pub(super) c: Vec<f64>,
    /// H, m×d.
    pub(super) h: Vec<f64>,
    /// Γ, d×m.
    pub(super) gamma: Vec<f64>,
    /// S = HΓ + D, m×m.
    pub(super) s: Vec<f64>,
    /// r_j, k×m.
    pub(super) r: Vec<f64>,
}

/// Why a step map was not accepted (the caller then solves the LCP another way).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StepMapError {
    #[error("{0}: sizes do not match k = {1}, d = {2}, m = {3}")]
    Size(&'static str, usize, usize, usize),
    #[error("{0} pairs per step; the step-map solver takes at most {MAX_PAIRS}")]
    TooManyPairs(usize),
    #[error("the step matrix S = HΓ + D is not a P-matrix (principal minor of rows {0:?} is {1:e}): a step's LCP may have no or several answers")]
    NotP(Vec<usize>, f64),
    #[error("the step map holds NaN or infinite values")]
    NonFinite,
}

impl StepMapLcp {
    /// Checks sizes, finiteness and that S = HΓ + D is a P-matrix.
    pub fn new(data: StepMapData) -> Result<Self, StepMapError> {
        let StepMapData { k, d, m, phi, carry, c, h, gamma, flexibility, r } = data;
        let size = |what, ok: bool| if ok { Ok(()) } else { Err(StepMapError::Size(what, k, d, m)) };
        size("phi", phi.len() == d * d)?;
        size("carry", carry.iter().all(|&(i, j)| i < d && j < d))?;
        size("c", c.len() == k * d)?;
        size("h", h.len() == m * d)?;
        size("gamma", gamma.len() == d * m)?;
        size("flexibility", flexibility.len() == m * m)?;
        size("r", r.len() == k * m)?;
        if m > MAX_PAIRS {
            return Err(StepMapError::TooManyPairs(m));
        }
        if !phi.iter().chain(&c).chain(&h).chain(&gamma).chain(&flexibility).chain(&r).all(|v| v.is_finite()) {
            return Err(StepMapError::NonFinite);
        }
        let mut s = vec![0.0; m * m];
        for a in 0..m {
            for b in 0..m {
                s[a * m + b] = (0..d).map(|i| h[a * d + i] * gamma[i * m + b]).sum::<f64>() + flexibility[a * m + b];
            }
        }
        check_p_matrix(&s, m)?;
        let phi = Mat::from_fn(d, d, |i, j| phi[i * d + j]);
        Ok(StepMapLcp { k, d, m, phi, carry, c, h, gamma, s, r })
    }

    /// One march over the period from `s0` with every step's LCP solved (its active set tried
    /// first from `guess`, per step): (s_k, the active set of each step, z stacked j·m + c).
    /// `None` when a step breaks down. For analyses of the orbit (continuation, stability).
    pub fn march_period(&self, s0: &[f64], guess: Option<&[u32]>) -> Option<(Vec<f64>, Vec<u32>, Vec<f64>)> {
        let m = march(self, s0, 0.0, Contacts::Solve(guess.unwrap_or(&[])))?;
        Some((m.end, m.masks, m.z))
    }

    /// One march with each step's active set imposed (w_a = 0, z_a free in sign): the affine
    /// piece of P these sets belong to, so that its fixed point is (I − dP/ds0)⁻¹ P(0). `None`
    /// when the sets do not fit k or a step's block is singular. For continuation.
    pub fn march_frozen(&self, s0: &[f64], masks: &[u32]) -> Option<Vec<f64>> {
        if masks.len() != self.k || s0.len() != self.d {
            return None;
        }
        march(self, s0, 0.0, Contacts::Frozen(masks)).map(|m| m.end)
    }

    /// [dP/ds0 | dP/dδ] (d×(d+1), δ a uniform offset of every pair's r_j) on the piece of these
    /// active sets; at a closed orbit dP/ds0 is the discrete monodromy matrix, whose eigenvalues
    /// are the orbit's Floquet multipliers as k grows (src/formulation.md §7).
    pub fn period_jacobian(&self, masks: &[u32]) -> Mat<f64> {
        let mut j = Mat::zeros(self.d, self.d + 1);
        period_jacobian(self, masks, &PhiPowers::new(self), &mut j);
        j
    }

    /// Φ with its unit entries, dense (for the Jacobian's powers).
    fn phi_full(&self) -> Mat<f64> {
        let mut p = self.phi.clone();
        for &(i, j) in &self.carry {
            p[(i, j)] += 1.0;
        }
        p
    }

    pub fn k(&self) -> usize {
        self.k
    }
    pub fn state_size(&self) -> usize {
        self.d
    }
    pub fn pairs(&self) -> usize {
        self.m
    }
    /// The step matrix S (m×m, row-major).
    pub fn step_matrix(&self) -> &[f64] {
        &self.s
    }
}

/// Every principal minor of S positive (2^m − 1 determinants of at most MAX_PAIRS rows).
fn check_p_matrix(s: &[f64], m: usize) -> Result<(), StepMapError> {
    let scale = s.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for mask in 1u32..(1 << m) {
        let rows: Vec<usize> = (0..m).filter(|i| mask >> i & 1 == 1).collect();
        let det = determinant(&rows.iter().flat_map(|&a| rows.iter().map(move |&b| s[a * m + b])).collect::<Vec<_>>(), rows.len());
        // A minor at round-off of the entries' scale counts as zero: not a P-matrix.
        if !(det > 1e-13 * scale.powi(rows.len() as i32)) {
            return Err(StepMapError::NotP(rows, det));
        }
    }
    Ok(())
}

/// Gaussian elimination with partial pivoting of the n×n `a` (row-major), applied to `b` too and
/// finished by back substitution (b becomes a⁻¹b); returns det(a), 0 when a pivot is exactly 0.
fn eliminate(a: &mut [f64], b: &mut [f64], n: usize) -> f64 {
    let mut det = 1.0;
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs())).unwrap_or(col);
        if !(a[piv * n + col].abs() > 0.0) {
            return 0.0;
        }
        if piv != col {
            for j in 0..n {
                a.swap(piv * n + j, col * n + j);
            }
            b.swap(piv, col);
            det = -det;
        }
        det *= a[col * n + col];
        for i in col + 1..n {
            let f = a[i * n + col] / a[col * n + col];
            for j in col..n {
                a[i * n + j] -= f * a[col * n + j];
            }
            b[i] -= f * b[col];
        }
    }
    for i in (0..n).rev() {
        let t: f64 = (i + 1..n).map(|j| a[i * n + j] * b[j]).sum();
        b[i] = (b[i] - t) / a[i * n + i];
    }
    det
}

/// Determinant of the n×n `a` (n ≤ MAX_PAIRS).
fn determinant(a: &[f64], n: usize) -> f64 {
    eliminate(&mut a.to_vec(), &mut [0.0; MAX_PAIRS][..n], n)
}

/// Solves S_aa z_a = −r_a for the active set `mask` into `z` (zero off the set); false when the
/// principal block is singular to working precision.
fn solve_active(s: &[f64], m: usize, r: &[f64], mask: u32, z: &mut [f64]) -> bool {
    z.iter_mut().for_each(|v| *v = 0.0);
    // The active pairs on the stack: this runs at every step of every march (no allocation).
    let mut members = [0usize; MAX_PAIRS];
    let mut p = 0;
    for i in (0..m).filter(|&i| mask >> i & 1 == 1) {
        members[p] = i;
        p += 1;
    }
    let act = &members[..p];
    if p == 0 {
        return true;
    }
    let mut a = [0.0; MAX_PAIRS * MAX_PAIRS];
    let mut b = [0.0; MAX_PAIRS];
    for (i, &ai) in act.iter().enumerate() {
        b[i] = -r[ai];
        for (j, &aj) in act.iter().enumerate() {
            a[i * p + j] = s[ai * m + aj];
        }
    }
    if eliminate(&mut a[..p * p], &mut b[..p], p) == 0.0 {
        return false;
    }
    for (i, &ai) in act.iter().enumerate() {
        z[ai] = b[i];
    }
    z.iter().all(|v| v.is_finite())
}

/// The answer of one step's LCP w = S z + r: tries `guess` first (the same step's set at the
/// previous march, usually right), then Murty's least-index principal pivoting, finite for a
/// P-matrix (Murty 1974). Returns the active set, z and the number of set changes.
pub(super) fn step_lcp(s: &[f64], m: usize, r: &[f64], guess: u32, z: &mut [f64], w: &mut [f64]) -> Option<(u32, usize)> {
    // Round-off of a zero: a sign within this of zero counts as zero.
    let tol = 1e-14 * r.iter().fold(f64::MIN_POSITIVE, |a, v| a.max(v.abs()));
    let complementary = |mask: u32, z: &mut [f64], w: &mut [f64]| -> Option<Option<usize>> {
        if !solve_active(s, m, r, mask, z) {
            return None;
        }
        for i in 0..m {
            w[i] = r[i] + (0..m).map(|j| s[i * m + j] * z[j]).sum::<f64>();
        }
        Some((0..m).find(|&i| if mask >> i & 1 == 1 { z[i] < -tol } else { w[i] < -tol }))
    };
    let finish = |mask: u32, z: &mut [f64], w: &mut [f64]| {
        for i in 0..m {
            if mask >> i & 1 == 1 {
                z[i] = z[i].max(0.0);
                w[i] = 0.0;
            } else {
                w[i] = w[i].max(0.0);
            }
        }
    };
    if let Some(None) = complementary(guess, z, w) {
        finish(guess, z, w);
        return Some((guess, 0));
    }
    let mut mask = 0u32;
    for changes in 1..=(1usize << m) + 1 {
        match complementary(mask, z, w)? {
            None => {
                finish(mask, z, w);
                return Some((mask, changes));
            }
            Some(i) => mask ^= 1 << i,
        }
    }
    None
}

/// Rows `mask` of H J (|a|×d) or of H (J = None).
fn active_rows(sm: &StepMapLcp, mask: u32) -> Vec<usize> {
    (0..sm.m).filter(|i| mask >> i & 1 == 1).collect()
}

/// What one march over the period gives.
pub(super) struct March {
    /// s_k = P(s_0).
    pub end: Vec<f64>,
    /// z_j, k×m.
    pub z: Vec<f64>,
    /// The active set of each step.
    pub masks: Vec<u32>,
    /// Step-LCP set changes summed over the period (the march's "pivots").
    pub changes: usize,
    /// The smallest w over the period (negative: a pair violated, only in a free march).
    pub min_w: f64,
}

/// How a march treats the contacts.
#[derive(Clone, Copy)]
pub(super) enum Contacts<'a> {
    /// z = 0 throughout (the contact-free orbit).
    Free,
    /// Each step's LCP solved, starting from these sets (per step).
    Solve(&'a [u32]),
    /// The active set of each step imposed (w_a = 0, z_a free in sign): an affine map.
    Frozen(&'a [u32]),
}

/// a·b by plain loops. Why not faer's product: its gemm kernels keep thread-local packing buffers
/// that an FMU unloaded by `dlclose` can never free (valgrind: definitely lost), and at d ≤ 128
/// the loops cost well under the march.
pub fn product(a: &Mat<f64>, b: &Mat<f64>) -> Mat<f64> {
    let (n, inner, m) = (a.nrows(), a.ncols(), b.ncols());
    let mut c = Mat::<f64>::zeros(n, m);
    for j in 0..m {
        for l in 0..inner {
            let blj = b[(l, j)];
            if blj != 0.0 {
                for i in 0..n {
                    c[(i, j)] += a[(i, l)] * blj;
                }
            }
        }
    }
    c
}

/// LU with partial pivoting of a small dense matrix, by plain loops (see [`product`] for why
/// not faer's). A zero pivot is kept: the solutions are then not finite, which callers check.
pub struct DenseLu {
    n: usize,
    lu: Vec<f64>,
    perm: Vec<usize>,
}

impl DenseLu {
    pub fn new(a: &Mat<f64>) -> DenseLu {
        let n = a.nrows();
        let mut lu: Vec<f64> = (0..n * n).map(|e| a[(e / n, e % n)]).collect();
        let mut perm: Vec<usize> = (0..n).collect();
        for col in 0..n {
            let piv = (col..n).max_by(|&i, &j| lu[i * n + col].abs().total_cmp(&lu[j * n + col].abs())).unwrap_or(col);
            if piv != col {
                for j in 0..n {
                    lu.swap(piv * n + j, col * n + j);
                }
                perm.swap(piv, col);
            }
            let p = lu[col * n + col];
            for i in col + 1..n {
                let f = lu[i * n + col] / p;
                lu[i * n + col] = f;
                for j in col + 1..n {
                    lu[i * n + j] -= f * lu[col * n + j];
                }
            }
        }
        DenseLu { n, lu, perm }
    }

    /// a⁻¹ b.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut x: Vec<f64> = self.perm.iter().map(|&i| b[i]).collect();
        for i in 0..n {
            let t: f64 = (0..i).map(|j| self.lu[i * n + j] * x[j]).sum();
            x[i] -= t;
        }
        for i in (0..n).rev() {
            let t: f64 = (i + 1..n).map(|j| self.lu[i * n + j] * x[j]).sum();
            x[i] = (x[i] - t) / self.lu[i * n + i];
        }
        x
    }
}

/// Powers Φ^(2^i), i = 0..=log2 k, to jump over steps without contact in the Jacobian.
pub(super) struct PhiPowers(Vec<Mat<f64>>);

impl PhiPowers {
    pub(super) fn new(sm: &StepMapLcp) -> Self {
        let mut p = vec![sm.phi_full()];
        while 1usize << p.len() <= sm.k {
            let last = p.last().expect("one power");
            p.push(product(last, last));
        }
        PhiPowers(p)
    }
    /// J ← Φ^n J.
    fn apply(&self, mut n: usize, j: &mut Mat<f64>) {
        let mut i = 0;
        while n > 0 {
            if n & 1 == 1 {
                *j = product(&self.0[i], j);
            }
            n >>= 1;
            i += 1;
        }
    }
}

/// Marches one period from `s0` with offset `shift` added to every r_j.
pub(super) fn march(sm: &StepMapLcp, s0: &[f64], shift: f64, contacts: Contacts<'_>) -> Option<March> {
    let (k, d, m) = (sm.k, sm.d, sm.m);
    let mut s = s0.to_vec();
    let mut y = vec![0.0; d];
    let mut r = vec![0.0; m];
    let mut zs = vec![0.0; m];
    let mut ws = vec![0.0; m];
    let mut out = March { end: Vec::new(), z: vec![0.0; k * m], masks: vec![0; k], changes: 0, min_w: f64::INFINITY };
    for step in 0..k {
        for i in 0..d {
            y[i] = sm.c[step * d + i] + (0..d).map(|l| sm.phi[(i, l)] * s[l]).sum::<f64>();
        }
        for &(i, l) in &sm.carry {
            y[i] += s[l];
        }
        for a in 0..m {
            r[a] = sm.r[step * m + a] + shift + (0..d).map(|i| sm.h[a * d + i] * y[i]).sum::<f64>();
        }
        let mask = match contacts {
            Contacts::Free => {
                out.min_w = r.iter().fold(out.min_w, |a, &v| a.min(v));
                zs.iter_mut().for_each(|v| *v = 0.0);
                0
            }
            Contacts::Solve(guess) => {
                let (mask, changes) = step_lcp(&sm.s, m, &r, guess.get(step).copied().unwrap_or(0), &mut zs, &mut ws)?;
                out.changes += changes;
                mask
            }
            Contacts::Frozen(sets) => {
                let mask = sets[step];
                if !solve_active(&sm.s, m, &r, mask, &mut zs) {
                    return None;
                }
                mask
            }
        };
        out.masks[step] = mask;
        out.z[step * m..(step + 1) * m].copy_from_slice(&zs);
        for i in 0..d {
            s[i] = y[i] + (0..m).map(|a| sm.gamma[i * m + a] * zs[a]).sum::<f64>();
        }
    }
    if !s.iter().all(|v| v.is_finite()) {
        return None;
    }
    out.end = s;
    Some(out)
}

/// [dP/ds0 | dP/dshift] (d×(d+1)) on the piece of these active sets: P is affine there, so the
/// Jacobian depends on the sets alone (dP/ds0 is the discrete monodromy matrix when the orbit
/// closes). Each step is T_j = (I − Γ_a S_aa⁻¹ H_a) Φ, runs of steps without contact are one power
/// of Φ, and the shift enters each active step as −Γ_a S_aa⁻¹ 1_a.
pub(super) fn period_jacobian(sm: &StepMapLcp, masks: &[u32], powers: &PhiPowers, j: &mut Mat<f64>) {
    let d = sm.d;
    *j = Mat::from_fn(d, d + 1, |r, c| if r == c { 1.0 } else { 0.0 });
    let mut free_run = 0usize;
    for &mask in masks {
        if mask == 0 {
            free_run += 1;
        } else {
            powers.apply(free_run + 1, j);
            free_run = 0;
            correct_jacobian(sm, mask, j);
        }
    }
    powers.apply(free_run, j);
}

/// J ← J − Γ_a S_aa⁻¹ (H_a J + [0 | 1_a]): the active pairs hold w_a = 0, so
/// z_a = −S_aa⁻¹(r_a + shift + H_a y); the last column of J is the derivative in the shift.
fn correct_jacobian(sm: &StepMapLcp, mask: u32, j: &mut Mat<f64>) {
    let (d, m) = (sm.d, sm.m);
    let act = active_rows(sm, mask);
    let mut dz = vec![0.0; m];
    let mut rhs = vec![0.0; m];
    for col in 0..=d {
        for &a in &act {
            rhs[a] = (0..d).map(|i| sm.h[a * d + i] * j[(i, col)]).sum::<f64>() + if col == d { 1.0 } else { 0.0 };
        }
        // S_aa dz_a = −(H_a J)[:, col]
        solve_active(&sm.s, m, &rhs, mask, &mut dz);
        for i in 0..d {
            let g: f64 = act.iter().map(|&a| sm.gamma[i * m + a] * dz[a]).sum();
            j[(i, col)] += g;
        }
    }
}
