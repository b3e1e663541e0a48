//! Each contact's gap samples (static clearance and casing motion) on the problem's grid, kept
//! per grid: they depend on neither ω nor the forces. Why: the step map, the LCP's q and the
//! recovery each sampled them at every solve, 5 % of the real blade's 200-point sweep (issue 23).
use super::PeriodicProblem;
use crate::model::GridAngles;
use std::sync::{Arc, Mutex};

/// The samples of every contact per (instants, period multiple) grid, shared by the clones of one
/// problem (the model's contacts are the same in each: a new model builds a new problem).
#[derive(Clone, Debug, Default)]
pub(super) struct GapSamples(Arc<Mutex<Vec<GridGaps>>>);

/// (instants, period multiple) and each contact's gap at those instants.
type GridGaps = ((usize, usize), Arc<Vec<Vec<f64>>>);

impl PeriodicProblem {
    /// gap_c(t_j) of every contact c at the problem's instants ([`crate::model::Contact::gap_samples`]),
    /// computed on the first call for this grid.
    pub(super) fn gap_samples(&self) -> Arc<Vec<Vec<f64>>> {
        let key = (self.instants(), self.period_multiple());
        // A panic elsewhere while the lock was held leaves whole entries only.
        let mut grids = self.gaps.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, gaps)) = grids.iter().find(|(k, _)| *k == key) {
            return Arc::clone(gaps);
        }
        let angles = GridAngles::new(key.0);
        let gaps = Arc::new(self.model().contacts.iter().map(|c| c.gap_samples(&angles, key.1)).collect::<Vec<_>>());
        grids.push((key, Arc::clone(&gaps)));
        gaps
    }
}
