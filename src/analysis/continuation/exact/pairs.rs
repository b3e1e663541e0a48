//! A pair of events of one contact removed where the phase between them has vanished, or
//! inserted at a grazing; the multiplier events across such a change.
use super::family::{Node, Signature, lambda_axis};
use super::locate::{detail_of, side};
use super::{EventKind, NEW_PAIR, Switch, Walk, signature};

impl Walk<'_> {
    /// The grazing at `here` where phase `e` has vanished: the point recorded, the pair of
    /// events removed, and the first point of the branch without it, oriented in the parameter
    /// as the branch came.
    pub(super) fn remove_pair(&mut self, here: &Node, e: usize) -> Option<Node> {
        let rho = self.fam.rho;
        let ev = self.fam.sig.events[e];
        let before = self.fam.ne();
        let (sig, guess) = signature::remove(&self.fam, &here.orbit, e, here.w[here.w.len() - 1])?;
        let detail = format!(
            "contact {}: events per period {before} -> {} (its {} phase vanishes)",
            ev.contact,
            sig.events.len(),
            if ev.kind == Switch::On { "closed" } else { "open" }
        );
        self.push(here, Some(EventKind::Grazing), detail);
        self.fam.sig = sig;
        let d = self.fam.dim();
        let e_l = lambda_axis(d);
        let w = super::profile::caller("pair", f64::NAN, || self.fam.correct(&guess, &e_l, here.lambda(rho) / rho)).ok()?;
        let sign = here.tangent[here.tangent.len() - 1].signum();
        let prev: Vec<f64> = e_l.iter().map(|x| x * if sign == 0.0 { 1.0 } else { sign }).collect();
        self.fam.node(w, &prev)
    }

    /// The grazing at `lo`, the last point after `here` where no contact's clearance has crossed
    /// zero between its events (located on the arc): recorded with the events between, the
    /// pair of events inserted around the touch, and the first point of the branch with its phase
    /// [`NEW_PAIR`] long.
    pub(super) fn insert_pair(&mut self, here: &Node, lo: &Node) -> Option<Node> {
        for (kind, node, detail) in self.events_between(here, lo) {
            self.push(&node, Some(kind), detail);
        }
        let touch = *lo.worst_touch()?;
        let before = self.fam.ne();
        let wl = lo.w[lo.w.len() - 1];
        let kinds = if touch.closed { (Switch::Off, Switch::On) } else { (Switch::On, Switch::Off) };
        let (sig, guess, pair) = signature::insert(&self.fam, &lo.orbit, &touch, kinds, NEW_PAIR, wl);
        let detail = format!(
            "contact {}: events per period {before} -> {} ({} phase begins)",
            touch.contact,
            sig.events.len(),
            if touch.closed { "an open" } else { "a closed" }
        );
        self.push(lo, Some(EventKind::Grazing), detail);
        let first = self.open_phase(sig, &guess, pair, NEW_PAIR)?;
        self.multipliers_across(lo, &first);
        Some(first)
    }

    /// The first point of the branch of signature `sig` whose phase between its events `ia` and
    /// `ib` (one contact's) begins at a grazing: corrected from `guess` with that phase `len`
    /// ([`NEW_PAIR`] or shorter) and twice that long, its tangent along the secant (the phase
    /// growing). The family keeps its old signature when the corrector fails.
    pub(super) fn open_phase(&mut self, sig: Signature, guess: &[f64], (ia, ib): (usize, usize), len: f64) -> Option<Node> {
        let old = std::mem::replace(&mut self.fam.sig, sig);
        let d = self.fam.dim();
        let n2 = d - 1 - self.fam.ne();
        let mut normal = vec![0.0; d];
        normal[n2 + ib] = 1.0;
        normal[n2 + ia] = -1.0;
        let wrap = if ib < ia { 1.0 } else { 0.0 };
        let mut g = guess.to_vec();
        g[n2 + ib] = g[n2 + ia] + len - wrap;
        let first = super::profile::caller("pair", f64::NAN, || self.fam.correct(&g, &normal, len - wrap)).ok().and_then(|w1| {
            let mut g2 = w1.clone();
            g2[n2 + ia] -= 0.5 * len;
            g2[n2 + ib] += 0.5 * len;
            let w2 = self.fam.correct(&g2, &normal, 2.0 * len - wrap).ok()?;
            let sec: Vec<f64> = w2.iter().zip(&w1).map(|(a, b)| a - b).collect();
            self.fam.node(w1, &sec)
        });
        if first.is_none() {
            self.fam.sig = old;
        }
        first
    }

    /// Multiplier events across a grazing, from `lo` (the old signature) to `first` (the new
    /// one): both orbits are the same there.
    pub(super) fn multipliers_across(&mut self, lo: &Node, first: &Node) {
        for kind in [EventKind::PeriodDoubling, EventKind::NeimarkSacker] {
            if side(lo, kind) != side(first, kind) {
                self.push(first, Some(kind), detail_of(kind, first));
            }
        }
    }
}
