//! The exact walk's re-entry (issue 24): where the exact walk stops short (a change of signature
//! it could not start: the real blade at 1013.0333963 rad/s, validation/RECORD.md), the discrete
//! walk carries the branch past the stop, and the exact walk starts again from the first of its
//! orbits whose grid solve polishes into an exact orbit of the same branch; again at each stop,
//! up to [`MOST_REENTRIES`] times. Each point keeps its source; the branch's `stop` names the
//! discrete stretches and why each began.
use super::{Branch, BranchPoint, ContinuationSettings, EventKind, OnPoint, Parameter, active_set, exact, handover, run_discrete_until};
use crate::error::Error;
use crate::periodic::PeriodicProblem;
use std::cell::{Cell, RefCell};

/// Re-entries per continuation at most: each costs a discrete stretch and its exact starts.
const MOST_REENTRIES: usize = 8;
/// Exact starts tried per discrete stretch, at its points past the stop, each at least twice as
/// far from it as the last tried (the first point, then doubling: the real blade's stop at
/// 1013.0334 rad/s has no exact start at 1013.02 and one at 1013.06). Each is a grid solve and a
/// polish, with finer grids' solves where the scene's sequence is not admissible (the real blade
/// at 1013.0: k = 8192). Past them the discrete walk goes on to the end.
const TRIES: usize = 4;

