//! The contacts' forces along the polished orbit for the written series: each rigid contact's
//! force over a step (impulses plus the held force's integral, 5-point Gauss–Legendre between
//! events, as the LCP reports impulse per step), with the held and compliant forces in closed form
//! along a phase with an eigendecomposed Â (as the admissibility check's signals, signals.rs):
//! s(t) = Re Σ_j m_j e^{λ_j (t − a)} + Re Σ_p ĥ_p e^{ipωt}, the exponentials shared by every
//! contact. A node cost a flow of the full state and the stuck forces' n-sized products before
//! (the 1024 instants' 5 nodes were a third of the real blade's polish).
use super::orbit::PolishedOrbit;
use crate::model::Compliance;
use nalgebra::DVector;
use num_complex::Complex64 as C;

/// What a contact's force is in a phase: none (a free rigid contact), the held force of a stuck
/// one, or a compliant one's stiffness times its penetration (the signal is its clearance).
#[derive(Clone, Copy)]
enum Kind {
    Free,
    Held,
    Spring(f64),
}

/// Every contact's force signal along one phase (see the module).
pub(super) struct PhaseForces {
    start: f64,
    lambda: Vec<C>,
    /// The harmonics' rates pω.
    rates: Vec<f64>,
    /// Per contact: its kind, modal coefficients m_j and harmonic amplitudes ĥ_p (over `rates`).
    contacts: Vec<(Kind, Vec<C>, Vec<C>)>,
}

impl PhaseForces {
    /// Every contact's force at `t` of the phase.
    fn at(&self, t: f64) -> Vec<f64> {
        let modes: Vec<C> = self.lambda.iter().map(|l| (l * (t - self.start)).exp()).collect();
        let waves: Vec<C> = self.rates.iter().map(|w| C::from_polar(1.0, w * t)).collect();
        let signal = |m: &[C], h: &[C]| m.iter().zip(&modes).map(|(a, b)| (a * b).re).sum::<f64>() + h.iter().zip(&waves).map(|(a, b)| (a * b).re).sum::<f64>();
        self.contacts
            .iter()
            .map(|(kind, m, h)| match kind {
                Kind::Free => 0.0,
                Kind::Held => signal(m, h),
                Kind::Spring(k) => k * (-signal(m, h)).max(0.0),
            })
            .collect()
    }
}

impl PolishedOrbit {
    /// Phase `e`'s [`PhaseForces`]; `None` without an eigendecomposition (its flows are Padé's).
    fn phase_forces(&self, e: usize) -> Option<PhaseForces> {
        let (model, ph) = (&self.model, &self.phases[e]);
        let (n, w) = (model.n(), model.frequency);
        let start = self.times[e];
        let transient = ph.transient(start, &self.after[e])?;
        let part = ph.particular();
        let stuck: Vec<usize> = ph.stuck_contacts().collect();
        let held = if stuck.is_empty() { vec![] } else { ph.stuck_force_particular(&part) };
        let mut orders: Vec<u32> = part.iter().map(|(p, _)| *p).chain(self.gaps.iter().flatten().map(|(p, _)| *p)).collect();
        orders.sort_unstable();
        orders.dedup();
        let slot = |p: u32| orders.iter().position(|&q| q == p).expect("collected");
        let mut contacts = Vec::with_capacity(model.contacts.len());
        for (i, c) in model.contacts.iter().enumerate() {
            let mut h = vec![C::new(0.0, 0.0); orders.len()];
            let (kind, rho) = if let Some(s) = stuck.iter().position(|&k| k == i) {
                held.iter().for_each(|(p, z)| h[slot(*p)] += z[s]);
                (Kind::Held, ph.stuck_force_gradient().row(s).transpose())
            } else if let Compliance::Compliant { stiffness } = c.compliance {
                // gap(t) − B_i x(t).
                let mut rho = DVector::zeros(2 * n);
                c.row.iter().for_each(|&(d, cd)| rho[d] = -cd);
                self.gaps[i].iter().for_each(|(p, g)| h[slot(*p)] += g[0]);
                part.iter().for_each(|(p, y)| h[slot(*p)] -= c.along(|d| y[d]));
                (Kind::Spring(stiffness), rho)
            } else {
                contacts.push((Kind::Free, vec![], vec![]));
                continue;
            };
            contacts.push((kind, transient.coefficients(&rho), h));
        }
        Some(PhaseForces { start, lambda: transient.lambda.clone(), rates: orders.iter().map(|&p| p as f64 * w).collect(), contacts })
    }

    /// Every phase's [`PhaseForces`], for [`Self::force_integrals`].
    pub(super) fn all_phase_forces(&self) -> Vec<Option<PhaseForces>> {
        (0..self.phases.len()).map(|e| self.phase_forces(e)).collect()
    }

    /// ∫ of every contact's force over [a, b] plus its impulses in [a, b), by 5-point
    /// Gauss–Legendre on each piece between events (the forces in closed form where `forces` has
    /// the phase's, else from the state).
    pub(super) fn force_integrals(&self, forces: &[Option<PhaseForces>], a: f64, b: f64) -> Vec<f64> {
        const X: [f64; 5] = [0.0, -0.538_469_310_105_683, 0.538_469_310_105_683, -0.906_179_845_938_664, 0.906_179_845_938_664];
        const W: [f64; 5] = [0.568_888_888_888_889, 0.478_628_670_499_366, 0.478_628_670_499_366, 0.236_926_885_056_189, 0.236_926_885_056_189];
        let mut cuts = vec![a, b];
        let mut total = vec![0.0; self.model.contacts.len()];
        for (e, (&t, &p)) in self.times.iter().zip(&self.impulses).enumerate() {
            for tk in [t - self.period, t, t + self.period] {
                if tk >= a && tk < b {
                    cuts.push(tk);
                    if let Some(ev) = self.events.get(e) {
                        total[ev.contact] += p;
                    }
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        for w in cuts.windows(2) {
            let (c, h) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
            if h > 0.0 {
                for (x, wt) in X.iter().zip(W) {
                    let t = c + h * x;
                    let (e, tt) = self.locate(t);
                    let f = match &forces[e] {
                        Some(pf) => pf.at(tt),
                        None => self.contact_forces(t),
                    };
                    for (sum, f) in total.iter_mut().zip(f) {
                        *sum += h * wt * f;
                    }
                }
            }
        }
        total
    }

    /// The grid LCP's active set of this orbit on `problem`'s k instants (z indices j·m + i, as
    /// its solve reports them and [`Self::write`] reads them): a rigid contact's instants whose
    /// impulse over the step is positive, a compliant one's whose paired clearance is negative.
    /// A warm start for the grid LCP on this orbit's branch (one period T).
    pub fn active_set(&self, problem: &crate::periodic::PeriodicProblem) -> Vec<usize> {
        let (k, m) = (problem.instants(), self.model.contacts.len());
        let h = self.period / k as f64;
        let forces = self.all_phase_forces();
        let mut set = Vec::new();
        for j in 0..k {
            let t = j as f64 * h;
            let impulses = self.force_integrals(&forces, t, t + h);
            for (i, c) in self.model.contacts.iter().enumerate() {
                let active = match c.compliance {
                    Compliance::Rigid => impulses[i] > 0.0,
                    Compliance::Compliant { .. } => {
                        let tp = ((j + problem.pairing_at(i).offset()) % k) as f64 * h;
                        self.clearance(i, &self.state(tp), tp) < 0.0
                    }
                };
                if active {
                    set.push(j * m + i);
                }
            }
        }
        set
    }
}
