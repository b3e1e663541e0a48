//! The rigid changes' trace on stderr (`PC_TRACE_UNMERGE` set): why a restart or a merge fails.
use super::super::family::{Family, Node};
use super::super::signature;
use crate::analysis::polish::Event;

/// A line of the trace on stderr when `PC_TRACE_UNMERGE` is set.
pub(super) fn trace(line: std::fmt::Arguments) {
    if tracing() {
        eprintln!("{line}");
    }
}

/// Whether the trace is on: for a line whose arguments cost (format_args! evaluates them anyway).
pub(super) fn tracing() -> bool {
    std::env::var_os("PC_TRACE_UNMERGE").is_some()
}

/// A flight `e` of `contact` (release → sticking landing) about to be merged at `here`: the orbit's
/// events within 2e-3 of the period of it (`list`, fractions of the period), the family's θ of
/// the pair (`ne` events in the family's signature), and the old orbit's margin.
pub(super) fn merge(here: &Node, list: &[(f64, Event)], (e, ne): (usize, usize), contact: usize, removed: bool) {
    if std::env::var_os("PC_TRACE_UNMERGE").is_none() {
        return;
    }
    let n2 = here.w.len() - 1 - ne;
    let theta = (here.w[n2 + e], here.w[n2 + (e + 1) % ne]);
    eprintln!("merge: flight {e} of contact {contact} removed: {removed}; the family's θ of the pair {theta:?} ({ne} events; the orbit {})", list.len());
    let t0 = list[e].0;
    for (k, (at, x)) in list.iter().enumerate().filter(|(_, l)| ((l.0 - t0 + 0.5).rem_euclid(1.0) - 0.5).abs() < 2e-3) {
        eprintln!("merge: orbit event {k} at {at:.12} of the period: contact {} {:?}", x.contact, x.kind);
    }
    if let Some(m) = here.rigid_margin() {
        eprintln!("merge: the old orbit's margin: contact {} {} {:e} at {:.12}", m.contact, m.what, m.value, m.time / here.orbit.period());
    }
}

/// The corrector stalled at `here` (`rigid_stall`): λ, the tangent's λ-component and every
/// phase between two events of one contact (`pairs`: event, contact, length and rate of
/// shrinking along the tangent, fractions of the period).
pub(super) fn stall(here: &Node, rho: f64, pairs: &[(usize, usize, f64, f64)]) {
    if std::env::var_os("PC_TRACE_UNMERGE").is_none() {
        return;
    }
    let t = &here.tangent;
    eprintln!("stall: rigid_stall at λ {:.10}, the tangent's λ-component {:e}, {} pair phases", here.lambda(rho), t[t.len() - 1], pairs.len());
    let mut sorted = pairs.to_vec();
    sorted.sort_by(|a, b| a.2.total_cmp(&b.2));
    for (e, c, len, rate) in sorted {
        eprintln!("stall: phase {e} of contact {c}: {len:e} of the period, shrinking at {rate:e} per unit of arclength");
    }
    // The events within 2e-3 of the period of the smallest margin: is it at a landing?
    if let Some(m) = here.rigid_margin() {
        let (p, at) = (here.orbit.period(), m.time / here.orbit.period());
        eprintln!("stall: the smallest margin: contact {} {} {:e} at {at:.9} (event {:?})", m.contact, m.what, m.value, m.event);
        for (k, (x, s)) in here.orbit.events().iter().zip(here.orbit.times()).enumerate() {
            if ((s / p - at + 0.5).rem_euclid(1.0) - 0.5).abs() < 2e-3 {
                eprintln!("stall: event {k} at {:.9}: contact {} {:?}", s / p, x.contact, x.kind);
            }
        }
    }
}

/// A massless contact's held arc from event `e` about to be removed at `here`: its end (the
/// [`signature::partner`]), its length and rate, the other contacts' events inside it (θ).
pub(super) fn held_arc(here: &Node, fam: &Family, e: usize) {
    if std::env::var_os("PC_TRACE_UNMERGE").is_none() {
        return;
    }
    let ne = fam.ne();
    let n2 = here.w.len() - 1 - ne;
    let Some((b, len)) = signature::pair_phase(fam, &here.w, e) else { return };
    let rate = here.tangent[n2 + e] - here.tangent[n2 + b];
    let t = &here.tangent;
    eprintln!(
        "held arc: contact {} events {e} → {b} at θ {:.13} → {:.13}: {len:e} of the period, shrinking at {rate:e} per unit of arclength (λ-component {:e}) at λ {:.10}",
        fam.sig.events[e].contact,
        here.w[n2 + e],
        here.w[n2 + b],
        t[t.len() - 1],
        here.lambda(fam.rho)
    );
    let mut k = (e + 1) % ne;
    while k != b {
        eprintln!("held arc:   inside: event {k} contact {} {:?} at θ {:.13}", fam.sig.events[k].contact, fam.sig.events[k].kind, here.w[n2 + k]);
        k = (k + 1) % ne;
    }
}
