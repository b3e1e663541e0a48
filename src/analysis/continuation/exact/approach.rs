//! A rigid contact's flight between a pure impact and the sticking impact after it, predicted to
//! vanish within the step: merged where the merged orbit's landing force crosses zero (located
//! there to the bracket, [`Walk::held_merge`]) instead of landed on by quarters. On the coarse
//! rigid blade at 2390–2398 rad/s contacts 0 and 2 open and close such flights every 0.2–0.6
//! rad/s, and the quarters took 10–15 points per merge (validation/RECORD.md, session 21). A
//! massless contact's short phase is landed on at its end with its length fixed ([`Walk::land`]).
use super::family::Node;
use super::{Switch, VANISH, Walk, rigid, signature};

/// Flights shorter than this (fraction of the period) are merged ahead when the step would reach
/// their vanishing; longer ones are walked (the merged orbit far from theirs, its zero not near).
const EARLY: f64 = 1e-4;
/// A phase shorter than this that binds the step is landed on at once ([`Walk::land`]).
const LAND_FROM: f64 = 1e-3;
/// The length (fraction of the period) such a landing fixes: below [`VANISH`], so it is a grazing.
const LANDING: f64 = 0.5 * VANISH;

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

    /// The point where the phase whose vanishing binds the step (among `shrinking`, shorter than
    /// [`LAND_FROM`]) is [`LANDING`] long, corrected with that length fixed, and the arclength to
    /// it. A massless contact's phase goes as √ in λ, so the branch turns in λ where it vanishes and
    /// steps along the tangent land on it by quarters with a failed corrector each (≈ 20 points per
    /// vanishing on the real blade); the family is smooth in the phase's length there, so Newton
    /// at a fixed length is regular (Allgower & Georg 1990, §10.2: local parametrisation by the
    /// coordinate the tangent favours). `None` where it fails: the quarters go on.
    pub(super) fn land(&mut self, here: &Node, shrinking: &[(usize, f64, f64)], along: &[f64]) -> Option<(Node, f64)> {
        let &(e, len, rate) = shrinking.iter().min_by(|a, b| (a.1 / a.2).total_cmp(&(b.1 / b.2)))?;
        // Massless rigid contacts only: their phases end as √ in λ. Where a contact has mass, the
        // coarse rigid blade's events lie on the step path (the 2351.193 cluster, a period doubling
        // at 2400.63 rad/s lost when its landings were taken this way; validation/RECORD.md).
        let model = self.problem.model();
        let contact = &model.contacts[self.fam.sig.events[e].contact];
        if len > LAND_FROM || len <= LANDING || !contact.is_rigid() || !model.contact_is_massless(contact) {
            return None;
        }
        let ne = self.fam.ne();
        let n2 = here.w.len() - 1 - ne;
        let b = signature::partner(self.fam.base(), &self.fam.sig.events, e)?;
        let mut normal = vec![0.0; here.w.len()];
        (normal[n2 + b], normal[n2 + e]) = (1.0, -1.0);
        let wrap = if b <= e { 1.0 } else { 0.0 };
        let h = (len - LANDING) / rate;
        let pred: Vec<f64> = here.w.iter().zip(along).map(|(w, t)| w + h * t).collect();
        let w = super::profile::caller("land", h, || self.fam.correct(&pred, &normal, LANDING - wrap)).ok()?;
        let n = self.fam.node_with(w, along, false)?;
        let metric = &self.fam.metric;
        let drift = metric.norm(&n.w.iter().zip(&pred).map(|(a, b)| a - b).collect::<Vec<_>>());
        let s = metric.norm(&n.w.iter().zip(&here.w).map(|(a, b)| a - b).collect::<Vec<_>>());
        // The predictor overshoots a √ phase's end by about half its step; farther is another branch.
        // An orbit that breaks a rigid margin is past another change (the real blade at 1149.0959492
        // rad/s: contact 15's arc with another contact's event in it, landed on 8e-6 rad/s early).
        let near = drift <= h && s <= 2.0 * h && rigid::margin(&n) >= -1e-9;
        if std::env::var_os("PC_TRACE_STEP").is_some() {
            eprintln!(
                "landing: phase {e} {len:.2e} → {LANDING:e}, step {h:.2e}, drift {drift:.2e}, arclength {s:.2e}: {}",
                if near { "kept" } else { "refused" }
            );
        }
        // Events that passed each other in the step are the quarters' to re-order (`Walk::pass`).
        let theta = &n.w[n2..n2 + ne];
        let ordered = theta.windows(2).all(|p| p[1] > p[0]) && theta.last().zip(theta.first()).is_some_and(|(l, f)| l - f < 1.0);
        if !near || !ordered || signature::reversed(&self.fam, &n.w) {
            return None;
        }
        self.drift = drift / h;
        Some((n, s))
    }
}
