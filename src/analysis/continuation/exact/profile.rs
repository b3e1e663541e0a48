//! Where the exact walk's time goes, under `PERIODIC_CONTACT_PROFILE`: the thread's CPU time
//! (Linux: /proc/thread-self/schedstat, the figure to read on a loaded machine) summed per stage
//! of the family and the walk, printed when the walk ends. Nothing is measured without it.
use super::family::Failure;
use std::cell::{Cell, RefCell};
use std::sync::OnceLock;

/// The stages measured, in the order printed.
#[derive(Clone, Copy)]
pub(super) enum Stage {
    /// An orbit of the signature built at λ (its phases, modes shared).
    Build,
    /// A shooting residual.
    Residual,
    /// The state and time columns of a Jacobian (the variational flow of one period).
    Variational,
    /// A Jacobian's λ column (two residuals on orbits rebuilt at λ ± h).
    LambdaColumn,
    /// A point's orbit, multipliers and touches ([`super::family::Family::node_with`]).
    Node,
    /// The outputs' amplitudes and touches sampled over a period.
    Amplitudes,
    /// Bisections locating events.
    Bisect,
    /// One trial point of a bisection (a correction and a point).
    Trial,
    /// An event's test function at a bisection's point (e.g. the rigid margin's sampled period).
    Test,
    /// A corrector's chord iterations (the last point's Jacobian), converged or not.
    Chord,
    /// A corrector's Newton iterations (fresh Jacobians): where the chord failed or had none.
    Newton,
}

const NAMES: [&str; 11] = [
    "orbit built",
    "residual",
    "variational flow",
    "λ column",
    "point (monodromy, touches)",
    "amplitudes",
    "bisections (inclusive)",
    "bisection trial points (inclusive)",
    "bisection test functions",
    "correctors by chord (inclusive)",
    "correctors by Newton (inclusive)",
];

thread_local! {
    static TOTALS: RefCell<Option<[(f64, usize); 11]>> = const { RefCell::new(None) };
}

pub(super) fn enabled() -> bool {
    std::env::var_os("PERIODIC_CONTACT_PROFILE").is_some()
}

/// The thread's CPU time so far [s].
pub(super) fn cpu() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat").ok().and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok()).unwrap_or(f64::NAN) * 1e-9
}

/// `f`'s thread CPU time added to `stage` (when profiling).
pub(super) fn timed<T>(stage: Stage, f: impl FnOnce() -> T) -> T {
    if !enabled() {
        return f();
    }
    let start = cpu();
    let out = f();
    let spent = cpu() - start;
    TOTALS.with(|t| {
        let mut t = t.borrow_mut();
        let row = &mut t.get_or_insert([(0.0, 0); 11])[stage as usize];
        row.0 += spent;
        row.1 += 1;
    });
    out
}

/// Prints the totals (when profiling) with the number of points walked, and clears them.
pub(super) fn report(points: usize) {
    if !enabled() {
        return;
    }
    let Some(totals) = TOTALS.with(|t| t.borrow_mut().take()) else { return };
    eprintln!("exact walk profile: {points} points, thread CPU {:.1} s", cpu());
    for (name, (s, n)) in NAMES.iter().zip(totals) {
        eprintln!("exact walk profile: {name}: {s:.1} s CPU in {n} calls ({:.1} ms each)", 1e3 * s / n.max(1) as f64);
    }
}

thread_local! {
    /// Who calls the corrector (PC_TRACE_NEWTON) and its predictor's step (scaled unknowns).
    static CALLER: Cell<(&'static str, f64)> = const { Cell::new(("other", f64::NAN)) };
}

fn tracing_newton() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("PC_TRACE_NEWTON").is_some())
}

/// `f` with the correctors it calls traced as `caller`'s, from a predictor `step` away.
pub(super) fn caller<T>(caller: &'static str, step: f64, f: impl FnOnce() -> T) -> T {
    if !tracing_newton() {
        return f();
    }
    let before = CALLER.with(|c| c.replace((caller, step)));
    let out = f();
    CALLER.with(|c| c.set(before));
    out
}

/// The thread's CPU time when tracing the correctors (0 otherwise).
pub(super) fn newton_clock() -> f64 {
    if tracing_newton() { cpu() } else { 0.0 }
}

/// PC_TRACE_NEWTON: one line per Newton run of a corrector (chord or fresh Jacobians), its
/// outcome and corrections, for the tally of why correctors fail.
pub(super) fn newton_call(fresh: bool, out: &Result<Vec<f64>, Failure>, corrections: &[(f64, bool)], start: f64) {
    if !tracing_newton() {
        return;
    }
    let spent = cpu() - start;
    let (who, step) = CALLER.with(Cell::get);
    let outcome = match out {
        Ok(_) => "ok".to_string(),
        Err(f) => format!("{f:?}"),
    };
    let list: Vec<String> = corrections.iter().map(|(c, jacobian)| format!("{c:.2e}{}", if *jacobian && !fresh { "J" } else { "" })).collect();
    eprintln!(
        "newton: {who} step {step:.3e} {} {} cpu {spent:.6} iterations {} corrections {}",
        if fresh { "fresh" } else { "chord" },
        outcome,
        corrections.len(),
        list.join(",")
    );
}

/// PC_TRACE_NEWTON: a search's end (from λ `from`, its result).
pub(super) fn search_done(what: &str, from: f64, found: Option<f64>, start: f64) {
    if tracing_newton() {
        eprintln!("search: {what} from {from:.10} found {found:?} cpu {:.6}", cpu() - start);
    }
}