/// The rest of the range after the exact walk `walked` from `from` stopped short of `to`: the
/// discrete walk from its last point, re-entering the exact orbit where it can.
pub(super) fn go_on(
    problem: &PeriodicProblem,
    param: Parameter,
    (from, to): (f64, f64),
    settings: &ContinuationSettings,
    on_point: &OnPoint,
    walked: exact::Walked,
) -> Result<Branch, Error> {
    let name = param.name();
    let (rho, dir, m) = ((to - from).abs(), (to - from).signum(), problem.model().contacts.len());
    let branch = |points, stop, marches| Ok(Branch { parameter: param, points, stop, marches, period_multiple: 1, label: "T".to_string() });
    let mut points = walked.points;
    let (mut stop, mut seam_orbit) = (walked.stop, walked.stopped);
    // The discrete stretches the exact walk re-entered after, each with why it began.
    let mut stretches: Vec<String> = Vec::new();
    let mut marches = 0;
    loop {
        let at = points.last().map_or(from, |p| p.parameter);
        let history = |s: &[String]| if s.is_empty() { String::new() } else { format!("; discrete stretches: {}", s.join(", ")) };
        // Not past the point limit (the exact walk stopped there), nor more than MOST_REENTRIES times;
        // only where the exact walk stopped heading towards `to`.
        let ahead = heading(&points, dir);
        let may = ahead && points.len() < settings.max_points && stretches.len() < MOST_REENTRIES;
        let (tries, turned, failed) = (Cell::new(0), Cell::new(false), RefCell::new(Vec::new()));
        let reach = Cell::new(0.0);
        let started: RefCell<Option<exact::Started>> = RefCell::new(None);
        let refused = Cell::new(false);
        let until = |new: &[BranchPoint]| {
            // The stretch's first orbit is another branch's: no use walking it (refused below).
            if refused.get() {
                return true;
            } else if !may {
                return false;
            }
            // A fold in the stretch: past it the branch runs back towards `from`, over orbits the
            // exact walk has not met from this side; the discrete walk goes on (no re-entry).
            turned.set(turned.get() || new.iter().any(|p| p.event == Some(EventKind::Fold)));
            let Some(p) = new.last().filter(|p| p.certified && (p.parameter - at) * dir > 0.0) else { return false };
            if turned.get() || tries.get() >= TRIES || (p.parameter - at).abs() < 2.0 * reach.get() {
                return false;
            }
            tries.set(tries.get() + 1);
            reach.set((p.parameter - at).abs());
            let s = match exact::start(problem, param, p.parameter, to, rho, Some(&active_set(&p.masks, m))) {
                Ok(s) => s,
                Err(e) => {
                    failed.borrow_mut().push(format!("{}: {e}", p.parameter));
                    return false;
                }
            };
            // The same orbit as the discrete one, up to the scheme's error, or another branch.
            if let Some(jump) = handover::jump(p, s.point()) {
                failed.borrow_mut().push(format!("{}: another orbit (amplitudes differ by {:.1}%)", p.parameter, 100.0 * jump));
                return false;
            }
            *started.borrow_mut() = Some(s);
            true
        };
        // The stretch's first orbit is the exact walk's last, not streamed twice; none of it when
        // the hand-over refuses that orbit (another branch's).
        let seam = Cell::new(true);
        let streamed = |p: &BranchPoint| {
            if seam.replace(false) {
                refused.set(points.last().is_some_and(|last| handover::left_branch(last, p, name).is_some()));
            } else if !refused.get() {
                on_point(p)
            }
        };
        // Its first orbit warm-started from the exact one's active set where it may re-enter: a cold
        // solve there may find a coexisting orbit (the contact-free one), which the hand-over refuses.
        let warm = match seam_orbit.as_ref().filter(|_| may) {
            Some(o) => {
                let mut p = problem.clone();
                param.apply(&mut p, at)?;
                o.active_set(&p)
            }
            None => Vec::new(),
        };
        // Within the point limit: its first orbit is the seam (not appended), so one point at the limit.
        let budget = ContinuationSettings { max_points: settings.max_points.saturating_sub(points.len()) + 1, ..settings.clone() };
        let rest = match run_discrete_until((problem, param), (at, to), (&budget, &streamed), (&warm, Some(&until))) {
            Ok(rest) => rest,
            Err(e) => return branch(points, format!("{stop}; the discrete walk from there failed: {e}{}", history(&stretches)), marches),
        };
        marches += rest.marches;
        if let (Some(last), Some(first)) = (points.last(), rest.points.first())
            && let Some(why) = handover::left_branch(last, first, name)
        {
            return branch(points, format!("{stop}; exact orbit up to {name} = {at}, {why}{}", history(&stretches)), marches);
        }
        let added = rest.points.len().saturating_sub(1);
        points.extend(rest.points.into_iter().skip(1));
        if points.len() >= settings.max_points {
            let then = if added > 0 { format!(" at {name} = {at}; the discrete walk from there to the point limit") } else { String::new() };
            return branch(points, format!("{stop}{then}{}", history(&stretches)), marches);
        }
        let failed = failed.into_inner();
        let Some(s) = started.into_inner() else {
            let tried = if failed.is_empty() { String::new() } else { format!("; no exact start at {}", failed.join("; ")) };
            let stop = format!("{}; exact orbit up to {name} = {at} ({stop}), discrete walk from there{tried}{}", rest.stop, history(&stretches));
            return branch(points, stop, marches);
        };
        let back = s.point().parameter;
        let missed = if failed.is_empty() { String::new() } else { format!(", after no exact start at {}", failed.join("; ")) };
        stretches.push(format!("[{at}, {back}] (the exact walk stopped: {stop}; re-entered at {name} = {back}{missed})"));
        let budget = ContinuationSettings { max_points: settings.max_points.saturating_sub(points.len()), ..settings.clone() };
        let again = s.follow(from, to, &budget, on_point);
        points.extend(again.points);
        if again.reached || again.turned_back {
            return branch(points, format!("{}{}", again.stop, history(&stretches)), marches);
        }
        (stop, seam_orbit) = (again.stop, again.stopped);
    }
}

/// The branch's last points head towards `to` (λ moving the way `dir` says, no fold among the last
/// two). Where the walk stopped heading back or at a fold, the discrete walk towards `to` may take
/// the arm the exact walk came along (seen: the random family's seed-77 member, a fold located at
/// the stop, the re-entered walk back down that arm through all its events): no re-entry there.
fn heading(points: &[BranchPoint], dir: f64) -> bool {
    let Some(last) = points.last() else { return false };
    let turned = points.iter().rev().take(2).any(|p| p.event == Some(EventKind::Fold));
    let before = points.iter().rev().find(|p| p.parameter != last.parameter);
    !turned && before.is_some_and(|b| (last.parameter - b.parameter) * dir > 0.0)
}
