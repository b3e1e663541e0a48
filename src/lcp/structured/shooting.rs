//! Shooting on a step-map LCP: the periodic answer is the fixed point of the period map
//! P(s_0) = s_k, found by nonsmooth Newton on F(s) = s − P(s).
//!
//! P is piecewise affine; on the piece of the current active sets its Jacobian is the product of
//! the step Jacobians (the discrete monodromy matrix). Newton with that Jacobian is exact once the
//! active sets are right, so it ends in a few iterations; a backtracking line search on ‖F‖∞
//! keeps it from leaving a good iterate. When Newton stalls (a 2-cycle between a touching and a
//! free orbit is typical of compliant contact), a homotopy in a uniform offset δ of every r_j
//! takes over: at δ₀ no pair is active on the contact-free orbit, which is then the answer, and δ
//! is brought to 0 by steps, each solved by Newton from a secant prediction of the previous.
//! Nothing here is certified on the stacked LCP: the caller does that and falls back.
use super::jacobian::{PhiPowers, RunsJacobian};
use super::step_lcp::ActiveBlocks;
use super::step_map::{Contacts, DenseLu, March, StepMapLcp, march_with};
use faer::Mat;

/// A defect Newton cannot lower on an unchanged piece is accepted up to this (relative): the
/// march's round-off, about k·ε·‖s‖, is above a fixed tolerance at large k.
const ROUND_OFF_FLOOR: f64 = 1e-9;

/// A bound on a k-step march's relative round-off in units of k·ε: measured 0.07–0.6 on the
/// Craig–Bampton blade at k = 16 384 and 2.7 on the coarse blade at k = 1024; an order above.
const ROUND_OFF_STEPS: f64 = 32.0;

/// Relative defect at which a point of the offset path is accepted.
const PATH_TOLERANCE: f64 = 1e-11;

/// Settings of the shooting solver, with defaults.
#[derive(Clone, Debug)]
pub struct ShootingSettings {
    /// Newton iterations per solve (per homotopy step, `homotopy_iterations`).
    pub max_iterations: usize,
    /// Newton iterations per homotopy step before the step is halved.
    pub homotopy_iterations: usize,
    /// Most homotopy steps.
    pub max_homotopy_steps: usize,
    /// ‖s − P(s)‖∞ ≤ tolerance · max(‖s‖∞, ‖c‖∞·k) ends Newton.
    pub tolerance: f64,
    /// Estimated floating-point operations after which shooting gives up (about a second), at
    /// least `work_iterations` Newton iterations' worth: the caller's fallback (dense Lemke) is
    /// then the cheaper way on a small problem. Why: the offset homotopy of a stiff reduced
    /// model near resonance can meet hundreds of kinks, each a Jacobian.
    pub max_work: f64,
    /// The budget's floor in Newton iterations (a march and the costliest period Jacobian formed
    /// so far): on a large problem one iteration alone passes `max_work` (≈ 10¹⁰ flops at d = 200,
    /// k = 8192), and there is no cheaper fallback.
    pub work_iterations: f64,
    /// With a warm start, give up when Newton from it misses (no contact-free start, no offset
    /// homotopy): a guarded sweep's quick try, which has other routes (ω sub-steps, a neighbour
    /// on the other side) cheaper than a homotopy of hundreds of kinks.
    pub warm_only: bool,
    /// Without a warm start (or past it), follow the offset homotopy when Newton from the
    /// contact-free orbit misses. Off: a guarded sweep's cold try inside a run of failed points
    /// (issue 23: there it met 70–100 kinks and missed, 2–5 s each).
    pub homotopy: bool,
    /// With a warm start, first march this many periods from its orbit (the period map iterated:
    /// time marching), then Newton from where they end: the jump onto the attractor past a fold
    /// that Newton from the warm orbit alone misses (a lone rubbing solve's frequency walk).
    pub settle: usize,
    /// With a warm start, an orbit state s_0 to start Newton from (the same orbit solved on
    /// another grid, carried here) before the warm sets' frozen fixed point: that fixed point
    /// costs a march and a period Jacobian (issue 23: a third of a refinement's shooting).
    pub warm_state: Option<Vec<f64>>,
}

