//! Locating an event between two points of the exact branch: each trial point the orbit on a
//! hyperplane normal to the first bracket's secant a → b, at a coordinate u along it chosen by
//! regula falsi on the event's test function (Illinois variant, Dowell & Jarratt 1971:
//! superlinear, the bracket kept) where the event has one (a margin, a clearance, the tangent's
//! λ component, det(I + M)), by bisection where it has only a side (a count of multipliers).
//!
//! The bracket is the interval of u, set exactly by the hyperplanes: with the secant of the
//! current ends as the normal (before session 22) the bracket's length carried the corrector's
//! noise (up to 1e-8 of the scaled unknowns where Newton stalls at its attainable accuracy),
//! never reached [`BRACKET`], and every location on the coarse rigid blade spent its 80 trials.
//!
//! A test of the orbit and touches alone ([`Test::Value`]: a rigid margin, a clearance) gets
//! trial points without tangent nor multipliers ([`Family::orbit_node`]); the two ends found
//! are completed as points.
use super::family::{Family, Node};
use super::{BRACKET, NEWTON_NOISE, Walk, dot, profile};
use crate::analysis::continuation::{EventKind, floquet};

/// What tells the two sides of an event apart.
pub(super) enum Test<'a> {
    /// A function of the orbit and its touches ≥ 0 on `a`'s side and < 0 past the event,
    /// continuous across it.
    Value(&'a dyn Fn(&Node) -> f64),
    /// Likewise, of the point's tangent or multipliers.
    Point(&'a dyn Fn(&Node) -> f64),
    /// Only whether a point (its tangent or multipliers) is on `a`'s side.
    Side(&'a dyn Fn(&Node) -> bool),
}

impl Test<'_> {
    /// The test's value at `n`: a side as ±1.
    fn at(&self, n: &Node) -> f64 {
        match self {
            Test::Value(g) | Test::Point(g) => g(n),
            Test::Side(same) => {
                if same(n) {
                    1.0
                } else {
                    -1.0
                }
            }
        }
    }
}

/// The event between `a` (on its side of `test`) and `b` (past it), bracketed to [`BRACKET`] of
/// the scaled unknowns along a → b: the last points on either side (with their touches when
/// `touches`). `None` where the corrector fails on a bracket longer than its own noise.
pub(super) fn locate(fam: &Family, a: &Node, b: &Node, test: Test, touches: bool) -> Option<(Node, Node)> {
    let start = profile::enabled().then(profile::cpu);
    let out = profile::timed(profile::Stage::Bisect, || locate_on(fam, a, b, &test, touches));
    if let (Some(start), Some((lo, hi))) = (start, &out) {
        let rho = fam.rho;
        eprintln!("exact walk profile: located in [{:.12}, {:.12}], {:.2} s CPU", lo.lambda(rho), hi.lambda(rho), profile::cpu() - start);
    }
    out
}

fn locate_on(fam: &Family, a: &Node, b: &Node, test: &Test, touches: bool) -> Option<(Node, Node)> {
    let orbit_only = matches!(test, Test::Value(_));
    let sec: Vec<f64> = b.w.iter().zip(&a.w).map(|(x, y)| x - y).collect();
    let length = sec.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(length > BRACKET) {
        return Some((a.clone(), b.clone()));
    }
    let normal: Vec<f64> = sec.iter().map(|x| x / length).collect();
    let origin = dot(&normal, &a.w);
    // The ends' points; their coordinates along the normal are the bracket's (exact: each
    // trial's last Newton row).
    let (mut lo, mut hi) = (a.clone(), b.clone());
    let (g_a, g_b) = profile::timed(profile::Stage::Test, || (test.at(a), test.at(b)));
    let mut bracket = Bracket::new(length, (g_a, g_b), !matches!(test, Test::Side(_)));
    let trace = std::env::var_os("PC_TRACE_LOCATE").is_some();
    for _ in 0..80 {
        if bracket.len() <= BRACKET {
            break;
        }
        let u = bracket.next();
        let s = (u - bracket.lo.u) / bracket.len();
        let pred: Vec<f64> = lo.w.iter().zip(&hi.w).map(|(x, y)| x + s * (y - x)).collect();
        let trial = || {
            let w = profile::caller("bisect", (u - bracket.lo.u).abs(), || fam.correct(&pred, &normal, origin + u)).ok()?;
            if orbit_only { fam.orbit_node(w, &lo.tangent, touches) } else { fam.node_with(w, &lo.tangent, touches) }
        };
        // A bracket within the corrector's accuracy is the event: the coarse blade's fold at
        // 2795.947 rad/s, bracketed to 5e-11, lost its next midpoint to Newton's noise (≈1e-10).
        let Some(node) = profile::timed(profile::Stage::Trial, trial) else {
            let gap = lo.w.iter().zip(&hi.w).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
            return (gap <= NEWTON_NOISE).then(|| complete(fam, a, lo, hi, orbit_only, touches)).flatten();
        };
        let g = profile::timed(profile::Stage::Test, || test.at(&node));
        if trace {
            eprintln!("locate trial: bracket {:.3e} s {s:.3e} λ {:.13} g {g:.6e}", bracket.len(), node.lambda(fam.rho));
        }
        if bracket.update(u, g) {
            lo = node;
        } else {
            hi = node;
        }
    }
    complete(fam, a, lo, hi, orbit_only, touches)
}

impl Walk<'_> {
    /// The events between two points of one signature, each located by bisection, in order.
    pub(super) fn events_between(&self, a: &Node, b: &Node) -> Vec<(EventKind, Node, String)> {
        self.events_on(a, b).0
    }

    /// [`Self::events_between`], and whether one of them was not located (a trial's corrector
    /// failed inside its bracket).
    pub(super) fn events_on(&self, a: &Node, b: &Node) -> (Vec<(EventKind, Node, String)>, bool) {
        let mut found = Vec::new();
        let mut unlocated = false;
        for kind in [EventKind::Fold, EventKind::PeriodDoubling, EventKind::NeimarkSacker] {
            if side(a, kind) == side(b, kind) {
                continue;
            }
            let s = side(a, kind);
            if kind == EventKind::Fold && std::env::var_os("PC_TRACE_FOLD").is_some() {
                let (ta, tb) = (test_value(a, kind), test_value(b, kind));
                let (raw, met) = (dot(&a.tangent, &b.tangent), self.fam.metric.dot(&a.tangent, &b.tangent));
                let rho = self.fam.rho;
                eprintln!(
                    "fold trace: a λ {:.10} t_λ {ta:e}, b λ {:.10} t_λ {tb:e}; tangents' product {raw:e}, in the metric {met:e}",
                    a.lambda(rho),
                    b.lambda(rho)
                );
            }
            let value = |n: &Node| if side(n, kind) == s { 1.0 } else { -1.0 } * test_value(n, kind).abs();
            let same = |n: &Node| side(n, kind) == s;
            let test = if kind == EventKind::NeimarkSacker { Test::Side(&same) } else { Test::Point(&value) };
            let located = locate(&self.fam, a, b, test, false);
            let missed = located.is_none();
            let node = located.map_or_else(|| b.clone(), |(_, hi)| hi);
            // det(I + M) also changes sign when a multiplier passes through ∞ (an impact's
            // velocity fading at a grazing, Nordmark 1991): no multiplier at −1, no doubling.
            // Unlocated (a trial's corrector failed), a real multiplier crossing −1 between the
            // two points is the doubling (the real blade's at 2283.42 rad/s was dropped so).
            let doubling = if missed { floquet::crosses(&a.mu, &b.mu, -1.0) } else { node.mu.iter().any(|m| (m + 1.0).norm() < 1e-3) };
            if kind == EventKind::PeriodDoubling && !doubling {
                continue;
            }
            // Unlocated, a fold needs a real multiplier through +1 too: the tangent's λ component
            // alone flips in the corrector's noise where the walk crawls into a singular merge
            // (the coarse rigid blade at 2402.2578806 rad/s: steps of 2e-11, |μ| 0.9495 on both sides).
            if kind == EventKind::Fold && missed && !floquet::crosses(&a.mu, &b.mu, 1.0) {
                continue;
            }
            let mut detail = detail_of(kind, &node);
            unlocated |= missed;
            if missed {
                detail += &format!(
                    "; not located: between λ = {} and {} (a trial's corrector failed), given at the latter",
                    a.lambda(self.fam.rho),
                    b.lambda(self.fam.rho)
                );
            }
            found.push((kind, node, detail));
        }
        let sec: Vec<f64> = b.w.iter().zip(&a.w).map(|(x, y)| x - y).collect();
        let coord = |n: &Node| n.w.iter().zip(&a.w).zip(&sec).map(|((x, y), s)| (x - y) * s).sum::<f64>();
        found.sort_by(|x, y| coord(&x.1).total_cmp(&coord(&y.1)));
        (found, unlocated)
    }
}

