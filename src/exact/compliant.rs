//! Bilinear oscillator (compliant stop, src/formulation.md §6.2):
//!
//!   m x'' + c x' + k x + k_c·max(0, x − g0) = F cos Ωt,
//!
//! i.e. a penalty stop x ≤ g0 of stiffness k_c (direction +1) whose compressive force
//! z = k_c·max(0, x − g0) ≥ 0 pushes the mass by −z.
//!
//! A one-contact periodic orbit enters the contact at t0 with velocity v0 > 0 (x = g0), leaves it
//! at t1 (x = g0, velocity v1 < 0) and flies freely until t0 + T. Both phases are linear with
//! constant coefficients:
//! - contact: m x'' + c x' + (k + k_c) x = F cos Ωt + k_c g0,
//! - free:    m x'' + c x' + k x = F cos Ωt,
//!
//! with closed-form flows ([`super::flow`]). Unknowns (t0, t1, v0); equations
//! x_c(t1) = g0, x_f(t0 + T) = g0, v_f(t0 + T) = v0, solved by Newton with the analytic
//! Jacobian, seeded by an event-driven simulation of the same exact flows (or a given seed).
use super::flow::{PhaseFlow, State, extrema};
use super::{ExactError, LinearOrbit, Oscillator, check_finite};

#[derive(Clone, Copy, Debug, PartialEq)]
struct Phases {
    t0: f64,
    t1: f64,
    v0: f64,
    v1: f64,
    free: PhaseFlow,
    contact: PhaseFlow,
}

/// Periodic orbit of the bilinear oscillator: one contact phase per period, or no contact at all
/// when the linear response stays below g0.
#[derive(Clone, Debug, PartialEq)]
pub struct CompliantStopOrbit {
    osc: Oscillator,
    contact_stiffness: f64,
    gap: f64,
    phases: Option<Phases>,
    linear: LinearOrbit,
    min_x: f64,
    max_x: f64,
    newton_iterations: usize,
    residual: f64,
}

impl CompliantStopOrbit {
    /// `seed`: optional (t0, t1, v0) to start Newton from (e.g. from a coarse LCP solution);
    /// without it the seed comes from an event-driven simulation of the exact flows, started on
    /// the linear orbit. Returns the contact-free linear orbit (see [`Self::has_contact`]) when
    /// no seed is given and max x of the linear response is ≤ g0.
    ///
    /// When the simulation does not settle to a period-T attractor, Newton still starts from its
    /// last contact phase: the orbit found may then be unstable (see [`Self::is_stable`]).
    ///
    /// Fails (naming the parameter) on invalid input, when the simulated steady state has several
    /// contact phases per period, and when Newton does not converge or its answer is not a
    /// one-contact orbit (x > g0 in the free phase, x < g0 in the contact phase,
    /// t1 − t0 ∉ (0, T), v0 ≤ 0).
    pub fn solve(osc: &Oscillator, contact_stiffness: f64, gap: f64, seed: Option<[f64; 3]>) -> Result<Self, ExactError> {
        osc.validate()?;
        osc.require_stiffness()?;
        if !(contact_stiffness.is_finite() && contact_stiffness > 0.0) {
            return Err(ExactError::param("contact_stiffness", format!("is {contact_stiffness}, must be finite and > 0")));
        }
        check_finite("gap", gap)?;
        if let Some(s) = seed {
            for (name, v) in ["seed.t0", "seed.t1", "seed.v0"].iter().zip(s) {
                check_finite(name, v)?;
            }
        }
        let linear = LinearOrbit::solve(osc)?;
        let (m, c, k, f, w) = (osc.mass, osc.damping, osc.stiffness, osc.force, osc.omega);
        let free = PhaseFlow::new(m, c, k, f, w, 0.0)?;
        let contact = PhaseFlow::new(m, c, k + contact_stiffness, f, w, contact_stiffness * gap)?;
        let mut orbit = CompliantStopOrbit {
            osc: *osc,
            contact_stiffness,
            gap,
            phases: None,
            linear,
            min_x: -linear.amplitude(),
            max_x: linear.amplitude(),
            newton_iterations: 0,
            residual: 0.0,
        };
        let seed = match seed {
            Some(s) => s,
            None => {
                if linear.amplitude() <= gap {
                    return Ok(orbit);
                }
                orbit.simulation_seed(&free, &contact)?
            }
        };
        let period = osc.period();
        // Newton near t = 0: absolute times of late periods would cost digits in cos(Ωt).
        let s0 = (seed[0] / period).floor() * period;
        let seed = [seed[0] - s0, seed[1] - s0, seed[2]];
        let (x, iters, res) = orbit.newton(&free, &contact, seed)?;
        let shift = (x[0] / period).floor() * period;
        let (t0, t1, v0) = (x[0] - shift, x[1] - shift, x[2]);
        let v1 = contact.propagate(t0, [gap, v0], t1)[1];
        orbit.phases = Some(Phases { t0, t1, v0, v1, free, contact });
        orbit.newton_iterations = iters;
        orbit.residual = res;
        orbit.check()?;
        Ok(orbit)
    }

