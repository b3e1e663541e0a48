//! Coulomb friction rows in the periodic LCP (src/formulation.md §9).
//!
//! A friction contact is one more row b of B: the assembly sees it as an extra contact row
//! ([`with_rows`]), so Ĝ, B X̂lin and Ẑ⁻¹Bᵀ cover the unilateral and the friction rows alike.
//! At the instants the friction force f ∈ [−μN, μN] and the slip velocity v = D(b x) satisfy
//! f = μN·sign(v) (v ≠ 0) and |f| ≤ μN (v = 0). With w = −v = A f + b_q, A = D·G (+ D/k_t for a
//! Jenkins element), the box is mapped to an LCP by z₁ = f + μN ≥ 0 and a slack α ≥ 0
//! (Siconos' `relay_to_lcp`):
//!
//! ```text
//!   [w₁]   [A   I] [z₁]   [b_q − A·μN]
//!   [w₂] = [−I  0] [α ] + [   2μN    ],   0 ≤ (z₁, α) ⊥ (w₁, w₂) ≥ 0,
//! ```
//!
//! with the unilateral contacts' rows (gap = A z + q, displacement receptance) in front. zᵀMz =
//! z₁ᵀAz₁ ≥ 0 for a passive structure: M is positive semi-definite and Lemke ends with a solution
//! (friction alone). The slip velocity is α − w₁.
//!
//! The matrix is dense: N = k·(m_c + 2·m_f) unknowns, at most [`FRICTION_DENSE_MAX`].
use super::friction_events::{EventLaws, MAX_ROUNDS, RELAY_HALF_STEPS_ENV, nyquist};
use super::friction_half_steps::HalfStepMap;
use super::friction_shooting::{FrictionStepMap, ShotFailure, coarse_start};
use super::{Assembly, NoStepMap, PeriodFft, PeriodicProblem, SolveError, lcp_failure, recovery};
use crate::lcp::{DenseMatrix, LcpInfo, LcpMethod, LcpOutcome, LcpSolution, LcpStep, Lemke, LemkeSettings, residuals};
use crate::model::{Compliance, Contact, Model};
use crate::response::{FrictionResponse, Response};
use crate::time::Scheme;
use num_complex::Complex64 as C;
use std::borrow::Cow;
use std::time::Instant;

/// Most unknowns of the dense friction LCP. Why: the matrix and Lemke's basis inverse are two
/// N×N arrays (2·8·N² bytes: 256 MiB at 4096) and Lemke's pivots cost O(N²) each; a structured
/// (block-circulant) friction solver is future work.
pub const FRICTION_DENSE_MAX: usize = 4096;

/// Lemke's pivot budget per unknown on the friction LCP. Why: its matrix is only positive
/// semi-definite (skew for an undamped structure under cds), and the complementary path can be
/// longer than the default budget of unilateral contacts allows.
const FRICTION_PIVOTS_PER_DIM: usize = 200;

/// `model` with one extra contact row per friction contact (after the unilateral contacts), for
/// the assembly; borrowed unchanged without friction.
pub(super) fn with_rows(model: &Model) -> Result<Cow<'_, Model>, SolveError> {
    if model.frictions.is_empty() {
        return Ok(Cow::Borrowed(model));
    }
    let mut rows = model.clone();
    for (i, f) in model.frictions.iter().enumerate() {
        let &[(dof, direction)] = f.row.as_slice() else {
            return Err(SolveError::Invalid(format!("friction[{i}]: a sliding direction over several DOFs is not yet supported; slide along one DOF")));
        };
        if direction.abs() != 1.0 {
            return Err(SolveError::Invalid(format!("friction[{i}]: the row coefficient is {direction}, this version takes ±1 on one DOF")));
        }
        rows.contacts.push(Contact::on_dof(dof, direction, 0.0, Compliance::Rigid));
    }
    Ok(Cow::Owned(rows))
}

