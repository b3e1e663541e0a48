//! Lemke's method started from an arbitrary complementary basis (Cottle, Pang & Stone 1992,
//! §4.4, "Lemke's method with a general covering vector"): the finishing step of the fast path.
//!
//! Given a guess F of the indices with z > 0, the start basis holds z_F and w_G (G = not F).
//! The covering vector d is chosen so that B_F⁻¹ d = 1: z0 then lifts every infeasible basic
//! variable at once, and complementary pivoting repairs the few wrong indices. Basis solves use
//! the LU of A_FF and one product with A (an FFT away for a block-circulant A), then the
//! product-form etas of the pivots made since: O(|F|² + N log N + N·pivots) per pivot, and
//! memory O(|F|² + N·pivots) — never the N² tableau.
use crate::lcp::principal::{LuScratch, well_conditioned};
use crate::lcp::status::{finite_or_zero, residuals};
use crate::lcp::{LcpInfo, LcpMatrix, LcpOutcome, LcpSolution};
use faer::Mat;
use faer::linalg::solvers::PartialPivLu;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Var {
    W(usize),
    Z(usize),
    Z0,
}

/// B⁻¹ = E_t ⋯ E_1 B_F⁻¹, B_F = [−A_{:,F} | e_G] (columns in row order: row i holds z_i or w_i).
///
/// Every buffer of a basis solve is owned here, so [`Basis::apply_inverse`] allocates nothing;
/// the etas are one flat array that grows amortised (no allocation per pivot).
struct Basis<'a> {
    a: &'a dyn LcpMatrix,
    n: usize,
    f: Vec<usize>,
    /// Position of index i in `f`, or usize::MAX.
    pos: Vec<usize>,
    lu: Option<PartialPivLu<f64>>,
    /// Pivot rows of the etas, and their columns (B⁻¹·entering column before the pivot), n each.
    eta_rows: Vec<usize>,
    eta_cols: Vec<f64>,
    /// −v_F, then y_F (|F|×1).
    rhs: Mat<f64>,
    /// y_F padded with zeros to length n, and A times it.
    padded: Vec<f64>,
    product: Vec<f64>,
    lu_scratch: LuScratch,
}

impl<'a> Basis<'a> {
    fn new(a: &'a dyn LcpMatrix, active: &[bool], lu: Option<PartialPivLu<f64>>) -> Option<Self> {
        let n = a.dim();
        let f: Vec<usize> = (0..n).filter(|&i| active[i]).collect();
        let mut pos = vec![usize::MAX; n];
        f.iter().enumerate().for_each(|(c, &i)| pos[i] = c);
        let lu = match lu {
            Some(lu) => Some(lu),
            None if f.is_empty() => None,
            None => {
                let mut col = vec![0.0; n];
                let mut aff = Mat::<f64>::zeros(f.len(), f.len());
                for (cj, &j) in f.iter().enumerate() {
                    a.column_into(j, &mut col);
                    for (ci, &i) in f.iter().enumerate() {
                        aff[(ci, cj)] = col[i];
                    }
                }
                let lu = aff.partial_piv_lu();
                if !well_conditioned(lu.U()) {
                    return None;
                }
                Some(lu)
            }
        };
        let r = f.len();
        Some(Basis {
            a,
            n,
            f,
            pos,
            lu,
            eta_rows: Vec::new(),
            eta_cols: Vec::new(),
            rhs: Mat::zeros(r, 1),
            padded: vec![0.0; n],
            product: vec![0.0; n],
            lu_scratch: LuScratch::new(r),
        })
    }

    /// Appends the eta of a pivot on row r with column `col` (B⁻¹·entering column).
    fn push_eta(&mut self, r: usize, col: &[f64]) {
        self.eta_rows.push(r);
        self.eta_cols.extend_from_slice(col);
    }

