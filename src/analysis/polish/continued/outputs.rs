//! [`PolishedOrbit::amplitudes`] in closed form, without the states: along phase e from its
//! start a, an output's value is r·x(t) = Re Σ_p r·X̂_p e^{ipωt} + Re Σ_j m_j e^{λ_j (t − a)}
//! (the phase's particular solution along the row r, and its transient: phase/particular.rs),
//! a signal whose smallest and largest values over the phase are the rigid margin's certified
//! search (signals.rs, `Signal::minimum_stepped`: 17 samples, intervals bisected where the bound
//! on the bend lets the signal pass the best value met). The period was sampled at 2 per radian of
//! the phase's fastest motion (≈ 3 300 samples on the coarse blade) and the Hermite minima refined
//! by Newton on flowed states: 4.1 ms a point, 13 % of the coarse rigid walk.
use super::super::signals::{Samples, Signal};
use super::PolishedOrbit;
use crate::periodic::OutputMap;
use nalgebra::DVector;

/// The extrema's tolerance over the signal's size ([`Signal::size`]): the amplitudes are written
/// with 16 digits.
const TOL: f64 = 1e-15;

impl PolishedOrbit {
    /// [`Self::amplitudes`] in closed form (see the module); `None` where a phase has no
    /// eigendecomposition (then from the sampled states).
    pub(super) fn output_amplitudes(&self, map: Option<&OutputMap>, dofs: &[usize]) -> Option<Vec<Option<f64>>> {
        let (n, w) = (self.model.n(), self.model.frequency);
        let rows: Vec<Option<Vec<(usize, f64)>>> = dofs
            .iter()
            .map(|&d| match map {
                Some(m) => m.rows.get(&d).cloned(),
                None => (d < n).then(|| vec![(d, 1.0)]),
            })
            .collect();
        let (mut lo, mut hi) = (vec![f64::INFINITY; dofs.len()], vec![f64::NEG_INFINITY; dofs.len()]);
        for e in 0..self.events.len().max(1) {
            let (a, b) = (self.times[e], self.end_of(e));
            let ph = &self.phases[e];
            let transient = ph.transient(a, &self.after[e])?;
            let signals: Vec<Option<Signal>> = rows
                .iter()
                .map(|row| {
                    let row = row.as_ref()?;
                    let mut rho = DVector::zeros(2 * n);
                    row.iter().for_each(|&(d, c)| rho[d] += c);
                    let harmonics = ph.particular_along(row).into_iter().map(|(p, x)| (p as f64 * w, x)).collect();
                    Some(Signal::new(a, transient.lambda.clone(), transient.coefficients(&rho), harmonics))
                })
                .collect();
            // One set of samples for every output (the same times and eigenvalues).
            let rates: Vec<f64> = signals.iter().flatten().flat_map(|s| s.rates()).collect();
            let samples = Samples::new(a, &transient.lambda, (a, b), rates.into_iter());
            for (k, signal) in signals.iter().enumerate() {
                let Some(signal) = signal else { continue };
                let tol = TOL * signal.size();
                lo[k] = lo[k].min(signal.minimum_stepped(&samples, tol).0);
                hi[k] = hi[k].max(-signal.negated().minimum_stepped(&samples, tol).0);
            }
        }
        Some(rows.iter().zip(lo.iter().zip(&hi)).map(|(row, (l, h))| row.as_ref().map(|_| 0.5 * (h - l))).collect())
    }
}