/// One end of a [`Bracket`]: its coordinate, its test value (scaled by Illinois' rule), the
/// value as measured, and the end it replaced on its side (coordinate, value as measured).
struct End {
    u: f64,
    g: f64,
    measured: f64,
    before: Option<(f64, f64)>,
}

impl End {
    fn new(u: f64, g: f64) -> End {
        End { u, g, measured: g, before: None }
    }

    /// The zero of the secant through this end and the one it replaced, where it falls inside
    /// (lo, hi): this side's values tell how far the event is.
    fn zero(&self, (lo, hi): (f64, f64)) -> Option<f64> {
        let (u1, g1) = self.before?;
        let r = self.u - self.measured * (self.u - u1) / (self.measured - g1);
        (r >= lo && r <= hi).then_some(r)
    }

    fn replace(&mut self, u: f64, g: f64) {
        *self = End { u, g, measured: g, before: Some((self.u, self.measured)) };
    }
}

/// The event's coordinate u along the first secant, bracketed: the test ≥ 0 at `lo`, < 0 at
/// `hi`. Regula falsi, Illinois variant, where both sides' values tell the distance to the
/// event; where only one side's do (the other flat: a rigid margin that is the clearance of a
/// contact just released, ≈ 0 on the orbit's side of a grazing, TOL added, while past it the
/// clearance of the new impact falls linearly), the secant of that side's last two ends,
/// nudged to straddle its zero. Illinois alone took 75 trials there, the flat side's value
/// moving each trial by 1e-3 of the bracket (the coarse rigid blade at 2329.9566 rad/s).
struct Bracket {
    lo: End,
    hi: End,
    /// Values rather than sides only (which get bisection).
    values: bool,
    /// Which end the last two trials replaced (−1 lo, 1 hi), and the bracket's lengths before them.
    kept: (i8, i8),
    lengths: [f64; 2],
}