/// The LCP size with `mc` contacts and `mf` friction contacts over `k` instants, refused above
/// [`FRICTION_DENSE_MAX`] with the memory it would take.
pub fn check_size(k: usize, mc: usize, mf: usize) -> Result<usize, SolveError> {
    let n = k.saturating_mul(mc + 2 * mf);
    if n > FRICTION_DENSE_MAX {
        let gib = 2.0 * 8.0 * (n as f64).powi(2) / f64::from(1u32 << 30);
        return Err(SolveError::Limit(format!(
            "friction: steps = {k} with {mc} contact(s) and {mf} friction contact(s) make an LCP of {n} unknowns (steps × (contacts + 2 × friction contacts)), solved densely: ≈ {gib:.1} GiB and O(N³) work; at most {FRICTION_DENSE_MAX} unknowns are accepted: reduce discretization.steps to {} or fewer",
            FRICTION_DENSE_MAX / (mc + 2 * mf)
        )));
    }
    Ok(n)
}

/// How the friction samples meet the scheme (src/formulation.md §9).
/// - bds1: f_j and the backward slip velocity (u_j − u_{j−1})/h at t_j, bds1's own derivative
///   (implicit Euler, Moreau's time-stepping in the period); D = σ1 has Re ≥ 0. Measured
///   (tests/friction.rs): a steady first-order lag dominates its error, so Richardson works.
/// - cds and galerkin, half steps: f_j acts on (t_j, t_{j+1}) and pairs with the mean slip
///   velocity (u_{j+1} − u_j)/h there; the structure at t_j feels (f_{j−1} + f_j)/2 (galerkin:
///   linear hats for u, a piecewise-constant force). D·E = σ1 of cds, so A's form is
///   Re(σ1 G) ≥ 0. On the relay alone the O(h) impulse error μN·h·(2ξ − 1) follows the event's
///   place ξ in its step, erratically in k; so the steps around each slip end take a fitted law
///   (`friction_events`, unless [`RELAY_HALF_STEPS_ENV`]) and converge at order 2 (measured,
///   README "Friction"). Solved by the half-step map (`friction_half_steps`) by default: dense
///   Lemke's path on this LCP is degenerate (E(π) = 0).
pub struct FrictionGrid {
    /// Symbol of the slip velocity from the displacement at the instants, per harmonic.
    pub velocity: Vec<C>,
    /// Symbol of the force the structure feels at the instants from the friction samples.
    pub spread: Vec<C>,
}

impl FrictionGrid {
    pub fn new(scheme: Scheme, k: usize, period: f64) -> Result<Self, SolveError> {
        let h = period / k as f64;
        let nh = k / 2 + 1;
        let theta = |p: usize| 2.0 * std::f64::consts::PI * p as f64 / k as f64;
        // 1 − cos θ = 2 sin²(θ/2): no cancellation in the low harmonics.
        let versine = |p: usize| 2.0 * (theta(p) / 2.0).sin().powi(2);
        match scheme {
            // (1 − z)/h, z = e^{−iθ} the one-step delay.
            Scheme::Bds1 => Ok(FrictionGrid { velocity: (0..nh).map(|p| C::new(versine(p), theta(p).sin()) / h).collect(), spread: vec![C::ONE; nh] }),
            // (z⁻¹ − 1)/h and (1 + z)/2.
            Scheme::Cds | Scheme::Galerkin => Ok(FrictionGrid {
                velocity: (0..nh).map(|p| C::new(-versine(p), theta(p).sin()) / h).collect(),
                spread: (0..nh).map(|p| C::new(2.0 - versine(p), -theta(p).sin()) / 2.0).collect(),
            }),
            other => Err(SolveError::Invalid(format!(
                "discretization.scheme: is \"{other}\", but friction contacts are solved with bds1 (first order) or cds and galerkin (event-fitted half steps, second order; src/formulation.md §9); set scheme = \"cds\", \"galerkin\" or \"bds1\""
            ))),
        }
    }

    /// Whether the friction samples sit at the half steps t_{j+1/2} (cds, galerkin).
    pub fn half_steps(&self) -> bool {
        self.spread.iter().any(|e| *e != C::ONE)
    }

    /// The force the structure feels at the instants from the friction samples `f`.
    pub fn felt(&self, f: &[f64]) -> Vec<f64> {
        if !self.half_steps() {
            return f.to_vec();
        }
        let k = f.len();
        (0..k).map(|j| 0.5 * (f[(j + k - 1) % k] + f[j])).collect()
    }
}

/// Index of unknown (row `a`, instant `j`): contact rows first (time-major), then z₁ of the
/// friction rows, then their slacks α.
pub(super) struct Layout {
    pub(super) k: usize,
    pub(super) mc: usize,
    pub(super) mf: usize,
}

