//! The half-step friction pairing of cds and galerkin as a step map, with the event-fitted laws
//! (src/formulation.md §9 "Event-fitted half steps", "Friction by shooting").
//!
//! The scheme's row at t_j, N₀u_(j+1) + N₁u_j + N₂u_(j−1) = Σ_i a0_i F(t_(j+1−i)) − B_fᵀ(f_(j−1) + f_j)/2
//! (N_i = a2_i M/h² + a1_i C/h + a0_i K: cds a0 = (0, 1, 0), galerkin (1, 4, 1)/6), steps from the
//! state y = (u_(j−1), u_j, f_(j−1)): with W = N₀⁻¹ the prediction without f_j is
//! u⁰ = W(F(t_j) − N₁u_j − N₂u_(j−1) − B_fᵀf_(j−1)/2), and the sample's mean slip velocity
//! v̄_j = B_f(u_(j+1) − u_j)/h = v⁰ − T f_j, T = B_f W B_fᵀ/(2h) (symmetric positive definite for
//! M > 0). Each step is one box problem (friction_shooting's [`Relay`]): the relay for v̄, or in a
//! law's step for v̄ − c − ε f/μN (T gains ε/μN on its diagonal, s⁰ loses c). The dense LCP's
//! unfelt force mode f_j + (−1)ʲc (E(π) = 0) does not stall the march: each step's T is definite.
//! Newton on the period map with the sets fixed ([`shoot`]), then the laws are refitted from the
//! orbit's samples until they repeat ([`MAX_ROUNDS`]), each refit starting from the last orbit.
use super::friction::{FrictionGrid, certify, shooting_failed};
use super::friction_events::{EventLaws, MAX_ROUNDS};
use super::friction_shooting::{FrictionMarch, FrictionShot, FrictionStepMap, March, Relay, ShotFailure, shoot};
use super::{Assembly, NoStepMap, PeriodFft, PeriodicProblem, SHOOTING_WORK_MAX, SolveError};
use crate::lcp::{DenseLu, LcpMethod, LcpOutcome, LcpSolution, LcpStep, dense_product};
use faer::Mat;
use std::ops::Range;
use std::time::Instant;

/// Solves the friction problem on `map` (its k instants), certified on the full half-step LCP
/// with the last laws: the solution in the dense layout, the LCP time and the path's sentence.
pub(super) fn solve(
    problem: &PeriodicProblem,
    map: HalfStepMap,
    (asm, fft, grid): (&Assembly, &PeriodFft, &FrictionGrid),
    relay_only: bool,
) -> Result<(LcpSolution, f64, String), SolveError> {
    let t_lcp = Instant::now();
    let (k, mf) = (map.k, map.mf);
    let nn = 2 * k * mf;
    let (fitted, started) = fit_from_starts(problem, &map, relay_only).map_err(|e| shooting_failed(e, 2 * mf))?;
    let mut sol = certify(problem, (asm, fft, grid), &fitted.shot.forces, Some(&fitted.laws));
    let lcp_time = t_lcp.elapsed().as_secs_f64();
    sol.info.pivots = fitted.iterations;
    sol.info.time_s = lcp_time;
    sol.info.path = vec![LcpStep { method: LcpMethod::Shooting, size: nn, pivots: fitted.iterations, outcome: sol.outcome, time_s: lcp_time }];
    if sol.outcome != LcpOutcome::Solved {
        let hint = "the half-step shooting orbit does not satisfy its periodic friction LCP to solver.tolerance (a set change the march missed); set scheme = \"bds1\", or solver.method = \"lemke\" where the dense LCP fits".to_string();
        return Err(SolveError::Lcp { outcome: sol.outcome, info: sol.info, hint });
    }
    let laws = if relay_only { "the relay alone (diagnostic)".to_string() } else { format!("event-fitted laws after {} refits", fitted.refits) };
    let path = format!(
        "friction by shooting on the half steps (N = {nn}: the box LCP of the friction rows, src/formulation.md §9), {laws}: Newton on the {} period map{started}, {} iterations in all (periodicity {:.1e}), certified on the full LCP by FFT products (residual {:.1e}), {lcp_time:.3} s → {}",
        problem.discretization().scheme,
        fitted.iterations,
        fitted.shot.residual,
        sol.info.residual,
        sol.outcome.name()
    );
    Ok((sol, lcp_time, path))
}