/// What a shooting solve may try beyond Newton from its warm start ([`ShootingSettings`]'s
/// `warm_only`, `homotopy`, `settle` and `warm_state`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShootingReach<'a> {
    pub warm_only: bool,
    pub homotopy: bool,
    pub settle: usize,
    pub state: Option<&'a [f64]>,
}

impl ShootingReach<'static> {
    /// Everything: warm Newton, the contact-free start, the offset homotopy.
    pub const FULL: ShootingReach<'static> = ShootingReach { warm_only: false, homotopy: true, settle: 0, state: None };
}

impl Default for ShootingSettings {
    fn default() -> Self {
        ShootingSettings {
            max_iterations: 30,
            homotopy_iterations: 8,
            max_homotopy_steps: 200,
            tolerance: 1e-13,
            max_work: 6e9,
            work_iterations: 40.0,
            warm_only: false,
            homotopy: true,
            settle: 0,
            warm_state: None,
        }
    }
}

/// How the shooting ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShootingOutcome {
    /// F(s) = 0 to the tolerance: z is the step LCPs' answers along the closed orbit.
    Converged,
    /// Neither Newton nor the homotopy reached the tolerance.
    NotConverged,
    /// A march broke down (a singular active block or a non-finite state).
    Breakdown,
}

/// The answer of a shooting solve.
#[derive(Clone, Debug)]
pub struct ShootingSolution {
    pub outcome: ShootingOutcome,
    /// z_j stacked (index j·m + c).
    pub z: Vec<f64>,
    /// The closed orbit's initial state s_0.
    pub state: Vec<f64>,
    /// The active set of each step (bit c: pair c active) along that orbit.
    pub masks: Vec<u64>,
    /// ‖s − P(s)‖∞ at the end.
    pub defect: f64,
    /// Newton iterations (Jacobians formed), homotopy steps included.
    pub iterations: usize,
    /// Homotopy steps taken (0: Newton alone converged).
    pub homotopy_steps: usize,
    /// Marches over the period (line search and homotopy included).
    pub marches: usize,
    /// Step-LCP set changes summed over every march.
    pub changes: usize,
    /// Period Jacobians formed (one per piece of the map met; the costly part at large d).
    pub jacobians: usize,
    /// Where Newton started: "warm" (the given active sets), "free" (the contact-free orbit).
    pub start: &'static str,
    /// Floating-point operations spent, estimated (marches and Jacobians).
    pub work: f64,
    /// Of which one Newton iteration at most: a march and the costliest period Jacobian.
    pub work_per_iteration: f64,
}

/// Newton's state between iterations.
struct Newton<'a> {
    sm: &'a StepMapLcp,
    powers: PhiPowers,
    /// What the next Jacobian can reuse of the last ones (the same step map throughout).
    runs: RunsJacobian,
    /// The step LCPs' factored blocks, shared by every march of the solve.
    blocks: ActiveBlocks,
    settings: &'a ShootingSettings,
    scale: f64,
    iterations: usize,
    marches: usize,
    changes: usize,
    /// Jacobians formed (one per piece met).
    jacobians: usize,
    /// Floating-point operations spent, estimated (marches and Jacobians).
    work: f64,
    /// One march, and the costliest Jacobian formed so far (0 before).
    march_work: f64,
    jacobian_work: f64,
    jac: Mat<f64>,
    /// The active sets `jac` belongs to.
    jac_masks: Option<Vec<u64>>,
    /// Seconds spent marching and forming Jacobians (printed under `PERIODIC_CONTACT_PROFILE`).
    march_s: f64,
    jacobian_s: f64,
}

/// An iterate with its march.
struct Iterate {
    s: Vec<f64>,
    march: March,
    defect: f64,
}

