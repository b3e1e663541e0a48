//! The period's LCP from the assembly (src/formulation.md §3): the block-circulant matrix of the
//! contacts' responses with its spectrum, and q.
use super::{Assembly, PeriodFft, PeriodicProblem};
use crate::lcp::BlockCirculant;
use std::sync::Arc;

impl PeriodicProblem {
    /// The LCP of the period: A block-circulant of spectrum Ĝ (its blocks, the inverse FFT, formed
    /// when a solver asks for them), and q = gap − B xlin, each contact row shifted by its pairing
    /// offset (λ_j ⊥ gap(t_{j+s})).
    pub fn lcp(&self, asm: &Assembly, fft: &PeriodFft) -> (BlockCirculant, Vec<f64>) {
        let (k, m) = (asm.k, asm.m);
        let nh = k / 2 + 1;
        let mut q = vec![0.0; k * m];
        let gaps = self.gap_samples(k);
        // B X̂lin per contact from one pass over its harmonic-major storage; a zero spectrum (no
        // force: the real blade's casing moves q through the gaps alone) is zero in time (it was
        // m strided passes and m transforms per solve, issue 23).
        let mut spectra = vec![vec![num_complex::Complex64::ZERO; nh]; m];
        for (p, harmonic) in asm.bxlin_hat.chunks_exact(m.max(1)).enumerate().take(nh) {
            for (spec, &v) in spectra.iter_mut().zip(harmonic) {
                spec[p] = v;
            }
        }
        let bx: Vec<Option<Vec<f64>>> = spectra.iter().map(|spec| spec.iter().any(|v| *v != num_complex::Complex64::ZERO).then(|| fft.inverse(spec))).collect();
        let shifts: Vec<usize> = self.model().contacts.iter().map(|ca| self.pairing_of(ca).offset()).collect();
        for (j, row) in q.chunks_exact_mut(m.max(1)).enumerate() {
            for (a, (v, &shift)) in row.iter_mut().zip(&shifts).enumerate() {
                let jj = (j + shift) % k;
                *v = gaps[a][jj] - bx[a].as_ref().map_or(0.0, |b| b[jj]);
            }
        }
        // The blocks are formed from the spectrum only if a solver asks for them.
        let (spectrum, real_ends) = self.lcp_spectrum(asm);
        let a = BlockCirculant::from_spectrum(k, m, spectrum);
        (if real_ends { a.with_real_ends() } else { a }, q)
    }

    /// The DFT of [`Self::lcp`]'s blocks from Ĝ directly: row a shifted by its pairing offset s
    /// multiplies harmonic p by e^(2πi ps/k) (the shift theorem), a compliance adds 1/k_c to
    /// every harmonic's diagonal; the DC and Nyquist bins keep their real parts, as the blocks'
    /// real transform does. Why: the FFT products' m² forward transforms of the blocks were a
    /// tenth of a real-blade sweep point (issue 23).
    /// Returns it, and whether its DC and Nyquist bins' imaginary parts are to be read as 0
    /// ([`BlockCirculant::with_real_ends`]: Ĝ shared, unchanged otherwise).
    fn lcp_spectrum(&self, asm: &Assembly) -> (Arc<Vec<num_complex::Complex64>>, bool) {
        let (k, m) = (asm.k, asm.m);
        if m == 0 {
            return (Arc::clone(&asm.g_hat), false);
        }
        let rows: Vec<(usize, f64)> = self
            .model()
            .contacts
            .iter()
            .map(|ca| {
                let compliance = match ca.compliance {
                    crate::model::Compliance::Compliant { stiffness } => 1.0 / stiffness,
                    crate::model::Compliance::Rigid => 0.0,
                };
                (self.pairing_of(ca).offset(), compliance)
            })
            .collect();
        if unchanged_by_lcp(&asm.g_hat, m, &rows) {
            return (Arc::clone(&asm.g_hat), true);
        }
        let mut spectrum = asm.g_hat.as_ref().clone();
        // Harmonic by harmonic, each block in storage order (contact by contact, these were m
        // strided passes over the whole spectrum, issue 23).
        for (p, block) in spectrum.chunks_exact_mut(m * m).enumerate().take(k / 2 + 1) {
            for (a, (row, &(s, compliance))) in block.chunks_exact_mut(m).zip(&rows).enumerate() {
                // Unshifted rows skip the sin/cos (k/2 + 1 per contact, every solve).
                if s != 0 {
                    let turn = 2.0 * std::f64::consts::PI * ((p * s) % k) as f64 / k as f64;
                    let shift = num_complex::Complex64::from_polar(1.0, turn);
                    row.iter_mut().for_each(|v| *v *= shift);
                }
                row[a] += compliance;
                if p == 0 || 2 * p == k {
                    row.iter_mut().for_each(|v| v.im = 0.0);
                }
            }
        }
        (Arc::new(spectrum), false)
    }
}

