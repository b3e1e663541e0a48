//! A rigid margin's dip below −TOL between two points of one signature, which neither point
//! sees. Each part of the margin (a contact's clearance or held force along one phase, an impulse)
//! is smooth in the parameter while the signature holds and its minimum is inside its phase: its
//! parabola through the step's two ends and the point before them predicts a dip; the part's
//! minimum on the arc is then sought by successive parabolic interpolation (Brent 1973, ch. 5) on
//! orbits corrected along the step, and where it is below −[`TOL`] the step is retried up to it.
//! Such an event then does not depend on the step path: the coarse rigid blade's micro-flight at
//! 2343.54 rad/s (a held force's lift-off height reaching 1e-9 of the clearance scale over
//! 2343.54–2344.87), met by session 30's path and stepped over by session 31's (validation/RECORD.md).
//! Not caught: a clearance part pinned at 0 by the contact's own event at its phase's end, whose
//! interior dip stays hidden until it is below zero (the touch at 2351.1930441 rad/s).
use super::super::family::Node;
use super::super::{Walk, dot};
use super::TOL;
use crate::analysis::polish::MarginPart;

/// A part's predicted minimum below −this × [`TOL`] is examined (the prediction is a parabola's).
const SUSPECT: f64 = 0.1;
/// The orbits tried per suspected part (corrections along the step).
const TRIALS: usize = 6;

/// The walk's point before `here`: `here`'s unknowns (the record is `here`'s while they are the
/// same), the step from it to `here` and its margins' parts.
pub(in super::super) struct Behind {
    pub at: Vec<f64>,
    pub step: f64,
    pub parts: Vec<MarginPart>,
}

impl Behind {
    /// The record for the step after `here`, reached by a step of `step` from the point before.
    pub fn of(before: &Node, here: &Node, step: f64) -> Option<Behind> {
        here.margins()?;
        Some(Behind { at: here.w.clone(), step, parts: parts(before).to_vec() })
    }
}

/// `n`'s margin parts (none without rigid contacts).
fn parts(n: &Node) -> &[MarginPart] {
    n.margins().map_or(&[], |m| &m.parts[..])
}

/// A part whose parabola dips inside the step: its predicted minimum, key and three points (arclength, value).
type Suspect<'a> = (f64, &'a MarginPart, [(f64, f64); 3]);

/// The vertex (x, value) of the parabola through three points of distinct abscissas, when it is convex.
fn vertex(p: [(f64, f64); 3]) -> Option<(f64, f64)> {
    let [(x0, f0), (x1, f1), (x2, f2)] = p;
    let (d01, d12) = ((f1 - f0) / (x1 - x0), (f2 - f1) / (x2 - x1));
    let a = (d12 - d01) / (x2 - x0);
    if !(a > 0.0 && a.is_finite()) {
        return None;
    }
    let x = 0.5 * (x0 + x1) - d01 / (2.0 * a);
    Some((x, f0 + d01 * (x - x0) + a * (x - x0) * (x - x1)))
}

/// The value of the part `key` (contact, what, index) of `n`'s margins.
fn part(n: &Node, key: &MarginPart) -> Option<f64> {
    parts(n).iter().find(|p| p.contact == key.contact && p.what == key.what && p.at == key.at).map(|p| p.value)
}