/// The straddle's nudge past a one-sided secant's zero, as a fraction of the zero's distance
/// from its side's end: each pair of trials then shrinks the bracket ≈ 100 times.
const NUDGE: f64 = 1e-2;

impl Bracket {
    fn new(length: f64, (g_a, g_b): (f64, f64), values: bool) -> Bracket {
        Bracket { lo: End::new(0.0, g_a), hi: End::new(length, g_b), values, kept: (0, 0), lengths: [f64::INFINITY; 2] }
    }

    fn len(&self) -> f64 {
        self.hi.u - self.lo.u
    }

    /// The coordinate to try next.
    fn next(&mut self) -> f64 {
        let (len, inside) = (self.len(), (self.lo.u, self.hi.u));
        // Bisection where the bracket failed to halve over the last two trials (a test that is
        // not smooth there, or noisy), or the values are not of opposite signs.
        let halved = len <= 0.5 * self.lengths[1] || self.lengths[1].is_infinite();
        let signs = self.lo.g >= 0.0 && self.hi.g < 0.0 && self.lo.g.is_finite() && self.hi.g.is_finite();
        self.lengths = [len, self.lengths[0]];
        let mid = self.lo.u + 0.5 * len;
        if !(self.values && halved && signs) {
            return mid;
        }
        let (r, end) = match (self.lo.zero(inside), self.hi.zero(inside)) {
            (None, Some(r)) => (r, self.hi.u),
            (Some(r), None) => (r, self.lo.u),
            // A side whose secant points outside is flat: its values tell nothing, the other
            // side has one end only.
            (None, None) if self.lo.before.is_some() || self.hi.before.is_some() => return mid,
            _ => return self.lo.u + (self.lo.g / (self.lo.g - self.hi.g)).clamp(1e-3, 1.0 - 1e-3) * len,
        };
        let nudge = (NUDGE * (end - r)).abs().max(0.25 * BRACKET) * (r - end).signum();
        [r + nudge, r - nudge].into_iter().find(|&u| u > inside.0 && u < inside.1).unwrap_or(mid)
    }