impl Layout {
    pub(super) fn row(&self, a: usize, j: usize) -> usize {
        if a < self.mc { j * self.mc + a } else { self.k * self.mc + j * self.mf + (a - self.mc) }
    }
    pub(super) fn slack(&self, t: usize, j: usize) -> usize {
        self.k * (self.mc + self.mf) + j * self.mf + t
    }
}

/// The dense LCP (M, q) of contacts and friction rows; `asm` is assembled with [`with_rows`].
pub fn friction_lcp(problem: &PeriodicProblem, asm: &Assembly, fft: &PeriodFft, grid: &FrictionGrid) -> (DenseMatrix, Vec<f64>) {
    let model = problem.model();
    let (k, m, nh) = (asm.k, asm.m, asm.k / 2 + 1);
    let lay = Layout { k, mc: model.contacts.len(), mf: model.frictions.len() };
    let nn = k * (lay.mc + 2 * lay.mf);
    let slip: Vec<f64> = model.frictions.iter().map(|f| f.slip_force()).collect();
    let coupled = super::friction_coupled::couplings(model);
    let mut data = vec![0.0; nn * nn];
    let mut q = vec![0.0; nn];
    let period = problem.period();
    let mut spec = vec![C::ZERO; nh];
    for a in 0..m {
        // Contact rows pair force j with the gap at t_{j+s} (`PeriodicProblem::lcp`); friction
        // rows are velocities, w = −v, at the force's own instant.
        let friction = a >= lay.mc;
        let s = if friction { 0 } else { problem.pairing_at(a).offset() };
        let scale = |p: usize| if friction { grid.velocity[p] } else { C::ONE };
        for (p, v) in spec.iter_mut().enumerate() {
            *v = asm.bxlin_hat[p * m + a] * scale(p);
        }
        let bx = fft.inverse(&spec);
        for j in 0..k {
            let jj = (j + s) % k;
            q[lay.row(a, j)] = if friction { -bx[j] } else { model.contacts[a].gap_at(model.frequency, jj as f64 * period / k as f64) - bx[jj] };
        }
        // Columns: the response of row a to each row's force (−G for displacements, −D·G for
        // velocities, so +G and +D·G in w), a Jenkins element's D/k_t on its own row.
        for b in 0..m {
            let spread = |p: usize| if b >= lay.mc { grid.spread[p] } else { C::ONE };
            for (p, v) in spec.iter_mut().enumerate() {
                *v = asm.g_hat[(p * m + a) * m + b] * scale(p) * spread(p);
            }
            let mut ker = fft.inverse(&spec);
            // Jenkins: the slider's velocity is D(u − f/k_t).
            if friction
                && a == b
                && let Some(kt) = model.frictions[a - lay.mc].stiffness
            {
                let d = fft.inverse(&grid.velocity);
                ker.iter_mut().zip(&d).for_each(|(g, d)| *g += d / kt);
            }
            for j in 0..k {
                let r = lay.row(a, j);
                for l in 0..k {
                    let v = ker[(j + s + k - l) % k];
                    data[r * nn + lay.row(b, l)] += v;
                    // f = z₁ − μN: the constant part moves to q.
                    if b >= lay.mc {
                        q[r] -= v * slip[b - lay.mc];
                        // Coupled: f = z₁ − μλ_n, so λ_n's column gains −μ times f's.
                        if let Some((c, mu)) = coupled[b - lay.mc] {
                            data[r * nn + lay.row(c, l)] -= mu * v;
                        }
                    }
                }
            }
        }
        if let Some(Contact { compliance: Compliance::Compliant { stiffness }, .. }) = model.contacts.get(a) {
            (0..k).for_each(|j| data[lay.row(a, j) * nn + lay.row(a, j)] += 1.0 / stiffness);
        }
    }
    for (t, mu_n) in slip.iter().enumerate() {
        for j in 0..k {
            let (r, sl) = (lay.row(lay.mc + t, j), lay.slack(t, j));
            data[r * nn + sl] = 1.0;
            data[sl * nn + r] = -1.0;
            q[sl] = 2.0 * mu_n;
            // Coupled: the box is [−μλ_n, μλ_n], so w₂ = 2μλ_n − z₁.
            if let Some((c, mu)) = coupled[t] {
                data[sl * nn + lay.row(c, j)] = 2.0 * mu;
            }
        }
    }
    (DenseMatrix::from_row_major(nn, data), q)
}