impl<'a> Newton<'a> {
    fn march(&mut self, s: &[f64], shift: f64, guess: &[u64], jacobian: bool) -> Option<Iterate> {
        // Over budget every march fails, and so does every loop that needs one.
        if self.work > self.budget() {
            return None;
        }
        self.marches += 1;
        self.work += self.march_work;
        let clock = std::time::Instant::now();
        let m = march_with(&mut self.blocks, self.sm, s, shift, Contacts::Solve(guess));
        self.march_s += clock.elapsed().as_secs_f64();
        let m = m?;
        self.changes += m.changes;
        if jacobian {
            self.ensure_jacobian(&m.masks);
        }
        let defect = s.iter().zip(&m.end).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        Some(Iterate { s: s.to_vec(), march: m, defect })
    }

    /// Makes `jac` the Jacobian of the piece of `masks`; P is affine on a piece, so a Jacobian
    /// is formed only when the sets change (Newton's last iterations keep them).
    fn ensure_jacobian(&mut self, masks: &[u64]) {
        if self.jac_masks.as_deref() != Some(masks) {
            let clock = std::time::Instant::now();
            let products = self.runs.form(self.sm, masks, &self.powers, &mut self.jac);
            self.jacobian_s += clock.elapsed().as_secs_f64();
            self.jac_masks = Some(masks.to_vec());
            self.jacobians += 1;
            // (d+1)×(d+1) products of the runs' powers, 2(d+1)³ flops each.
            let work = products.max(1) as f64 * 2.0 * (self.sm.d as f64 + 1.0).powi(3);
            self.jacobian_work = self.jacobian_work.max(work);
            self.work += work;
        }
    }

    /// The work allowed: `max_work`, or `work_iterations` Newton iterations when more.
    fn budget(&self) -> f64 {
        self.settings.max_work.max(self.settings.work_iterations * (self.march_work + self.jacobian_work))
    }

    fn size(&self, it: &Iterate) -> f64 {
        it.s.iter().fold(self.scale, |a, v| a.max(v.abs()))
    }

    fn converged(&self, it: &Iterate) -> bool {
        it.defect <= self.settings.tolerance * self.size(it)
    }

    /// The defect is within a k-step march's round-off, ROUND_OFF_STEPS·k·ε·‖s‖ (or converged).
    fn at_round_off(&self, it: &Iterate) -> bool {
        it.defect <= (ROUND_OFF_STEPS * self.sm.k as f64 * f64::EPSILON).max(self.settings.tolerance) * self.size(it)
    }

    /// Newton from `s` at offset `shift`; Ok: converged iterate, Err: the best iterate met.
    fn solve(&mut self, s: Vec<f64>, shift: f64, guess: &[u64], max_iterations: usize) -> Result<Iterate, Option<Iterate>> {
        let mut cur = match self.march(&s, shift, guess, true) {
            Some(it) => it,
            None => return Err(None),
        };
        for _ in 0..max_iterations {
            if self.converged(&cur) {
                return Ok(cur);
            }
            self.iterations += 1;
            // (I − J) δ = −(s − P(s)), with J the Jacobian of the march that gave `cur`.
            let d = self.sm.d;
            let a = Mat::from_fn(d, d, |i, j| if i == j { 1.0 } else { 0.0 } - self.jac[(i, j)]);
            let rhs: Vec<f64> = (0..d).map(|i| cur.march.end[i] - cur.s[i]).collect();
            let step = DenseLu::new(&a).solve(&rhs);
            if !step.iter().all(|v| v.is_finite()) {
                return Err(Some(cur));
            }
            let mut t = 1.0;
            let next = loop {
                let trial: Vec<f64> = (0..d).map(|i| cur.s[i] + t * step[i]).collect();
                // Only an accepted trial needs its Jacobian: march it again then (rare: t < 1).
                match self.march(&trial, shift, &cur.march.masks, false) {
                    // P is affine on a piece: a full step that keeps the Jacobian's sets is Newton's
                    // exact answer, and a defect left at the march's round-off (about k·ε·‖s‖, above
                    // `tolerance` at large k) more steps only redraw (issue 23, the CB warm start).
                    Some(it) if t == 1.0 && it.march.masks == cur.march.masks && self.at_round_off(&it) => return Ok(it),
                    Some(it) if it.defect < (1.0 - 1e-4 * t) * cur.defect || self.converged(&it) => {
                        self.ensure_jacobian(&it.march.masks);
                        break Some(it);
                    }
                    _ if t > 1.0 / 64.0 => t /= 2.0,
                    _ => break None,
                }
            };
            match next {
                Some(it) => cur = it,
                // Newton on an unchanged piece is exact: a defect it cannot lower is round-off of
                // the march (it grows with k), accepted when small; the caller certifies it.
                None if cur.march.changes == 0 && cur.defect <= ROUND_OFF_FLOOR * self.size(&cur) => return Ok(cur),
                None => return Err(Some(cur)),
            }
        }
        if self.converged(&cur) { Ok(cur) } else { Err(Some(cur)) }
    }
}

