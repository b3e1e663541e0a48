//! The phase sequence of several friction contacts: read from the LCP's per-contact stuck flags
//! and force signs (all contacts' switches merged in time order), or found by an event-driven
//! march of the exact flows until two successive periods have the same events.
use super::super::super::PolishFailure;
use super::super::Slide;
use super::{Mode, MultiFlows, MultiOrbit, fail};
use crate::periodic::PeriodicProblem;
use crate::response::Response;
use nalgebra::{DMatrix, DVector};
use std::collections::HashMap;

/// Steps per period of the march (events refined by bisection on the exact flow).
const STEPS: usize = 512;
/// Periods marched at most before the topology is declared unsettled.
const MAX_PERIODS: usize = 600;

/// An event: time, contact, the contact's phase after.
type Switch = (f64, usize, Slide);

/// The orbit whose events over one period are `evs` (increasing times), `before` the mode
/// before the first; the origin in the middle of the longest interval between events.
fn assemble(fl: &MultiFlows, period: f64, evs: &[Switch], before: Mode, constants: &[f64]) -> MultiOrbit {
    let m = evs.len();
    if m == 0 {
        return MultiOrbit::new(fl.clone(), period, 0.0, before, vec![], vec![], constants);
    }
    let mut after = vec![before];
    for &(_, i, to) in evs {
        let mut mode = after[after.len() - 1].clone();
        mode[i] = to;
        after.push(mode);
    }
    let end = |g: usize| if g + 1 < m { evs[g + 1].0 } else { evs[0].0 + period };
    let longest = (0..m).max_by(|&a, &b| (end(a) - evs[a].0).total_cmp(&(end(b) - evs[b].0))).unwrap_or(0);
    let start = 0.5 * (evs[longest].0 + end(longest));
    let order: Vec<usize> = (1..=m).map(|k| (longest + k) % m).collect();
    let times = order.iter().map(|&g| start + (evs[g].0 - start).rem_euclid(period)).collect();
    let events = order.iter().map(|&g| (evs[g].1, evs[g].2)).collect();
    MultiOrbit::new(fl.clone(), period, start, after[longest + 1].clone(), events, times, constants)
}

/// The orbit of the LCP's phases: instant j describes (t_{j−1}, t_j] under bds1, so a run
/// starting at instant j starts at t_{j−1}.
fn from_series(fl: &MultiFlows, series: &[Vec<Slide>], h: f64, period: f64, constants: &[f64]) -> MultiOrbit {
    let k = series[0].len();
    let mut evs: Vec<(usize, usize, Slide)> = Vec::new();
    for (i, s) in series.iter().enumerate() {
        evs.extend((0..k).filter(|&j| s[j] != s[(j + k - 1) % k]).map(|j| (j, i, s[j])));
    }
    // A pinned contact's sticking is the stop's impact, not an event of its own.
    evs.retain(|&(j, i, to)| !(to == Slide::Stick && i < fl.contacts() && fl.pinned(&series.iter().map(|s| s[j]).collect::<Vec<_>>(), i)));
    // At one instant a rigid stop switches first: it opens (λ = 0) before the friction contact
    // it pinned can slip.
    let rigid = |i: usize| i >= fl.contacts() && fl.stops[i - fl.contacts()].rigid();
    evs.sort_by_key(|e| (e.0, !rigid(e.1), e.1));
    let j0 = evs.first().map_or(1, |e| e.0);
    let before = series.iter().map(|s| s[(j0 + k - 1) % k]).collect();
    let switches: Vec<Switch> = evs.iter().map(|&(j, i, to)| ((j as f64 - 1.0) * h, i, to)).collect();
    // Keep times increasing from the first (instant 0 starts at t_{−1} = −h).
    assemble(fl, period, &switches, before, constants)
}

/// A rigid contact's stick runs of at most two instants taken for reversals: the LCP's trace
/// of a continuous motion through v = 0 (they take the slip that follows).
fn smoothed(s: &[Slide]) -> Vec<Slide> {
    let k = s.len();
    let mut out = s.to_vec();
    for j in 0..k {
        let starts = s[j] == Slide::Stick && s[(j + k - 1) % k] != Slide::Stick;
        let len = (0..k).take_while(|&d| s[(j + d) % k] == Slide::Stick).count();
        if starts && len <= 2 && len < k {
            let next = s[(j + len) % k];
            (0..len).for_each(|d| out[(j + d) % k] = next);
        }
    }
    out
}

