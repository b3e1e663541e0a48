//! Explicit time-marching reference (src/formulation.md §5): central differences with forward-increment
//! Lagrange multipliers (Carpenter, Taylor & Katona 1991), for dense multi-DOF models.
//!
//! In the user-facing signs of [`crate::model`] (contact i: `s_i·x[d_i] ≤ gap_i(t)`, row i of B is
//! s_i e_{d_i}ᵀ, compressive force z_i ≥ 0 pushing DOF d_i by −s_i z_i):
//!
//! ```text
//! Ŵ = (M/h² + C/(2h))⁻¹
//! f_n   = f(t_n) − Σ_compliant s_i e_{d_i} k_c,i max(0, s_i x_n[d_i] − gap_i(t_n))    (explicit penalty)
//! x^p   = Ŵ [ f_n + (2M/h² − K) x_n − (M/h² − C/(2h)) x_{n−1} ]                       (predictor)
//! w^p   = gap(t_{n+1}) − B_r x^p                                                        (rigid contacts)
//! LCP   w = G λ + w^p,  G = B_r Ŵ B_rᵀ,  λ ≥ 0, w ≥ 0, λᵀw = 0
//! x_{n+1} = x^p − Ŵ B_rᵀ λ                                                              (corrector)
//! ```
//!
//! Evaluated in the summed (increment) form of Störmer's method (Henrici 1962, *Discrete Variable
//! Methods in ODEs*, §6.2–6.4; Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §VIII.5),
//! the same recurrence rearranged so that no O(1) matrix 2I − h²M⁻¹K is formed:
//!
//! ```text
//! Δ_n = x_n − x_{n−1},  Δ^p = Δ_n − ŴK x_n − (ŴC/h) Δ_n + Ŵ f_n,  x^p = x_n + Δ^p
//! Δ_{n+1} = Δ^p − Ŵ B_rᵀ λ,  x_{n+1} = x_n + Δ_{n+1}   (both sums compensated, Kahan)
//! ```
//!
//! Why: the two-step form's Ŵ(2M/h² − K) is 2I − h²M⁻¹K rounded to ε·‖Ŵ‖‖M‖/h², a stiffness
//! error ε·κ/h² that grows as N²: on the Craig–Bampton blade (h ≈ 1.6e-8 s) it erred 4e-5 at
//! N = 20 992 and 1.2e-3 at 163 840 instead of falling as N⁻² (validation/RECORD.md "On a family").
//!
//! λ_n is a force acting in the step equation at t_n; it enforces the clearance at t_{n+1}
//! (forward increment), and its impulse is λ_n·h. On a contact DOF carrying mass this is a
//! perfectly plastic impact (restitution 0).
//!
//! A model with massless DOFs (a massless boundary) is marched with those DOFs condensed
//! statically at each instant (`massless.rs`).
//!
//! Stability: h < 2/ω_max, with ω_max² the largest eigenvalue of (K + Σ k_c e_d e_dᵀ, M)
//! (compliant contacts closed). The viscous term C(x_{n+1} − x_{n−1})/(2h) does not lower this
//! bound for a 1-DOF or proportionally damped system.
mod massless;
mod small_lcp;

use crate::error::ErrorKind;
use crate::model::{Compliance, Model, ModelError};
use faer::Mat;
use faer::linalg::solvers::{DenseSolveCore, Solve};
pub use massless::stable_omega_max;
pub use small_lcp::StepLcpError;
use small_lcp::solve_small_lcp;
use std::time::Instant;

/// Why a march could not run or ended without a state: a setting (field: value: remedy), the
/// model's checks, a step LCP without solution, or a diverged state.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MarchError {
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A setting or the structure is not usable (`settings.steps_per_period`, `structure.mass`, …).
    #[error("{field}: {message}")]
    Setting { field: String, message: String },
    #[error("step {step} of period {period}: {error}")]
    Step { step: usize, period: usize, error: small_lcp::StepLcpError },
    #[error("the march diverged at step {step} of period {period} (non-finite displacement)")]
    Diverged { step: usize, period: usize },
}

impl MarchError {
    fn setting(field: impl Into<String>, message: impl Into<String>) -> Self {
        MarchError::Setting { field: field.into(), message: message.into() }
    }

    /// Settings and the model are the caller's to change; the rest is the march's outcome.
    pub fn kind(&self) -> ErrorKind {
        match self {
            MarchError::Model(_) | MarchError::Setting { .. } => ErrorKind::Input,
            MarchError::Step { .. } | MarchError::Diverged { .. } => ErrorKind::Solve,
        }
    }
}

