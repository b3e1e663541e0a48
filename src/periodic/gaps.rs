//! Each contact's clearance sampled on the grid, kept by the problem: the samples depend on
//! neither ω nor the solution, yet the step map, the stacked LCP's q and the recovery each
//! sampled them (13 harmonics × k per contact, three times a solve: 4 % of the real blade's
//! 1e-3 sweep, issue 23). A problem cloned to another grid keeps its key and recomputes.
use super::PeriodicProblem;
use crate::model::{Contact, GridAngles};
use std::sync::{Arc, Mutex};

/// What the samples depend on: the instants, the periods they span, and each contact's static
/// gap and motion (amplitude, harmonic, phase) as bits.
type Key = (usize, usize, Vec<(u64, Vec<(u64, u32, u64)>)>);

/// Every contact's samples (model order), shared by the problem's clones.
type Samples = Arc<Vec<Vec<f64>>>;

/// The last samples computed, with their key.
#[derive(Debug, Default)]
pub(super) struct GapSamples(Mutex<Option<(Key, Samples)>>);

impl Clone for GapSamples {
    fn clone(&self) -> Self {
        GapSamples(Mutex::new(self.0.lock().ok().and_then(|kept| kept.clone())))
    }
}

fn key(contacts: &[Contact], instants: usize, periods: usize) -> Key {
    let motion = |c: &Contact| c.motion.iter().map(|h| (h.amplitude.to_bits(), h.harmonic, h.phase.to_bits())).collect();
    (instants, periods, contacts.iter().map(|c| (c.gap.to_bits(), motion(c))).collect())
}

impl PeriodicProblem {
    /// [`Contact::gap_samples`] of every contact (model order) at `instants` instants over the
    /// problem's periods, computed once per grid and model.
    pub(super) fn gap_samples(&self, instants: usize) -> Samples {
        let contacts = &self.model().contacts;
        let periods = self.period_multiple();
        let wanted = key(contacts, instants, periods);
        let mut kept = self.gaps.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some((k, samples)) = kept.as_ref()
            && *k == wanted
        {
            return Arc::clone(samples);
        }
        let angles = GridAngles::new(instants);
        let samples = Arc::new(contacts.iter().map(|c| c.gap_samples(&angles, periods)).collect::<Vec<_>>());
        *kept = Some((wanted, Arc::clone(&samples)));
        samples
    }
}

#[cfg(test)]
mod tests {
    use super::super::assembly::tests::chain_with_massless_boundary;
    use super::super::{OutputSelection, PeriodicProblem, SolverSettings};
    use crate::model::{Contact, GridAngles, Harmonic};
    use crate::time::{Discretization, Pairing, Scheme};

    fn direct(contacts: &[Contact], k: usize) -> Vec<Vec<f64>> {
        contacts.iter().map(|c| c.gap_samples(&GridAngles::new(k), 1)).collect()
    }

    /// The kept samples are each contact's own, and follow a new grid, a new clearance and a
    /// new motion.
    #[test]
    fn kept_gap_samples_follow_the_grid_and_the_contacts() {
        let mut model = chain_with_massless_boundary();
        model.contacts[0].motion = vec![Harmonic { amplitude: 2e-4, harmonic: 2, phase: 0.4 }, Harmonic { amplitude: -1e-4, harmonic: 5, phase: 1.1 }];
        let disc = Discretization { scheme: Scheme::Cds, steps: 64, pairing: Some(Pairing::Same) };
        let problem = PeriodicProblem::new(model.clone(), disc, OutputSelection::default(), SolverSettings::default()).unwrap();
        assert_eq!(*problem.gap_samples(64), direct(&model.contacts, 64));
        assert_eq!(*problem.gap_samples(64), direct(&model.contacts, 64), "kept");
        assert_eq!(*problem.gap_samples(128), direct(&model.contacts, 128), "another grid");
        model.contacts[1].gap = 2e-3;
        let moved = problem.with_model(model.clone(), disc).unwrap();
        assert_eq!(*moved.gap_samples(128), direct(&model.contacts, 128), "another clearance");
        model.contacts[0].motion[1].phase = 0.2;
        let mut moved = moved.with_model(model.clone(), disc).unwrap();
        assert_eq!(*moved.gap_samples(128), direct(&model.contacts, 128), "another motion");
        moved.set_discretization(Discretization { steps: 256, ..disc }).unwrap();
        assert_eq!(*moved.gap_samples(256), direct(&model.contacts, 256), "the grid changed in place");
    }
}