/// Solves a problem with friction on `asm` (assembled with [`with_rows`]) by dense Lemke,
/// certified; recovers the responses and the friction contacts' forces and slip.
pub(super) fn solve(problem: &PeriodicProblem, asm: &Assembly, fft: &PeriodFft, t_start: Instant) -> Result<Response, SolveError> {
    let model = problem.model();
    let (k, m) = (asm.k, asm.m);
    let lay = Layout { k, mc: model.contacts.len(), mf: model.frictions.len() };
    debug_assert_eq!(m, lay.mc + lay.mf, "assembled with the friction rows");
    let nn = k * (lay.mc + 2 * lay.mf);
    let grid = FrictionGrid::new(problem.discretization().scheme, k, problem.period())?;
    let coupled = super::friction_coupled::couplings(model);
    let method = problem.solver_settings().method;
    let relay_only = std::env::var_os(RELAY_HALF_STEPS_ENV).is_some();
    if grid.half_steps() && (lay.mc > 0 || model.frictions.iter().any(|f| f.stiffness.is_some() || f.contact.is_some())) {
        // A Jenkins slider at a half step would see only the central difference (f_(j+1) −
        // f_(j−1))/2h of its spring force; the coupled rows and contacts have no laws yet.
        return Err(SolveError::Invalid(format!(
            "discretization.scheme: is \"{}\", whose friction pairing (event-fitted half steps, second order) takes rigid Coulomb contacts under a constant normal load without unilateral contacts; this scene has {}: set scheme = \"bds1\" (first order)",
            problem.discretization().scheme,
            if lay.mc > 0 { "unilateral contacts" } else { "a Jenkins element (friction.stiffness) or a coupled normal load (friction.contact)" }
        )));
    }
    // Shooting where the dense LCP is refused (or asked for); the dense path keeps small N. The
    // half steps shoot by default: dense Lemke's path on their LCP is degenerate (E(π) = 0).
    let shoot = method == LcpMethod::Shooting || (method == LcpMethod::Auto && (nn > FRICTION_DENSE_MAX || grid.half_steps()));
    if shoot && grid.half_steps() {
        match HalfStepMap::new(problem, k) {
            Ok(map) => {
                let t_assembly = t_start.elapsed().as_secs_f64();
                let (sol, lcp_time, path) = super::friction_half_steps::solve(problem, map, (asm, fft, &grid), relay_only)?;
                return finish(problem, (asm, fft, &grid), sol, (t_start, t_assembly, lcp_time), path);
            }
            Err(why) if method == LcpMethod::Shooting || nn > FRICTION_DENSE_MAX => {
                return Err(check_size(k, lay.mc, lay.mf)
                    .err()
                    .map_or(SolveError::Invalid(format!("solver.method: \"shooting\" needs a time-stepping map: {why}; use \"auto\"")), |e| {
                        shooting_refused(e, &why)
                    }));
            }
            Err(_) => {} // the dense LCP below
        }
    }
    let (sol, t_assembly, lcp_time, path) = if shoot && !grid.half_steps() {
        let t_assembly = t_start.elapsed().as_secs_f64();
        let t_lcp = Instant::now();
        let map = match FrictionStepMap::new(problem, k, problem.period()) {
            Ok(map) => map,
            Err(why) if method == LcpMethod::Shooting => {
                return Err(SolveError::Invalid(format!(
                    "solver.method: \"shooting\" needs a time-stepping map, and this friction problem has none: {why}; use \"auto\""
                )));
            }
            Err(why) => return Err(check_size(k, lay.mc, lay.mf).err().map_or(SolveError::Invalid(why.to_string()), |e| shooting_refused(e, &why))),
        };
        let shot = map.shoot(coarse_start(problem, k, problem.period())).map_err(|e| shooting_failed(e, lay.mc + 2 * lay.mf))?;
        let mut sol = certify(problem, (asm, fft, &grid), &shot.forces, None);
        let lcp_time = t_lcp.elapsed().as_secs_f64();
        sol.info.pivots = shot.iterations;
        sol.info.time_s = lcp_time;
        sol.info.path = vec![LcpStep { method: LcpMethod::Shooting, size: nn, pivots: shot.iterations, outcome: sol.outcome, time_s: lcp_time }];
        if sol.outcome != LcpOutcome::Solved {
            let hint = "the shooting orbit does not satisfy the periodic friction LCP to solver.tolerance (a set change the march missed); reduce discretization.steps or use solver.method = \"lemke\" where the dense LCP fits".to_string();
            return Err(SolveError::Lcp { outcome: sol.outcome, info: sol.info, hint });
        }
        let family = match shot.family {
            0 => String::new(),
            r => format!(
                "; the positions are one member of a {r}-parameter family of periodic orbits (stuck contacts hold a static offset: I − P has rank {r} less; the velocities are unique)"
            ),
        };
        let path = format!(
            "friction by shooting (N = {nn}: the box LCP of the friction rows, src/formulation.md §9): Newton on the bds1 period map, {} iterations (periodicity {:.1e}), certified on the full LCP by FFT products (residual {:.1e}), {lcp_time:.3} s → {}{family}",
            shot.iterations,
            shot.residual,
            sol.info.residual,
            sol.outcome.name()
        );
        (sol, t_assembly, lcp_time, path)
    } else {
        check_size(k, lay.mc, lay.mf)?;
        let (a, q) = friction_lcp(problem, asm, fft, &grid);
        if let Some(i) = q.iter().chain(a.as_slice()).position(|v| !v.is_finite()) {
            return Err(SolveError::Invalid(format!(
                "friction: the LCP holds a non-finite value (entry {i}): loads, gaps, μN or stiffnesses overflow floating point; rescale the units"
            )));
        }
        let t_assembly = t_start.elapsed().as_secs_f64();
        let t_lcp = Instant::now();
        let settings =
            LemkeSettings { certify_tol: problem.solver_settings().tolerance, max_pivots_per_dim: FRICTION_PIVOTS_PER_DIM, ..LemkeSettings::default() };
        let is_coupled = coupled.iter().any(Option::is_some);
        // Coupled rows under "auto": the orbit continued from a coarse grid (several may coexist).
        let (mut sol, continued) = if is_coupled && method == LcpMethod::Auto {
            super::friction_coupled::continued(problem, (&a, &q), &settings)?
        } else {
            let cold = if is_coupled {
                "; cold at k alone (\"lemke\"): the coupled LCP can hold several periodic orbits, \"auto\" continues the coarse grid's"
            } else {
                ""
            };
            (Lemke::new(settings.clone()).solve(&a, &q), cold.to_string())
        };
        if sol.outcome != LcpOutcome::Solved {
            return Err(if is_coupled { super::friction_coupled::no_solution(problem, asm, sol) } else { lcp_failure(sol) });
        }
        let mut rounds = 0;
        if grid.half_steps() && !relay_only {
            (sol, rounds) = fit_events(problem, asm, (&a, &q), &lay, sol, &settings)?;
        }
        let lcp_time = t_lcp.elapsed().as_secs_f64();
        sol.info.path = vec![LcpStep { method: LcpMethod::Lemke, size: nn, pivots: sol.info.pivots, outcome: sol.outcome, time_s: lcp_time }];
        let fitted = if rounds > 0 { format!(", event-fitted half steps after {rounds} refits") } else { String::new() };
        let path = format!(
            "friction (N = {nn}: contacts and the box LCP of the friction rows, src/formulation.md §9): dense lexicographic Lemke, {} pivots{fitted}{continued}, {lcp_time:.3} s → {}",
            sol.info.pivots,
            sol.outcome.name()
        );
        (sol, t_assembly, lcp_time, path)
    };
    finish(problem, (asm, fft, &grid), sol, (t_start, t_assembly, lcp_time), path)
}

