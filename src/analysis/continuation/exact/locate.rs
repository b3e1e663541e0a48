//! Locating an event between two points of the exact branch: on the arc, each trial point the
//! orbit on the hyperplane normal to the bracket's secant, by regula falsi on the event's test
//! function (Illinois variant, Dowell & Jarratt 1971: superlinear, the bracket kept) where the
//! event has one (a margin, a clearance, the tangent's λ component, det(I + M)), by bisection
//! where it has only a side (a count of multipliers).
//!
//! Each trial point costs a correction and a point (its Jacobian, orbit and monodromy): on the
//! real blade (k = 1024, 52 events) 52 s CPU per bisection to [`BRACKET`], about 37 halvings.
use super::family::{Family, Node};
use super::{BRACKET, NEWTON_NOISE, dot, profile};
use crate::analysis::continuation::{EventKind, floquet};

/// What tells the two sides of an event apart.
pub(super) enum Test<'a> {
    /// A function ≥ 0 on `a`'s side and < 0 past the event, continuous across it.
    Value(&'a dyn Fn(&Node) -> f64),
    /// Only whether a point is on `a`'s side.
    Side(&'a dyn Fn(&Node) -> bool),
}

impl Test<'_> {
    /// The test's value at `n`: a side as ±1.
    fn at(&self, n: &Node) -> f64 {
        match self {
            Test::Value(g) => g(n),
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
/// the scaled unknowns: the last points on either side (with their touches when `touches`).
/// `None` where the corrector fails on a bracket longer than its own noise.
pub(super) fn locate(fam: &Family, a: &Node, b: &Node, test: Test, touches: bool) -> Option<(Node, Node)> {
    profile::timed(profile::Stage::Bisect, || locate_on(fam, a, b, &test, touches))
}

fn locate_on(fam: &Family, a: &Node, b: &Node, test: &Test, touches: bool) -> Option<(Node, Node)> {
    let (mut lo, mut hi) = (a.clone(), b.clone());
    let (mut g_lo, mut g_hi) = (test.at(a), test.at(b));
    // Illinois: which end the last two trials replaced, and the bracket's lengths before them.
    let mut kept: (i8, i8) = (0, 0);
    let mut lengths = [f64::INFINITY; 2];
    for _ in 0..80 {
        let sec: Vec<f64> = hi.w.iter().zip(&lo.w).map(|(x, y)| x - y).collect();
        let len = sec.iter().map(|x| x * x).sum::<f64>().sqrt();
        if len <= BRACKET {
            break;
        }
        // Regula falsi unless the bracket failed to halve over the last two trials (noise, or a
        // test that is not smooth there) or the values are not of opposite signs.
        let falsi = matches!(test, Test::Value(_)) && (len <= 0.5 * lengths[1] || lengths[1].is_infinite());
        let s = if falsi && g_lo >= 0.0 && g_hi < 0.0 && g_lo.is_finite() && g_hi.is_finite() { (g_lo / (g_lo - g_hi)).clamp(1e-3, 1.0 - 1e-3) } else { 0.5 };
        lengths = [len, lengths[0]];
        let normal: Vec<f64> = sec.iter().map(|x| x / len).collect();
        let pred: Vec<f64> = lo.w.iter().zip(&sec).map(|(x, d)| x + s * d).collect();
        let target = dot(&normal, &pred);
        // A bracket within the corrector's accuracy is the event: the coarse blade's fold at
        // 2795.947 rad/s, bracketed to 5e-11, lost its next midpoint to Newton's noise (≈1e-10).
        let Some(node) = profile::timed(profile::Stage::Trial, || fam.correct(&pred, &normal, target).and_then(|w| fam.node_with(w, &lo.tangent, touches)))
        else {
            return (len <= NEWTON_NOISE).then_some((lo, hi));
        };
        let g = test.at(&node);
        if g >= 0.0 {
            (lo, g_lo) = (node, g);
            kept = (kept.1, -1);
            // The far end kept twice: its value halved, so that the next trial moves towards it.
            if kept == (-1, -1) {
                g_hi *= 0.5;
            }
        } else {
            (hi, g_hi) = (node, g);
            kept = (kept.1, 1);
            if kept == (1, 1) {
                g_lo *= 0.5;
            }
        }
    }
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
