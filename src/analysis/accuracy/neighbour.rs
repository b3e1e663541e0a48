//! The error estimate's neighbour solves (k/2, k/4 or 2k), bounded. As a guarded sweep's point
//! (`analysis::sweep`'s `solve_guarded`): shooting warm from the point's own active set carried to
//! the neighbour's k, then cold shooting, then dense Lemke only while its projected cost fits the
//! estimate's CPU budget, with its pivots capped by what is left. Past the budget the neighbour
//! is a typed miss ([`EstimateMissing`]) and the point keeps its own certified answer. Why: on the
//! rubbing real blade (issue 23) the neighbours missed shooting and `auto`'s dense fallback ran
//! minutes each on the non-symmetric LCP (254 s CPU for one estimate, against 8 s for the solve).
use crate::periodic::{
    DENSE_MEMORY_MAX, LEMKE_FLOPS_PER_S, LcpMethod, PeriodFft, PeriodicProblem, PeriodicSolver, SolveError, SolverSettings, dense_lemke_seconds, dense_memory,
    progress,
};
use crate::response::{EstimateMissing, MissingCause, Response};
use crate::time::Scheme;
use std::time::Instant;

/// CPU seconds the neighbour solves of one estimate may take together by default. Why: a few
/// times a hard solve (the rubbing real blade's lone solve, walk included: 6–8 s CPU), far below
/// the minutes of an unbounded dense fallback.
pub const ESTIMATE_BUDGET_CPU_S: f64 = 30.0;

/// A neighbour solve taking longer than this [s CPU] says so on the progress lines.
const SLOW_NEIGHBOUR_S: f64 = 5.0;

/// The CPU time left to an estimate's neighbour solves, measured on the calling thread (the
/// solves run there; wall time where /proc is unavailable).
#[derive(Clone, Debug)]
pub struct Budget {
    limit: f64,
    cpu0: Option<f64>,
    wall0: Instant,
}

impl Budget {
    /// `limit` CPU seconds from now.
    pub fn new(limit: f64) -> Self {
        Budget { limit, cpu0: crate::analysis::polish::thread_cpu(), wall0: Instant::now() }
    }

    /// CPU seconds spent since [`Budget::new`].
    pub fn spent(&self) -> f64 {
        match (self.cpu0, crate::analysis::polish::thread_cpu()) {
            (Some(a), Some(b)) => b - a,
            _ => self.wall0.elapsed().as_secs_f64(),
        }
    }

    /// CPU seconds left (≤ 0 when spent).
    pub fn left(&self) -> f64 {
        self.limit - self.spent()
    }

    pub fn limit(&self) -> f64 {
        self.limit
    }
}

/// Dense Lemke's pivots that fit in `seconds` on an LCP of `n` unknowns: 2N² flops a pivot at
/// [`LEMKE_FLOPS_PER_S`] (the rate `dense_lemke_seconds` projects with).
pub fn pivots_within(seconds: f64, n: usize) -> usize {
    let per_pivot = 2.0 * (n as f64).powi(2) / LEMKE_FLOPS_PER_S;
    (seconds.max(0.0) / per_pivot).floor() as usize
}