/// The responses of a solved friction LCP `sol` (in the dense layout), with its timings
/// (start, assembly, LCP) and path.
pub(super) fn finish(
    problem: &PeriodicProblem,
    (asm, fft, grid): (&Assembly, &PeriodFft, &FrictionGrid),
    sol: LcpSolution,
    (t_start, t_assembly, lcp_time): (Instant, f64, f64),
    path: String,
) -> Result<Response, SolveError> {
    let model = problem.model();
    let (k, m) = (asm.k, asm.m);
    let lay = Layout { k, mc: model.contacts.len(), mf: model.frictions.len() };
    let nn = k * (lay.mc + 2 * lay.mf);
    let coupled = super::friction_coupled::couplings(model);
    let slip: Vec<f64> = model.frictions.iter().map(|f| f.slip_force()).collect();
    // The forces in the assembly's row order (j·m + a), friction forces f = z₁ − μN.
    let mut z = vec![0.0; k * m];
    let mut forces = vec![Vec::new(); lay.mf];
    for (t, f) in forces.iter_mut().enumerate() {
        // Coupled: f = z₁ − μλ_n at each instant.
        let pressed = |j: usize| coupled[t].map_or(0.0, |(c, mu)| mu * sol.z[lay.row(c, j)]);
        *f = (0..k).map(|j| sol.z[lay.row(lay.mc + t, j)] - slip[t] - pressed(j)).collect();
    }
    // What the structure feels at the instants (the half-step samples' mean under cds, galerkin).
    let felt: Vec<Vec<f64>> = forces.iter().map(|f| grid.felt(f)).collect();
    for j in 0..k {
        for a in 0..lay.mc {
            z[j * m + a] = sol.z[lay.row(a, j)];
        }
        for (t, f) in felt.iter().enumerate() {
            z[j * m + lay.mc + t] = f[j];
        }
    }
    let rows = LcpSolution { outcome: sol.outcome, z, w: Vec::new(), info: sol.info.clone() };
    let t_rec = Instant::now();
    let mut response = recovery::recover(problem, asm, fft, &rows)?;
    response.friction = (0..lay.mf).map(|t| friction_response(problem, (asm, fft, grid), (&rows.z, &forces[t]), &sol, &lay, t)).collect::<Result<_, _>>()?;
    response.lcp.size = nn;
    response.lcp.path = path;
    // Warm starts are not used by this path: no active set to carry.
    response.active_set.clear();
    response.timing_s.assembly = t_assembly;
    response.timing_s.lcp = lcp_time;
    response.timing_s.recovery = t_rec.elapsed().as_secs_f64();
    response.timing_s.total = t_start.elapsed().as_secs_f64();
    Ok(response)
}

