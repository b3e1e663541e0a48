//! [`PolishedOrbit::amplitudes`]' samples in closed form, without the states: along phase e
//! from its start a, an output's value is r·x(t) = Re Σ_p r·X̂_p e^{ipωt} + Re Σ_j m_j e^{λ_j (t − a)}
//! (the phase's particular solution along the row r, and its transient: phase/particular.rs),
//! its slope the same with ipω and λ_j; e^{λ_j h} is made once per phase and turned per sample,
//! e^{ipωt} once per sample for every output. The samples, their extrema's selection and
//! refinement are [`Sampled`]'s (a full state per sample cost most of an exact point's outputs).
use super::{PolishedOrbit, Sampled, user_value};
use crate::periodic::OutputMap;
use nalgebra::DVector;
use num_complex::Complex64 as C;

/// An output row's modal coefficients m_j and λ_j m_j, and r·X̂_p per harmonic order p.
type RowParts = (Vec<C>, Vec<C>, Vec<(u32, C)>);

impl PolishedOrbit {
    /// [`Self::amplitudes`] from the samples in closed form (see the module); `None` where a
    /// phase has no eigendecomposition (then from the sampled states).
    pub(super) fn output_amplitudes(&self, map: Option<&OutputMap>, dofs: &[usize]) -> Option<Vec<Option<f64>>> {
        let (n, w) = (self.model.n(), self.model.frequency);
        let rows: Vec<Option<Vec<(usize, f64)>>> = dofs
            .iter()
            .map(|&d| match map {
                Some(m) => m.rows.get(&d).cloned(),
                None => (d < n).then(|| vec![(d, 1.0)]),
            })
            .collect();
        let mut samples = Vec::new();
        let (mut at, mut at_end) = (vec![Vec::new(); dofs.len()], vec![Vec::new(); dofs.len()]);
        for e in 0..self.events.len().max(1) {
            let (a, b, h, count) = self.sample_grid(e);
            let ph = &self.phases[e];
            let transient = ph.transient(a, &self.after[e])?;
            let lambda = &transient.lambda;
            // Per output: the modal coefficients m_j and λ_j m_j, and r·X̂_p per harmonic.
            let parts: Vec<Option<RowParts>> = rows
                .iter()
                .map(|row| {
                    let row = row.as_ref()?;
                    let mut rho = DVector::zeros(2 * n);
                    row.iter().for_each(|&(d, c)| rho[d] += c);
                    let m = transient.coefficients(&rho);
                    let dm = m.iter().zip(lambda).map(|(m, l)| m * l).collect();
                    Some((m, dm, ph.particular_along(row)))
                })
                .collect();
            let mut orders: Vec<u32> = parts.iter().flatten().flat_map(|p| p.2.iter().map(|(q, _)| *q)).collect();
            // One e^{ipωt} per order, not per output's harmonic (the same values).
            orders.sort_unstable();
            orders.dedup();
            // (value, slope) of every output at t, the transient's exponentials being `modes`.
            let jets = |t: f64, modes: &[C]| {
                let turns: Vec<(u32, C)> = orders.iter().map(|&p| (p, C::from_polar(1.0, p as f64 * w * t))).collect();
                parts
                    .iter()
                    .map(|part| {
                        let Some((m, dm, harmonics)) = part else { return (0.0, 0.0) };
                        let mut v: f64 = m.iter().zip(modes).map(|(m, z)| (m * z).re).sum();
                        let mut d: f64 = dm.iter().zip(modes).map(|(m, z)| (m * z).re).sum();
                        for (p, x) in harmonics {
                            let z = x * turns.iter().find(|(q, _)| q == p).map_or(C::new(1.0, 0.0), |(_, u)| *u);
                            v += z.re;
                            d -= *p as f64 * w * z.im;
                        }
                        (v, d)
                    })
                    .collect::<Vec<(f64, f64)>>()
            };
            let step: Vec<C> = lambda.iter().map(|l| (l * h).exp()).collect();
            let mut modes = vec![C::new(1.0, 0.0); lambda.len()];
            for j in 0..count {
                if j > 0 {
                    modes.iter_mut().zip(&step).for_each(|(z, s)| *z *= s);
                }
                for (k, jet) in jets(a + h * j as f64, &modes).into_iter().enumerate() {
                    at[k].push(jet);
                }
                samples.push((a + h * j as f64, e));
            }
            let end: Vec<C> = lambda.iter().map(|l| (l * (b - a)).exp()).collect();
            for (k, jet) in jets(b, &end).into_iter().enumerate() {
                at_end[k].push(jet);
            }
        }
        let sampled = Sampled { samples, states: Vec::new(), ends: Vec::new() };
        let out = rows
            .iter()
            .enumerate()
            .map(|(k, row)| {
                row.as_ref()?;
                let dof = dofs[k];
                let full = |sign: f64| {
                    move |e: usize, y: &DVector<f64>, t: f64| {
                        let value = user_value(map, dof, y, 0, n).unwrap_or(0.0);
                        let slope = user_value(map, dof, y, n, n).unwrap_or(0.0);
                        let bend = user_value(map, dof, &self.phases[e].acceleration(y, t), 0, n).unwrap_or(0.0);
                        (sign * value, sign * slope, sign * bend)
                    }
                };
                let flip = |v: &[(f64, f64)]| v.iter().map(|(a, b)| (-a, -b)).collect::<Vec<_>>();
                let lo = sampled.smallest_of(self, (&at[k], &at_end[k]), &full(1.0), &|_| false, true)?.0;
                let hi = -sampled.smallest_of(self, (&flip(&at[k]), &flip(&at_end[k])), &full(-1.0), &|_| false, true)?.0;
                Some(0.5 * (hi - lo))
            })
            .collect();
        Some(out)
    }
}