/// A start for Newton: the state, the laws to begin with (none: the relay) and its sentence.
type Start = (Option<Vec<f64>>, Option<EventLaws>, &'static str);

/// The event-fitted orbit on `map` from the first start that converges, and that start's
/// sentence; else the first start's failure.
fn fit_from_starts(problem: &PeriodicProblem, map: &HalfStepMap, relay_only: bool) -> Result<(FittedShot, &'static str), ShotFailure> {
    // Starts in turn: bds1's orbit with its laws; with the laws of the half steps' own orbit at
    // k/2; bds1's orbit without laws; rest. Why the second: bds1 (numerically damped) reverses
    // 2 steps before the half steps do on Den Hartog c = 0, Ω = 1.310, μN = 0.647 at k = 512, so
    // its laws' window (±1 step) missed the reversal and Newton wandered off (periodicity 1.3e-2
    // after 60 iterations); the k/2 orbit's laws hold the event (measured, validation/RECORD.md "Friction").
    // Why the third: from bds1's laws Newton cycled on Den Hartog c = 0, Ω = 1.506, μN = 0.51 at
    // k = 256 (I − P near singular on those sets); from bds1's orbit on the relay it converges.
    let pilot = bds1_start(problem, map);
    let mut failure = None;
    for attempt in 0..4 {
        let start: Option<Start> = match attempt {
            0 if !relay_only => pilot.clone().map(|(y, laws)| (Some(y), Some(laws), " from bds1's orbit and its laws")),
            1 if !relay_only => coarse_laws(problem, map).map(|laws| (pilot.as_ref().map(|p| p.0.clone()), Some(laws), " from the laws of its orbit at k/2")),
            2 => pilot.clone().map(|(y, _)| (Some(y), None, " from bds1's orbit")),
            3 => Some((None, None, " from rest")),
            _ => None,
        };
        let Some((y, laws, how)) = start else { continue };
        let mut trial = map.clone();
        if let Some(l) = laws {
            trial.laws = l;
        }
        match trial.shoot_fitted(y, relay_only) {
            Ok(f) => return Ok((f, how)),
            Err(e) => failure = failure.or(Some(e)),
        }
    }
    Err(failure.expect("rest is always a start"))
}

/// Coarsest k whose half-step orbit lends its laws to 2k. Why: below it the laws' window spans
/// a large part of a slip phase and the coarse solve's own fallbacks buy nothing.
const COARSE_LAWS_MIN: usize = 64;

/// The laws for `map`'s k fitted to the event-fitted orbit at k/2 (solved as here, recursively),
/// its samples carried to k: each force over two steps, the mean velocities interpolated to the
/// fine steps' middles. `None` for odd k, k/2 below [`COARSE_LAWS_MIN`], or when k/2 fails too.
fn coarse_laws(problem: &PeriodicProblem, map: &HalfStepMap) -> Option<EventLaws> {
    let (kc, mf) = (map.k / 2, map.mf);
    if !map.k.is_multiple_of(2) || kc < COARSE_LAWS_MIN {
        return None;
    }
    let coarse = HalfStepMap::new(problem, kc).ok()?;
    let (fitted, _) = fit_from_starts(problem, &coarse, false).ok()?;
    let (f, v) = (&fitted.shot.forces, &fitted.shot.velocity);
    let (mut forces, mut velocity) = (vec![0.0; map.k * mf], vec![0.0; map.k * mf]);
    for j in 0..map.k {
        // Fine step j = 2i + r lies in coarse step i; its middle is 3/4 of the way from coarse
        // middle i − 1 to i (r = 0) or 1/4 from i to i + 1 (r = 1).
        let (i, r) = (j / 2, j % 2);
        let (a, b) = if r == 0 { ((i + kc - 1) % kc, i) } else { (i, (i + 1) % kc) };
        let wb = if r == 0 { 0.75 } else { 0.25 };
        for t in 0..mf {
            forces[j * mf + t] = f[i * mf + t];
            velocity[j * mf + t] = (1.0 - wb) * v[a * mf + t] + wb * v[b * mf + t];
        }
    }
    Some(EventLaws::fit(&map.nyquist, &map.slip, (&forces, &velocity), map.h))
}

/// The half-step map of a problem whose only nonsmooth rows are rigid Coulomb contacts under a
/// constant normal load, every DOF with mass.
#[derive(Clone)]
pub(super) struct HalfStepMap {
    n: usize,
    mf: usize,
    k: usize,
    /// μN of friction i.
    slip: Vec<f64>,
    /// [E; Q] ((n + mf) × d): u⁰ = E y + W F(t_j), v⁰ = Q y + B_f W F(t_j)/h.
    rows: Mat<f64>,
    /// W B_fᵀ/2 (n × mf).
    wbt: Mat<f64>,
    /// T (mf × mf, row-major).
    t: Vec<f64>,
    /// W F(t_j) at the k instants (k × n).
    forcing: Vec<f64>,
    /// The sliding DOF and its sign per friction contact.
    dofs: Vec<(usize, f64)>,
    h: f64,
    /// The receptance of each friction row at the Nyquist harmonic, B_f(N₁ − N₀ − N₂)⁻¹B_fᵀ (the
    /// assembly's G(π)), for the laws' g.
    nyquist: Vec<f64>,
    /// The law of each sample (none: the relay).
    pub laws: EventLaws,
}

/// An event-fitted orbit: the shot under the last laws, those laws, the refits and Newton's
/// iterations over all of them.
pub(super) struct FittedShot {
    pub shot: FrictionShot,
    pub laws: EventLaws,
    pub refits: usize,
    pub iterations: usize,
}

impl HalfStepMap {
    /// The map of `problem` over `k` instants (cds or galerkin), or why there is none.
    pub(super) fn new(problem: &PeriodicProblem, k: usize) -> Result<Self, NoStepMap> {
        let model = problem.model();
        let scheme = problem.discretization().scheme;
        let Some((1, a2, a1, a0)) = super::state_space::coefficients(scheme) else {
            return Err(NoStepMap(format!("{scheme} has no half-step friction map (cds and galerkin do)")));
        };
        if !model.contacts.is_empty() {
            return Err(NoStepMap("friction together with unilateral contacts has no step map yet (the dense LCP solves them)".to_string()));
        }
        if !model.massless_dofs().is_empty() {
            return Err(NoStepMap(format!("DOFs {:?} are massless: the friction step map needs a mass on every DOF", model.massless_dofs())));
        }
        let (n, mf) = (model.n(), model.frictions.len());
        let mut dofs = Vec::with_capacity(mf);
        for (i, f) in model.frictions.iter().enumerate() {
            if f.stiffness.is_some() || f.contact.is_some() {
                return Err(NoStepMap(format!(
                    "friction[{i}] is a Jenkins element or coupled to a contact: the half steps take rigid Coulomb under a constant normal load"
                )));
            }
            let &[(dof, dir)] = f.row.as_slice() else {
                return Err(NoStepMap(format!("friction[{i}] slides along several DOFs")));
            };
            dofs.push((dof, dir));
        }
        let d = 2 * n + mf;
        let work = k as f64 * (n + mf) as f64 * (d * d) as f64;
        if work > SHOOTING_WORK_MAX {
            return Err(NoStepMap(format!(
                "shooting on {n} DOFs with {mf} friction contacts over k = {k} steps costs ≈ {work:.1e} flops per Newton iteration (at most {SHOOTING_WORK_MAX:.0e})"
            )));
        }
        let h = problem.period() / k as f64;
        let s = &model.structure;
        let (mass, stiffness) = (s.mass.to_dense(), s.stiffness.to_dense());
        let damping = s.damping.as_ref().map(|c| c.to_dense());
        let combine = |i: usize| {
            Mat::from_fn(n, n, |r, c| a2[i] / (h * h) * mass[(r, c)] + a1[i] / h * damping.as_ref().map_or(0.0, |d| d[(r, c)]) + a0[i] * stiffness[(r, c)])
        };
        let lu = DenseLu::new(&combine(0));
        let columns: Vec<Vec<f64>> = (0..n).map(|c| lu.solve(&(0..n).map(|r| if r == c { 1.0 } else { 0.0 }).collect::<Vec<_>>())).collect();
        if columns.iter().flatten().any(|v| !v.is_finite()) {
            return Err(NoStepMap(format!("the {scheme} step's matrix N₀ is singular")));
        }
        let w = Mat::from_fn(n, n, |r, c| columns[c][r]);
        let (wn1, wn2) = (dense_product(&w, &combine(1)), dense_product(&w, &combine(2)));
        let wbt = Mat::from_fn(n, mf, |r, i| 0.5 * w[(r, dofs[i].0)] * dofs[i].1);
        // E = W [−N₂, −N₁, −B_fᵀ/2]; Q = (B_f E − [0, B_f, 0])/h.
        let mut rows = Mat::zeros(n + mf, d);
        for r in 0..n {
            for c in 0..n {
                rows[(r, c)] = -wn2[(r, c)];
                rows[(r, n + c)] = -wn1[(r, c)];
            }
            for i in 0..mf {
                rows[(r, 2 * n + i)] = -wbt[(r, i)];
            }
        }
        for (i, &(dof, dir)) in dofs.iter().enumerate() {
            for c in 0..d {
                rows[(n + i, c)] = dir * rows[(dof, c)] / h;
            }
            rows[(n + i, n + dof)] -= dir / h;
        }
        let t: Vec<f64> = (0..mf * mf).map(|il| dofs[il / mf].1 * wbt[(dofs[il / mf].0, il % mf)] / h).collect();
        // The load as the scheme weighs it, Σ_i a0_i F(t_(j+1−i)) (galerkin: the hats' (1, 4, 1)/6,
        // the assembly's w_p F̂_p; cds: F(t_j)); the friction force enters unweighted, as contacts.
        let samples = super::state_space::force_samples(model, k, h);
        let load = |j: usize, l: usize| (0..3).map(|i| a0[i] * samples[((j + k + 1 - i) % k) * n + l]).sum::<f64>();
        let mut forcing = vec![0.0; k * n];
        for j in 0..k {
            for r in 0..n {
                forcing[j * n + r] = (0..n).map(|l| w[(r, l)] * load(j, l)).sum();
            }
        }
        // z = e^{−iπ} = −1 in N₀z⁻¹ + N₁ + N₂z.
        let (n0, n1, n2) = (combine(0), combine(1), combine(2));
        let nyquist_lu = DenseLu::new(&Mat::from_fn(n, n, |r, c| n1[(r, c)] - n0[(r, c)] - n2[(r, c)]));
        let nyquist = dofs.iter().map(|&(dof, _)| nyquist_lu.solve(&(0..n).map(|r| if r == dof { 1.0 } else { 0.0 }).collect::<Vec<_>>())[dof]).collect();
        let slip = model.frictions.iter().map(|f| f.slip_force()).collect();
        Ok(HalfStepMap { n, mf, k, slip, rows, wbt, t, forcing, dofs, h, nyquist, laws: EventLaws::none(k, mf) })
    }

    /// Step j's T (with its laws' ε/μN on the diagonal) and the laws' offsets c.
    fn step_relay(&self, j: usize) -> (Vec<f64>, Vec<f64>) {
        let mut t = self.t.clone();
        let mut offset = vec![0.0; self.mf];
        for (i, &mu_n) in self.slip.iter().enumerate() {
            if let Some((c, eps)) = self.laws.at(i, j)
                && mu_n > 0.0
            {
                t[i * self.mf + i] += eps / mu_n;
                offset[i] = c;
            }
        }
        (t, offset)
    }

    /// Newton on this map from `start`, then the laws refitted from each orbit until they repeat
    /// (none with `relay_only`). A Newton that stalls below [`REFIT_STALLED`] also refits, from
    /// its last iterate. Why: on Den Hartog c = 0, Ω = 0.924, μN = 0.665 at k = 256 (seed 37)
    /// bds1's laws sat 4 steps after the half steps' reversal, and Newton on those sets stalled at
    /// periodicity 1.2e-5 (the relay's unfelt force mode has no periodic orbit there); the laws
    /// fitted to that iterate hold the event and Newton converges (measured).
    pub(super) fn shoot_fitted(mut self, start: Option<Vec<f64>>, relay_only: bool) -> Result<FittedShot, ShotFailure> {
        let (mut refits, mut iterations, mut state) = (0, 0, start);
        loop {
            let (shot, failure) = match shoot(&self, state) {
                Ok(shot) => (shot, None),
                Err(e) => match e.last {
                    Some(last) if !relay_only && refits < MAX_ROUNDS && e.residual <= REFIT_STALLED => {
                        (*last, Some(ShotFailure { iterations: iterations + e.iterations, last: None, ..e }))
                    }
                    last => return Err(ShotFailure { iterations: iterations + e.iterations, last, ..e }),
                },
            };
            iterations += shot.iterations;
            let next = (!relay_only && refits < MAX_ROUNDS).then(|| EventLaws::fit(&self.nyquist, &self.slip, (&shot.forces, &shot.velocity), self.h));
            match (next, failure) {
                (Some(next), _) if !next.repeats(&self.laws, 1e-10) => {
                    self.laws = next;
                    refits += 1;
                    state = Some(shot.state);
                }
                (_, Some(failure)) => return Err(failure),
                (_, None) => return Ok(FittedShot { shot, laws: self.laws, refits, iterations }),
            }
        }
    }
}

/// A stalled Newton's periodicity below which its last iterate refits the laws. Why: a stall
/// there is a set pattern the laws' windows miss by a few steps (measured 1.2e-5, seed 37);
/// far above it the iterate's events are no guide.
const REFIT_STALLED: f64 = 1e-3;

impl FrictionMarch for HalfStepMap {
    fn state_size(&self) -> usize {
        2 * self.n + self.mf
    }

    fn march(&self, y: &[f64], guess: Option<&[i8]>) -> March {
        let (n, mf, d) = (self.n, self.mf, self.state_size());
        let mut state = y.to_vec();
        let (mut modes, mut forces, mut velocity) = (vec![0i8; self.k * mf], vec![0.0; self.k * mf], vec![0.0; self.k * mf]);
        let mut pred = vec![0.0; n + mf];
        let mut last = vec![0i8; mf];
        for j in 0..self.k {
            for (r, out) in pred.iter_mut().enumerate() {
                *out = (0..d).map(|c| self.rows[(r, c)] * state[c]).sum::<f64>();
            }
            for r in 0..n {
                pred[r] += self.forcing[j * n + r];
            }
            for (i, &(dof, dir)) in self.dofs.iter().enumerate() {
                pred[n + i] += dir * self.forcing[j * n + dof] / self.h;
            }
            let (t, offset) = self.step_relay(j);
            let s0: Vec<f64> = (0..mf).map(|i| pred[n + i] - offset[i]).collect();
            let mode = &mut modes[j * mf..(j + 1) * mf];
            mode.copy_from_slice(guess.map_or(&last[..], |g| &g[j * mf..(j + 1) * mf]));
            let f = &mut forces[j * mf..(j + 1) * mf];
            Relay { t: &t, slip: &self.slip }.box_step(&s0, mode, f);
            last.copy_from_slice(mode);
            for i in 0..mf {
                velocity[j * mf + i] = pred[n + i] - (0..mf).map(|l| self.t[i * mf + l] * f[l]).sum::<f64>();
            }
            // (u_(j−1), u_j, f_(j−1)) ← (u_j, u⁰ − W B_fᵀ f_j/2, f_j).
            for r in 0..n {
                state[r] = state[n + r];
                state[n + r] = pred[r] - (0..mf).map(|i| self.wbt[(r, i)] * f[i]).sum::<f64>();
            }
            state[2 * n..].copy_from_slice(f);
        }
        March { end: state, modes, forces, velocity }
    }

    fn instants(&self) -> usize {
        self.k
    }

    fn tangent_over(&self, modes: &[i8], steps: Range<usize>) -> Mat<f64> {
        let (n, mf, d) = (self.n, self.mf, self.state_size());
        let mut p = Mat::<f64>::identity(d, d);
        for j in steps {
            let rp = dense_product(&self.rows, &p);
            let (t, _) = self.step_relay(j);
            let df = Relay { t: &t, slip: &self.slip }.stuck_tangent(&modes[j * mf..(j + 1) * mf], |i, c| rp[(n + i, c)], d);
            let mut next = Mat::<f64>::zeros(d, d);
            for c in 0..d {
                for r in 0..n {
                    next[(r, c)] = p[(n + r, c)];
                    next[(n + r, c)] = rp[(r, c)] - (0..mf).map(|i| self.wbt[(r, i)] * df[(i, c)]).sum::<f64>();
                }
                for i in 0..mf {
                    next[(2 * n + i, c)] = df[(i, c)];
                }
            }
            p = next;
        }
        p
    }
}

/// A start for Newton on k instants: bds1's orbit on the same k (friction_shooting: numerically
/// damped, so its Newton converges from rest), as half-step samples (bds1's f_(j+1) and v_(j+1)
/// pair with the step (t_j, t_(j+1)) as the half steps' f_j and v̄_j do), its state carried to
/// (u_(k−1), u_k, f_(k−1)) and the laws fitted to it. Why: Newton on the relay half steps cycles
/// between sets (measured: Den Hartog c = 0, Ω = 0.6 at k = 256, 512, 1024), and the undamped
/// relay has a family of periodic orbits (P's eigenvalue 1: an interior sample is felt only in
/// the mean of two); the laws pin it. `None` when bds1's shooting fails (Newton from rest).
fn bds1_start(problem: &PeriodicProblem, map: &HalfStepMap) -> Option<(Vec<f64>, EventLaws)> {
    let (k, n, mf) = (map.k, map.n, map.mf);
    let shot = FrictionStepMap::new(problem, k, problem.period()).ok()?.shoot(None).ok()?;
    let rotate = |v: &[f64]| -> Vec<f64> { (0..k * mf).map(|e| v[(e + mf) % (k * mf)]).collect() };
    let (forces, velocity) = (rotate(&shot.forces), rotate(&shot.velocity));
    // The state (x_(k−1), v_(k−1)): u_k = x_(k−1) + h v_k ≈ x_(k−1) + h v_(k−1).
    let mut y: Vec<f64> = shot.state[..n].to_vec();
    y.extend((0..n).map(|r| shot.state[r] + map.h * shot.state[n + r]));
    y.extend_from_slice(&forces[(k - 1) * mf..]);
    Some((y, EventLaws::fit(&map.nyquist, &map.slip, (&forces, &velocity), map.h)))
}
