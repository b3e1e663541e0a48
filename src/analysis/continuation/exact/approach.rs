//! A rigid contact's flight between a pure impact and the sticking impact after it, predicted to
//! vanish within the step: merged where the merged orbit's landing force crosses zero (located
//! there to the bracket, [`Walk::held_merge`]) instead of landed on by quarters. On the coarse
//! rigid blade at 2390–2398 rad/s contacts 0 and 2 open and close such flights every 0.2–0.6
//! rad/s, and the quarters took 10–15 points per merge (validation/RECORD.md, session 21).
use super::family::Node;
use super::{Switch, Walk, rigid};

/// Flights shorter than this (fraction of the period) are merged ahead when the step would reach
/// their vanishing; longer ones are walked (the merged orbit far from theirs, its zero not near).
const EARLY: f64 = 1e-4;

impl Walk<'_> {
    /// The first point of the merged branch, when a pure impact → sticking impact flight among
    /// `shrinking` ((phase, length, rate per unit arclength), [`super::signature::shrinking`]) is
    /// shorter than [`EARLY`] and vanishes within the step `ds` (the quarters' rule would bind);
    /// `None` otherwise or where the landing force's zero is not found ahead.
    pub(super) fn early_merge(&mut self, here: &Node, shrinking: &[(usize, f64, f64)], ds: f64) -> Option<Node> {
        let ne = self.fam.ne();
        let flight = |e: usize| {
            (self.fam.sig.events[e].kind, self.fam.sig.events[(e + 1) % ne].kind) == (Switch::Impact { stick: false }, Switch::Impact { stick: true })
        };
        let &(e, len, _) = shrinking.iter().find(|&&(e, len, rate)| len < EARLY && 0.75 * len / rate < ds && self.rigid_event(e) && flight(e))?;
        let mut list = rigid::timed(&here.orbit);
        list.remove(e);
        let what = format!("contact {}: its free phase vanishes ({len:.1e} of the period, merged ahead)", self.fam.sig.events[e].contact);
        self.held_merge(here, &list, if e + 1 < ne { e } else { 0 }, &what)
    }
}