    /// Event-driven simulation of the exact piecewise-linear flows, started on the linear orbit,
    /// until the state at the start of a period settles; returns the last (t0, t1, v0).
    fn simulation_seed(&self, free: &PhaseFlow, contact: &PhaseFlow) -> Result<[f64; 3], ExactError> {
        let g0 = self.gap;
        let period = self.osc.period();
        let steps = 400;
        let dt = period / steps as f64;
        let (x, v, _) = self.linear.eval(0.0);
        let mut s: State = [x, v];
        let mut inside = s[0] > g0;
        let scale = self.linear.amplitude().max(g0.abs());
        let mut last: Option<(f64, f64, f64)> = None; // (t_up, v_up, t_down)
        let mut pending_up: Option<(f64, f64)> = None;
        let mut prev_start = s;
        // Periods for the free transient e^{−ct/2m} to fall by e^{−200} (slower period maps near a
        // bifurcation need more than e^{−20}), within bounds.
        let decay = self.osc.damping / (2.0 * self.osc.mass) * period;
        let max_periods = if decay > 0.0 { ((200.0 / decay).ceil() as usize + 100).min(20_000) } else { 200 };
        let mut settled = None;
        for p in 0..max_periods {
            let mut ups = 0;
            for j in 0..steps {
                let mut ta = (p * steps + j) as f64 * dt;
                let tb = ta + dt;
                loop {
                    let fl = if inside { contact } else { free };
                    let sb = fl.propagate(ta, s, tb);
                    let crossed = if inside { sb[0] < g0 } else { sb[0] > g0 };
                    if !crossed {
                        s = sb;
                        break;
                    }
                    // First instant in (ta, tb] on the wrong side of g0 (ta is not).
                    let (mut lo, mut hi) = (ta, tb);
                    for _ in 0..200 {
                        let mid = 0.5 * (lo + hi);
                        if mid <= lo || mid >= hi {
                            break;
                        }
                        let xm = fl.propagate(ta, s, mid)[0];
                        if (inside && xm < g0) || (!inside && xm > g0) { hi = mid } else { lo = mid }
                    }
                    let tc = hi;
                    let sc = fl.propagate(ta, s, tc);
                    if inside {
                        if let Some((tu, vu)) = pending_up.take() {
                            last = Some((tu, vu, tc));
                        }
                    } else {
                        pending_up = Some((tc, sc[1]));
                        ups += 1;
                    }
                    inside = !inside;
                    s = [g0, sc[1]];
                    ta = tc;
                    if ta >= tb {
                        break;
                    }
                }
            }
            let d = (s[0] - prev_start[0]).abs().max((s[1] - prev_start[1]).abs() / self.osc.omega);
            prev_start = s;
            if p > 2 && d < 1e-9 * scale {
                settled = Some(ups);
                break;
            }
        }
        match (settled, last) {
            (Some(1), Some((t0, v0, t1))) => Ok([t0, t1, v0]),
            (Some(0), _) => Err(ExactError::param(
                "gap",
                format!(
                    "is {g0}; the linear response exceeds it (max x = {}) but the simulated steady state never touches the stop: no one-contact orbit from the default seed, give a seed",
                    self.linear.amplitude()
                ),
            )),
            (Some(u), _) => {
                Err(ExactError::param("gap", format!("is {g0}; the simulated steady state has {u} contact phases per period: not a one-contact orbit")))
            }
            // No period-T attractor (subharmonic, chaotic, undamped): an unstable period-T orbit
            // may still exist; let Newton try from the last contact phase.
            (None, Some((t0, v0, t1))) => Ok([t0, t1, v0]),
            (None, None) => Err(ExactError::param(
                "gap",
                format!("is {g0}; the simulated response did not settle to a period-T orbit within {max_periods} periods and made no contact: give a seed"),
            )),
        }
    }