impl From<MarchError> for crate::Error {
    fn from(e: MarchError) -> Self {
        crate::Error::new(e.kind(), e.to_string())
    }
}

/// Settings of [`march`].
#[derive(Clone, Debug, PartialEq)]
pub struct MarchSettings {
    /// N: time steps per period, h = T/N.
    pub steps_per_period: usize,
    /// Stop after this many periods even when not converged.
    pub max_periods: usize,
    /// Compare at least this many periods (≥ 2).
    pub min_periods: usize,
    /// Converged when ‖x(period p) − x(period p−1)‖∞ / peak-to-peak < tolerance.
    pub tolerance: f64,
    /// x(0); zeros when `None`.
    pub initial_displacement: Option<Vec<f64>>,
    /// v(0); zeros when `None`.
    pub initial_velocity: Option<Vec<f64>>,
}

impl Default for MarchSettings {
    fn default() -> Self {
        MarchSettings { steps_per_period: 1000, max_periods: 10_000, min_periods: 2, tolerance: 1e-8, initial_displacement: None, initial_velocity: None }
    }
}

/// The last simulated period, sampled at t_j = j·h, j = 0…N−1 (times within the period;
/// the absolute time is `(periods − 1)·T + t_j`).
#[derive(Clone, Debug)]
pub struct MarchResult {
    /// t_j = j·h.
    pub time: Vec<f64>,
    /// `displacement[j][dof]`.
    pub displacement: Vec<Vec<f64>>,
    /// Central velocity (x_{j+1} − x_{j−1}) / (2h), `velocity[j][dof]`.
    pub velocity: Vec<Vec<f64>>,
    /// `contact_force[j][contact]`: the force in the step equation at t_j (rigid: λ_j, enforcing
    /// the clearance at t_{j+1}; compliant: k_c·max(0, penetration at t_j)).
    pub contact_force: Vec<Vec<f64>>,
    /// `contact_impulse[j][contact] = contact_force[j][contact]·h`.
    pub contact_impulse: Vec<Vec<f64>>,
    /// `clearance[j][contact] = gap(t_j) − s·x_j[d]`.
    pub clearance: Vec<Vec<f64>>,
    /// Periods simulated.
    pub periods: usize,
    pub steps_per_period: usize,
    /// h = T/N.
    pub step: f64,
    /// The ω_max used for the stability check.
    pub omega_max: f64,
    /// Elapsed time of the (single-threaded) march, set-up included, in seconds.
    pub cpu_time_s: f64,
    pub converged: bool,
    /// Final periodicity defect (∞ when fewer than two periods were simulated).
    pub defect: f64,
    /// Defect after each period p ≥ 2.
    pub defect_history: Vec<f64>,
}

impl MarchResult {
    /// Σ_j impulse over the last period, per contact.
    pub fn impulse_per_period(&self) -> Vec<f64> {
        let m = self.contact_impulse.first().map_or(0, |r| r.len());
        (0..m).map(|i| self.contact_impulse.iter().map(|r| r[i]).sum()).collect()
    }
}

/// Row-major n×n product y = A x.
fn matvec_add(a: &[f64], x: &[f64], y: &mut [f64], n: usize) {
    for i in 0..n {
        let row = &a[i * n..(i + 1) * n];
        y[i] += row.iter().zip(x).map(|(p, q)| p * q).sum::<f64>();
    }
}

