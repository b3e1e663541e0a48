//! A step of the walk ([`Walk::try_step`]), why it is refused, and the step trace (PC_TRACE_STEP):
//! what bound each step, to tell where a walk's points go.
use super::family::{Failure, Node};
use super::{MAX_DRIFT, MIN_COS, Walk, dot, profile, signature};

/// PC_TRACE_STEP: per point of the walk, its step and what bound it (the controller growing
/// ×GROWTH or regrowing ×REGROWTH after a change, the maximum step, a landing on a vanishing
/// phase) and the retries shorter before it (why each).
pub(super) struct StepTrace {
    on: bool,
    landing: bool,
    retries: Vec<&'static str>,
}

impl StepTrace {
    pub(super) fn new() -> StepTrace {
        StepTrace { on: std::env::var_os("PC_TRACE_STEP").is_some(), landing: false, retries: Vec::new() }
    }

    pub(super) fn bound(&mut self, landing: bool) {
        self.landing = landing;
    }

    pub(super) fn retry(&mut self, why: &'static str) {
        if self.on {
            self.retries.push(why);
        }
    }

    pub(super) fn point(&mut self, lambda: f64, step: f64, ds: f64, cap: f64, max: f64, drift: f64) {
        if self.on {
            let by = if self.landing {
                "landing"
            } else if ds >= max {
                "max"
            } else if step < cap {
                "regrowth"
            } else {
                "controller"
            };
            eprintln!("step trace: λ {lambda:.10} step {step:.3e} by {by}, drift/step {drift:.2e}; retries {:?}", self.retries);
        }
        self.retries.clear();
    }
}

/// Why a step of the walk found no point ([`Walk::try_step`]): named where the walk stops on it.
#[derive(Clone, Copy, Debug)]
pub(super) enum Refused {
    /// The corrector failed ([`family::Failure`]).
    Corrector(Failure),
    /// The corrected point's tangent or orbit could not be made.
    Point,
    /// The tangent turned: the cosine between successive tangents, below [`MIN_COS`].
    Turned(f64),
    /// The corrected point lies this many steps from its predictor, above [`MAX_DRIFT`].
    Drifted(f64),
    /// A phase between two events of one contact is not positive at the corrected point.
    Reversed,
    /// A pair of events collapsed between the predictor and the corrected point.
    Collapsed,
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::Corrector(why) => write!(f, "the corrector failed: {why}"),
            Refused::Point => write!(f, "the corrected point's tangent or orbit could not be made"),
            Refused::Turned(cos) => write!(f, "the tangent turned by arccos {cos:.3}"),
            Refused::Drifted(steps) => write!(f, "the corrected point lies {steps:.2} steps from its predictor"),
            Refused::Reversed => write!(f, "a phase between two events of one contact is not positive at the corrected point"),
            Refused::Collapsed => write!(f, "a pair of events collapsed within the step"),
        }
    }
}

impl Walk<'_> {
    /// The step from `here` to the predictor `pred` ([`Self::pass`] first): the corrected point
    /// and `here` re-expressed in a new order of its events, when the successive tangents are
    /// within arccos [`MIN_COS`] (or the step is the smallest) and the point within [`MAX_DRIFT`]
    /// steps of the predictor.
    pub(super) fn try_step(&mut self, here: &Node, pred: Vec<f64>, step: f64, min_step: f64) -> Result<(Node, Option<Node>), Refused> {
        let (pred, passed) = self.pass(here, pred);
        let metric = &self.fam.metric;
        // The metric weighs the event times alike: re-ordering them keeps the tangent a unit one.
        let along = metric.unit(passed.as_ref().map_or(&here.tangent, |p| &p.tangent));
        let normal = metric.lower(&along);
        let target = dot(&normal, &pred);
        // Oriented in the metric too ([`Family::tangent`]).
        let w = profile::caller("step", step, || self.fam.correct(&pred, &normal, target)).map_err(Refused::Corrector)?;
        let n = self.fam.node_with(w, &along, false).ok_or(Refused::Point)?;
        let metric = &self.fam.metric;
        let drift = metric.norm(&n.w.iter().zip(&pred).map(|(a, b)| a - b).collect::<Vec<_>>());
        let turn = metric.dot(&metric.unit(&n.tangent), &along);
        self.drift = drift / step;
        if turn < MIN_COS && step > min_step {
            return Err(Refused::Turned(turn));
        }
        if drift > MAX_DRIFT * step {
            return Err(Refused::Drifted(drift / step));
        }
        if signature::reversed(&self.fam, &n.w) {
            return Err(Refused::Reversed);
        }
        if signature::collapsed(&self.fam, &pred, &n.w) {
            return Err(Refused::Collapsed);
        }
        Ok((n, passed))
    }
}
