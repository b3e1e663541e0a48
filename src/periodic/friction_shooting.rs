//! Shooting for friction contacts under a constant normal load (src/formulation.md §9, "Friction
//! by shooting").
//!
//! bds1 is implicit Euler in (x, v), v_j = (x_j − x_(j−1))/h:
//! (M/h + C + hK) v_j = M v_(j−1)/h − K x_(j−1) + f(t_j) − B_fᵀ f_j, x_j = x_(j−1) + h v_j,
//! so with W = (M/h + C + hK)⁻¹ the slip velocity of friction i at t_j is
//! σ = s⁰ − T f_j, s⁰ = B_f W (M v/h − K x + f(t_j)) + g/(h k_t), T = B_f W B_fᵀ + diag(1/(h k_t)),
//! where g = f_(j−1) is carried in the state for a Jenkins element (its slider velocity is
//! D(u − f/k_t), the `friction_lcp`'s A + D/k_t) and 1/k_t = 0 for rigid Coulomb. Each instant
//! is a box problem f ∈ [−μN, μN], f_i = μN·sign(σ_i) when σ_i ≠ 0: the KKT conditions of
//! min ½fᵀTf − s⁰ᵀf over the box, monotone because T's symmetric part is positive definite for a
//! passive structure (Moreau's time stepping). Each instant's set is stick / slip+ / slip−;
//! with the sets fixed the period map is affine, so Newton's step (I − P) δ = y_end − y is exact
//! and the march re-checks the sets, as shooting does for unilateral contacts.
//!
//! The answer is certified by the caller on the full periodic LCP (FFT products).
use super::friction_family::{family_dimension, family_step};
pub(super) use super::friction_relay::Relay;
use super::{NoStepMap, PeriodicProblem, SHOOTING_WORK_MAX};
use crate::lcp::{DenseLu, dense_product};
use faer::Mat;
use std::ops::Range;

/// Newton iterations of the friction shooting at most. Why: each fixes the sets of the last
/// march; a set that keeps changing (a cycle of the piecewise-affine map) ends as a typed failure.
const MAX_ITERATIONS: usize = 60;

/// Halvings of a Newton step that raises the periodicity residual, at most.
const HALVINGS: i32 = 6;

/// A Newton step longer than this many times the state is taken as I − P's (near) null space,
/// and the least-norm step replaces it. Why: measured on Den Hartog c = 0, Ω = 1.506, μN = 0.510
/// at k = 256 (cds): an interior sample of the undamped half steps left I − P with σ_min ≈ 1e-13,
/// LU's step was 3e9 times the state, even 1/128 of it threw the orbit off, and Newton cycled.
const NEAR_SINGULAR: f64 = 1e6;

/// Fewest instants of a coarse grid worth solving first ([`coarse_start`]). Why: below, Newton
/// from rest costs less than the coarse solve saves.
const COARSE_MIN: usize = 256;

/// Shortest run of equal modes whose tangent is taken as a power ([`FrictionStepMap`]'s
/// `tangent_over`). Why: a step tangent costs about one product, so squaring pays from 3 steps.
const RUN_POWER_MIN: usize = 3;

/// The bds1 step map of a problem whose only nonsmooth rows are friction contacts.
pub(super) struct FrictionStepMap {
    n: usize,
    mf: usize,
    k: usize,
    h: f64,
    /// Slot of friction i's previous force in the state (Jenkins elements only).
    jenkins: Vec<Option<usize>>,
    /// μN of friction i.
    slip: Vec<f64>,
    /// [E; Q] ((n + mf) × d): v_pred = E y + W f(t_j), s⁰ = Q y + B_f W f(t_j).
    rows: Mat<f64>,
    /// W B_fᵀ (n × mf).
    wbt: Mat<f64>,
    /// T (mf × mf, row-major).
    t: Vec<f64>,
    /// W f(t_j) at the k instants (k × n).
    forcing: Vec<f64>,
    /// The sliding DOF and its sign per friction contact.
    dofs: Vec<(usize, f64)>,
}

