//! One orbit followed to new knob values, and the Floquet stability of one orbit: the front
//! ends' re-solve (FMU, C API; issue 13 item 6).
//!
//! A front end re-solves after its knobs (a [`Tuning`]) changed. Warm-starting the solver from the
//! last active sets is not enough to stay on a branch: the discrete period map is piecewise
//! affine, and where a contact gains or loses a step its branch can wiggle (a pair of tiny folds;
//! measured on the drop-in demo's oscillator, cds k = 256, at ω = 1.32165 rad/s), so Newton at
//! the new value alone cycles between two pieces and the solver drops to another orbit. Here the
//! orbit is continued by pseudo-arclength along the straight path from the old tuning to the new
//! one (λ from 0 to 1, [`Family`]): through the wiggles, and, when the path turns back for good
//! (a fold: the branch ends), the caller is told so and solves for the orbit that exists.
use super::corrector::{Family, Path, Solved};
use super::exact_follow::Outcome;
use super::{ContinuationSettings, Parameter, active_set, floquet};
use crate::analysis::polish::PolishedOrbit;
use crate::error::Error;
use crate::periodic::{PeriodicProblem, PeriodicSolver, Tuning};
use crate::response::Response;
use crate::time::Discretization;
use num_complex::Complex64;

/// The outcome of [`follow`].
#[derive(Clone, Debug, PartialEq)]
pub enum Followed {
    /// The branch reaches the new tuning: the active set (the LCP's z indices) of its orbit there,
    /// to warm-start the certified solve from.
    Reached(Vec<usize>),
    /// The branch turns back before the new tuning (a fold): `at` is the farthest fraction of the
    /// way (0 = old, 1 = new tuning) the branch reached.
    Fold { at: f64 },
    /// Not followed (why): the caller solves as before, warm-started from the active set.
    NotFollowed(String),
}

/// A path that retreats by this much after turning back (relative to the knob values, as
/// [`ContinuationSettings::fold_merge`], and at least the whole step) has passed a fold; the
/// wiggles of the discrete branch retreat far less (≤ 2e-4 relative, measured on NLvib 03 at
/// k = 4096).
const RETREAT: f64 = 1e-3;

/// A fold is reported as a jump when the amplitude changes by more than this (relative): on the
/// demo's oscillator (cds, k = 256) the orbit found past a discrete fold next to the true one
/// differed by 6e-4, the jumps at the folds by 33 % and 92 %.
pub(super) const JUMP_MIN: f64 = 0.02;

/// Most arclength steps of one follow.
const MAX_STEPS: usize = 200;

/// The active sets as bit masks per step (bit c: contact c).
fn masks_of(set: &[usize], k: usize, m: usize) -> Vec<u64> {
    let mut masks = vec![0u64; k];
    for &i in set.iter().filter(|&&i| m > 0 && i < k * m) {
        masks[i / m] |= 1 << (i % m);
    }
    masks
}

/// The relative size of the change from `a` to `b`: each knob's change over its scale (ω, the
/// scales, and the largest static gap plus offset for the gap offset).
fn relative_change(base: &PeriodicProblem, a: &Tuning, b: &Tuning) -> f64 {
    let gap = base.model().contacts.iter().fold(0.0f64, |g, c| g.max((c.gap + a.gap_offset).abs()));
    let rel = |x: f64, y: f64, scale: f64| (y - x).abs() / if scale > 0.0 { scale } else { 1.0 };
    rel(a.frequency, b.frequency, a.frequency.abs())
        .max(rel(a.force_scale, b.force_scale, a.force_scale.abs()))
        .max(rel(a.motion_scale, b.motion_scale, a.motion_scale.abs()))
        .max(rel(a.gap_offset, b.gap_offset, gap))
}

/// Continues the orbit of `base` tuned at `from` with the active set `set` (the certified
/// solve's) to the tuning `to`, both on the grid `disc`. Needs the step map of a difference scheme.
pub fn follow(base: &PeriodicProblem, disc: Discretization, from: Tuning, to: Tuning, set: &[usize]) -> Followed {
    let not = |why: &str| Followed::NotFollowed(why.to_string());
    if from == to {
        return Followed::Reached(set.to_vec());
    }
    // λ enters the unknowns as λ·rel (rel: the change's relative size), so that the arclength
    // weighs a relative change of the knobs like one of the state, as the continuation's λ/ρ does:
    // in λ alone the corrector's hyperplane would be λ = const, where Newton cycles at a kink.
    let rel = relative_change(base, &from, &to).max(f64::MIN_POSITIVE);
    let mut fam = Family::new(base, Path::Tuning { from, to, disc }, 1.0 / rel);
    if let Err(e) = fam.map_at(0.0) {
        return Followed::NotFollowed(e.message().to_string());
    }
    let m = base.model().contacts.len();
    let Some(start) = fam.start(0.0, &masks_of(set, disc.steps, m)) else {
        return not("the current orbit does not close on its active sets");
    };
    let d = start.v.len() - 1;
    let e_lambda: Vec<f64> = (0..=d).map(|i| if i == d { 1.0 } else { 0.0 }).collect();
    let Some(tangent) = start.tangent(&e_lambda) else {
        return not("singular Jacobian at the current orbit");
    };
    // Both ways along the branch: where the orbit sits on the backward part of a wiggle, the way
    // to the new tuning starts with λ decreasing. The branch has ended (a fold) when neither
    // reaches λ = 1 and one turned back for good.
    let mut outcome = not("no way along the branch");
    for sign in [1.0, -1.0] {
        let t: Vec<f64> = tangent.iter().map(|v| sign * v).collect();
        match walk(&mut fam, start.clone(), t, rel, m) {
            Followed::Reached(set) => return Followed::Reached(set),
            Followed::Fold { at } => match outcome {
                Followed::Fold { at: other } => outcome = Followed::Fold { at: at.max(other) },
                _ => outcome = Followed::Fold { at },
            },
            other if sign > 0.0 => outcome = other,
            _ => {}
        }
    }
    outcome
}

