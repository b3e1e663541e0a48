//! The LCP policy: which method solves a block-circulant LCP, and the fallbacks (`auto`).
//! Shared by the engine and by `periodic-contact lcp`, so it knows nothing of mechanics.
use super::status::{evaluate, recheck_exactly};
use super::structured::{ShootingOutcome, ShootingReach, ShootingSettings, StepMapLcp, solve_shooting};
use super::{BlockCirculant, BlockPivoting, CirculantOperator, LcpOutcome, LcpSolution, LcpStep, Lemke, LemkeSettings, PivotingSettings, WarmOutcome};
use std::time::Instant;

/// Which LCP method to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LcpMethod {
    /// Picks by size and falls back on failure.
    Auto,
    /// Lexicographic Lemke.
    Lemke,
    /// Block principal pivoting on the active set, FFT products.
    Pivoting,
    /// Shooting on the period map of a time-stepping scheme (needs the step map: `solve` of a
    /// scene, not a raw LCP), certified on the stacked LCP.
    Shooting,
}

impl LcpMethod {
    /// Every method, in the order of the documentation.
    pub const ALL: [LcpMethod; 4] = [LcpMethod::Auto, LcpMethod::Lemke, LcpMethod::Pivoting, LcpMethod::Shooting];

    pub fn name(self) -> &'static str {
        match self {
            LcpMethod::Auto => "auto",
            LcpMethod::Lemke => "lemke",
            LcpMethod::Pivoting => "pivoting",
            LcpMethod::Shooting => "shooting",
        }
    }
}

/// Up to this LCP size `auto` uses lexicographic Lemke directly; above, block pivoting finished
/// by Lemke from its best basis, with full lexicographic Lemke as the fallback.
pub const AUTO_LEMKE_MAX: usize = 256;

/// Solves a block-circulant LCP with `method` (`auto` uses lexicographic Lemke up to
/// [`AUTO_LEMKE_MAX`], above it block pivoting with FFT products, falling back to Lemke when that
/// fails). Used by `periodic-contact lcp` for a raw LCP whose matrix is block-circulant; the
/// engine calls [`solve_periodic_lcp`], which tries shooting first when it has the step map.
pub fn solve_circulant_lcp(a: &BlockCirculant, q: &[f64], method: LcpMethod, tolerance: f64, warm_start: Option<&[usize]>) -> LcpSolution {
    solve_periodic_lcp(a, q, None, method, tolerance, warm_start).0
}

/// After a failed shooting, dense Lemke is the next step up to this size (block pivoting first
/// above it).
pub const LEMKE_AFTER_SHOOTING_MAX: usize = 4096;

/// The most memory the dense methods may take: Lemke's B⁻¹ or the pivoting LU of the active
/// block can hold N² numbers ([`dense_memory`]), 8 GiB at N = [`DENSE_MAX`]. Above, only
/// shooting runs, whose memory is O(d² log k + k·(d + m)).
pub const DENSE_MEMORY_MAX: f64 = 8.0 * GIB;

/// The largest LCP whose dense methods fit in [`DENSE_MEMORY_MAX`].
pub const DENSE_MAX: usize = 1 << 15;

/// Bytes in a GiB.
pub const GIB: f64 = (1u64 << 30) as f64;

/// Bytes the dense methods can need on an LCP of `n` unknowns: N² numbers.
pub fn dense_memory(n: usize) -> f64 {
    8.0 * (n as f64).powi(2)
}

/// Dense Lemke's speed on one core, flops per second, for its projected time: on the fine blade
/// (N = 6144, ≈ N/2 pivots of 2N² flops: N³) it took 20 s (see `solve_periodic_lcp_with`).
pub const LEMKE_FLOPS_PER_S: f64 = 1e10;

/// After a failed shooting, `auto` runs dense Lemke only when it is projected to take at most
/// this [s]; above, the failure is typed with the projected cost and the remedies. Why: on the
/// rubbing real blade (N = 17 408) the fallback ran 20 min silently without finishing.
pub const DENSE_FALLBACK_MAX_S: f64 = 120.0;

/// Dense Lemke's projected seconds on an LCP of `n` unknowns: about N/2 pivots of 2N² flops.
pub fn dense_lemke_seconds(n: usize) -> f64 {
    (n as f64).powi(3) / LEMKE_FLOPS_PER_S
}

/// Whether `auto` may fall back on dense Lemke after shooting missed on an LCP of `n` unknowns:
/// `Err` names the projected time and memory (the caller adds why shooting missed and remedies).
pub fn dense_fallback_allowed(n: usize) -> Result<(), String> {
    let (seconds, bytes) = (dense_lemke_seconds(n), dense_memory(n));
    if seconds <= DENSE_FALLBACK_MAX_S && bytes <= DENSE_MEMORY_MAX {
        return Ok(());
    }
    Err(format!(
        "dense Lemke at N = {n} would take ≈ {:.0} min (N³ flops at {LEMKE_FLOPS_PER_S:.0e}/s; at most {DENSE_FALLBACK_MAX_S:.0} s in auto) and ≈ {:.1} GiB",
        seconds / 60.0,
        bytes / GIB
    ))
}