/// `grid` (the neighbour: `note` names it, "k/2 = 512") solved for the estimate of an answer
/// whose active set, carried to `grid`'s instants, is `carried`: warm shooting, cold shooting,
/// then dense Lemke within `budget` (`auto` only; `shooting` stops before it, and a dense method
/// the user chose runs as asked: at k/2 it costs an eighth of the point's).
pub fn solve(grid: &PeriodicProblem, carried: &[usize], budget: &Budget, note: &str) -> Result<Response, EstimateMissing> {
    let method = grid.solver_settings().method;
    let (t, before) = (Instant::now(), budget.spent());
    let slow = |what: &str| {
        let spent = budget.spent() - before;
        if spent > SLOW_NEIGHBOUR_S {
            progress(&format!("error estimate: the neighbour at {note} {what} after {spent:.1} s CPU ({:.1} s wall)", t.elapsed().as_secs_f64()));
        }
    };
    let mut session = PeriodicSolver::new(grid.clone());
    session.set_warm_start(carried);
    if matches!(method, LcpMethod::Lemke | LcpMethod::Pivoting) {
        let r = session.solve();
        slow(if r.is_ok() { "solved" } else { "missed" });
        return r
            .map_err(|e| missed(note, format!("{} missed: {}", method.name(), short(&e)), "solve the point at a finer k, or with method = \"auto\"".into()));
    }
    let n = grid.instants() * grid.model().contacts.len();
    // Fourier collocation has no step map: its only method is dense.
    let tried = if grid.discretization().scheme == Scheme::Fourier {
        "fourier collocation has no step map to shoot on".to_string()
    } else {
        let cold = match session.solve_by_shooting(true) {
            Ok(r) => return Ok(r),
            Err(_) if budget.left() <= 0.0 => return Err(over_budget(note, budget, "warm shooting missed".into())),
            Err(_) => session.solve_by_shooting(false),
        };
        match cold {
            Ok(r) => {
                slow("solved by cold shooting");
                return Ok(r);
            }
            Err(e) => format!("shooting missed warm from the point's active set and cold ({})", short(&e)),
        }
    };
    if method == LcpMethod::Shooting || dense_memory(n) > DENSE_MEMORY_MAX {
        let remedy = "solve the point with method = \"auto\" (a dense fallback within the estimate's budget), or at another k".into();
        return Err(missed(note, tried, remedy));
    }
    let (left, projected) = (budget.left(), dense_lemke_seconds(n));
    if projected > left {
        return Err(over_budget(
            note,
            budget,
            format!("{tried}; dense Lemke at N = {n} is projected ≈ {projected:.0} s (N³ flops at {LEMKE_FLOPS_PER_S:.0e}/s)"),
        ));
    }
    let cap = pivots_within(left, n);
    if projected > SLOW_NEIGHBOUR_S {
        progress(&format!(
            "error estimate: {tried} at {note}; dense Lemke at N = {n} (projected ≈ {projected:.0} s, at most {cap} pivots: {left:.0} s CPU left)"
        ));
    }
    let mut dense = grid.clone();
    let settings = SolverSettings { method: LcpMethod::Lemke, dense_pivots: Some(cap), ..grid.solver_settings().clone() };
    dense.set_solver_settings(settings).map_err(|e| missed(note, format!("{tried}; {e}"), String::new()))?;
    let r = dense.solve_with(&PeriodFft::new(dense.instants()), Some(carried));
    slow(if r.is_ok() { "solved by dense Lemke" } else { "missed" });
    r.map_err(|e| {
        let why = format!("{tried}; dense Lemke at N = {n} capped at {cap} pivots ({:.0} s CPU left of the budget) missed: {}", left, short(&e));
        match &e {
            SolveError::Lcp { info, .. } if info.pivots >= cap => over_budget(note, budget, why),
            _ => missed(note, why, "solve the point at a finer k (its neighbours then solve as its own grid does)".into()),
        }
    })
}

fn over_budget(note: &str, budget: &Budget, tried: String) -> EstimateMissing {
    EstimateMissing {
        cause: MissingCause::Budget,
        detail: format!("the neighbour at {note}: {tried}; the estimate's budget is {:.0} s CPU ({:.1} s spent)", budget.limit(), budget.spent()),
        remedy: "a budget above the projected cost (CLI `solve --estimate-budget SECONDS`, C API `pc_problem_set_error_estimate_budget`), or compare with a solve at 2k by hand".into(),
    }
}

fn missed(note: &str, tried: String, remedy: String) -> EstimateMissing {
    EstimateMissing { cause: MissingCause::Missed, detail: format!("the neighbour at {note}: {tried}"), remedy }
}

fn short(e: &SolveError) -> String {
    let s = e.to_string();
    let cut = s.char_indices().nth(200).map_or(s.len(), |(i, _)| i);
    if cut < s.len() { format!("{}…", &s[..cut]) } else { s }
}