/// Whether [`PeriodicProblem::lcp_spectrum`]'s changes but the DC and Nyquist bins' imaginary
/// parts leave Ĝ bit for bit as it is: no shifted row, no compliance (adding +0.0 keeps every
/// diagonal but a −0.0). Why: the real blade's rigid, same-paired contacts then share the
/// assembly's spectrum instead of copying it (4.7 MB per solve at k = 2048, issue 23).
fn unchanged_by_lcp(g_hat: &[num_complex::Complex64], m: usize, rows: &[(usize, f64)]) -> bool {
    rows.iter().all(|&(s, compliance)| s == 0 && compliance.to_bits() == 0)
        && g_hat.chunks_exact(m * m).all(|block| (0..m).all(|a| block[a * m + a].re.to_bits() != (-0.0f64).to_bits()))
}

#[cfg(test)]
mod tests {
    use super::super::assembly::tests::chain_with_massless_boundary;
    use super::super::{OutputSelection, PeriodFft, PeriodicProblem, SolverSettings};
    use crate::lcp::{BlockCirculant, CirculantOperator, LcpMatrix};
    use crate::model::Compliance;
    use crate::time::{Discretization, Pairing, Scheme};

    /// The blocks of the LCP, formed from its spectrum on demand, equal the blocks built directly
    /// (each column of Ĝ transformed back, its row shifted by the pairing offset in time, the
    /// compliance on block 0's diagonal), under both pairings and with a compliant contact; the
    /// FFT product on the spectrum equals the direct product on those blocks; and the spectrum's
    /// bound of max|A| is at least the blocks' max|A|.
    #[test]
    fn the_spectrum_from_the_assembly_gives_the_blocks_products() {
        let mut model = chain_with_massless_boundary();
        model.contacts[2].compliance = Compliance::Compliant { stiffness: 2.0e4 };
        for pairing in [Pairing::Same, Pairing::Forward] {
            let disc = Discretization { scheme: Scheme::Bds1, steps: 64, pairing: Some(pairing) };
            let p = PeriodicProblem::new(model.clone(), disc, OutputSelection::default(), SolverSettings::default()).unwrap();
            let fft = PeriodFft::new(64);
            let (a, _) = p.assemble_lcp(&fft).unwrap();
            assert!(a.spectrum().is_some(), "the LCP carries its spectrum");
            let bound = a.max_abs_bound();
            let direct_blocks = blocks_by_time_shift(&p, &fft);
            let plain = BlockCirculant::new(a.k(), a.m(), direct_blocks);
            let block_scale = plain.max_abs().0;
            let block_gap = a.blocks().iter().zip(plain.blocks()).fold(0.0f64, |w, (x, y)| w.max((x - y).abs()));
            let z: Vec<f64> = (0..a.dim()).map(|i| ((i * 37 % 11) as f64 - 3.0).max(0.0)).collect();
            let (mut fast, mut direct) = (vec![0.0; a.dim()], vec![0.0; a.dim()]);
            CirculantOperator::new(&a).mul_into(&z, &mut fast);
            plain.mul_into(&z, &mut direct);
            let mut refft = vec![0.0; a.dim()];
            CirculantOperator::new(&plain).mul_into(&z, &mut refft);
            let scale = direct.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            let worst = fast.iter().zip(&direct).fold(0.0f64, |w, (x, y)| w.max((x - y).abs()));
            let against_fft = fast.iter().zip(&refft).fold(0.0f64, |w, (x, y)| w.max((x - y).abs()));
            eprintln!(
                "{pairing:?}: blocks from the spectrum against the shifted ones {:.1e}; spectrum product against the direct one {:.1e}, against the blocks' FFT {:.1e} (of {scale:.2e}); bound {:.3e} ≥ max|A| {block_scale:.3e}",
                block_gap / block_scale,
                worst / scale,
                against_fft / scale,
                bound.0
            );
            assert!(block_gap <= 1e-12 * block_scale, "{pairing:?}: blocks differ by {block_gap:e} of {block_scale:e}");
            assert!(scale > 0.0 && worst <= 1e-12 * scale && against_fft <= 1e-12 * scale, "{pairing:?}: {worst:e}, {against_fft:e} of {scale:e}");
            assert!(bound.1 && bound.0 >= block_scale, "{pairing:?}: bound {:e} below max|A| {block_scale:e}", bound.0);
            assert_eq!(a.max_abs_bound(), a.max_abs(), "{pairing:?}: once the blocks are formed the bound is their max|A|");
        }
    }