/// Marches the model period after period from the initial state until the periodicity defect is
/// below `settings.tolerance` (and at least `min_periods` periods ran) or `max_periods` is
/// reached. Errors (naming the parameter and value) on an invalid model or settings, an unstable
/// step, a failed step LCP or a non-finite state.
pub fn march(model: &Model, settings: &MarchSettings) -> Result<MarchResult, MarchError> {
    let start = Instant::now();
    model.validate()?;
    let n = model.n();
    let ns = settings.steps_per_period;
    if ns < 2 {
        return Err(MarchError::setting("settings.steps_per_period", format!("is {ns}, must be ≥ 2")));
    }
    if settings.max_periods < 1 {
        return Err(MarchError::setting("settings.max_periods", format!("is {}, must be ≥ 1", settings.max_periods)));
    }
    if !(settings.tolerance.is_finite() && settings.tolerance > 0.0) {
        return Err(MarchError::setting("settings.tolerance", format!("is {}, must be finite and > 0", settings.tolerance)));
    }
    for (name, v) in [("settings.initial_displacement", &settings.initial_displacement), ("settings.initial_velocity", &settings.initial_velocity)] {
        if let Some(v) = v {
            if v.len() != n {
                return Err(MarchError::setting(name, format!("has {} entries, the model has {n} DOFs", v.len())));
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(MarchError::setting(format!("{name}[{i}]"), format!("is {}, must be finite", v[i])));
            }
        }
    }
    let massless = model.massless_dofs();
    if !massless.is_empty() {
        return massless::march_massless(model, settings, &massless, start);
    }
    let period = model.period();
    let h = period / ns as f64;
    let mm = model.structure.mass.to_dense();
    let kk = model.structure.stiffness.to_dense();
    let cc = model.structure.damping.as_ref().map_or_else(|| Mat::<f64>::zeros(n, n), |c| c.to_dense());

    // Stability limit with the compliant contacts closed (the model's one ω_max routine).
    let omega_max = model.omega_max()?;
    if omega_max * h >= 2.0 {
        let n_min = (period * omega_max / 2.0).floor() as usize + 1;
        return Err(MarchError::setting(
            "settings.steps_per_period",
            format!(
                "is {ns}, h = T/N = {h:e} exceeds the central-difference stability limit 2/ω_max = {:e} (ω_max = {omega_max:e}); use more than {n_min} steps per period",
                2.0 / omega_max
            ),
        ));
    }

    // Ŵ and the increment matrices −ŴK and −ŴC/h (summed form: no 2I − h²M⁻¹K is rounded).
    let lhs = Mat::<f64>::from_fn(n, n, |i, j| mm[(i, j)] / (h * h) + cc[(i, j)] / (2.0 * h));
    let w_hat = lhs.partial_piv_lu().inverse();
    let q1m = -(&w_hat * &kk);
    let q2m = -(&w_hat * &cc) * faer::Scale(1.0 / h);
    let row_major = |a: &Mat<f64>| -> Vec<f64> { (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| a[(i, j)]).collect() };
    let (q1, q2, wr) = (row_major(&q1m), row_major(&q2m), row_major(&w_hat));
    if q1.iter().chain(&q2).chain(&wr).any(|v| !v.is_finite()) {
        return Err(MarchError::setting("structure", "M/h² + C/(2h) is singular"));
    }
    let damped = model.structure.damping.is_some();
    let nc = model.contacts.len();
    let rigid: Vec<usize> = (0..nc).filter(|&i| model.contacts[i].is_rigid()).collect();
    let mr = rigid.len();
    // Columns Ŵ B_iᵀ and G = B_r Ŵ B_rᵀ.
    let cols: Vec<Vec<f64>> = rigid
        .iter()
        .map(|&i| {
            let c = &model.contacts[i];
            (0..n).map(|r| c.along(|d| w_hat[(r, d)])).collect()
        })
        .collect();
    let mut g = vec![0.0; mr * mr];
    for (a, &i) in rigid.iter().enumerate() {
        let ci = &model.contacts[i];
        for b in 0..mr {
            g[a * mr + b] = ci.normal_displacement(&cols[b]);
        }
    }

    // Start-up: x_{−1} = x_0 − h v_0 + h²/2 a_0, a_0 from the equation of motion (no rigid force).
    let omega = model.frequency;
    let x0 = settings.initial_displacement.clone().unwrap_or_else(|| vec![0.0; n]);
    let v0 = settings.initial_velocity.clone().unwrap_or_else(|| vec![0.0; n]);
    let mut f = vec![0.0; n];
    let penalty = |t: f64, x: &[f64], f: &mut [f64], z: &mut [f64]| {
        for (i, c) in model.contacts.iter().enumerate() {
            if let Compliance::Compliant { stiffness } = c.compliance {
                let zi = stiffness * (c.normal_displacement(x) - c.gap_at(omega, t)).max(0.0);
                z[i] = zi;
                c.push_back(zi, f);
            }
        }
    };
    let mut zbuf = vec![0.0; nc];
    model.force_at(0.0, &mut f);
    penalty(0.0, &x0, &mut f, &mut zbuf);
    let mut r0 = Mat::<f64>::from_fn(n, 1, |i, _| f[i]);
    for i in 0..n {
        for j in 0..n {
            r0[(i, 0)] -= cc[(i, j)] * v0[j] + kk[(i, j)] * x0[j];
        }
    }
    let acc0 = mm.partial_piv_lu().solve(&r0);
    // Δ_0 = x_0 − x_{−1} = h v_0 − h²/2 a_0.
    let mut d_cur: Vec<f64> = (0..n).map(|i| h * v0[i] - 0.5 * h * h * acc0[(i, 0)]).collect();
    let mut x_cur = x0;
    let (mut x_next, mut d_next, mut x_pred) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut sum = Compensated::new(n);

    let mut rec = Recorder::new(n, nc, ns, h);
    let mut q = vec![0.0; mr];
    for p in 0..settings.max_periods {
        for j in 0..ns {
            let t = j as f64 * h;
            let t1 = (j + 1) as f64 * h;
            model.force_at(t, &mut f);
            zbuf.iter_mut().for_each(|v| *v = 0.0);
            penalty(t, &x_cur, &mut f, &mut zbuf);
            // Predictor: the increment δ = −ŴK x_n − (ŴC/h) Δ_n + Ŵ f_n.
            d_next.iter_mut().for_each(|v| *v = 0.0);
            matvec_add(&q1, &x_cur, &mut d_next, n);
            if damped {
                matvec_add(&q2, &d_cur, &mut d_next, n);
            }
            for (k, &fk) in f.iter().enumerate() {
                if fk != 0.0 {
                    for i in 0..n {
                        d_next[i] += wr[i * n + k] * fk;
                    }
                }
            }
            // Rigid contacts: forward-increment multipliers on x^p = x_n + Δ_n + δ.
            if mr > 0 {
                for i in 0..n {
                    x_pred[i] = x_cur[i] + (d_cur[i] + d_next[i]);
                }
                for (a, &i) in rigid.iter().enumerate() {
                    let c = &model.contacts[i];
                    q[a] = c.gap_at(omega, t1) - c.normal_displacement(&x_pred);
                }
                if q.iter().any(|&v| v < 0.0) {
                    let lam = solve_small_lcp(&g, &q, mr).map_err(|e| MarchError::Step { step: j, period: p + 1, error: e })?;
                    for (a, &i) in rigid.iter().enumerate() {
                        if lam[a] != 0.0 {
                            for r in 0..n {
                                d_next[r] -= lam[a] * cols[a][r];
                            }
                        }
                        zbuf[i] = lam[a];
                    }
                }
            }
            sum.step(&x_cur, &d_cur, &mut x_next, &mut d_next, 0..n);
            if x_next.iter().any(|v| !v.is_finite()) {
                return Err(MarchError::Diverged { step: j, period: p + 1 });
            }
            rec.contacts(j, model, t, &zbuf, &x_cur);
            rec.state(j, &x_cur, &d_cur, &d_next);
            std::mem::swap(&mut x_cur, &mut x_next);
            std::mem::swap(&mut d_cur, &mut d_next);
        }
        if rec.end_period(p, settings) {
            break;
        }
    }
    Ok(rec.finish(omega_max, start))
}