/// Pseudo-arclength steps from `here` along `tangent` until λ = 1, or until the path has turned
/// back by [`RETREAT`] (a fold), or fails.
fn walk(fam: &mut Family, mut here: Solved, mut tangent: Vec<f64>, rel: f64, m: usize) -> Followed {
    let not = |why: &str| Followed::NotFollowed(why.to_string());
    let d = here.v.len() - 1;
    let retreat = (RETREAT / rel).max(1.0);
    // The first step aims at λ = 1 along the tangent.
    let mut ds = rel / tangent[d].abs().max(1e-12 * rel);
    let min_ds = 1e-9 * ds;
    let mut farthest = 0.0f64;
    for _ in 0..MAX_STEPS {
        let pred: Vec<f64> = here.v.iter().zip(&tangent).map(|(v, t)| v + ds * t).collect();
        let Some((next, iterations)) = fam.correct(&pred, &tangent, &here.masks) else {
            ds /= 2.0;
            if ds < min_ds {
                return not("no convergence along the branch with the smallest step");
            }
            continue;
        };
        let Some(t_next) = next.tangent(&tangent) else {
            ds /= 2.0;
            continue;
        };
        let lambda = next.parameter(fam.rho);
        if lambda >= 1.0 {
            return Followed::Reached(end_set(fam, &here, &next, m));
        }
        farthest = farthest.max(lambda);
        if lambda < farthest - retreat {
            return Followed::Fold { at: farthest };
        }
        here = next;
        tangent = t_next;
        if iterations <= 3 {
            ds *= 2.0;
        }
    }
    not("too many steps along the branch")
}

/// The active set at λ = 1 between `here` (λ < 1) and `next` (λ ≥ 1) on the path: bisection
/// along the secant (each trial the orbit on the hyperplane through its midpoint normal to it, as
/// [`super::events`] locates events) until both ends share their sets, the piece the path
/// crosses λ = 1 on; its fixed point at λ = 1 is then the orbit the certified solve returns.
fn end_set(fam: &mut Family, here: &Solved, next: &Solved, m: usize) -> Vec<usize> {
    let (mut lo, mut hi) = (here.clone(), next.clone());
    for _ in 0..48 {
        if lo.masks == hi.masks {
            break;
        }
        let sec: Vec<f64> = hi.v.iter().zip(&lo.v).map(|(x, y)| x - y).collect();
        let len = sec.iter().map(|x| x * x).sum::<f64>().sqrt();
        let normal: Vec<f64> = sec.iter().map(|x| x / len).collect();
        let pred: Vec<f64> = lo.v.iter().zip(&sec).map(|(x, s)| x + 0.5 * s).collect();
        let Some((mid, _)) = fam.correct(&pred, &normal, &lo.masks) else { break };
        if mid.parameter(fam.rho) < 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    active_set(&hi.masks, m)
}

/// The Floquet stability of one orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct Stability {
    /// The multipliers, largest modulus first.
    pub multipliers: Vec<Complex64>,
    /// The largest modulus.
    pub largest: f64,
    /// All multipliers inside the unit circle (|μ| ≤ 1).
    pub stable: bool,
}

/// The multipliers of the orbit of `problem` with the active set `set` (the certified solve's):
/// the continuation's own (the discrete monodromy of the step map on the orbit's active sets,
/// smoothed over the kinks as in [`ContinuationSettings::smoothing`]), so that a front end reports
/// what `periodic-contact continue` reports for the same orbit. `Err(why)` without a step map.
pub fn stability(problem: &PeriodicProblem, set: &[usize]) -> Result<Stability, String> {
    let omega = problem.model().frequency;
    let mut fam = Family::new(problem, Path::Parameter(Parameter::Frequency), omega);
    fam.smoothing = ContinuationSettings::default().smoothing;
    fam.map_at(omega).map_err(|e| e.message().to_string())?;
    let (k, m) = (problem.discretization().steps, problem.model().contacts.len());
    let solved = fam.start(omega, &masks_of(set, k, m)).ok_or("the orbit does not close on its active sets")?;
    let blocks = fam.blocks;
    let monodromy = fam.smoothed_monodromy(&solved, blocks, fam.smoothing).unwrap_or_else(|| solved.monodromy.clone());
    let multipliers = floquet::multipliers(&monodromy);
    let largest = floquet::largest(&multipliers);
    if !largest.is_finite() {
        return Err("the monodromy's Schur form did not converge (its multipliers are unknown): no stability is reported".into());
    }
    Ok(Stability { stable: largest <= 1.0, largest, multipliers })
}

