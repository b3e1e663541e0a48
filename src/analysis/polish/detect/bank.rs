//! The phases of every contact set a sweep has met, kept across its points: a set absent from the
//! previous orbit (an iterate's, or one met some points before) is then re-tuned to the new ω
//! (its particular solution only) instead of made again with its eigendecomposition (on the
//! compliant real blade 1199 phases were made anew over 200 points, of 297 sets).
use super::super::phase::Phase;
use super::grid::Fixed;
use crate::model::Model;
use std::sync::Arc;

/// The most sets kept (~0.25 MB each on the 69-DOF blade); the least recently used goes first.
const CAPACITY: usize = 512;

/// The phases kept, by closed set, for one system (`model` up to its frequency).
#[derive(Default)]
pub struct PhaseBank {
    model: Option<Model>,
    /// (last use, closed set, phase, its switch-search grid's ω-independent part).
    phases: Vec<(u64, Vec<usize>, Phase, Arc<Fixed>)>,
    clock: u64,
}

impl PhaseBank {
    /// The phase of the closed set `closed` kept, at the ω it was made, and its grid's
    /// ω-independent part; `same` is [`Self::is_for`] of the model asked for (compared once per point).
    pub(super) fn find(&self, same: bool, closed: &[usize]) -> Option<(&Phase, &Arc<Fixed>)> {
        same.then(|| self.phases.iter().find(|(_, set, _, _)| set == closed).map(|(_, _, p, f)| (p, f))).flatten()
    }

    /// Whether the bank holds phases of `model`'s system (`model` up to its frequency).
    pub(super) fn is_for(&self, model: &Model) -> bool {
        self.model.as_ref().is_some_and(|m| super::same_system(model, m))
    }

    /// Keeps `phases` (of `model`, with their grids' ω-independent parts), replacing those of the
    /// same sets; a new system empties the bank.
    pub(super) fn keep(&mut self, model: &Model, phases: Vec<(Phase, Arc<Fixed>)>) {
        if !self.is_for(model) {
            self.model = Some(model.clone());
            self.phases.clear();
        }
        self.clock += 1;
        for (p, f) in phases {
            let set: Vec<usize> = (0..model.contacts.len()).filter(|&i| p.closed(i)).collect();
            match self.phases.iter_mut().find(|(_, s, _, _)| *s == set) {
                Some(slot) => *slot = (self.clock, set, p, f),
                None => self.phases.push((self.clock, set, p, f)),
            }
        }
        while self.phases.len() > CAPACITY {
            let oldest = self.phases.iter().enumerate().min_by_key(|(_, (t, _, _, _))| *t).map(|(k, _)| k).expect("over capacity");
            self.phases.swap_remove(oldest);
        }
    }
}
