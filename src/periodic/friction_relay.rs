//! One instant's box problem of the friction shooting (src/formulation.md §9, "Friction by
//! shooting"): f ∈ [−μN, μN] per contact, f_i = μN·sign(σ_i) when σ_i ≠ 0, solved by a
//! primal–dual active set with Lemke on the relay LCP as the fallback.
use crate::lcp::{DenseLu, DenseMatrix, LcpOutcome, Lemke, LemkeSettings};
use faer::Mat;

/// One instant's box problem σ = s⁰ − T f, f ∈ [−μN, μN] ⊥ σ (T row-major, mf × mf; μN per row).
pub(super) struct Relay<'a> {
    pub t: &'a [f64],
    pub slip: &'a [f64],
}

impl Relay<'_> {
    /// Solves from the guessed modes by a primal–dual active set (mode updates from the
    /// violations), else Lemke on the relay LCP; `mode` and `f` hold the answer.
    pub(super) fn box_step(&self, s0: &[f64], mode: &mut [i8], f: &mut [f64]) {
        let mf = self.slip.len();
        for _ in 0..2 * mf + 2 {
            self.solve_modes(s0, mode, f);
            if !self.update_modes(s0, mode, f) {
                return;
            }
        }
        // relay_to_lcp: z₁ = f + μN, slack α; w₁ = T z₁ + α − s⁰ − T μN, w₂ = 2μN − z₁.
        let nn = 2 * mf;
        let mut data = vec![0.0; nn * nn];
        let mut q = vec![0.0; nn];
        for i in 0..mf {
            for l in 0..mf {
                data[i * nn + l] = self.t[i * mf + l];
            }
            data[i * nn + mf + i] = 1.0;
            data[(mf + i) * nn + i] = -1.0;
            q[i] = -s0[i] - (0..mf).map(|l| self.t[i * mf + l] * self.slip[l]).sum::<f64>();
            q[mf + i] = 2.0 * self.slip[i];
        }
        let sol = Lemke::new(LemkeSettings::default()).solve(&DenseMatrix::from_row_major(nn, data), &q);
        if sol.outcome != LcpOutcome::Solved {
            return; // the march's end state shows the failure to Newton (no convergence)
        }
        for i in 0..mf {
            let fi = sol.z[i] - self.slip[i];
            mode[i] = if fi.abs() < self.slip[i] * (1.0 - 1e-9) { 0 } else { fi.signum() as i8 };
        }
        self.solve_modes(s0, mode, f);
        if self.update_modes(s0, mode, f) {
            // Lemke's own forces when the modes it names do not reproduce them (degenerate ties).
            (0..mf).for_each(|i| f[i] = sol.z[i] - self.slip[i]);
        }
    }

    /// f with the modes fixed: slipping rows at ±μN, stuck rows from T_SS f_S = s⁰_S − T_SL f_L.
    fn solve_modes(&self, s0: &[f64], mode: &[i8], f: &mut [f64]) {
        let mf = self.slip.len();
        let stuck: Vec<usize> = (0..mf).filter(|&i| mode[i] == 0).collect();
        for i in 0..mf {
            f[i] = f64::from(mode[i]) * self.slip[i];
        }
        if stuck.is_empty() {
            return;
        }
        let rhs: Vec<f64> = stuck.iter().map(|&i| s0[i] - (0..mf).filter(|&l| mode[l] != 0).map(|l| self.t[i * mf + l] * f[l]).sum::<f64>()).collect();
        let ts = Mat::from_fn(stuck.len(), stuck.len(), |a, b| self.t[stuck[a] * mf + stuck[b]]);
        let fs = DenseLu::new(&ts).solve(&rhs);
        for (a, &i) in stuck.iter().enumerate() {
            f[i] = fs[a];
        }
    }

    /// Moves violated rows to their other mode; whether any moved.
    fn update_modes(&self, s0: &[f64], mode: &mut [i8], f: &[f64]) -> bool {
        let mf = self.slip.len();
        let scale = s0.iter().fold(0.0f64, |a, v| a.max(v.abs()))
            + (0..mf).map(|i| (0..mf).map(|l| self.t[i * mf + l].abs() * self.slip[l]).sum::<f64>()).fold(0.0, f64::max);
        let tol = 1e-12 * scale.max(f64::MIN_POSITIVE);
        let mut moved = false;
        for i in 0..mf {
            let sigma = s0[i] - (0..mf).map(|l| self.t[i * mf + l] * f[l]).sum::<f64>();
            let next = match mode[i] {
                0 if f[i] > self.slip[i] * (1.0 + 1e-12) => 1,
                0 if f[i] < -self.slip[i] * (1.0 + 1e-12) => -1,
                1 if sigma < -tol => 0,
                -1 if sigma > tol => 0,
                other => other,
            };
            moved |= next != mode[i] || !f[i].is_finite();
            mode[i] = next;
        }
        moved
    }

    /// df (mf × d) with the modes fixed: stuck rows solve T_SS df_S = ds⁰_S (`ds0(i, c)`), slipping
    /// rows keep their force.
    pub(super) fn stuck_tangent(&self, mode: &[i8], ds0: impl Fn(usize, usize) -> f64, d: usize) -> Mat<f64> {
        let mf = self.slip.len();
        let stuck: Vec<usize> = (0..mf).filter(|&i| mode[i] == 0).collect();
        let mut df = Mat::<f64>::zeros(mf, d);
        if !stuck.is_empty() {
            let ts = Mat::from_fn(stuck.len(), stuck.len(), |a, b| self.t[stuck[a] * mf + stuck[b]]);
            let lu = DenseLu::new(&ts);
            for c in 0..d {
                let col = lu.solve(&stuck.iter().map(|&i| ds0(i, c)).collect::<Vec<_>>());
                for (a, &i) in stuck.iter().enumerate() {
                    df[(i, c)] = col[a];
                }
            }
        }
        df
    }
}