    /// The trial at `u` with test value `g` replaces the end on its side: true where it is `lo`.
    fn update(&mut self, u: f64, g: f64) -> bool {
        let low = g >= 0.0;
        let side = if low { -1 } else { 1 };
        if low {
            self.lo.replace(u, g)
        } else {
            self.hi.replace(u, g)
        }
        self.kept = (self.kept.1, side);
        // The far end kept twice: its value halved, so that the next trial moves towards it.
        if self.kept == (side, side) {
            if low { self.hi.g *= 0.5 } else { self.lo.g *= 0.5 }
        }
        low
    }
}

/// The bracket's ends as points (their tangents, oriented along `a`'s, and multipliers) where
/// the trials were orbits only; the walk's own points `a` and `b` kept as they are.
fn complete(fam: &Family, a: &Node, lo: Node, hi: Node, orbit_only: bool, touches: bool) -> Option<(Node, Node)> {
    if !orbit_only {
        return Some((lo, hi));
    }
    let point = |n: Node, prev: &[f64]| if n.mu.is_empty() { fam.node_with(n.w, prev, touches) } else { Some(n) };
    let lo = point(lo, &a.tangent)?;
    let hi = point(hi, &lo.tangent)?;
    Some((lo, hi))
}

/// The side of a point for an event's test function.
pub(super) fn side(n: &Node, kind: EventKind) -> i64 {
    match kind {
        EventKind::Fold => i64::from(n.tangent[n.tangent.len() - 1] > 0.0),
        EventKind::PeriodDoubling => i64::from(floquet::doubling_sign(&n.mu)),
        EventKind::NeimarkSacker => floquet::complex_outside(&n.mu) as i64,
        EventKind::Grazing => 0,
    }
}

/// A fold's and a period doubling's test function, whose sign is [`side`]'s: the tangent's λ
/// component, det(I + M) (Seydel 2010, §7.4). The others: 1.
pub(super) fn test_value(n: &Node, kind: EventKind) -> f64 {
    match kind {
        EventKind::Fold => n.tangent[n.tangent.len() - 1],
        EventKind::PeriodDoubling => floquet::doubling_test(&n.mu),
        _ => 1.0,
    }
}

pub(super) fn detail_of(kind: EventKind, node: &Node) -> String {
    floquet::event_detail(kind, &node.mu)
}

#[cfg(test)]
mod tests {
    use super::{BRACKET, Bracket};

    /// The bracket's ends after locating g's sign change on [0, length], and the trials spent.
    fn located(g: impl Fn(f64) -> f64, length: f64) -> (f64, f64, usize) {
        let mut bracket = Bracket::new(length, (g(0.0), g(length)), true);
        let mut trials = 0;
        while bracket.len() > BRACKET && trials < 80 {
            let u = bracket.next();
            bracket.update(u, g(u));
            trials += 1;
        }
        (bracket.lo.u, bracket.hi.u, trials)
    }

    #[test]
    fn a_smooth_test_is_located_superlinearly() {
        // cos u = u: the Dottie number (OEIS A003957).
        let (lo, hi, trials) = located(|u| u.cos() - u, 1.0);
        let root = 0.739_085_133_215_160_6;
        assert!(lo <= root + 1e-15 && hi >= root - 1e-15 && hi - lo <= BRACKET, "[{lo}, {hi}]");
        assert!(trials <= 12, "{trials} trials");
    }

    #[test]
    fn a_test_flat_on_one_side_is_located_from_the_other() {
        // A rigid margin near a grazing (validation/RECORD.md, session 22): 1e-9 and 3 % round-off before, a
        // clearance falling at 0.05 per unit past 0.3; the sign changes at 0.3 + 1e-9/0.05.
        let g = |u: f64| (1e-9 + 3e-11 * (1e3 * u).sin()).min(1e-9 - 0.05 * (u - 0.3));
        let root = 0.3 + 1e-9 / 0.05;
        for length in [0.31, 0.5, 1.0] {
            let (lo, hi, trials) = located(g, length);
            assert!(lo <= root + 1e-15 && hi >= root - 1e-15 && hi - lo <= BRACKET, "[{lo}, {hi}]");
            assert!(trials <= 20, "{trials} trials on [0, {length}]");
        }
    }
}