    fn residual_and_jacobian(&self, free: &PhaseFlow, contact: &PhaseFlow, x: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let (g0, period) = (self.gap, self.osc.period());
        let [t0, t1, v0] = x;
        let s0 = [g0, v0];
        let s1 = contact.propagate(t0, s0, t1);
        let te = t0 + period;
        let se = free.propagate(t1, s1, te);
        let pc = contact.phi(t1 - t0);
        let pf = free.phi(te - t1);
        let mul = |p: &[[f64; 2]; 2], v: [f64; 2]| [p[0][0] * v[0] + p[0][1] * v[1], p[1][0] * v[0] + p[1][1] * v[1]];
        // Sensitivities of s1 = contact flow from (t0, s0) to t1.
        let fc0 = [v0, contact.accel(t0, s0)];
        let ds1_dt0 = mul(&pc, fc0).map(|v| -v);
        let ds1_dt1 = [s1[1], contact.accel(t1, s1)];
        let ds1_dv0 = [pc[0][1], pc[1][1]];
        // se = free flow from (t1, s1) to t0 + T.
        let ff1 = [s1[1], free.accel(t1, s1)];
        let ffe = [se[1], free.accel(te, se)];
        let a = mul(&pf, ds1_dt0);
        let dse_dt0 = [a[0] + ffe[0], a[1] + ffe[1]];
        let b = mul(&pf, ds1_dt1);
        let c = mul(&pf, ff1);
        let dse_dt1 = [b[0] - c[0], b[1] - c[1]];
        let dse_dv0 = mul(&pf, ds1_dv0);
        let r = [s1[0] - g0, se[0] - g0, se[1] - v0];
        let j = [[ds1_dt0[0], ds1_dt1[0], ds1_dv0[0]], [dse_dt0[0], dse_dt1[0], dse_dv0[0]], [dse_dt0[1], dse_dt1[1], dse_dv0[1] - 1.0]];
        (r, j)
    }

    fn newton(&self, free: &PhaseFlow, contact: &PhaseFlow, seed: [f64; 3]) -> Result<([f64; 3], usize, f64), ExactError> {
        let period = self.osc.period();
        let xs = self.linear.amplitude().max(self.gap.abs()).max(f64::MIN_POSITIVE);
        let vs = xs * self.osc.omega;
        let norm = |r: [f64; 3]| (r[0].abs() / xs).max(r[1].abs() / xs).max(r[2].abs() / vs);
        let mut x = seed;
        let (mut r, mut j) = self.residual_and_jacobian(free, contact, x);
        for it in 0..100 {
            let nr = norm(r);
            if nr < 1e-14 {
                return Ok((x, it, nr));
            }
            let dx = solve3(j, r).ok_or_else(|| ExactError::param("seed", format!("Newton met a singular Jacobian at (t0, t1, v0) = {x:?}")))?;
            let mut lam = 1.0;
            let mut accepted = false;
            for _ in 0..40 {
                let y = [x[0] - lam * dx[0], x[1] - lam * dx[1], x[2] - lam * dx[2]];
                if y[1] > y[0] && y[1] - y[0] < period && y.iter().all(|v| v.is_finite()) {
                    let (ry, jy) = self.residual_and_jacobian(free, contact, y);
                    if norm(ry) < nr || (lam == 1.0 && norm(ry) < 2.0 * nr && nr < 1e-10) {
                        x = y;
                        r = ry;
                        j = jy;
                        accepted = true;
                        break;
                    }
                }
                lam *= 0.5;
            }
            if !accepted {
                if nr < 1e-11 {
                    return Ok((x, it, nr));
                }
                return Err(ExactError::param("seed", format!("Newton stalled at (t0, t1, v0) = {x:?} with residual {nr:e}")));
            }
        }
        let nr = norm(r);
        if nr < 1e-11 { Ok((x, 100, nr)) } else { Err(ExactError::param("seed", format!("Newton did not converge, residual {nr:e}"))) }
    }

