//! The orbits whose phases the exact walk's orbit builds share ([`Modes`]), at most [`KEPT`].
use crate::analysis::polish::{Event, EventKind, PolishedOrbit};
use crate::model::Model;

/// A signature's events (contact, kind) and its contacts closed all period long.
pub(super) type SignatureKey = (Vec<(usize, EventKind)>, Vec<usize>);

/// The most orbits kept (one per signature met; the real blade's tips' events pass each other
/// every few points, each new order a signature): unbounded, they were the walk's growing memory
/// (heap +1.3 MB a point, 3.9 GiB at 2153 points; validation/RECORD.md). A phase dropped with its
/// orbit is made again where its contact set comes back, bit for bit (the same CSV with 2 kept).
const KEPT: usize = 32;

/// The first orbit built of each signature met, whose phases' eigendecompositions every later
/// orbit shares (the phase matrices do not depend on the parameter: one decomposition per contact
/// set). With the first orbit's only, every orbit past the coarse blade's first grazing decomposed
/// its new phases again: a quarter of the walk's time. Each with its last use: the least recently
/// used goes first.
#[derive(Default)]
pub(super) struct Modes {
    orbits: Vec<(SignatureKey, PolishedOrbit, u64)>,
    /// The builds made (the clock of the uses).
    clock: u64,
}

impl Modes {
    /// The orbit of the signature `key` (`events`, `always`) for `model`, its phases re-tuned from
    /// the kept orbits': the signature's own first, then any other's.
    pub fn build(&mut self, key: SignatureKey, model: &Model, events: Vec<Event>, always: &[usize]) -> Option<PolishedOrbit> {
        self.clock += 1;
        let mut bank: Vec<&PolishedOrbit> = self.orbits.iter().filter(|(k, _, _)| *k == key).map(|(_, o, _)| o).collect();
        let known = !bank.is_empty();
        bank.extend(self.orbits.iter().filter(|(k, _, _)| *k != key).map(|(_, o, _)| o));
        let orbit = PolishedOrbit::unsolved_retuning(model, events, always, &bank).ok()?;
        if known {
            let clock = self.clock;
            self.orbits.iter_mut().filter(|(k, _, _)| *k == key).for_each(|m| m.2 = clock);
        } else {
            if self.orbits.len() >= KEPT
                && let Some(oldest) = self.orbits.iter().enumerate().min_by_key(|(_, m)| m.2).map(|(i, _)| i)
            {
                self.orbits.swap_remove(oldest);
            }
            self.orbits.push((key, orbit.clone(), self.clock));
        }
        Some(orbit)
    }
}