/// Solves a step-map LCP by shooting. `warm`: active sets per step (bit masks) of a neighbouring
/// answer, e.g. the previous frequency's; Newton then starts from the orbit those sets give.
pub fn solve_shooting(sm: &StepMapLcp, warm: Option<&[u64]>, settings: &ShootingSettings) -> ShootingSolution {
    let (k, d) = (sm.k, sm.d);
    let scale = sm.c.iter().fold(0.0f64, |a, v| a.max(v.abs())) * k as f64;
    let mut nt = Newton {
        sm,
        powers: PhiPowers::new(sm),
        runs: RunsJacobian::default(),
        blocks: ActiveBlocks::default(),
        settings,
        scale: scale.max(f64::MIN_POSITIVE),
        iterations: 0,
        marches: 0,
        changes: 0,
        jacobians: 0,
        work: 0.0,
        march_work: k as f64 * (d as f64 * d as f64 + 2.0 * (d * sm.m) as f64),
        jacobian_work: 0.0,
        jac: Mat::zeros(d, d + 1),
        jac_masks: None,
        march_s: 0.0,
        jacobian_s: 0.0,
    };
    let solution = shoot(&mut nt, warm);
    if std::env::var_os("PERIODIC_CONTACT_PROFILE").is_some() {
        eprintln!(
            "shooting profile: k = {k}, d = {d}, m = {}: {} marches {:.3} s, {} Jacobians {:.3} s, {} iterations, {} homotopy steps",
            sm.m, nt.marches, nt.march_s, nt.jacobians, nt.jacobian_s, nt.iterations, solution.homotopy_steps
        );
    }
    solution
}