impl Walk<'_> {
    /// Where along the step from `here` to `next` (arclength `step`) a part of the rigid margin dips
    /// below −[`TOL`] though both ends are above it: the arclength to step to instead, `None`
    /// where no part dips (the step stands as it is).
    pub(in super::super) fn dip(&self, behind: Option<&Behind>, here: &Node, next: &Node, step: f64) -> Option<f64> {
        if std::env::var_os("PC_TRACE_DIP").is_some_and(|v| v == "parts") {
            let parts: Vec<String> = parts(next).iter().map(|p| format!("{} {} {} {:.3e}", p.contact, p.at, &p.what[..5], p.value)).collect();
            eprintln!("dip parts: λ {:.10}: {parts:?}", next.lambda(self.fam.rho));
        }
        let behind = behind.filter(|b| b.at == here.w)?;
        let model = self.problem.model();
        let mut suspects: Vec<Suspect> = behind
            .parts
            .iter()
            // A massless point's held force is round-off at 1e-9 of its scale (tests/event_swap.rs: −1.2e-9 … −6e-10 a step apart).
            .filter(|p| !model.contact_is_massless(&model.contacts[p.contact]))
            .filter_map(|p| {
                let pts = [(-behind.step, p.value), (0.0, part(here, p)?), (step, part(next, p)?)];
                let (x, v) = vertex(pts)?;
                (x > 0.0 && x < step && v < -SUSPECT * TOL).then_some((v, p, pts))
            })
            .collect();
        suspects.sort_by(|a, b| a.0.total_cmp(&b.0));
        let trace = std::env::var_os("PC_TRACE_DIP").is_some();
        let along = self.fam.metric.unit(&here.tangent);
        let normal = self.fam.metric.lower(&along);
        for (predicted, key, pts) in suspects {
            let mut seen: Vec<(f64, f64)> = pts.to_vec();
            for _ in 0..TRIALS {
                seen.sort_by(|a, b| a.0.total_cmp(&b.0));
                // The lowest point seen on the step and its neighbours (the point before as the left one at `here`).
                let low = (1..seen.len()).min_by(|&a, &b| seen[a].1.total_cmp(&seen[b].1)).expect("three points");
                let mid = low.clamp(1, seen.len() - 2);
                let Some((x, _)) = vertex([seen[mid - 1], seen[mid], seen[mid + 1]]) else { break };
                // Inside the step and apart from the points seen (else the minimum is found).
                let x = x.clamp(1e-3 * step, (1.0 - 1e-3) * step);
                if seen.iter().any(|s| (s.0 - x).abs() < 1e-4 * step) {
                    break;
                }
                let pred: Vec<f64> = here.w.iter().zip(&along).map(|(w, t)| w + x * t).collect();
                let Some(v) = super::super::profile::caller("dip", f64::NAN, || self.fam.correct(&pred, &normal, dot(&normal, &pred)))
                    .ok()
                    .and_then(|w| self.fam.orbit_node(w, &along, false))
                    .and_then(|n| part(&n, key))
                else {
                    break;
                };
                if trace {
                    eprintln!(
                        "dip trace: λ {:.10}, step {step:e}: contact {} {} (phase/event {}) predicted {predicted:e}; at {x:e} of the step: {v:e}",
                        here.lambda(self.fam.rho),
                        key.contact,
                        key.what,
                        key.at
                    );
                }
                if v < -TOL {
                    return Some(x);
                }
                seen.push((x, v));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::vertex;
    use crate::analysis::continuation::exact::family::tests::forced_with_rigid_stop;
    use crate::analysis::continuation::exact::walk;
    use crate::analysis::continuation::{ContinuationSettings, EventKind, Parameter};
    use crate::model::{Matrix, Structure};

    /// x'' + 0.1 x' + x = cos Ωt with a rigid stop at x = `gap`, bds1 with 256 steps.
    fn oscillator(gap: f64, omega: f64) -> crate::periodic::PeriodicProblem {
        let structure =
            Structure { mass: Matrix::from_rows(&[vec![1.0]]), stiffness: Matrix::from_rows(&[vec![1.0]]), damping: Some(Matrix::from_rows(&[vec![0.1]])) };
        forced_with_rigid_stop(structure, 0, gap, 256, omega)
    }

    /// A stop 0.5 % below the linear resonance's peak is touched over a window 0.010 rad/s wide
    /// (5 % of the range), which long steps pass over with the contact-free orbit admissible at
    /// both ends: before the margin's dips were sought, walks with the larger steps here recorded
    /// no grazing and went on contact-free through 1.1. Every step path must find the first touch
    /// where the linear orbit's amplitude 1/√((1 − Ω²)² + (cΩ)²) reaches the gap (closed form: Ω²
    /// the smaller root of u² − (2 − c²)u + 1 − 1/gap² = 0).
    #[test]
    fn a_touch_within_one_step_is_found_whatever_the_step() {
        let c: f64 = 0.1;
        let peak = 1.0 / (c * (1.0 - c * c / 4.0).sqrt());
        let gap = 0.995 * peak;
        let b = 2.0 - c * c;
        let touch = (0.5 * (b - (b * b - 4.0 * (1.0 - 1.0 / (gap * gap))).sqrt())).sqrt();
        for (initial_step, exact_max_step) in [(0.05, 0.3), (0.1, 0.5), (0.02, 0.1), (0.07, 0.4)] {
            let settings = ContinuationSettings { initial_step, exact_max_step, max_points: 40, ..ContinuationSettings::default() };
            let walked = walk(&oscillator(gap, 0.9), Parameter::Frequency, 0.9, 1.1, &settings, &|_| {}).expect("the walk from Ω = 0.9");
            let first = walked.points.iter().find(|p| p.event == Some(EventKind::Grazing));
            let lambdas: Vec<f64> = walked.points.iter().map(|p| p.parameter).take(12).collect();
            eprintln!("steps {initial_step}, {exact_max_step}: first grazing {:?} (closed form {touch:.12}); λ {lambdas:.5?}", first.map(|p| p.parameter));
            let at = first.unwrap_or_else(|| panic!("steps {initial_step}, {exact_max_step}: no grazing (the touch at Ω = {touch}); λ {lambdas:?}")).parameter;
            assert!((at - touch).abs() < 1e-9, "steps {initial_step}, {exact_max_step}: the touch at Ω = {at}, the closed form's at {touch}");
        }
    }

    /// The vertex of a parabola from three of its points, spaced unevenly: exact to round-off.
    #[test]
    fn a_parabolas_vertex_from_three_points() {
        let f = |x: f64| 3.0 * (x - 0.37).powi(2) - 2e-9;
        let (x, v) = vertex([(-0.5, f(-0.5)), (0.0, f(0.0)), (1.3, f(1.3))]).expect("convex");
        assert!((x - 0.37).abs() < 1e-12 && (v + 2e-9).abs() < 1e-14, "({x}, {v})");
        assert!(vertex([(-0.5, -f(-0.5)), (0.0, -f(0.0)), (1.3, -f(1.3))]).is_none(), "a concave parabola has no minimum");
    }
}