    /// Checks that the Newton answer is a one-contact orbit and records min/max x.
    fn check(&mut self) -> Result<(), ExactError> {
        let p = self.phases.expect("phases set");
        let period = self.osc.period();
        let g0 = self.gap;
        let tol = 1e-9 * self.linear.amplitude().max(g0.abs());
        if !(p.t1 > p.t0 && p.t1 - p.t0 < period) {
            return Err(ExactError::param("seed", format!("converged to t0 = {}, t1 = {}: not a contact phase shorter than T = {period}", p.t0, p.t1)));
        }
        if !(p.v0 > 0.0 && p.v1 < 0.0) {
            return Err(ExactError::param("seed", format!("converged to entry velocity {} and exit velocity {}: not a one-contact orbit", p.v0, p.v1)));
        }
        let (cmin, cmax) = extrema(|t| p.contact.propagate(p.t0, [g0, p.v0], t), p.t0, p.t1, 512);
        let (fmin, fmax) = extrema(|t| p.free.propagate(p.t1, [g0, p.v1], t), p.t1, p.t0 + period, 1024);
        if cmin < g0 - tol {
            return Err(ExactError::param("seed", format!("the converged contact phase leaves the stop (min x = {cmin} < gap {g0}): not a one-contact orbit")));
        }
        if fmax > g0 + tol {
            return Err(ExactError::param("seed", format!("the converged free phase crosses the stop (max x = {fmax} > gap {g0}): not a one-contact orbit")));
        }
        self.min_x = cmin.min(fmin);
        self.max_x = cmax.max(fmax);
        Ok(())
    }