/// Refits the event laws of the half-step samples (`friction_events`) from `sol` and solves again
/// until they repeat; the answer's w₁ then holds −v̄ + α (the mean slip velocity, not the law's
/// shifted one). Returns the last solution and the refits made.
fn fit_events(
    problem: &PeriodicProblem,
    asm: &Assembly,
    (a, q): (&DenseMatrix, &[f64]),
    lay: &Layout,
    mut sol: LcpSolution,
    settings: &LemkeSettings,
) -> Result<(LcpSolution, usize), SolveError> {
    let (k, nn) = (lay.k, q.len());
    let slip: Vec<f64> = problem.model().frictions.iter().map(|f| f.slip_force()).collect();
    let h = problem.period() / k as f64;
    let mut laws = EventLaws::none(k, lay.mf);
    let mut rounds = 0;
    // The samples' forces and mean slip velocities (k × mf), undoing the laws' shift v̄ − c − ε s.
    let samples = |sol: &LcpSolution, laws: &EventLaws| -> (Vec<f64>, Vec<f64>) {
        let (mut f, mut v) = (vec![0.0; k * lay.mf], vec![0.0; k * lay.mf]);
        for (t, mu_n) in slip.iter().enumerate() {
            for j in 0..k {
                let (r, sl) = (lay.row(lay.mc + t, j), lay.slack(t, j));
                f[j * lay.mf + t] = sol.z[r] - mu_n;
                let (c, eps) = laws.at(t, j).unwrap_or((0.0, 0.0));
                v[j * lay.mf + t] = sol.z[sl] - sol.w[r] + c + eps * f[j * lay.mf + t] / mu_n;
            }
        }
        (f, v)
    };
    while rounds < MAX_ROUNDS {
        let (f, v) = samples(&sol, &laws);
        let next = EventLaws::fit(&nyquist(asm, lay.mc, lay.mf), &slip, (&f, &v), h);
        if next.repeats(&laws, 1e-10) {
            break;
        }
        laws = next;
        rounds += 1;
        let (mut data, mut q) = (a.as_slice().to_vec(), q.to_vec());
        for (t, mu_n) in slip.iter().enumerate() {
            for j in 0..k {
                if let Some((c, eps)) = laws.at(t, j) {
                    let r = lay.row(lay.mc + t, j);
                    data[r * nn + r] += eps / mu_n;
                    q[r] += c - eps;
                }
            }
        }
        sol = Lemke::new(settings.clone()).solve(&DenseMatrix::from_row_major(nn, data), &q);
        if sol.outcome != LcpOutcome::Solved {
            return Err(lcp_failure(sol));
        }
    }
    let (_, v) = samples(&sol, &laws);
    for t in 0..lay.mf {
        for j in 0..k {
            let (r, sl) = (lay.row(lay.mc + t, j), lay.slack(t, j));
            sol.w[r] = sol.z[sl] - v[j * lay.mf + t];
        }
    }
    Ok((sol, rounds))
}