    /// v ← B⁻¹ v.
    fn apply_inverse(&mut self, v: &mut [f64]) {
        let n = self.n;
        // B_F⁻¹: −A_FF y_F = v_F, then y_G = v_G + A_GF y_F.
        if let Some(lu) = &self.lu {
            for (c, &i) in self.f.iter().enumerate() {
                self.rhs[(c, 0)] = -v[i];
            }
            self.lu_scratch.solve_in_place(lu, self.rhs.as_mut());
            self.padded.fill(0.0);
            self.f.iter().enumerate().for_each(|(c, &i)| self.padded[i] = self.rhs[(c, 0)]);
            self.a.mul_into(&self.padded, &mut self.product);
            for (i, vi) in v.iter_mut().enumerate() {
                *vi = if self.pos[i] != usize::MAX { self.padded[i] } else { *vi + self.product[i] };
            }
        }
        for (&r, col) in self.eta_rows.iter().zip(self.eta_cols.chunks_exact(n)) {
            let yr = v[r] / col[r];
            for (vi, ci) in v.iter_mut().zip(col) {
                *vi -= ci * yr;
            }
            v[r] = yr;
        }
    }

    /// The column of variable `var` in [I, −A, −d].
    fn column(&self, var: Var, d: &[f64], out: &mut [f64]) {
        match var {
            Var::W(i) => {
                out.iter_mut().for_each(|v| *v = 0.0);
                out[i] = 1.0;
            }
            Var::Z(i) => {
                self.a.column_into(i, out);
                out.iter_mut().for_each(|v| *v = -*v);
            }
            Var::Z0 => out.iter_mut().zip(d).for_each(|(o, di)| *o = -di),
        }
    }
}

/// Lemke from the complementary basis `active` (z_i basic for active i). `lu`: the LU of
/// A_FF if the caller has it. `max_pivots` bounds the work; the caller falls back on failure.
pub fn solve_from_basis(a: &dyn LcpMatrix, q: &[f64], active: &[bool], lu: Option<PartialPivLu<f64>>, max_pivots: usize, certify_tol: f64) -> LcpSolution {
    let start = std::time::Instant::now();
    let n = a.dim();
    let done = |outcome, pivots, z: Vec<f64>, w: Vec<f64>| {
        let (residual, relative_error) = residuals(q, &z, &w);
        LcpSolution {
            outcome,
            z,
            w,
            info: LcpInfo { pivots, residual, relative_error, time_s: start.elapsed().as_secs_f64(), warm_start_used: false, ..LcpInfo::default() },
        }
    };
    let Some(mut basis) = Basis::new(a, active, lu) else {
        return done(LcpOutcome::Inaccurate, 0, vec![0.0; n], q.to_vec());
    };
    let mut basic: Vec<Var> = (0..n).map(|i| if active[i] { Var::Z(i) } else { Var::W(i) }).collect();
    let mut x = q.to_vec();
    basis.apply_inverse(&mut x);
    let qmax = q.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let tol = 1e-12 * qmax;
    // d = B_F·1 so that B_F⁻¹ d = 1: the column of z0 is −d and B⁻¹(−d) = −1.
    let ones: Vec<f64> = (0..n).map(|i| if active[i] { 1.0 } else { 0.0 }).collect();
    let mut d = vec![0.0; n];
    a.mul_into(&ones, &mut d);
    for i in 0..n {
        d[i] = if active[i] { -d[i] } else { 1.0 - d[i] };
    }
    let Some((r0, &xmin)) = x.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1)) else {
        return done(LcpOutcome::Solved, 0, vec![], vec![]);
    };
    let mut pivots = 0;
    if xmin >= -tol {
        return finish(a, q, &mut basis, &basic, &mut x, 0, certify_tol, start);
    }
    // z0 enters at row r0: every basic variable rises by −xmin.
    let t = -xmin;
    x.iter_mut().for_each(|v| *v += t);
    x[r0] = t;
    let mut col = vec![-1.0; n];
    basis.push_eta(r0, &col);
    let mut leaving = basic[r0];
    basic[r0] = Var::Z0;
    loop {
        pivots += 1;
        if pivots > max_pivots {
            return done(LcpOutcome::PivotLimit, pivots, vec![0.0; n], q.to_vec());
        }
        let entering = match leaving {
            Var::W(i) => Var::Z(i),
            Var::Z(i) => Var::W(i),
            Var::Z0 => unreachable!("z0 leaving ends the loop"),
        };
        basis.column(entering, &d, &mut col);
        basis.apply_inverse(&mut col);
        let amax = col.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let ptol = 1e-11 * amax.max(1.0);
        // Ratio test; ties prefer z0 (it ends the run), then the larger pivot.
        let mut best: Option<(usize, f64)> = None;
        for i in 0..n {
            if col[i] > ptol {
                let ratio = x[i].max(0.0) / col[i];
                best = match best {
                    None => Some((i, ratio)),
                    Some((b, rb)) => {
                        let tie = (ratio - rb).abs() <= 1e-12 * rb.abs().max(1e-300);
                        let better = if tie { basic[i] == Var::Z0 || (basic[b] != Var::Z0 && col[i] > col[b]) } else { ratio < rb };
                        if better { Some((i, ratio)) } else { Some((b, rb)) }
                    }
                };
            }
        }
        let Some((r, t)) = best else {
            return done(LcpOutcome::RayTermination, pivots, vec![0.0; n], q.to_vec());
        };
        for i in 0..n {
            x[i] -= t * col[i];
        }
        x[r] = t;
        leaving = basic[r];
        basic[r] = entering;
        basis.push_eta(r, &col);
        if leaving == Var::Z0 {
            return finish(a, q, &mut basis, &basic, &mut x, pivots, certify_tol, start);
        }
    }
}