/// A converged friction orbit: the forces f_j (k × mf, time-major) and Newton's figures.
pub(super) struct FrictionShot {
    /// The periodic state y = (x, v, g) at t_(k−1).
    pub state: Vec<f64>,
    pub forces: Vec<f64>,
    /// The march's slip velocities (half steps: the mean v̄_j; bds1: the backward v_j).
    pub velocity: Vec<f64>,
    pub iterations: usize,
    /// max |y_end − y| / max(|y|, tiny) of the last march.
    pub residual: f64,
    /// Dimension of the family of periodic orbits this one belongs to (0: unique). Stuck contacts
    /// hold a static offset: the velocities are unique, the positions one member.
    pub family: usize,
}

/// Why the shooting did not converge (a typed outcome for the caller).
pub(super) struct ShotFailure {
    pub iterations: usize,
    pub residual: f64,
    pub why: &'static str,
    /// Newton's last iterate (not periodic) when the iterations ran out, for a refit.
    pub last: Option<Box<FrictionShot>>,
}

/// One march over the period: the end state, each instant's modes, forces and slip velocities
/// (k × mf, time-major; the half steps' mean velocities v̄_j, bds1's backward v_j).
pub(super) struct March {
    pub end: Vec<f64>,
    pub modes: Vec<i8>,
    pub forces: Vec<f64>,
    pub velocity: Vec<f64>,
}

/// A period map with friction sets: marched, and differentiated with the sets fixed, for
/// [`shoot`].
pub(super) trait FrictionMarch {
    fn state_size(&self) -> usize;
    /// Marches one period from `y`; step j starts from `guess[j]`'s modes (or the previous step's).
    fn march(&self, y: &[f64], guess: Option<&[i8]>) -> March;
    /// Instants per period.
    fn instants(&self) -> usize;
    /// ∂y_(last)/∂y_(first − 1) over `steps` with every instant's modes (`modes`: the whole period's)
    /// fixed.
    fn tangent_over(&self, modes: &[i8], steps: Range<usize>) -> Mat<f64>;
    /// Blocks [`PeriodTangent`] splits the period into (1: the tangent is rebuilt whole).
    fn tangent_blocks(&self) -> usize {
        1
    }
}

/// Blocks of instants whose tangents [`PeriodTangent`] keeps. Why: measured on the bench case
/// `friction` (seed 37, draw 1, k = 4096), Newton's last iterations change the modes of 1–30
/// instants, so rebuilding only their blocks cuts the k-step tangent to a few blocks' worth.
const TANGENT_BLOCKS: usize = 64;

/// ∂y_end/∂y₀ as the product of per-block tangents, each rebuilt only when its modes changed
/// (a step's tangent depends on its own modes alone).
struct PeriodTangent {
    blocks: Vec<(Range<usize>, Vec<i8>, Mat<f64>)>,
    rebuilt: usize,
}

impl PeriodTangent {
    fn new() -> Self {
        PeriodTangent { blocks: Vec::new(), rebuilt: 0 }
    }

    /// The period's tangent with `modes` fixed.
    fn at(&mut self, map: &impl FrictionMarch, modes: &[i8]) -> Mat<f64> {
        let k = map.instants();
        let per = modes.len() / k.max(1);
        if self.blocks.is_empty() {
            let length = k.div_ceil(map.tangent_blocks().max(1)).max(1);
            self.blocks = (0..k).step_by(length).map(|a| (a..(a + length).min(k), Vec::new(), Mat::zeros(0, 0))).collect();
        }
        let d = map.state_size();
        let mut p = Mat::<f64>::identity(d, d);
        for (steps, kept, tangent) in &mut self.blocks {
            let now = &modes[steps.start * per..steps.end * per];
            if kept.as_slice() != now {
                *tangent = map.tangent_over(modes, steps.clone());
                self.rebuilt += 1;
                *kept = now.to_vec();
            }
            p = dense_product(tangent, &p);
        }
        p
    }
}