/// The summed form's two sums Δ_{n+1} = Δ_n + δ and x_{n+1} = x_n + Δ_{n+1} with Kahan's
/// compensation (Hairer, Lubich & Wanner, GNI §VIII.5, Algorithm 5.1): the δ ≈ (hω)²|x| increment
/// is below x's last digit at fine steps, and the carried error term keeps those digits.
struct Compensated {
    d: Vec<f64>,
    x: Vec<f64>,
}

impl Compensated {
    fn new(n: usize) -> Self {
        Compensated { d: vec![0.0; n], x: vec![0.0; n] }
    }

    /// On entry `d_next` holds δ; on exit Δ_{n+1}, and `x_next` x_{n+1}, for the DOFs in `dofs`.
    fn step(&mut self, x_cur: &[f64], d_cur: &[f64], x_next: &mut [f64], d_next: &mut [f64], dofs: impl Iterator<Item = usize>) {
        for i in dofs {
            let y = d_next[i] - self.d[i];
            let s = d_cur[i] + y;
            self.d[i] = (s - d_cur[i]) - y;
            d_next[i] = s;
            let y = s - self.x[i];
            let s = x_cur[i] + y;
            self.x[i] = (s - x_cur[i]) - y;
            x_next[i] = s;
        }
    }
}

/// The samples of the period being marched and of the one before, and the convergence test on
/// them: the bookkeeping both marchers (this one and `massless`) share.
struct Recorder {
    n: usize,
    m: usize,
    ns: usize,
    h: f64,
    disp: Vec<f64>,
    disp_prev: Vec<f64>,
    vel: Vec<f64>,
    force: Vec<f64>,
    clear: Vec<f64>,
    defect: f64,
    history: Vec<f64>,
    converged: bool,
    periods: usize,
}

