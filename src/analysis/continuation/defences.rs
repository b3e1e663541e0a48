//! The discrete walk's defences against the grid (issue 24: the exact walk needs none): a
//! zigzag band, where the discrete branch turns back and forth across the kinks of the map near a
//! fold sharper than them (the coarse blade's resonance tip), and the merging of fold chains, the
//! discrete branch's wiggles across its kinks (NLvib 03 at k = 4096 near its peak; the test that
//! needs them: tests/continuation.rs::nlvib03_branch_events_amplitudes_stability).
use super::{BranchPoint, EventKind};

/// Steps looked back at for a zigzag, the width of its band (relative to the range) and the
/// least number of turns in it. The coarse blade at its tip (k = 1024): pieces of 1e-7 m, turns
/// every 2–3 steps, over 0.15 rad/s of a range of 750.
pub(super) const ZIGZAG_STEPS: usize = 24;
pub(super) const ZIGZAG_BAND: f64 = 5e-4;
const ZIGZAG_TURNS: usize = 6;

/// (centre, lowest, highest) of the last [`ZIGZAG_STEPS`] parameters when they stay within
/// `width` and turn back at least [`ZIGZAG_TURNS`] times.
pub(super) fn zigzag_in(recent: &[f64], width: f64) -> Option<(f64, f64, f64)> {
    let last = recent.get(recent.len().checked_sub(ZIGZAG_STEPS)?..)?;
    let (lo, hi) = last.iter().fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    let turns = last.windows(3).filter(|w| (w[1] - w[0]) * (w[2] - w[1]) < 0.0).count();
    (hi - lo <= width && turns >= ZIGZAG_TURNS).then_some((0.5 * (lo + hi), lo, hi))
}

/// Folds in a chain of successive folds each closer than `width` to the last are the discrete
/// branch's wiggles across its kinks, except one: a chain of odd length turns the branch back
/// once, at its extreme parameter (the tip of a resonance, whose sides wiggle near it); one of
/// even length does not turn it.
pub(super) fn merge_fold_pairs(points: &mut [BranchPoint], width: f64) {
    let folds: Vec<usize> = (0..points.len()).filter(|&i| points[i].event == Some(EventKind::Fold)).collect();
    let mut start = 0;
    while start < folds.len() {
        let mut end = start + 1;
        while end < folds.len() && (points[folds[end]].parameter - points[folds[end - 1]].parameter).abs() < width {
            end += 1;
        }
        // An odd chain turns the branch once, where its parameter is extreme (the largest when it
        // came in rising) among the certified points the chain spans: the pieces' tangents that
        // detect folds disagree in sign with the path's own motion near a sharp tip.
        let (first, last) = (folds[start], folds[end - 1]);
        let rising = first == 0 || points[first].parameter >= points[first - 1].parameter;
        let extreme = |range: &mut dyn Iterator<Item = usize>| {
            range.max_by(|&a, &b| {
                let o = points[a].parameter.total_cmp(&points[b].parameter);
                if rising { o } else { o.reverse() }
            })
        };
        let turn = extreme(&mut (first..=last).filter(|&i| points[i].certified)).or_else(|| extreme(&mut folds[start..end].iter().copied()));
        let detail = turn.map(|t| points[t].detail.clone()).unwrap_or_default();
        for &i in &folds[start..end] {
            points[i].event = None;
            points[i].detail.clear();
        }
        if (end - start) % 2 == 1
            && let Some(t) = turn
        {
            points[t].event = Some(EventKind::Fold);
            points[t].detail = detail;
        }
        start = end;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::continuation::Source;

    fn at(parameter: f64, event: Option<EventKind>) -> BranchPoint {
        BranchPoint {
            parameter,
            amplitude: vec![],
            multipliers: vec![],
            max_multiplier: 0.0,
            stable: true,
            period_multiple: 1,
            event,
            detail: String::new(),
            certified: true,
            state: vec![],
            time: 0.0,
            masks: vec![],
            tangent: vec![],
            source: Source::Discrete,
        }
    }

    #[test]
    fn a_zigzag_is_a_narrow_band_walked_back_and_forth() {
        let back_and_forth: Vec<f64> = (0..ZIGZAG_STEPS).map(|i| 10.0 + if i % 2 == 0 { 0.0 } else { 0.01 }).collect();
        let (centre, lo, hi) = zigzag_in(&back_and_forth, 0.02).unwrap();
        assert!((centre - 10.005).abs() < 1e-12 && lo == 10.0 && hi == 10.01);
        assert_eq!(zigzag_in(&back_and_forth, 0.005), None, "wider than the band");
        assert_eq!(zigzag_in(&back_and_forth[1..], 0.02), None, "too few steps");
        let slow: Vec<f64> = (0..ZIGZAG_STEPS).map(|i| 10.0 + 1e-4 * i as f64).collect();
        assert_eq!(zigzag_in(&slow, 0.02), None, "a slow walk is not a zigzag");
    }

    #[test]
    fn an_odd_chain_of_folds_is_one_turn_at_its_extreme() {
        let fold = Some(EventKind::Fold);
        // Rising to a tip at 2.0 whose folds were detected late (1.99, 1.995, 1.98), then a real
        // fold far below (1.0), and an even pair of wiggles (1.5, 1.499).
        let params = [1.9, 1.99, 2.0, 1.995, 1.985, 1.98, 1.5, 1.499, 1.2, 1.0, 1.1];
        let events = [None, fold, None, fold, None, fold, fold, fold, None, fold, None];
        let mut points: Vec<BranchPoint> = params.iter().zip(events).map(|(&p, e)| at(p, e)).collect();
        merge_fold_pairs(&mut points, 0.05);
        let folds: Vec<f64> = points.iter().filter(|p| p.event == fold).map(|p| p.parameter).collect();
        assert_eq!(folds, vec![2.0, 1.0]);
    }
}