/// A front end's current orbit, to be continued by [`resolve`].
#[derive(Clone, Copy, Debug)]
pub struct Current<'a> {
    pub tuning: Tuning,
    pub disc: Discretization,
    /// The certified solve's active set.
    pub active_set: &'a [usize],
    /// Its [`amplitude`].
    pub amplitude: f64,
    /// Its exact orbit on the followed branch ([`Resolved::orbit`] of the last re-solve), when
    /// the front end kept it; without it the exact walk starts from the polish of the grid orbit.
    pub orbit: Option<&'a PolishedOrbit>,
    /// Follow the exact branch where the scene has one (the FMU, the C API); `false`: the
    /// discrete branch only (`sweep`'s branch check).
    pub exact: bool,
}

/// A jump off a branch that ended at a fold between the old and the new tuning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jump {
    /// Where the branch turned back (its farthest point on the straight path of the knobs).
    pub fold: Tuning,
    /// The [`amplitude`] before and after.
    pub from_amplitude: f64,
    pub to_amplitude: f64,
}

/// A re-solve: the certified response, and the jump or why the orbit was not followed.
#[derive(Clone, Debug)]
pub struct Resolved {
    pub response: Response,
    pub jump: Option<Jump>,
    /// Why the branch was not followed (the solve was warm-started from the active set only).
    pub not_followed: Option<String>,
    /// The exact orbit on the followed branch at the new values (the next [`Current::orbit`]).
    pub orbit: Option<PolishedOrbit>,
    /// The stability of that exact orbit (the multipliers of its exact monodromy).
    pub stability: Option<Stability>,
    /// Why the exact branch was not followed (the discrete branch was, as [`follow`]); `None`
    /// when it was, or when there was nothing to follow.
    pub exact: Option<String>,
}

/// Half the largest peak-to-peak of the displacement series of `r` (the recovered DOFs), or of
/// its contact gaps when it has none: the amplitude a jump is reported with.
pub fn amplitude(r: &Response) -> f64 {
    let half = |s: &Vec<f64>| Response::peak_to_peak(s) / 2.0;
    let shown = r.displacement.values().map(half).fold(0.0f64, f64::max);
    if r.displacement.is_empty() { r.contacts.iter().map(|c| half(&c.gap)).fold(0.0f64, f64::max) } else { shown }
}

/// Solves `base` at `tuning` on `disc` in `session`, continuing `current` (same grid) along its
/// branch ([`follow`]): the answer is the orbit the branch reaches, or, when the branch ends at a
/// fold on the way, the orbit the solver finds from the last active set (the jump of the physical
/// response), reported as a [`Jump`]. Without `current` (or on another grid) a plain solve.
pub fn resolve(
    session: &mut PeriodicSolver,
    base: &PeriodicProblem,
    disc: Discretization,
    tuning: Tuning,
    current: Option<Current<'_>>,
) -> Result<Resolved, Error> {
    session.update_problem(tuning.apply(base, disc)?);
    let current = current.filter(|c| c.disc == disc && !base.model().contacts.is_empty());
    let Some(c) = current else {
        session.reset_warm_start();
        return Ok(Resolved { response: session.solve()?, jump: None, not_followed: None, orbit: None, stability: None, exact: None });
    };
    let exact = match c.exact {
        true => match super::exact_follow::resolve(session, base, disc, tuning, &c)? {
            Outcome::Followed(resolved) => return Ok(*resolved),
            Outcome::Discrete(why) => Some(why),
        },
        false => None,
    };
    let (start, fold, not_followed) = match follow(base, disc, c.tuning, tuning, c.active_set) {
        Followed::Reached(set) => (set, None, None),
        Followed::Fold { at } => (c.active_set.to_vec(), Some(at), None),
        Followed::NotFollowed(why) => (c.active_set.to_vec(), None, Some(why)),
    };
    session.set_warm_start(&start);
    let response = session.solve()?;
    let jump = fold.map(|at| {
        let fold = c.tuning.towards(&tuning, at);
        Jump { fold, from_amplitude: c.amplitude, to_amplitude: amplitude(&response) }
    });
    // Near a true fold the discrete branch can end in a kink and go on in a neighbouring piece
    // (NLvib-like wiggles): the orbit the solver finds is then next to the old one, no jump.
    let jump = jump.filter(|j| (j.to_amplitude - j.from_amplitude).abs() > JUMP_MIN * j.from_amplitude.max(j.to_amplitude));
    Ok(Resolved { response, jump, not_followed, orbit: None, stability: None, exact })
}
