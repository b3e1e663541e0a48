//! The corrector's stall with the smallest step on an orbit with rigid contacts.
use super::super::family::{Node, lambda_axis};
use super::super::{VANISH, Walk, signature};
use super::trace::{self, trace};
use super::{TOL, margin};
use crate::analysis::polish;

/// The longest phase (fraction of the period) merged at a stall: 100 × [`VANISH`]. The merges
/// seen at a stall were flights of 6.5e-7 … 2.5e-6 of the period (coarse blade, 2215.5 and
/// 2226.26 rad/s); the k = 4096 blade's stall at 2278.9746626 rad/s had no phase below 2.18e-3
/// (a real flight of contact 2, its merged orbit held by a force of −8.2e-3 of the scale).
const MERGE_MAX: f64 = 100.0 * VANISH;
/// How far past the stall (fractions of ρ, along the walk) the old signature is corrected at λ
/// fixed when its smallest margin sits at zero there: the change is that margin's crossing.
const AHEAD: [f64; 4] = [1e-8, 1e-7, 1e-6, 1e-5];

impl Walk<'_> {
    /// The corrector stalls at `here` with the smallest step on an orbit with rigid contacts:
    /// events merging (a flight between two impacts shrinking as the second impact fades, a pure
    /// impact starting to stick), where the old signature's Jacobian turns singular; or a margin
    /// reaching zero there (then located as a crossing from the old signature's orbit just past
    /// it). `None` without rigid contacts.
    pub(in super::super) fn rigid_stall(&mut self, here: &Node, to: f64) -> Option<Node> {
        let m = here.rigid_margin()?;
        self.diagnose_stall(here);
        let what = format!("the events merge (the corrector stalls; the smallest margin: contact {}'s {}, {:.1e})", m.contact, m.what, m.value);
        // The shortest phase between two events of one contact: the one merging.
        let (ne, n2) = (self.fam.ne(), here.w.len() - 1 - self.fam.ne());
        let pairs: Vec<_> = (0..ne)
            .filter_map(|e| signature::pair_phase(&self.fam, &here.w, e).map(|(b, length)| (e, b, length)))
            .map(|(e, b, length)| (e, self.fam.sig.events[e].contact, length, here.tangent[n2 + e] - here.tangent[n2 + b]))
            .collect();
        trace::stall(here, self.fam.rho, &pairs);
        let shortest = pairs.iter().min_by(|a, b| a.2.total_cmp(&b.2));
        // A phase far from vanishing is a real one: merging it changes the orbit, not a zero phase.
        match shortest {
            Some(&(e, _, len, _)) if len <= MERGE_MAX => {
                if let Some(n) = self.merge(here, e, &what) {
                    return Some(n);
                }
            }
            Some(&(e, _, len, _)) => trace(format_args!("stall: phase {e} ({len:e} of the period) above {MERGE_MAX:e}: not merged")),
            None => {}
        }
        if m.value.abs() <= TOL
            && let Some(n) = self.past_zero_margin(here, to)
        {
            return Some(n);
        }
        // A sticking landing whose force is at zero (the k = 4096 blade at 2278.9746626: contact
        // 1's, the old signature not correctable past it): the flight after it, started at λ fixed.
        if m.value.abs() <= TOL
            && m.what == polish::STUCK
            && let Some(e) = super::landing(here, m.contact, m.time)
        {
            let sense = here.tangent[here.tangent.len() - 1].signum();
            trace(format_args!("stall: contact {}'s landing (event {e}) at zero force: unmerged", m.contact));
            if let Some(n) = self.unmerge(here, None, e, sense, &what) {
                return Some(n);
            }
        }
        self.reseed(here, &what, to)
    }

    /// `here`'s smallest margin is at zero: the old signature's orbit a short way past it ([`AHEAD`]),
    /// corrected at λ fixed; where its margin is negative, the change located between them.
    fn past_zero_margin(&mut self, here: &Node, to: f64) -> Option<Node> {
        let (rho, d) = (self.fam.rho, self.fam.dim());
        let e_l = lambda_axis(d);
        let sense = here.tangent[d - 1].signum();
        for f in AHEAD {
            let l = here.lambda(rho) + sense * f * rho;
            let mut g = here.w.clone();
            g[d - 1] = l / rho;
            let next =
                super::super::profile::caller("stall", f64::NAN, || self.fam.correct(&g, &e_l, l / rho)).ok().and_then(|w| self.fam.node_with(w, &e_l, false));
            trace(format_args!(
                "stall: the old signature at λ {l:.10} ({f:e} of ρ): corrected {}, margin {:?}",
                next.is_some(),
                next.as_ref().and_then(|n| n.rigid_margin().map(|m| (m.contact, m.what, m.value, m.event, m.time / n.orbit.period())))
            ));
            if let Some(next) = next.filter(|n| margin(n) < -TOL) {
                return self.rigid_crossing(here, &next, to, false);
            }
        }
        None
    }
}
