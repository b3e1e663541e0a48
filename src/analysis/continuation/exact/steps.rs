//! The walk's step trace (PC_TRACE_STEP): what bound each step, to tell where a walk's points go.

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