/// The full friction LCP's certificate of the forces f (k × m_f, time-major) of a friction-only
/// problem: z₁ = f + μN, α = max(σ, 0) with the slip velocity v = D(b xlin − G E f) (− D f/k_t)
/// by FFT products (E the half steps' spread) and σ = v − c − ε f/μN in a law's sample (`laws`,
/// the event-fitted half steps), w from the LCP's own rows; residual ‖min(z, w)‖∞ against
/// solver.tolerance × max(1, ‖q‖∞). The answer's w₁ then holds −v + α (the unshifted velocity).
pub(super) fn certify(
    problem: &PeriodicProblem,
    (asm, fft, grid): (&Assembly, &PeriodFft, &FrictionGrid),
    forces: &[f64],
    laws: Option<&EventLaws>,
) -> LcpSolution {
    let model = problem.model();
    let (k, m, nh) = (asm.k, asm.m, asm.k / 2 + 1);
    let lay = Layout { k, mc: 0, mf: m };
    let nn = 2 * k * m;
    let (mut z, mut w, mut q) = (vec![0.0; nn], vec![0.0; nn], vec![0.0; nn]);
    let f_hat: Vec<Vec<C>> = (0..m).map(|t| fft.forward(&(0..k).map(|j| forces[j * m + t]).collect::<Vec<_>>())).collect();
    let mut velocity = vec![0.0; nn];
    for (t, fr) in model.frictions.iter().enumerate() {
        let mu_n = fr.slip_force();
        let bq = fft.inverse(&(0..nh).map(|p| -asm.bxlin_hat[p * m + t] * grid.velocity[p]).collect::<Vec<_>>());
        let jenkins = fr.stiffness.map_or(0.0, |kt| 1.0 / kt);
        let af_hat: Vec<C> = (0..nh)
            .map(|p| grid.velocity[p] * ((0..m).map(|b| asm.g_hat[(p * m + t) * m + b] * f_hat[b][p]).sum::<C>() * grid.spread[p] + f_hat[t][p] * jenkins))
            .collect();
        let af = fft.inverse(&af_hat);
        for j in 0..k {
            let (r, sl) = (lay.row(t, j), lay.slack(t, j));
            let (c, eps) = laws.and_then(|l| l.at(t, j)).filter(|_| mu_n > 0.0).unwrap_or((0.0, 0.0));
            let f = forces[j * m + t];
            velocity[r] = -(af[j] + bq[j]);
            let sigma = velocity[r] - c - eps * f / mu_n.max(f64::MIN_POSITIVE);
            z[r] = f + mu_n;
            z[sl] = sigma.max(0.0);
            w[r] = z[sl] - sigma;
            w[sl] = 2.0 * mu_n - z[r];
            q[r] = bq[j] + c - eps;
            q[sl] = 2.0 * mu_n;
        }
    }
    let (residual, relative_error) = residuals(&q, &z, &w);
    let qmax = q.iter().fold(1.0f64, |a, v| a.max(v.abs()));
    let outcome = if residual <= problem.solver_settings().tolerance * qmax { LcpOutcome::Solved } else { LcpOutcome::Inaccurate };
    for t in 0..m {
        for j in 0..k {
            let (r, sl) = (lay.row(t, j), lay.slack(t, j));
            w[r] = z[sl] - velocity[r];
        }
    }
    LcpSolution { outcome, z, w, info: LcpInfo { residual, relative_error, ..LcpInfo::default() } }
}