/// Steps of iterative refinement of the final basic values. Why: the product-form etas and an
/// ill-conditioned A_FF leave the basic values off by cond·eps (measured: residual 1e-12 against
/// Lemke's 1e-15 on the 3-DOF two-stop chain at N = 1024, forces off by 3e-9 relative); one
/// refinement step costs one product with A and one basis solve.
const FINAL_REFINEMENT: usize = 2;

/// Reads z, w off the final basis (after iterative refinement of the basic values against the
/// original data), clips round-off, and certifies on the original data.
#[allow(clippy::too_many_arguments)]
fn finish(
    a: &dyn LcpMatrix,
    q: &[f64],
    basis: &mut Basis<'_>,
    basic: &[Var],
    x: &mut [f64],
    pivots: usize,
    certify_tol: f64,
    start: std::time::Instant,
) -> LcpSolution {
    let n = q.len();
    if !basic.contains(&Var::Z0) {
        // Basis equation: w − A z = q over the basic variables (non-basic ones are 0).
        let mut zb = vec![0.0; n];
        let mut res = vec![0.0; n];
        for _ in 0..FINAL_REFINEMENT {
            zb.iter_mut().for_each(|v| *v = 0.0);
            for (row, var) in basic.iter().enumerate() {
                if let Var::Z(i) = var {
                    zb[*i] = x[row];
                }
            }
            a.mul_into(&zb, &mut res);
            for i in 0..n {
                res[i] += q[i];
            }
            for (row, var) in basic.iter().enumerate() {
                if let Var::W(i) = var {
                    res[*i] -= x[row];
                }
            }
            basis.apply_inverse(&mut res);
            if !res.iter().all(|v| v.is_finite()) {
                break;
            }
            x.iter_mut().zip(&res).for_each(|(xi, di)| *xi += di);
        }
    }
    let n = q.len();
    let mut z = vec![0.0; n];
    for (row, var) in basic.iter().enumerate() {
        if let Var::Z(i) = var {
            z[*i] = x[row].max(0.0);
        }
    }
    let mut w = vec![0.0; n];
    a.mul_into(&z, &mut w);
    w.iter_mut().zip(q).for_each(|(wi, qi)| *wi += qi);
    let (residual, relative_error) = residuals(q, &z, &w);
    let qmax = q.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let outcome = if residual <= certify_tol * qmax { LcpOutcome::Solved } else { LcpOutcome::Inaccurate };
    let sol = LcpSolution {
        outcome,
        z,
        w,
        info: LcpInfo { pivots, residual, relative_error, time_s: start.elapsed().as_secs_f64(), warm_start_used: false, ..LcpInfo::default() },
    };
    finite_or_zero(sol, q)
}