/// Newton from the warm sets, from the contact-free orbit, then the offset homotopy.
fn shoot(nt: &mut Newton<'_>, warm: Option<&[u64]>) -> ShootingSolution {
    let (sm, settings) = (nt.sm, nt.settings);
    let (k, d) = (sm.k, sm.d);
    let fail = |nt: &Newton<'_>, outcome, best: Option<Iterate>, homotopy_steps| ShootingSolution {
        outcome,
        z: best.as_ref().map_or_else(|| vec![0.0; k * sm.m], |b| b.march.z.clone()),
        state: best.as_ref().map_or_else(|| vec![0.0; d], |b| b.s.clone()),
        masks: best.as_ref().map_or_else(|| vec![0; k], |b| b.march.masks.clone()),
        defect: best.as_ref().map_or(f64::INFINITY, |b| b.defect),
        iterations: nt.iterations,
        homotopy_steps,
        marches: nt.marches,
        changes: nt.changes,
        jacobians: nt.jacobians,
        start: if warm.is_some() { "warm" } else { "free" },
        work: nt.work,
        work_per_iteration: nt.march_work + nt.jacobian_work,
    };
    let done = |nt: &Newton<'_>, it: Iterate, homotopy_steps, start| ShootingSolution {
        outcome: ShootingOutcome::Converged,
        z: it.march.z,
        state: it.s,
        masks: it.march.masks,
        defect: it.defect,
        iterations: nt.iterations,
        homotopy_steps,
        marches: nt.marches,
        changes: nt.changes,
        jacobians: nt.jacobians,
        start,
        work: nt.work,
        work_per_iteration: nt.march_work + nt.jacobian_work,
    };
    // 0. Past a fold: time marching from the warm sets' orbit, then Newton.
    if settings.settle > 0
        && let Some(sets) = warm.filter(|w| w.len() == k)
        && let Some(it) = settle_then_newton(nt, sets)
    {
        return done(nt, it, 0, "warm");
    }
    // 1. Newton from a carried orbit state with the warm sets, then from the warm sets' orbit,
    // then from the contact-free orbit (formed only when the warm start fails: its Jacobian
    // costs as much as a Newton iteration).
    if let Some(sets) = warm.filter(|w| w.len() == k)
        && let Some(s) = settings.warm_state.as_ref().filter(|s| s.len() == d)
        && let Ok(it) = nt.solve(s.clone(), 0.0, sets, settings.max_iterations)
    {
        return done(nt, it, 0, "warm");
    }
    if let Some(sets) = warm.filter(|w| w.len() == k)
        && let Some(s) = fixed_state(nt, Contacts::Frozen(sets))
        && let Ok(it) = nt.solve(s, 0.0, sets, settings.max_iterations)
    {
        return done(nt, it, 0, "warm");
    }
    if settings.warm_only && warm.is_some() {
        return fail(nt, ShootingOutcome::NotConverged, None, 0);
    }
    // The contact-free orbit: the fixed point of the affine map without contact.
    let Some(free) = fixed_point(nt, Contacts::Free) else {
        return fail(nt, ShootingOutcome::Breakdown, None, 0);
    };
    let (s_free, free_march) = free;
    if free_march.min_w >= 0.0 {
        // No pair is active on the contact-free orbit: it is the answer.
        if let Some(it) = nt.march(&s_free, 0.0, &[], false) {
            return done(nt, it, 0, "free");
        }
    }
    let best = match nt.solve(s_free.clone(), 0.0, &[], settings.max_iterations) {
        Ok(it) => return done(nt, it, 0, "free"),
        Err(best) => best,
    };
    if !settings.homotopy {
        return fail(nt, ShootingOutcome::NotConverged, best, 0);
    }
    // 2. Homotopy in the offset: δ₀ makes the contact-free orbit feasible; the path (s, δ) is
    // followed by pseudo-arclength down to δ = 0, through its folds (coexisting orbits).
    let delta0 = -free_march.min_w * (1.0 + 1e-6) + f64::MIN_POSITIVE;
    match follow_offset(nt, s_free, delta0) {
        Ok((it, steps)) => done(nt, it, steps, "free"),
        Err(steps) => fail(nt, ShootingOutcome::NotConverged, best, steps),
    }
}

/// A point of the offset path: the state, the offset and the active sets met.
struct PathPoint {
    s: Vec<f64>,
    delta: f64,
    sets: Vec<u64>,
}

/// The unit vector e_i of length n.
fn unit(n: usize, i: usize) -> Vec<f64> {
    (0..n).map(|j| if j == i { 1.0 } else { 0.0 }).collect()
}