/// Whether `s` sticks but for slips of at most three instants each.
fn short_slips_only(s: &[Slide]) -> bool {
    let k = s.len();
    s.contains(&Slide::Stick)
        && (0..k).all(|j| s[j] == Slide::Stick || (1..3).any(|d| s[(j + d) % k] == Slide::Stick) && (1..3).any(|d| s[(j + k - d) % k] == Slide::Stick))
}

/// Converges and verifies `orbit`.
fn fit(mut orbit: MultiOrbit) -> Result<MultiOrbit, PolishFailure> {
    orbit.converge()?;
    // A contact stuck all period: its constant moved into |f| ≤ μN (twice: the events move too).
    for _ in 0..2 {
        if !orbit.shift_pins()? {
            break;
        }
    }
    orbit.verify()?;
    Ok(orbit)
}

/// Fits the stick–slip orbit of the several friction contacts of `problem` to the LCP's `r`.
pub fn polish(problem: &PeriodicProblem, r: &Response) -> Result<MultiOrbit, PolishFailure> {
    let model = problem.model();
    if !model.rubbing.is_empty() {
        return fail("friction contacts are fitted without rubbing contacts in this version");
    }
    if model.frictions.iter().any(|f| f.contact.is_some()) {
        return fail("a coupled normal–tangential contact has no constant slip force to fit");
    }
    if r.friction.len() != model.frictions.len() || r.contacts.len() != model.contacts.len() {
        return fail("the result has no friction or contact outputs ([output] contacts = false)");
    }
    let fl = MultiFlows::new(model)?;
    let (k, period) = (r.friction[0].stuck.len(), r.period);
    let h = period / k as f64;
    let mut series: Vec<Vec<Slide>> =
        r.friction.iter().map(|f| f.stuck.iter().zip(&f.force).map(|(&st, &x)| if st { Slide::Stick } else { Slide::Slip(x.signum()) }).collect()).collect();
    // The stops' phases follow the friction contacts' in a mode.
    series.extend(super::stops::series(r, &fl.stops));
    // Pressed on a rigid stop a friction contact along its normal is stuck (whatever the LCP's
    // split of the force between them).
    for j in 0..k {
        let mode = fl.pin_to_stops(series.iter().map(|s| s[j]).collect());
        series.iter_mut().zip(mode).for_each(|(s, p)| s[j] = p);
    }
    // Every friction contact stuck, the stops as the LCP has them at instant 0.
    let all_stuck: Mode = (0..fl.elements()).map(|i| if i < fl.contacts() { Slide::Stick } else { series[i][0] }).collect();
    // The slider constants of contacts stuck all period: the LCP's mean of bᵀx (rigid) or of
    // the slider bᵀx − f/k_t (Jenkins).
    let constants: Vec<f64> = r
        .friction
        .iter()
        .zip(&fl.kt)
        .map(|(f, kt)| f.displacement.iter().zip(&f.force).map(|(u, x)| u - kt.map_or(0.0, |kt| x / kt)).sum::<f64>() / k as f64)
        .collect();
    let mut candidates = vec![series.clone()];
    let merged: Vec<Vec<Slide>> = series.iter().enumerate().map(|(i, s)| if fl.kt.get(i) == Some(&None) { smoothed(s) } else { s.clone() }).collect();
    if merged != series {
        candidates.push(merged);
    }
    // A contact the LCP holds but for short slips (the trace of a holding force near μN) taken
    // as stuck all period, the others as read.
    let held: Vec<Vec<Slide>> = series.iter().map(|s| if short_slips_only(s) { vec![Slide::Stick; k] } else { s.clone() }).collect();
    if held != series && held.iter().any(|s| s.iter().any(|&p| p != Slide::Stick)) {
        candidates.push(held);
    }
    let mut last = PolishFailure(String::new());
    let mut seed = None;
    for c in &candidates {
        let orbit = from_series(&fl, c, h, period, &constants);
        if seed.is_none() {
            seed = orbit.seed();
        }
        match fit(orbit) {
            Ok(o) => return Ok(o),
            Err(e) => last = e,
        }
    }
    let stuck = MultiOrbit::new(fl.clone(), period, 0.0, all_stuck.clone(), vec![], vec![], &constants);
    if let Ok(o) = fit(stuck) {
        return Ok(o);
    }
    let seed = seed.unwrap_or_else(|| (0.0, all_stuck, fl.augment(0.0, &[])));
    match settle(&fl, period, seed) {
        Some((before, evs)) => {
            fit(assemble(&fl, period, &evs, before, &constants)).map_err(|e| PolishFailure(format!("{}; as read from the LCP: {}", e.0, last.0)))
        }
        None => Err(PolishFailure(format!("{}; the exact flows' march did not settle in {MAX_PERIODS} periods", last.0))),
    }
}

