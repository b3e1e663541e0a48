//! A massless contact's held arc vanishing, located on the orbit without it. With another
//! contact's event inside the arc (the real blade at 2278.97466 rad/s: contact 13's arc with
//! contact 15's landing in it, holding 15 relieving 13) the arc shrinks linearly in λ, not as a
//! √, so the point where it is below [`super::super::VANISH`] lies a finite way before its zero
//! (3e-5 rad/s there, the orbit without it penetrating by 2e-8 of the clearance scale). Where the
//! orbit without the arc is admissible at the merge already, a sign change found further on is
//! another contact's change, refused (the real blade at 1124.34 rad/s: contact 16's arc merged at
//! another contact's change 0.09 rad/s on, and the walk turned back up, validation/RECORD.md).
use super::super::family::Node;
use super::super::{Walk, signature};
use super::{timed, trace};

impl Walk<'_> {
    /// The branch past `here` without contact `events[e].contact`'s held arc from event `e` to
    /// its [`signature::partner`] (a massless contact: closing and release without impulse):
    /// the grazing located where the orbit without the arc touches the stop (bisection on its
    /// margin, [`Walk::fade`]), a short way ahead of `here` (the arc's length over its rate of
    /// shrinking, along λ); else that orbit's branch from `here` ([`Walk::restart`]).
    pub(super) fn merge_held_arc(&mut self, here: &Node, e: usize, what: &str) -> Option<Node> {
        trace::held_arc(here, &self.fam, e);
        let (ne, rho) = (self.fam.ne(), self.fam.rho);
        let (b, len) = signature::pair_phase(&self.fam, &here.w, e)?;
        let n2 = here.w.len() - 1 - ne;
        let rate = here.tangent[n2 + e] - here.tangent[n2 + b];
        let t_l = here.tangent[here.tangent.len() - 1];
        let (lambda, sense) = (here.lambda(rho), t_l.signum());
        let ahead = if rate > 0.0 { (len / rate * t_l).abs() } else { 0.0 };
        let mut reach = vec![1.5 * ahead, 3.0 * ahead, 1e-5, 1e-4, 1e-3];
        reach.retain(|f| *f > 0.0 && *f <= 1e-2);
        reach.sort_by(f64::total_cmp);
        let list: Vec<_> = timed(&here.orbit).into_iter().enumerate().filter(|(i, _)| *i != e && *i != b).map(|(_, l)| l).collect();
        // Another contact's change ahead is the next one, not this arc's end (`touch_point`'s `own`).
        let own = Some(self.fam.sig.events[e].contact);
        if let Some(n) = reach.into_iter().find_map(|f| self.fade((lambda, lambda + sense * f * rho), here, list.clone(), what, ("the held arc", own))) {
            return Some(n);
        }
        let (sig, guess) = signature::remove(&self.fam, &here.orbit, e, here.w[here.w.len() - 1])?;
        self.restart(here, sig, guess, what)
    }
}