/// Pseudo-arclength continuation (Keller 1977) of F(s, δ) = s − P(s; δ) = 0 from the contact-free
/// orbit at δ₀ to δ = 0. Natural stepping in δ stalls where the path folds back (seen on the
/// compliant stop: the orbit's amplitude is not monotone in the offset), arclength does not.
/// Predictor along the tangent t, corrector Newton on [F; tᵀ(u − u_pred)] with the matrix
/// [I − J_s, −J_δ; tᵀ]. At the first crossing of δ = 0, Newton at δ = 0 from the interpolated
/// state. Ok: the converged iterate and the number of path steps; Err: the steps spent.
fn follow_offset(nt: &mut Newton<'_>, s_free: Vec<f64>, delta0: f64) -> Result<(Iterate, usize), usize> {
    let d = nt.sm.d;
    let settings = nt.settings;
    let mut here = PathPoint { s: s_free, delta: delta0, sets: Vec::new() };
    // On the contact-free piece P does not depend on δ: the path leaves straight down in δ.
    let mut tangent = vec![0.0; d + 1];
    tangent[d] = -1.0;
    let mut ds = 0.25 * delta0;
    let (min_ds, max_ds) = (1e-9 * delta0, 4.0 * delta0);
    // Corrector failures at the current point: halving the step usually cures one; after three
    // the point is taken to sit before a kink the corrector cannot cross.
    let mut failures = 0;
    for step in 1..=settings.max_homotopy_steps {
        let mut res = correct(nt, &here, &tangent, ds);
        if res.is_none() && failures >= 3 {
            // Search the kink over the step that first failed here.
            res = cross_kink(nt, &here, &tangent, ds * f64::from(1u32 << failures.min(30)));
        }
        let Some((next, t_next, iterations)) = res else {
            failures += 1;
            ds /= 2.0;
            if ds < min_ds {
                return Err(step);
            }
            continue;
        };
        if next.delta <= 0.0 {
            // δ = 0 lies between here and next: Newton at δ = 0 from the interpolated state.
            let f = here.delta / (here.delta - next.delta);
            let guess: Vec<f64> = here.s.iter().zip(&next.s).map(|(a, b)| a + f * (b - a)).collect();
            if let Ok(it) = nt.solve(guess, 0.0, &next.sets, settings.max_iterations) {
                return Ok((it, step));
            }
            ds /= 2.0;
            if ds < min_ds {
                return Err(step);
            }
            continue;
        }
        if next.delta > delta0 && next.sets.iter().all(|&m| m == 0) {
            // Back on the contact-free family above the grazing offset: the path closed on
            // itself (seen on the rigid blade near resonance); it cannot reach δ = 0.
            return Err(step);
        }
        here = next;
        tangent = t_next;
        failures = 0;
        if iterations <= 3 {
            ds = (ds * 1.6).min(max_ds);
        }
    }
    Err(settings.max_homotopy_steps)
}

/// Crosses the kink of the path ahead when the corrector cannot (Newton cycles between two pieces
/// of P near a kink, and at a nonsmooth fold the path turns back there). On the current piece the
/// path is the straight line here + τ·t while the march keeps its active sets: bisection finds
/// the τ where they change, the next piece's Jacobian gives its direction (the null vector of
/// [I − J_s, −J_δ]), oriented into that piece, and one corrector step follows it.
fn cross_kink(nt: &mut Newton<'_>, here: &PathPoint, tangent: &[f64], ds: f64) -> Option<(PathPoint, Vec<f64>, usize)> {
    let d = nt.sm.d;
    let at = |tau: f64| -> Vec<f64> { (0..=d).map(|i| if i < d { here.s[i] } else { here.delta } + tau * tangent[i]).collect() };
    let sets_here = nt.march(&here.s, here.delta, &here.sets, false)?.march.masks;
    let beyond = at(ds);
    if nt.march(&beyond[..d], beyond[d], &sets_here, false)?.march.masks == sets_here {
        return None;
    }
    let (mut lo, mut hi) = (0.0f64, ds);
    while hi - lo > 1e-12 * ds {
        let mid = 0.5 * (lo + hi);
        let u = at(mid);
        if nt.march(&u[..d], u[d], &sets_here, false)?.march.masks == sets_here {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let u = at(hi);
    let sets_next = nt.march(&u[..d], u[d], &sets_here, false)?.march.masks;
    nt.ensure_jacobian(&sets_next);
    let bordered = Mat::from_fn(d + 1, d + 1, |i, j| match (i < d, j < d) {
        (true, true) => (if i == j { 1.0 } else { 0.0 }) - nt.jac[(i, j)],
        (true, false) => -nt.jac[(i, d)],
        (false, _) => tangent[j],
    });
    let t = DenseLu::new(&bordered).solve(&unit(d + 1, d));
    let norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return None;
    }
    let kink = PathPoint { s: at(lo)[..d].to_vec(), delta: at(lo)[d], sets: sets_next.clone() };
    // Either orientation of the next piece's line: the one whose step stays off the current piece.
    for sign in [1.0, -1.0] {
        let t_next: Vec<f64> = t.iter().map(|v| sign * v / norm).collect();
        if let Some(step) = correct(nt, &kink, &t_next, ds)
            && step.0.sets != sets_here
        {
            return Some(step);
        }
    }
    None
}

/// One arclength step of length `ds` from `here` along `tangent`: Newton on the bordered system.
/// Returns the new point, its tangent (oriented as `tangent`) and the corrector's iterations.
fn correct(nt: &mut Newton<'_>, here: &PathPoint, tangent: &[f64], ds: f64) -> Option<(PathPoint, Vec<f64>, usize)> {
    let d = nt.sm.d;
    let pred: Vec<f64> = (0..=d).map(|i| if i < d { here.s[i] } else { here.delta } + ds * tangent[i]).collect();
    let mut u = pred.clone();
    let mut sets = here.sets.clone();
    for iteration in 1..=nt.settings.homotopy_iterations {
        let it = nt.march(&u[..d], u[d], &sets, true)?;
        nt.iterations += 1;
        sets.clone_from(&it.march.masks);
        let bordered = Mat::from_fn(d + 1, d + 1, |i, j| match (i < d, j < d) {
            (true, true) => (if i == j { 1.0 } else { 0.0 }) - nt.jac[(i, j)],
            (true, false) => -nt.jac[(i, d)],
            (false, _) => tangent[j],
        });
        let lu = DenseLu::new(&bordered);
        let along: f64 = (0..=d).map(|i| tangent[i] * (u[i] - pred[i])).sum();
        // Points of the path need not be exact (only the one at δ = 0 is certified): relative
        // 1e-11, and the arclength condition to round-off of u.
        let size = nt.size(&it).max(u[d].abs());
        if it.defect <= PATH_TOLERANCE * size && along.abs() <= 1e-12 * ds.abs().max(size) {
            // The tangent at the new point: [DF; tᵀ] t' = e_(d+1), normalised.
            let t = lu.solve(&unit(d + 1, d));
            let norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return None;
            }
            let t_next: Vec<f64> = t.iter().map(|v| v / norm).collect();
            return Some((PathPoint { s: u[..d].to_vec(), delta: u[d], sets }, t_next, iteration));
        }
        let rhs: Vec<f64> = (0..=d).map(|i| if i < d { it.march.end[i] - u[i] } else { -along }).collect();
        let du = lu.solve(&rhs);
        if !du.iter().all(|v| v.is_finite()) {
            return None;
        }
        for i in 0..=d {
            u[i] += du[i];
        }
    }
    None
}