/// Marches the exact flows from (t₀, mode, state) until the events of two successive periods
/// agree to 1e-7·T; returns the mode at the last period's start and its events.
fn settle(fl: &MultiFlows, period: f64, (t0, mut mode, y): (f64, Mode, DVector<f64>)) -> Option<(Mode, Vec<Switch>)> {
    let dt = period / STEPS as f64;
    let mut steps: HashMap<Vec<usize>, DMatrix<f64>> = HashMap::new();
    let mut y = fl.project(&mode, y);
    let mut t = t0;
    let mut previous: Option<Vec<Switch>> = None;
    let any_ended = |mode: &Mode, y: &DVector<f64>| (0..fl.elements()).find(|&i| fl.ended(mode, i, y));
    // Bisections that barely advance (a grazing slip) are bounded too.
    let mut budget = 4 * STEPS * MAX_PERIODS;
    for p in 0..MAX_PERIODS {
        let (first, end) = (mode.clone(), t0 + (p + 1) as f64 * period);
        let mut events = Vec::new();
        while t < end {
            budget = budget.checked_sub(1)?;
            let dh = dt.min(end - t);
            let yn = if dh == dt {
                let key: Vec<usize> = mode.iter().map(|s| s.index()).collect();
                &*steps.entry(key).or_insert_with(|| fl.step_map(&mode, dt)) * &y
            } else {
                fl.flow(&mode, &y, dh)
            };
            if any_ended(&mode, &yn).is_none() {
                (y, t) = (yn, t + dh);
                continue;
            }
            let (mut lo, mut hi) = (0.0, dh);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if any_ended(&mode, &fl.flow(&mode, &y, mid)).is_some() { hi = mid } else { lo = mid }
            }
            let ye = fl.flow(&mode, &y, hi);
            let i = any_ended(&mode, &ye).unwrap_or(0);
            let to = fl.next(&mode, i, &ye);
            let mut after = mode.clone();
            after[i] = to;
            let after = fl.pin_to_stops(after);
            (y, t) = (fl.enter(&mode, &after, i, ye), t + hi);
            if to != mode[i] {
                events.push((t - p as f64 * period, i, to));
                mode = after;
            }
        }
        if let Some(prev) = &previous {
            let same = prev.len() == events.len() && prev.iter().zip(&events).all(|(a, b)| a.1 == b.1 && a.2 == b.2 && (a.0 - b.0).abs() <= 1e-7 * period);
            if same {
                return Some((first, events));
            }
        }
        previous = Some(events);
    }
    None
}

/// Replaces `r`'s series by the orbit's at the same instants, and every contact's outputs.
pub fn write(orbit: &MultiOrbit, problem: &PeriodicProblem, r: &mut Response) {
    super::super::write_flow_kinematics(r, problem, orbit.flows.n, |t| {
        let (mode, y) = orbit.at(t);
        (&orbit.flows.mode(mode).a * &y, y)
    });
    for (i, f) in r.friction.iter_mut().enumerate() {
        for (j, &t) in r.time.iter().enumerate() {
            (f.force[j], f.slip_velocity[j], f.displacement[j], f.stuck[j]) = orbit.contact(i, t);
        }
        f.dissipated_energy = orbit.dissipated_energy(i);
    }
}