    /// (x, v, contact force) at any t (periodic).
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        match &self.phases {
            None => {
                let (x, v, _) = self.linear.eval(t);
                (x, v, 0.0)
            }
            Some(p) => {
                let tau = p.t0 + (t - p.t0).rem_euclid(self.osc.period());
                if tau <= p.t1 {
                    let s = p.contact.propagate(p.t0, [self.gap, p.v0], tau);
                    (s[0], s[1], self.contact_stiffness * (s[0] - self.gap).max(0.0))
                } else {
                    let s = p.free.propagate(p.t1, [self.gap, p.v1], tau);
                    (s[0], s[1], 0.0)
                }
            }
        }
    }

    /// Acceleration from the equation of motion of the active phase.
    pub fn acceleration(&self, t: f64) -> f64 {
        let (x, v, z) = self.eval(t);
        let o = &self.osc;
        (o.force * (o.omega * t).cos() - o.damping * v - o.stiffness * x - z) / o.mass
    }

    /// Floquet multipliers: eigenvalues of the monodromy matrix Φ_free(T − (t1 − t0))·Φ_contact(t1 − t0)
    /// (the vector field is continuous across x = g0, so the saltation matrices are the identity).
    /// Their product is e^{−cT/m}. For the contact-free orbit: both equal to the free e^{AT}.
    pub fn floquet_multipliers(&self) -> [num_complex::Complex64; 2] {
        let period = self.osc.period();
        let mono = match &self.phases {
            None => PhaseFlow::new(self.osc.mass, self.osc.damping, self.osc.stiffness, 0.0, self.osc.omega, 0.0)
                .map(|f| f.phi(period))
                .unwrap_or([[f64::NAN; 2]; 2]),
            Some(p) => {
                let a = p.free.phi(p.t0 + period - p.t1);
                let b = p.contact.phi(p.t1 - p.t0);
                let mut m = [[0.0; 2]; 2];
                for (i, row) in m.iter_mut().enumerate() {
                    for (j, v) in row.iter_mut().enumerate() {
                        *v = a[i][0] * b[0][j] + a[i][1] * b[1][j];
                    }
                }
                m
            }
        };
        let tr = mono[0][0] + mono[1][1];
        let det = mono[0][0] * mono[1][1] - mono[0][1] * mono[1][0];
        let disc = num_complex::Complex64::new(tr * tr / 4.0 - det, 0.0).sqrt();
        [tr / 2.0 + disc, tr / 2.0 - disc]
    }

    /// Both Floquet multipliers inside the unit circle.
    pub fn is_stable(&self) -> bool {
        self.floquet_multipliers().iter().all(|m| m.norm() < 1.0)
    }

    /// False for the contact-free linear orbit.
    pub fn has_contact(&self) -> bool {
        self.phases.is_some()
    }
    /// Entry time t0 ∈ [0, T).
    pub fn entry_time(&self) -> Option<f64> {
        self.phases.map(|p| p.t0)
    }
    /// Exit time t1 ∈ (t0, t0 + T) (may exceed T).
    pub fn exit_time(&self) -> Option<f64> {
        self.phases.map(|p| p.t1)
    }
    /// v(t0) > 0.
    pub fn entry_velocity(&self) -> Option<f64> {
        self.phases.map(|p| p.v0)
    }
    /// v(t1) < 0.
    pub fn exit_velocity(&self) -> Option<f64> {
        self.phases.map(|p| p.v1)
    }
    pub fn min_x(&self) -> f64 {
        self.min_x
    }
    pub fn max_x(&self) -> f64 {
        self.max_x
    }
    pub fn peak_to_peak(&self) -> f64 {
        self.max_x - self.min_x
    }
    /// ∫ over one period of the contact force = k_c (∫_{t0}^{t1} x dt − g0 (t1 − t0)), exact.
    pub fn impulse_per_period(&self) -> f64 {
        match &self.phases {
            None => 0.0,
            Some(p) => self.contact_stiffness * (p.contact.integral_x(p.t0, [self.gap, p.v0], p.t1) - self.gap * (p.t1 - p.t0)),
        }
    }
    pub fn period(&self) -> f64 {
        self.osc.period()
    }
    pub fn oscillator(&self) -> &Oscillator {
        &self.osc
    }
    /// Newton iterations and final scaled residual.
    pub fn newton_info(&self) -> (usize, f64) {
        (self.newton_iterations, self.residual)
    }
}

/// 3×3 solve by Gaussian elimination with partial pivoting.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col] == 0.0 || !a[piv][col].is_finite() {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col];
            for (v, p) in a[row].iter_mut().zip(pivot_row).skip(col) {
                *v -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        let osc = Oscillator::new(1.0, 0.05, 1.0, 1.0, 1.3);
        let o = CompliantStopOrbit::solve(&osc, 10.0, 1.0, None).unwrap();
        let p = o.phases.unwrap();
        let x = [p.t0 + 0.01, p.t1 - 0.02, p.v0 * 1.01];
        let (_, j) = o.residual_and_jacobian(&p.free, &p.contact, x);
        for k in 0..3 {
            let h = 1e-6;
            let mut xp = x;
            xp[k] += h;
            let mut xm = x;
            xm[k] -= h;
            let (rp, _) = o.residual_and_jacobian(&p.free, &p.contact, xp);
            let (rm, _) = o.residual_and_jacobian(&p.free, &p.contact, xm);
            for i in 0..3 {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                assert!((fd - j[i][k]).abs() < 1e-6 * (1.0 + fd.abs()), "J[{i}][{k}] = {} vs fd {fd}", j[i][k]);
            }
        }
    }
}