    /// With rigid, same-paired contacts the LCP shares the assembly's Ĝ, its DC and Nyquist
    /// imaginary parts read as 0 ([`BlockCirculant::with_real_ends`]): its products and bound
    /// equal bit for bit those of a copy of Ĝ with them zeroed, and its blocks the ones built in time.
    #[test]
    fn a_shared_spectrum_reads_its_ends_as_real() {
        let model = chain_with_massless_boundary();
        let disc = Discretization { scheme: Scheme::Bds1, steps: 64, pairing: Some(Pairing::Same) };
        let p = PeriodicProblem::new(model, disc, OutputSelection::default(), SolverSettings::default()).unwrap();
        let fft = PeriodFft::new(64);
        let (a, _) = p.assemble_lcp(&fft).unwrap();
        assert!(a.real_ends(), "rigid contacts under the same pairing share Ĝ");
        let (k, m) = (a.k(), a.m());
        let mut zeroed = a.spectrum().unwrap().to_vec();
        let ends = zeroed.chunks_exact_mut(m * m).enumerate().filter(|(p, _)| *p == 0 || 2 * p == k);
        let dropped = ends.fold(0.0f64, |w, (_, block)| block.iter_mut().fold(w, |w, v| w.max(std::mem::take(&mut v.im).abs())));
        let copy = BlockCirculant::from_spectrum(k, m, zeroed);
        let z: Vec<f64> = (0..a.dim()).map(|i| ((i * 37 % 11) as f64 - 3.0).max(0.0)).collect();
        let (mut shared, mut copied) = (vec![0.0; a.dim()], vec![0.0; a.dim()]);
        CirculantOperator::new(&a).mul_into(&z, &mut shared);
        CirculantOperator::new(&copy).mul_into(&z, &mut copied);
        eprintln!("largest DC/Nyquist imaginary part read as 0: {dropped:.1e}");
        assert!(dropped > 0.0, "bds1's Nyquist bin has imaginary round-off: the test reads some as 0");
        assert!(shared.iter().zip(&copied).all(|(x, y)| x.to_bits() == y.to_bits()), "the shared spectrum's product differs from the copy's");
        assert_eq!(a.max_abs_bound(), copy.max_abs_bound());
        let direct = BlockCirculant::new(k, m, blocks_by_time_shift(&p, &fft));
        let scale = direct.max_abs().0;
        let gap = a.blocks().iter().zip(direct.blocks()).fold(0.0f64, |w, (x, y)| w.max((x - y).abs()));
        assert!(gap <= 1e-12 * scale, "blocks differ by {gap:e} of {scale:e}");
    }

    /// The LCP's blocks built in time: column (a, b) of Ĝ transformed back, row a read s_a
    /// instants later (its pairing offset), 1/k_c added to block 0's diagonal.
    fn blocks_by_time_shift(p: &PeriodicProblem, fft: &PeriodFft) -> Vec<f64> {
        let asm = p.assemble(fft).unwrap();
        let (k, m) = (asm.k, asm.m);
        let mut blocks = vec![0.0; k * m * m];
        for (a, ca) in p.model().contacts.iter().enumerate() {
            let s = p.pairing_of(ca).offset();
            for b in 0..m {
                let spec: Vec<_> = (0..=k / 2).map(|q| asm.g_hat[(q * m + a) * m + b]).collect();
                let col = fft.inverse(&spec);
                for d in 0..k {
                    blocks[(d * m + a) * m + b] = col[(d + s) % k];
                }
            }
            if let Compliance::Compliant { stiffness } = ca.compliance {
                blocks[a * m + a] += 1.0 / stiffness;
            }
        }
        blocks
    }
}
