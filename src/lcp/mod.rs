//! Linear complementarity problems: find z ≥ 0 with w = A z + q ≥ 0 and zᵀw = 0.
//!
//! This module knows nothing of mechanics. Matrices come through [`LcpMatrix`], so a solver can
//! work on a dense matrix or on a structured one ([`BlockCirculant`]) without forming it.
mod brute;
mod circulant_fft;
pub mod dat;
mod lemke;
mod matrix;
mod pivoting;
mod policy;
mod refine;
mod warm_lemke;

pub use brute::solve_by_enumeration;
pub use circulant_fft::CirculantOperator;
pub use dat::{DatError, parse_dat, read_dat, write_dat};
pub use lemke::{Lemke, LemkeSettings};
pub use matrix::{BlockCirculant, DenseMatrix, LcpMatrix};
pub use pivoting::{BlockPivoting, PivotingSettings};
pub use policy::{AUTO_LEMKE_MAX, LcpMethod, solve_circulant_lcp};

use serde::Serialize;

/// How a solve ended. Only `Solved` carries a certified answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LcpOutcome {
    /// z, w complementary, residual within the certification tolerance.
    Solved,
    /// Lemke's entering column has no blocking row: no solution reachable from the ray start
    /// (for a copositive-plus A: no solution at all).
    RayTermination,
    /// The pivot budget (proportional to the size) ran out.
    PivotLimit,
    /// A or q holds NaN or ±∞.
    NonFiniteData,
    /// A basis was found but its refined solution fails the residual check (ill-conditioning).
    Inaccurate,
}

impl LcpOutcome {
    pub fn name(self) -> &'static str {
        match self {
            LcpOutcome::Solved => "solved",
            LcpOutcome::RayTermination => "ray termination",
            LcpOutcome::PivotLimit => "pivot limit",
            LcpOutcome::NonFiniteData => "non-finite data",
            LcpOutcome::Inaccurate => "inaccurate",
        }
    }
}

/// Diagnostics of one solve.
#[derive(Clone, Debug, Default, Serialize)]
pub struct LcpInfo {
    pub pivots: usize,
    /// ‖min(z, A z + q)‖∞ on the original data.
    pub residual: f64,
    /// Siconos' ‖z − max(0, z − w)‖₂ / ‖q‖₂ (‖q‖₂ replaced by 1 when it is 0).
    pub relative_error: f64,
    pub time_s: f64,
    /// True when the warm-start guess was accepted without pivoting.
    pub warm_start_used: bool,
}

/// The outcome with the best iterate. z and w are always finite (zeros when nothing better).
#[derive(Clone, Debug)]
pub struct LcpSolution {
    pub outcome: LcpOutcome,
    pub z: Vec<f64>,
    pub w: Vec<f64>,
    pub info: LcpInfo,
}

/// ‖min(z, w)‖∞ and Siconos' relative error for a candidate z, with w = A z + q.
pub fn residuals(q: &[f64], z: &[f64], w: &[f64]) -> (f64, f64) {
    let mut inf = 0.0f64;
    let mut num = 0.0f64;
    for (&zi, &wi) in z.iter().zip(w) {
        let m = zi.min(wi);
        inf = inf.max(m.abs());
        let d = zi - (zi - wi).max(0.0);
        num += d * d;
    }
    let qn = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let rel = num.sqrt() / if qn > 0.0 { qn } else { 1.0 };
    if inf.is_nan() || rel.is_nan() { (f64::INFINITY, f64::INFINITY) } else { (inf, rel) }
}
