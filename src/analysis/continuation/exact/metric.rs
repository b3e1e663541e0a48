//! The arclength's metric of the exact walk: what a step measures.
//!
//! The unknowns weigh the state in an energy-like norm ([`super::family`]). Measured on the coarse
//! blade (2205–2300 rad/s): successive tangents turned 0.2–0.45 rad per step, and the turn was in
//! the velocities at the section of the LE and TE contact DOFs and of the first Craig–Bampton
//! coordinate (0.1–0.35 each, of unit tangents), the displacements and event times 3–10× less:
//! the stiff motion at the section rotates with ω while the orbit's low modes, event times and
//! outputs barely change, and it set the steps (313 to 2350 rad/s). The metric measures the
//! state by its projection on the structure's modes below a cut-off (contacts open), with
//! their energy weights (ω·η for a displacement, ω·η̇/max(ω_k, ω) for a velocity), plus the event
//! times and λ as they are. Newton still solves for every unknown. Without a mass-definite
//! model (a massless boundary) the metric is the unknowns' own.
use crate::model::Model;
use nalgebra::{DMatrix, DVector};

/// Modes up to this multiple of the scene's forcing frequency set the arclength (the coarse
/// blade: its first three, to 1.2e4 rad/s; a cut-off of 3 or 20 gave the same 79 steps to 2350 rad/s).
const CUTOFF: f64 = 8.0;

pub(super) struct Metric {
    /// Rows (M φ_k)ᵀ on the scaled displacement unknowns (ω·η_k/y_s = (M φ_k)ᵀ w_q), then the
    /// velocities' rows (ω/max(ω_k, ω)·(M φ_k)ᵀ over the velocity weights); n2 columns. `None`:
    /// the Euclidean metric of the unknowns.
    state: Option<DMatrix<f64>>,
    n2: usize,
}

impl Metric {
    /// The metric of `model` for state weights `weight` (the family's).
    pub fn new(model: &Model, weight: &[f64]) -> Metric {
        let n = model.n();
        let n2 = 2 * n;
        let euclid = Metric { state: None, n2 };
        let omega = model.frequency.abs();
        let dense = |m: &crate::model::Matrix| DMatrix::from_fn(n, n, |i, j| m.get(i, j));
        let (k, m) = (dense(&model.structure.stiffness), dense(&model.structure.mass));
        let Some(chol) = m.clone().cholesky() else { return euclid };
        let l = chol.l();
        let Some(li) = l.clone().try_inverse() else { return euclid };
        let a = &li * &k * li.transpose();
        let a = (&a + a.transpose()) * 0.5;
        let eig = a.symmetric_eigen();
        let mut rows: Vec<(DVector<f64>, f64)> = Vec::new();
        for (c, &lam) in eig.eigenvalues.iter().enumerate() {
            let wk = lam.max(0.0).sqrt();
            if wk <= CUTOFF * omega {
                // M φ_k = L u_k for φ_k = L⁻ᵀ u_k (mass-normalised).
                rows.push((&l * eig.eigenvectors.column(c), wk));
            }
        }
        if rows.is_empty() {
            return euclid;
        }
        let r = rows.len();
        let mut state = DMatrix::zeros(2 * r, n2);
        for (i, (mphi, wk)) in rows.iter().enumerate() {
            let f = omega / wk.max(omega);
            for j in 0..n {
                state[(i, j)] = mphi[j];
                state[(r + i, n + j)] = f * mphi[j] / weight[n + j];
            }
        }
        Metric { state: Some(state), n2 }
    }

    /// The coordinates L·x whose Euclidean norm is the metric's (x: the family's unknowns).
    fn coords(&self, x: &[f64]) -> Vec<f64> {
        match &self.state {
            None => x.to_vec(),
            Some(s) => {
                let mut y: Vec<f64> = (0..s.nrows()).map(|i| (0..self.n2).map(|j| s[(i, j)] * x[j]).sum()).collect();
                y.extend_from_slice(&x[self.n2..]);
                y
            }
        }
    }

    pub fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
        self.coords(a).iter().zip(self.coords(b)).map(|(x, y)| x * y).sum()
    }

    pub fn norm(&self, a: &[f64]) -> f64 {
        self.dot(a, a).sqrt()
    }

    /// G·x = Lᵀ L x: the normal of the metric's hyperplane along x.
    pub fn lower(&self, x: &[f64]) -> Vec<f64> {
        match &self.state {
            None => x.to_vec(),
            Some(s) => {
                let y = self.coords(x);
                let mut g: Vec<f64> = (0..self.n2).map(|j| (0..s.nrows()).map(|i| s[(i, j)] * y[i]).sum()).collect();
                g.extend_from_slice(&x[self.n2..]);
                g
            }
        }
    }

    /// `x` over its metric norm (as it is when that norm is nil).
    pub fn unit(&self, x: &[f64]) -> Vec<f64> {
        let n = self.norm(x);
        if !(n > 0.0 && n.is_finite()) {
            return x.to_vec();
        }
        x.iter().map(|v| v / n).collect()
    }
}