impl FrictionStepMap {
    /// The step map of `problem` (bds1, friction contacts only, no massless DOF), or why not.
    pub(super) fn new(problem: &PeriodicProblem, k: usize, period: f64) -> Result<Self, NoStepMap> {
        let model = problem.model();
        if !model.contacts.is_empty() {
            return Err(NoStepMap("friction together with unilateral contacts has no step map yet (the dense LCP solves them)".to_string()));
        }
        if !model.massless_dofs().is_empty() {
            return Err(NoStepMap(format!("DOFs {:?} are massless: the friction step map needs a mass on every DOF", model.massless_dofs())));
        }
        let (n, mf) = (model.n(), model.frictions.len());
        let mut dofs = Vec::with_capacity(mf);
        for (i, f) in model.frictions.iter().enumerate() {
            let &[(dof, dir)] = f.row.as_slice() else {
                return Err(NoStepMap(format!("friction[{i}] slides along several DOFs")));
            };
            dofs.push((dof, dir));
        }
        let h = period / k as f64;
        let mut jenkins = vec![None; mf];
        let mut slots = 0;
        for (i, f) in model.frictions.iter().enumerate() {
            if f.stiffness.is_some() {
                jenkins[i] = Some(slots);
                slots += 1;
            }
        }
        let d = 2 * n + slots;
        let work = k as f64 * (n + mf) as f64 * (d * d) as f64;
        if work > SHOOTING_WORK_MAX {
            return Err(NoStepMap(format!(
                "shooting on {n} DOFs with {mf} friction contacts over k = {k} steps costs ≈ {work:.1e} flops per Newton iteration (at most {SHOOTING_WORK_MAX:.0e})"
            )));
        }
        let s = &model.structure;
        let (mass, stiffness) = (s.mass.to_dense(), s.stiffness.to_dense());
        let damping = s.damping.as_ref().map(|c| c.to_dense());
        let n0 = Mat::from_fn(n, n, |r, c| mass[(r, c)] / h + damping.as_ref().map_or(0.0, |d| d[(r, c)]) + h * stiffness[(r, c)]);
        let lu = DenseLu::new(&n0);
        let unit = |c: usize| (0..n).map(|r| if r == c { 1.0 } else { 0.0 }).collect::<Vec<_>>();
        let columns: Vec<Vec<f64>> = (0..n).map(|c| lu.solve(&unit(c))).collect();
        let w = Mat::from_fn(n, n, |r, c| columns[c][r]);
        if columns.iter().flatten().any(|v| !v.is_finite()) {
            return Err(NoStepMap("M/h + C + hK is singular: no implicit Euler step".to_string()));
        }
        // E = W [−K, M/h, 0].
        let wk = dense_product(&w, &stiffness);
        let wm = dense_product(&w, &mass);
        let e = Mat::from_fn(n, d, |r, c| {
            if c < n {
                -wk[(r, c)]
            } else if c < 2 * n {
                wm[(r, c - n)] / h
            } else {
                0.0
            }
        });
        let wbt = Mat::from_fn(n, mf, |r, i| w[(r, dofs[i].0)] * dofs[i].1);
        let inv_kt_h: Vec<f64> = model.frictions.iter().map(|f| f.stiffness.map_or(0.0, |kt| 1.0 / (h * kt))).collect();
        let mut rows = Mat::zeros(n + mf, d);
        for r in 0..n {
            for c in 0..d {
                rows[(r, c)] = e[(r, c)];
            }
        }
        for (i, &(dof, dir)) in dofs.iter().enumerate() {
            for c in 0..d {
                rows[(n + i, c)] = dir * e[(dof, c)];
            }
            if let Some(slot) = jenkins[i] {
                rows[(n + i, 2 * n + slot)] += inv_kt_h[i];
            }
        }
        let mut t = vec![0.0; mf * mf];
        for (i, &(dof, dir)) in dofs.iter().enumerate() {
            for l in 0..mf {
                t[i * mf + l] = dir * wbt[(dof, l)];
            }
            t[i * mf + i] += inv_kt_h[i];
        }
        let forces = super::state_space::force_samples(model, k, h);
        let mut forcing = vec![0.0; k * n];
        for j in 0..k {
            for r in 0..n {
                forcing[j * n + r] = (0..n).map(|l| w[(r, l)] * forces[j * n + l]).sum();
            }
        }
        let slip = model.frictions.iter().map(|f| f.slip_force()).collect();
        Ok(FrictionStepMap { n, mf, k, h, jenkins, slip, rows, wbt, t, forcing, dofs })
    }