impl Recorder {
    /// `n` DOFs and `m` contacts per sample, `ns` samples of step `h` per period.
    fn new(n: usize, m: usize, ns: usize, h: f64) -> Self {
        let zeros = |len| vec![0.0; len];
        Recorder {
            n,
            m,
            ns,
            h,
            disp: zeros(ns * n),
            disp_prev: zeros(ns * n),
            vel: zeros(ns * n),
            force: zeros(ns * m),
            clear: zeros(ns * m),
            defect: f64::INFINITY,
            history: Vec::new(),
            converged: false,
            periods: 0,
        }
    }

    /// Sample j's contact forces and clearances (of x at t_j).
    fn contacts(&mut self, j: usize, model: &Model, t: f64, forces: &[f64], x: &[f64]) {
        for (i, c) in model.contacts.iter().enumerate() {
            self.force[j * self.m + i] = forces[i];
            self.clear[j * self.m + i] = c.gap_at(model.frequency, t) - c.normal_displacement(x);
        }
    }

    /// Sample j's displacement x_j and central velocity (x_{j+1} − x_{j−1})/(2h) = (Δ_j + Δ_{j+1})/(2h).
    fn state(&mut self, j: usize, x_cur: &[f64], d_cur: &[f64], d_next: &[f64]) {
        let n = self.n;
        self.disp[j * n..(j + 1) * n].copy_from_slice(x_cur);
        for i in 0..n {
            self.vel[j * n + i] = (d_cur[i] + d_next[i]) / (2.0 * self.h);
        }
    }

    /// After period p (0-based): true when the march has converged and stops.
    fn end_period(&mut self, p: usize, settings: &MarchSettings) -> bool {
        self.periods = p + 1;
        if p >= 1 {
            self.defect = period_defect(&self.disp, &self.disp_prev, self.n, self.ns);
            self.history.push(self.defect);
            if self.defect < settings.tolerance && self.periods >= settings.min_periods.max(2) {
                self.converged = true;
                return true;
            }
        }
        std::mem::swap(&mut self.disp, &mut self.disp_prev);
        false
    }

    fn finish(mut self, omega_max: f64, start: Instant) -> MarchResult {
        // After a converged break `disp` holds the last period; otherwise the final swap moved
        // it to `disp_prev`.
        let history = std::mem::take(&mut self.history);
        let last = if self.converged { &self.disp } else { &self.disp_prev };
        let samples = Samples { disp: last, vel: &self.vel, force: &self.force, clear: &self.clear, n: self.n, m: self.m, ns: self.ns, h: self.h };
        result(samples, self.periods, omega_max, start, self.converged, self.defect, history)
    }
}

/// ‖x(period p) − x(period p−1)‖∞ / peak-to-peak over the DOFs (`n` per sample, `ns` samples).
fn period_defect(disp: &[f64], disp_prev: &[f64], n: usize, ns: usize) -> f64 {
    let mut ptp = 0.0f64;
    for i in 0..n {
        let (lo, hi) = (0..ns).map(|j| disp[j * n + i]).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        ptp = ptp.max(hi - lo);
    }
    let diff = disp.iter().zip(disp_prev).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    if ptp > 0.0 { diff / ptp } else { diff }
}

/// The last period's samples, row-major: `n` DOFs and `m` contacts per sample, `ns` samples.
struct Samples<'a> {
    disp: &'a [f64],
    vel: &'a [f64],
    force: &'a [f64],
    clear: &'a [f64],
    n: usize,
    m: usize,
    ns: usize,
    h: f64,
}

fn result(s: Samples, periods: usize, omega_max: f64, start: Instant, converged: bool, defect: f64, defect_history: Vec<f64>) -> MarchResult {
    let (ns, h) = (s.ns, s.h);
    let rows = |buf: &[f64], w: usize| -> Vec<Vec<f64>> { (0..ns).map(|j| buf[j * w..(j + 1) * w].to_vec()).collect() };
    let contact_force = rows(s.force, s.m);
    let contact_impulse = contact_force.iter().map(|r| r.iter().map(|v| v * h).collect()).collect();
    MarchResult {
        time: (0..ns).map(|j| j as f64 * h).collect(),
        displacement: rows(s.disp, s.n),
        velocity: rows(s.vel, s.n),
        contact_force,
        contact_impulse,
        clearance: rows(s.clear, s.m),
        periods,
        steps_per_period: ns,
        step: h,
        omega_max,
        cpu_time_s: start.elapsed().as_secs_f64(),
        converged,
        defect,
        defect_history,
    }
}