/// The fixed point of the affine map the march is for these contacts (free, or frozen sets):
/// s = (I − J)⁻¹ P(0) with J = dP/ds; with its march from that point.
fn fixed_point(nt: &mut Newton<'_>, contacts: Contacts<'_>) -> Option<(Vec<f64>, March)> {
    let s = fixed_state(nt, contacts)?;
    nt.marches += 1;
    nt.work += nt.march_work;
    let m = march_with(&mut nt.blocks, nt.sm, &s, 0.0, contacts)?;
    Some((s, m))
}

/// `settle` periods marched from the orbit the warm sets give (each step's LCP solved: time
/// marching, which follows the transient onto an attractor), then Newton from their end.
fn settle_then_newton(nt: &mut Newton<'_>, sets: &[u64]) -> Option<Iterate> {
    let mut s = fixed_state(nt, Contacts::Frozen(sets))?;
    let mut masks = sets.to_vec();
    for _ in 0..nt.settings.settle {
        nt.marches += 1;
        let m = march_with(&mut nt.blocks, nt.sm, &s, 0.0, Contacts::Solve(&masks))?;
        (s, masks) = (m.end, m.masks);
    }
    nt.solve(s, 0.0, &masks, nt.settings.max_iterations).ok()
}

/// [`fixed_point`]'s state alone (a warm start's Newton marches from it with the sets solved).
fn fixed_state(nt: &mut Newton<'_>, contacts: Contacts<'_>) -> Option<Vec<f64>> {
    let d = nt.sm.d;
    let zero = vec![0.0; d];
    nt.marches += 1;
    nt.work += nt.march_work;
    let m0 = march_with(&mut nt.blocks, nt.sm, &zero, 0.0, contacts)?;
    nt.ensure_jacobian(&m0.masks);
    let a = Mat::from_fn(d, d, |i, j| if i == j { 1.0 } else { 0.0 } - nt.jac[(i, j)]);
    let s = DenseLu::new(&a).solve(&m0.end);
    s.iter().all(|v| v.is_finite()).then_some(s)
}