static PROGRESS: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Turns on progress lines of long solves on stderr (the CLI does; a library caller, the C API
/// and the FMU stay silent).
pub fn set_progress(on: bool) {
    PROGRESS.store(on, std::sync::atomic::Ordering::Relaxed);
}

/// Writes one progress line on stderr when [`set_progress`] turned them on.
pub fn progress(line: &str) {
    if PROGRESS.load(std::sync::atomic::Ordering::Relaxed) {
        eprintln!("{line}");
    }
}

/// The engine's policy for the period's LCP (A block-circulant, q), with the step map of the
/// scheme when it has one. `auto`: shooting first when there is a step map (certified on (A, q)
/// by FFT products), then, up to [`DENSE_MAX`], the block-circulant chain of
/// [`solve_circulant_lcp`]. Returns the answer and, after a converged shooting, the orbit's
/// initial state.
pub fn solve_periodic_lcp(
    a: &BlockCirculant,
    q: &[f64],
    step_map: Option<&StepMapLcp>,
    method: LcpMethod,
    tolerance: f64,
    warm_start: Option<&[usize]>,
) -> (LcpSolution, Option<Vec<f64>>) {
    solve_periodic_lcp_with(a, q, step_map, method, tolerance, warm_start, ShootingReach::FULL, None)
}

/// [`solve_periodic_lcp`]; `reach`: what shooting may try beyond Newton from the warm start
/// ([`ShootingReach`]: a guarded sweep's quick tries); `dense_pivots`: a cap on dense Lemke's
/// pivots ([`LemkeSettings::max_pivots`]: an error estimate's bounded fallback).
#[allow(clippy::too_many_arguments)]
pub fn solve_periodic_lcp_with(
    a: &BlockCirculant,
    q: &[f64],
    step_map: Option<&StepMapLcp>,
    method: LcpMethod,
    tolerance: f64,
    warm_start: Option<&[usize]>,
    reach: ShootingReach<'_>,
    dense_pivots: Option<usize>,
) -> (LcpSolution, Option<Vec<f64>>) {
    if q.is_empty() {
        return (LcpSolution { outcome: LcpOutcome::Solved, z: vec![], w: vec![], info: Default::default() }, None);
    }
    let step = |method, sol: &LcpSolution| LcpStep { method, size: q.len(), pivots: sol.info.pivots, outcome: sol.outcome, time_s: sol.info.time_s };
    let lemke = || {
        let settings =
            LemkeSettings { certify_tol: tolerance, warm_start: warm_start.map(<[usize]>::to_vec), max_pivots: dense_pivots, ..LemkeSettings::default() };
        let mut sol = Lemke::new(settings).solve(a, q);
        // Lemke accepts a guess that certifies as it is, or discards it and runs cold.
        sol.info.warm = match (warm_start, sol.info.warm_start_used) {
            (None, _) => WarmOutcome::NotOffered,
            (Some(_), true) => WarmOutcome::Accepted,
            (Some(_), false) => WarmOutcome::Rejected,
        };
        sol.info.path = vec![step(LcpMethod::Lemke, &sol)];
        sol
    };
    let pivoting = || {
        let settings = PivotingSettings { certify_tol: tolerance, warm_start: warm_start.map(<[usize]>::to_vec), ..PivotingSettings::default() };
        let mut sol = BlockPivoting::new(settings).solve(&CirculantOperator::new(a), q);
        // Block pivoting always starts from the guess: one exchange (the check) means it was right.
        sol.info.warm = match warm_start {
            None => WarmOutcome::NotOffered,
            Some(_) if sol.info.pivots <= 1 => WarmOutcome::Accepted,
            Some(_) => WarmOutcome::Repaired { pivots: sol.info.pivots },
        };
        sol.info.path = vec![step(LcpMethod::Pivoting, &sol)];
        sol
    };
    // A later method's pivots and time add to the earlier ones'; the path keeps every step.
    let then = |first: LcpSolution, next: &dyn Fn() -> LcpSolution| {
        if first.outcome == LcpOutcome::Solved {
            return first;
        }
        let mut sol = next();
        sol.info.pivots += first.info.pivots;
        sol.info.time_s += first.info.time_s;
        sol.info.path.splice(0..0, first.info.path);
        sol
    };
    let dense_ok = dense_memory(q.len()) <= DENSE_MEMORY_MAX;
    let blind = || match method {
        LcpMethod::Lemke => lemke(),
        LcpMethod::Pivoting => pivoting(),
        _ if q.len() <= AUTO_LEMKE_MAX => lemke(),
        _ => then(pivoting(), &lemke),
    };
    match (method, step_map) {
        (LcpMethod::Shooting | LcpMethod::Auto, Some(sm)) => {
            // Shooting may spend up to half of what its fallback would (dense Lemke: about N/2
            // pivots of 2N² flops each), not a fixed second: on the fine blade (N = 6144) Newton
            // converges in 189 iterations where the fixed budget handed over to 20 s of dense
            // Lemke. Without a fallback (`shooting` alone, as guarded sweeps ask) the fixed budget
            // bounds each try.
            let defaults = ShootingSettings::default();
            let max_work = if method == LcpMethod::Auto && dense_ok { defaults.max_work.max(0.5 * (q.len() as f64).powi(3)) } else { defaults.max_work };
            let (sol, state) = shooting(
                a,
                q,
                sm,
                tolerance,
                warm_start,
                &ShootingSettings {
                    max_work,
                    warm_only: reach.warm_only,
                    homotopy: reach.homotopy,
                    settle: reach.settle,
                    warm_state: reach.state.map(<[f64]>::to_vec),
                    ..defaults
                },
            );
            if sol.outcome == LcpOutcome::Solved || method == LcpMethod::Shooting || !dense_ok {
                return (sol, state);
            }
            // Shooting fails where the orbit is hard to reach (coexisting orbits near a
            // resonance): the certified reference next while it is cheap (N ≤
            // LEMKE_AFTER_SHOOTING_MAX: 0.1–0.6 s on the rigid blade at N = 3072, where block
            // pivoting took 8 s to end on a ray), else block pivoting first.
            let iterations = sol.info.pivots;
            let fallback = || {
                progress(&format!(
                    "shooting missed on N = {} after {iterations} Newton iterations; dense fallback (projected ≈ {:.0} s)",
                    q.len(),
                    dense_lemke_seconds(q.len())
                ));
                if q.len() <= LEMKE_AFTER_SHOOTING_MAX { lemke() } else { blind() }
            };
            (then(sol, &fallback), None)
        }
        _ => (blind(), None),
    }
}

/// Shooting on the step map, certified on (A, q) by FFT products (exactly summed when round-off
/// could reach the tolerance). Steps' counts: Newton iterations.
fn shooting(
    a: &BlockCirculant,
    q: &[f64],
    sm: &StepMapLcp,
    tolerance: f64,
    warm_start: Option<&[usize]>,
    settings: &ShootingSettings,
) -> (LcpSolution, Option<Vec<f64>>) {
    let start = Instant::now();
    let m = sm.pairs();
    let warm: Option<Vec<u64>> = warm_start.map(|set| {
        let mut masks = vec![0u64; sm.k()];
        for &i in set.iter().filter(|&&i| i < q.len()) {
            masks[i / m] |= 1 << (i % m);
        }
        masks
    });
    let shot = solve_shooting(sm, warm.as_deref(), settings);
    let clock = Instant::now();
    let qmax = q.iter().fold(1.0f64, |acc, v| acc.max(v.abs()));
    let cert = tolerance * qmax;
    let op = CirculantOperator::new(a);
    let cand = evaluate(&op, q, shot.z.clone(), cert);
    let solved = shot.outcome == ShootingOutcome::Converged && cand.residual <= cert;
    let outcome = if solved {
        LcpOutcome::Solved
    } else if shot.outcome == ShootingOutcome::Converged {
        LcpOutcome::Inaccurate
    } else {
        LcpOutcome::PivotLimit
    };
    let mut sol = LcpSolution { outcome, z: cand.z, w: cand.w, info: Default::default() };
    sol.info.residual = cand.residual;
    sol.info.relative_error = cand.relative_error;
    sol.info.pivots = shot.iterations;
    sol = recheck_exactly(sol, &op, q, tolerance);
    if std::env::var_os("PERIODIC_CONTACT_PROFILE").is_some() {
        eprintln!("shooting profile: certification on the stacked LCP (N = {}) {:.3} s", q.len(), clock.elapsed().as_secs_f64());
    }
    sol.info.time_s = start.elapsed().as_secs_f64();
    sol.info.warm = match (warm_start, shot.start) {
        (None, _) => WarmOutcome::NotOffered,
        (Some(_), "warm") if shot.iterations == 0 => WarmOutcome::Accepted,
        (Some(_), "warm") => WarmOutcome::Repaired { pivots: shot.iterations },
        (Some(_), _) => WarmOutcome::Rejected,
    };
    sol.info.warm_start_used = sol.info.warm == WarmOutcome::Accepted;
    sol.info.path = vec![LcpStep { method: LcpMethod::Shooting, size: q.len(), pivots: shot.iterations, outcome: sol.outcome, time_s: sol.info.time_s }];
    let state = solved.then_some(shot.state);
    sol.info.orbit_state = state.clone().map(std::sync::Arc::new);
    (sol, state)
}

/// Why a method name was not accepted.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LcpMethodError {
    /// Not one of [`LcpMethod::ALL`]'s names.
    #[error("unknown method \"{0}\"; expected auto, lemke, pivoting or shooting")]
    Unknown(String),
}

impl std::str::FromStr for LcpMethod {
    type Err = LcpMethodError;
    fn from_str(s: &str) -> Result<Self, LcpMethodError> {
        LcpMethod::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| LcpMethodError::Unknown(s.to_string()))
    }
}