    /// The box problems' relay with this map's T.
    fn relay(&self) -> Relay<'_> {
        Relay { t: &self.t, slip: &self.slip }
    }

    /// ∂y_j/∂y₀ from ∂y_(j−1)/∂y₀ with step j's modes fixed (stuck rows: T_SS df_S = dQ_S).
    fn step_tangent(&self, p: &Mat<f64>, mode: &[i8]) -> Mat<f64> {
        let (n, d) = (self.n, p.ncols());
        let rp = dense_product(&self.rows, p);
        let df = self.relay().stuck_tangent(mode, |i, c| rp[(n + i, c)], d);
        let mut next = Mat::<f64>::zeros(d, d);
        for c in 0..d {
            for r in 0..n {
                let dv = rp[(r, c)] - (0..self.mf).map(|i| self.wbt[(r, i)] * df[(i, c)]).sum::<f64>();
                next[(n + r, c)] = dv;
                next[(r, c)] = p[(r, c)] + self.h * dv;
            }
            for (i, slot) in self.jenkins.iter().enumerate() {
                if let Some(s) = slot {
                    next[(2 * n + s, c)] = df[(i, c)];
                }
            }
        }
        next
    }

    /// Newton on the periodic state ([`shoot`]).
    pub(super) fn shoot(&self, start: Option<Vec<f64>>) -> Result<FrictionShot, ShotFailure> {
        shoot(self, start)
    }
}

impl FrictionMarch for FrictionStepMap {
    fn state_size(&self) -> usize {
        2 * self.n + self.jenkins.iter().flatten().count()
    }

    fn march(&self, y: &[f64], guess: Option<&[i8]>) -> March {
        let (n, mf, d) = (self.n, self.mf, self.state_size());
        let mut state = y.to_vec();
        let mut modes = vec![0i8; self.k * mf];
        let mut forces = vec![0.0; self.k * mf];
        let mut velocity = vec![0.0; self.k * mf];
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
                pred[n + i] += dir * self.forcing[j * n + dof];
            }
            let mode = &mut modes[j * mf..(j + 1) * mf];
            mode.copy_from_slice(guess.map_or(&last[..], |g| &g[j * mf..(j + 1) * mf]));
            let f = &mut forces[j * mf..(j + 1) * mf];
            self.relay().box_step(&pred[n..], mode, f);
            last.copy_from_slice(mode);
            // v = v_pred − W B_fᵀ f, x += h v, g = f.
            for r in 0..n {
                let v = pred[r] - (0..mf).map(|i| self.wbt[(r, i)] * f[i]).sum::<f64>();
                state[n + r] = v;
                state[r] += self.h * v;
            }
            for (i, &(dof, dir)) in self.dofs.iter().enumerate() {
                velocity[j * mf + i] = dir * state[n + dof];
            }
            for (i, slot) in self.jenkins.iter().enumerate() {
                if let Some(s) = slot {
                    state[2 * n + s] = f[i];
                }
            }
        }
        March { end: state, modes, forces, velocity }
    }

    fn instants(&self) -> usize {
        self.k
    }

    fn tangent_blocks(&self) -> usize {
        TANGENT_BLOCKS
    }

    /// A run of m steps with the same modes has one step tangent S, so it contributes S^m, by
    /// squaring. Why: measured on the bench case `friction` (k = 4096), rebuilding tangent blocks
    /// step by step was most of a Newton iteration, and modes change every ≈ 60 steps.
    fn tangent_over(&self, modes: &[i8], steps: Range<usize>) -> Mat<f64> {
        let (d, mf) = (self.state_size(), self.mf);
        let mut p = Mat::<f64>::identity(d, d);
        let mut j = steps.start;
        while j < steps.end {
            let mode = &modes[j * mf..(j + 1) * mf];
            let run = (j..steps.end).take_while(|&l| &modes[l * mf..(l + 1) * mf] == mode).count();
            if run < RUN_POWER_MIN {
                for _ in 0..run {
                    p = self.step_tangent(&p, mode);
                }
            } else {
                let mut base = self.step_tangent(&Mat::<f64>::identity(d, d), mode);
                let mut left = run;
                while left > 0 {
                    if left & 1 == 1 {
                        p = dense_product(&base, &p);
                    }
                    left >>= 1;
                    if left > 0 {
                        base = dense_product(&base, &base);
                    }
                }
            }
            j += run;
        }
        p
    }
}