/// The typed outcome of a friction shooting that did not converge (`per_instant`: the dense LCP's
/// unknowns per instant, for the remedy).
pub(super) fn shooting_failed(e: ShotFailure, per_instant: usize) -> SolveError {
    SolveError::Lcp {
        outcome: LcpOutcome::PivotLimit,
        info: LcpInfo { pivots: e.iterations, residual: e.residual, ..LcpInfo::default() },
        hint: format!(
            "friction shooting: {} after {} Newton iterations (relative periodicity residual {:.1e}); remedies: add damping, or reduce discretization.steps to {} or fewer for the dense LCP",
            e.why,
            e.iterations,
            e.residual,
            FRICTION_DENSE_MAX / per_instant
        ),
    }
}

/// The dense size refusal, with why shooting does not apply either.
fn shooting_refused(dense: SolveError, why: &NoStepMap) -> SolveError {
    match dense {
        SolveError::Limit(text) => SolveError::Limit(format!("{text}; shooting does not apply: {why}")),
        other => other,
    }
}

/// Force, slip velocity, stuck flags, tangential displacement and dissipated energy of friction
/// `t`, at the instants: with half-step samples (cds, galerkin) the force the structure feels
/// there, the mean of the two slip velocities around t_j, and stuck where both samples stick.
fn friction_response(
    problem: &PeriodicProblem,
    (asm, fft, grid): (&Assembly, &PeriodFft, &FrictionGrid),
    (z, samples): (&[f64], &[f64]),
    sol: &LcpSolution,
    lay: &Layout,
    t: usize,
) -> Result<FrictionResponse, SolveError> {
    let f = &problem.model().frictions[t];
    let (k, m, nh) = (asm.k, asm.m, asm.k / 2 + 1);
    let a = lay.mc + t;
    // The slip force at each instant: μN, or μλ_n of a coupled contact.
    let bound: Vec<f64> = (0..k).map(|j| f.contact.map_or(f.slip_force(), |c| f.coefficient * sol.z[lay.row(c, j)])).collect();
    // The relay's velocity v = α − w₁ (src/formulation.md §9).
    let samples_velocity: Vec<f64> = (0..k).map(|j| sol.z[lay.slack(t, j)] - sol.w[lay.row(a, j)]).collect();
    // u = b xlin − Σ_b G_ab f_b, by the harmonics (z holds the forces felt at the instants).
    let z_hat: Vec<Vec<C>> = (0..m).map(|b| fft.forward(&(0..k).map(|j| z[j * m + b]).collect::<Vec<_>>())).collect();
    let u_hat: Vec<C> = (0..nh).map(|p| asm.bxlin_hat[p * m + a] - (0..m).map(|b| asm.g_hat[(p * m + a) * m + b] * z_hat[b][p]).sum::<C>()).collect();
    let displacement = fft.inverse(&u_hat);
    // Stuck: strictly inside the box (a slipping force sits on its bound to round-off).
    let sample_stuck: Vec<bool> = samples.iter().zip(&bound).map(|(v, b)| v.abs() < b * (1.0 - 1e-9)).collect();
    let (force, slip_velocity, stuck) = if grid.half_steps() {
        let before = |j: usize| (j + k - 1) % k;
        (
            grid.felt(samples),
            (0..k).map(|j| 0.5 * (samples_velocity[before(j)] + samples_velocity[j])).collect(),
            (0..k).map(|j| sample_stuck[before(j)] && sample_stuck[j]).collect(),
        )
    } else {
        (samples.to_vec(), samples_velocity.clone(), sample_stuck)
    };
    // ∮ f v dt over the samples: exact for the scheme (f and v constant over each step).
    let h = problem.period() / k as f64;
    let dissipated_energy = h * samples.iter().zip(&samples_velocity).map(|(f, v)| f * v).sum::<f64>();
    let all = force.iter().chain(&slip_velocity).chain(&displacement);
    if !all.clone().all(|v| v.is_finite()) || !dissipated_energy.is_finite() {
        return Err(SolveError::NonFinite(format!("friction {t}")));
    }
    Ok(FrictionResponse {
        coefficient: f.coefficient,
        normal_force: f.normal_force,
        contact: f.contact,
        stiffness: f.stiffness,
        force,
        slip_velocity,
        stuck,
        displacement,
        dissipated_energy,
    })
}
