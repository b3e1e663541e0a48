//! The period's LCP from the assembly (src/formulation.md §3): the block-circulant matrix of the
//! contacts' responses with its spectrum, and q.
use super::{Assembly, PeriodFft, PeriodicProblem};
use crate::lcp::BlockCirculant;

impl PeriodicProblem {
    /// The LCP of the period: A block-circulant from the inverse FFT of Ĝ, and q = gap − B xlin,
    /// each contact row shifted by its pairing offset (λ_j ⊥ gap(t_{j+s})).
    pub fn lcp(&self, asm: &Assembly, fft: &PeriodFft) -> (BlockCirculant, Vec<f64>) {
        let (k, m) = (asm.k, asm.m);
        let nh = k / 2 + 1;
        let mut blocks = vec![0.0; k * m * m];
        let mut q = vec![0.0; k * m];
        let mut spec = vec![num_complex::Complex64::ZERO; nh];
        let angles = crate::model::GridAngles::new(k);
        for (a, ca) in self.model().contacts.iter().enumerate() {
            let s = self.pairing_of(ca).offset();
            for b in 0..m {
                for (p, v) in spec.iter_mut().enumerate() {
                    *v = asm.g_hat[(p * m + a) * m + b];
                }
                let col = fft.inverse(&spec);
                for d in 0..k {
                    blocks[(d * m + a) * m + b] = col[(d + s) % k];
                }
            }
            for (p, v) in spec.iter_mut().enumerate() {
                *v = asm.bxlin_hat[p * m + a];
            }
            let bx = fft.inverse(&spec);
            let gap = ca.gap_samples(&angles, self.period_multiple());
            for j in 0..k {
                let jj = (j + s) % k;
                q[j * m + a] = gap[jj] - bx[jj];
            }
            if let crate::model::Compliance::Compliant { stiffness } = ca.compliance {
                blocks[a * m + a] += 1.0 / stiffness;
            }
        }
        (BlockCirculant::new(k, m, blocks).with_spectrum(self.lcp_spectrum(asm)), q)
    }

    /// The DFT of [`Self::lcp`]'s blocks from Ĝ directly: row a shifted by its pairing offset s
    /// multiplies harmonic p by e^(2πi ps/k) (the shift theorem), a compliance adds 1/k_c to
    /// every harmonic's diagonal; the DC and Nyquist bins keep their real parts, as the blocks'
    /// real transform does. Why: the FFT products' m² forward transforms of the blocks were a
    /// tenth of a real-blade sweep point (issue 23).
    fn lcp_spectrum(&self, asm: &Assembly) -> Vec<num_complex::Complex64> {
        let (k, m) = (asm.k, asm.m);
        let mut spectrum = asm.g_hat.clone();
        for (a, ca) in self.model().contacts.iter().enumerate() {
            let s = self.pairing_of(ca).offset();
            let compliance = match ca.compliance {
                crate::model::Compliance::Compliant { stiffness } => 1.0 / stiffness,
                crate::model::Compliance::Rigid => 0.0,
            };
            for p in 0..=k / 2 {
                let turn = 2.0 * std::f64::consts::PI * ((p * s) % k) as f64 / k as f64;
                let shift = num_complex::Complex64::from_polar(1.0, turn);
                let row = &mut spectrum[(p * m + a) * m..(p * m + a + 1) * m];
                row.iter_mut().for_each(|v| *v = if s == 0 { *v } else { *v * shift });
                row[a] += compliance;
                if p == 0 || 2 * p == k {
                    row.iter_mut().for_each(|v| v.im = 0.0);
                }
            }
        }
        spectrum
    }
}