/// max |y_end − y| relative to the states' size.
fn residual(y: &[f64], march: &March) -> f64 {
    let scale = y.iter().chain(&march.end).fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
    march.end.iter().zip(y).fold(0.0f64, |a, (e, s)| a.max((e - s).abs())) / scale
}

/// Newton on the periodic state with each march's sets fixed, from `start` (a coarser grid's
/// orbit, [`coarse_start`]) or rest. A step that does not lower the residual is halved (at most
/// [`HALVINGS`] times, then taken at the least length): the piecewise-affine map can make full
/// steps cycle between sets.
pub(super) fn shoot(map: &impl FrictionMarch, start: Option<Vec<f64>>) -> Result<FrictionShot, ShotFailure> {
    shoot_to(map, start, 1e-12)
}

/// [`shoot`] down to the periodicity residual `tol` (a coarse start needs less than round-off).
fn shoot_to(map: &impl FrictionMarch, start: Option<Vec<f64>>, tol: f64) -> Result<FrictionShot, ShotFailure> {
    let profile = std::env::var_os("PERIODIC_CONTACT_PROFILE").is_some().then(std::time::Instant::now);
    let d = map.state_size();
    let mut y = start.filter(|s| s.len() == d).unwrap_or_else(|| vec![0.0; d]);
    let mut march = map.march(&y, None);
    let mut res = residual(&y, &march);
    let mut unchanged = false;
    let mut tangent = PeriodTangent::new();
    let mut marches = 1;
    let mut least = None;
    let mut closings = 0;
    for iteration in 0..MAX_ITERATIONS {
        if !res.is_finite() {
            return Err(ShotFailure { iterations: iteration, residual: res, why: "the march overflowed", last: None });
        }
        // Round-off, or the sets of the affine solve came back unchanged (its fixed point).
        if res <= tol || (unchanged && res <= 1e-8) {
            let family = family_dimension(&tangent.at(map, &march.modes));
            if let Some(clock) = profile {
                eprintln!(
                    "friction shooting profile: k = {}: {iteration} iterations ({closings} closing overshoots), {marches} marches, {} tangent blocks rebuilt, {:.3} s, periodicity {res:.1e}, family dimension {family}",
                    map.instants(),
                    tangent.rebuilt,
                    clock.elapsed().as_secs_f64()
                );
            }
            return Ok(FrictionShot { state: y, forces: march.forces, velocity: march.velocity, iterations: iteration, residual: res, family });
        }
        let p = tangent.at(map, &march.modes);
        let i_minus_p = Mat::from_fn(d, d, |a, b| if a == b { 1.0 } else { 0.0 } - p[(a, b)]);
        let r: Vec<f64> = march.end.iter().zip(&y).map(|(e, s)| e - s).collect();
        let step = family_step(&i_minus_p, &r, least);
        least = Some(step.least);
        let mut delta = step.plain;
        let size = y.iter().chain(&march.end).fold(f64::MIN_POSITIVE, |a, v| a.max(v.abs()));
        if delta.iter().any(|v| !v.is_finite() || v.abs() > NEAR_SINGULAR * size) {
            // A family of periodic orbits (eigenvalue 1 of P: the half steps' relay on an undamped
            // structure, whose force at an interior step the structure feels only in mean): the
            // least-norm step, by normal equations with a Tikhonov term at round-off.
            delta = least_norm_step(&i_minus_p, &r);
        }
        if delta.iter().any(|v| !v.is_finite()) {
            return Err(ShotFailure {
                iterations: iteration,
                residual: res,
                why: "I − P is singular (a rigid contact stuck over the whole period leaves its position undetermined)",
                last: None,
            });
        }
        // A closing direction's overshoot first, kept when it lowers the residual.
        let overshot = step.closing.filter(|c| c.iter().all(|v| v.is_finite())).and_then(|c| {
            let cand: Vec<f64> = y.iter().zip(&c).map(|(s, dl)| s + dl).collect();
            let m = map.march(&cand, Some(&march.modes));
            marches += 1;
            (residual(&cand, &m) < res).then_some((cand, m))
        });
        let mut length = 1.0;
        let closed = overshot.is_some();
        let (next_y, next) = match overshot {
            Some(found) => found,
            None => loop {
                let cand: Vec<f64> = y.iter().zip(&delta).map(|(s, dl)| s + length * dl).collect();
                let m = map.march(&cand, Some(&march.modes));
                marches += 1;
                if residual(&cand, &m) < res || length < 0.5f64.powi(HALVINGS) {
                    break (cand, m);
                }
                length *= 0.5;
            },
        };
        closings += usize::from(closed);
        unchanged = length == 1.0 && !closed && next.modes == march.modes;
        y = next_y;
        march = next;
        res = residual(&y, &march);
    }
    let last = FrictionShot { state: y, forces: march.forces, velocity: march.velocity, iterations: MAX_ITERATIONS, residual: res, family: 0 };
    Err(ShotFailure { iterations: MAX_ITERATIONS, residual: res, why: "the stick/slip sets kept changing", last: Some(Box::new(last)) })
}

/// δ of least norm for A δ = r (A square, singular): (AᵀA + μI) δ = Aᵀr with μ at round-off of
/// AᵀA's diagonal.
fn least_norm_step(a: &Mat<f64>, r: &[f64]) -> Vec<f64> {
    let d = a.nrows();
    let ata = dense_product(&a.transpose().to_owned(), a);
    let mu = 1e-13 * (0..d).map(|i| ata[(i, i)]).fold(f64::MIN_POSITIVE, f64::max);
    let reg = Mat::from_fn(d, d, |i, l| ata[(i, l)] + if i == l { mu } else { 0.0 });
    let atr: Vec<f64> = (0..d).map(|i| (0..d).map(|l| a[(l, i)] * r[l]).sum()).collect();
    DenseLu::new(&reg).solve(&atr)
}

/// Periodicity a coarse grid's orbit is shot to before it starts the finer grid. Why: its
/// discretisation differs from the fine orbit by ≈ 1e-2, so round-off (1e-12) buys nothing, while
/// 1e-6 left the extrapolated start worse (measured on the bench case `friction`, seed 71 draw 4:
/// 6 iterations at k = 4096 from 1e-8, 19 from 1e-6).
const COARSE_TOL: f64 = 1e-8;

/// A start for Newton on k instants: the orbits on k/4 and k/16 instants (each shot from its own
/// coarser start, down to [`COARSE_MIN`]) extrapolated to k, y(h) ≈ y(4h) + (y(4h) − y(16h))/4
/// (Richardson for bds1's first order; the state at t_(k−1) is the state at t = T to first order
/// on every grid). Why: the k/4 orbit alone is ≈ 7e-3 off on the bench case `friction` and
/// Newton's first steps then flip thousands of modes (seed 71 draw 4: 22 iterations from it, 6
/// from the extrapolation). `None` when k is small or the coarse shooting fails (Newton then
/// starts from rest).
pub(super) fn coarse_start(problem: &PeriodicProblem, k: usize, period: f64) -> Option<Vec<f64>> {
    extrapolated(coarse_orbits(problem, k, period))
}

/// The k/4 state, or its Richardson step when the k/16 state is known.
fn extrapolated(states: Option<(Vec<f64>, Option<Vec<f64>>)>) -> Option<Vec<f64>> {
    match states? {
        (y4, Some(y16)) => Some(y4.iter().zip(&y16).map(|(a, b)| a + (a - b) / 4.0).collect()),
        (y4, None) => Some(y4),
    }
}

/// The periodic states on k/4 and (when it is shot too) k/16 instants.
fn coarse_orbits(problem: &PeriodicProblem, k: usize, period: f64) -> Option<(Vec<f64>, Option<Vec<f64>>)> {
    let kc = k / 4;
    if kc < COARSE_MIN || !k.is_multiple_of(4) {
        return None;
    }
    let map = FrictionStepMap::new(problem, kc, period).ok()?;
    let below = coarse_orbits(problem, kc, period);
    let y16 = below.as_ref().map(|b| b.0.clone());
    shoot_to(&map, extrapolated(below), COARSE_TOL).ok().map(|shot| (shot.state, y16))
}
