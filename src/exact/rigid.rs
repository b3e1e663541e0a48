//! Rigid stop with a perfectly plastic impact (restitution 0), src/formulation.md §6.3:
//!
//!   m x'' + c x' + k x = F cos Ωt − z,   x ≤ g0,  z ≥ 0,  z·(g0 − x) = 0,
//!
//! with an impact that stops the mass (v⁺ = 0, impulse m v⁻ ≥ 0). At rest on the stop the
//! contact force is z = F cos Ωt − k g0 (from the equation of motion with x = g0, v = a = 0);
//! the mass stays while z ≥ 0.
//!
//! Regimes (F ≥ 0):
//! - [`RigidRegime::NoContact`]: the linear response stays ≤ g0.
//! - [`RigidRegime::Sticking`] (−F < k g0 < F): the mass leaves at Ω t_d = arccos(k g0 / F), flies
//!   freely from (g0, 0) to its first return t_h, and sticks if Ω t_h ∈ [2π − Ω t_d, 2π + Ω t_d]
//!   (z(t_h) ≥ 0, and t_h before the next departure). No unknown: the departure is fixed.
//! - [`RigidRegime::Impacting`] (pure impacts, e.g. F ≤ k g0): the free flight from (g0, 0) at t0
//!   returns to g0 at exactly t0 + T, with x ≤ g0 in between and z(t0) ≤ 0 (the mass leaves at
//!   once). One scalar equation in t0, scanned on a grid and bisected. Its stability follows from
//!   the derivative μ = dt_next/dt0 of the impact map; [`RigidStopOrbit::solve`] returns a
//!   stable root (|μ| < 1).
//! - [`RigidRegime::Stuck`] (k g0 ≤ −F): the mass never leaves the stop.
use super::flow::{PhaseFlow, State, bisect, extrema};
use super::{ExactError, LinearOrbit, Oscillator, check_finite};

/// Which kind of periodic orbit was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RigidRegime {
    NoContact,
    Sticking,
    Impacting,
    Stuck,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    NoContact,
    Stuck,
    /// Departure t_d ∈ [0, T), impact t_h ∈ (t_d, t_d + T], incoming velocity v_h.
    Sticking {
        t_d: f64,
        t_h: f64,
        v_h: f64,
    },
    /// Impact (and immediate departure) at t0 ∈ [0, T), incoming velocity v_in, multiplier μ.
    Impacting {
        t0: f64,
        v_in: f64,
        multiplier: f64,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct RigidStopOrbit {
    osc: Oscillator,
    gap: f64,
    kind: Kind,
    free: PhaseFlow,
    linear: LinearOrbit,
    min_x: f64,
    max_x: f64,
}

impl RigidStopOrbit {
    /// Fails (naming the parameter) on invalid input (F < 0, k = 0, non-finite gap) and when no
    /// one-impact periodic orbit exists (the free flight would cross the stop, the impact would
    /// fall outside the sticking window with no pure-impact orbit either, or no stable one).
    pub fn solve(osc: &Oscillator, gap: f64) -> Result<Self, ExactError> {
        Self::solve_from(osc, gap, true)
    }

    /// The orbit with contact where one exists, even where the contact-free orbit is admissible
    /// too (the hysteresis of the impact oscillator: the stable impacting orbit up to its fold);
    /// otherwise as [`Self::solve`].
    pub fn with_contact(osc: &Oscillator, gap: f64) -> Result<Self, ExactError> {
        Self::solve_from(osc, gap, false)
    }

    fn solve_from(osc: &Oscillator, gap: f64, contact_free_first: bool) -> Result<Self, ExactError> {
        osc.validate()?;
        osc.require_stiffness()?;
        check_finite("gap", gap)?;
        if osc.force < 0.0 {
            return Err(ExactError::param("force", format!("is {}, must be ≥ 0 (shift the time origin by T/2 instead)", osc.force)));
        }
        let linear = LinearOrbit::solve(osc)?;
        let free = PhaseFlow::new(osc.mass, osc.damping, osc.stiffness, osc.force, osc.omega, 0.0)?;
        let mut orbit = RigidStopOrbit { osc: *osc, gap, kind: Kind::NoContact, free, linear, min_x: -linear.amplitude(), max_x: linear.amplitude() };
        if linear.amplitude() <= gap && contact_free_first {
            return Ok(orbit);
        }
        let (f, k, w) = (osc.force, osc.stiffness, osc.omega);
        let period = osc.period();
        if k * gap <= -f {
            orbit.kind = Kind::Stuck;
            orbit.min_x = gap;
            orbit.max_x = gap;
            return Ok(orbit);
        }
        let mut sticking_failure = None;
        if k * gap < f {
            let t_d = (k * gap / f).acos() / w;
            match orbit.first_return(t_d) {
                Some((t_h, v_h)) => {
                    let in_window = (w * t_h).cos() >= k * gap / f - 1e-12 && t_h <= t_d + period * (1.0 + 1e-12);
                    if in_window {
                        orbit.kind = Kind::Sticking { t_d, t_h, v_h };
                        let (lo, _) = extrema(|t| orbit.free.propagate(t_d, [gap, 0.0], t), t_d, t_h, 2048);
                        orbit.min_x = lo.min(gap);
                        orbit.max_x = gap;
                        return Ok(orbit);
                    }
                    sticking_failure = Some(format!(
                        "the free flight from the departure Ωt_d = {:.6} returns at Ωt_h = {:.6}, outside the sticking window [{:.6}, {:.6}]",
                        w * t_d,
                        w * t_h,
                        2.0 * std::f64::consts::PI - w * t_d,
                        2.0 * std::f64::consts::PI + w * t_d
                    ));
                }
                None => {
                    sticking_failure = Some(format!("the free flight from the departure Ωt_d = {:.6} does not return to the stop within two periods", w * t_d))
                }
            }
        }
        let cands = orbit.impacting_candidates();
        let stable: Vec<_> = cands.iter().filter(|c| c.2.abs() < 1.0).collect();
        match stable.first() {
            Some(&&(t0, v_in, multiplier)) => {
                orbit.kind = Kind::Impacting { t0, v_in, multiplier };
                let (lo, _) = extrema(|t| orbit.free.propagate(t0, [gap, 0.0], t), t0, t0 + period, 2048);
                orbit.min_x = lo.min(gap);
                orbit.max_x = gap;
                Ok(orbit)
            }
            None => {
                let mut msg = format!("gap: is {gap}; no stable one-impact periodic orbit (not a one-impact orbit)");
                if let Some(s) = sticking_failure {
                    msg += &format!("; sticking: {s}");
                }
                if cands.is_empty() {
                    msg += "; pure impacts: no free flight from (g0, 0) returns after exactly one period without crossing the stop";
                } else {
                    let list: Vec<String> = cands.iter().map(|c| format!("t0 = {:.6} (μ = {:.3})", c.0, c.2)).collect();
                    msg += &format!("; pure impacts: only unstable orbits {}", list.join(", "));
                }
                Err(ExactError::NoSolution(msg))
            }
        }
    }

    /// Every one-impact orbit (pure impacts, unstable ones too, where [`Self::solve`] keeps the
    /// first stable one): its impact instant t0 ∈ [0, T) and impact-map multiplier μ.
    pub fn pure_impacts(osc: &Oscillator, gap: f64) -> Result<Vec<(f64, f64)>, ExactError> {
        osc.validate()?;
        osc.require_stiffness()?;
        check_finite("gap", gap)?;
        let linear = LinearOrbit::solve(osc)?;
        let free = PhaseFlow::new(osc.mass, osc.damping, osc.stiffness, osc.force, osc.omega, 0.0)?;
        let orbit = RigidStopOrbit { osc: *osc, gap, kind: Kind::NoContact, free, linear, min_x: 0.0, max_x: 0.0 };
        Ok(orbit.impacting_candidates().into_iter().map(|(t0, _, mu)| (t0, mu)).collect())
    }

    /// First return to the stop of the free flight from (g0, 0) at `t_d`, within two periods:
    /// (t_h, v(t_h⁻)).
    fn first_return(&self, t_d: f64) -> Option<(f64, f64)> {
        let g0 = self.gap;
        let period = self.osc.period();
        let n = 4000;
        let dt = 2.0 * period / n as f64;
        let g = |t: f64| self.free.propagate(t_d, [g0, 0.0], t)[0] - g0;
        let mut ta = t_d + dt;
        let mut ga = g(ta);
        for _ in 1..n {
            let tb = ta + dt;
            let gb = g(tb);
            if ga < 0.0 && gb >= 0.0 {
                let t_h = bisect(g, ta, tb);
                let v = self.free.propagate(t_d, [g0, 0.0], t_h)[1];
                return Some((t_h, v));
            }
            ta = tb;
            ga = gb;
        }
        None
    }

    /// Roots t0 ∈ [0, T) of x(t0 + T; (g0, 0) at t0) = g0 that are one-impact orbits:
    /// (t0, v_in, multiplier μ).
    fn impacting_candidates(&self) -> Vec<(f64, f64, f64)> {
        let (g0, period) = (self.gap, self.osc.period());
        let o = &self.osc;
        let tol = 1e-9 * self.linear.amplitude().max(g0.abs());
        let h = |t0: f64| self.free.propagate(t0, [g0, 0.0], t0 + period)[0] - g0;
        let n = 1440;
        let mut out = Vec::new();
        let mut prev = (0.0, h(0.0));
        for i in 1..=n {
            let t = period * i as f64 / n as f64;
            let cur = (t, h(t));
            if (prev.1 <= 0.0) != (cur.1 <= 0.0) || prev.1 == 0.0 {
                let t0 = bisect(h, prev.0, cur.0).rem_euclid(period);
                let z0 = o.force * (o.omega * t0).cos() - o.stiffness * g0;
                let s_in = self.free.propagate(t0, [g0, 0.0], t0 + period);
                let (_, hi) = extrema(|t| self.free.propagate(t0, [g0, 0.0], t), t0 + period * 1e-4, t0 + period, 2048);
                let leaves = z0 <= 1e-12 * (o.force.abs() + (o.stiffness * g0).abs());
                if leaves && s_in[1] >= 0.0 && hi <= g0 + tol && !out.iter().any(|c: &(f64, f64, f64)| (c.0 - t0).abs() < 1e-9 * period) {
                    // Impact map t0 → t_next: x(t_next; t0) = g0, dx/dt0 = −[Φ(T) (0, a0)]_x.
                    let a0 = z0.min(0.0) / o.mass;
                    let phi = self.free.phi(period);
                    let mu = if s_in[1] > 0.0 { phi[0][1] * a0 / s_in[1] } else { f64::INFINITY };
                    out.push((t0, s_in[1], mu));
                }
            }
            prev = cur;
        }
        out
    }

    /// (x, v, contact force) at any t (periodic). The force is the stick-phase force
    /// F cos Ωt − k g0; the impact is a Dirac (see [`Self::impact_time`],
    /// [`Self::impact_impulse`]), and at the impact instant the state after it is returned.
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let period = self.osc.period();
        let (f, k, w, g0) = (self.osc.force, self.osc.stiffness, self.osc.omega, self.gap);
        match self.kind {
            Kind::NoContact => {
                let (x, v, _) = self.linear.eval(t);
                (x, v, 0.0)
            }
            Kind::Stuck => (g0, 0.0, f * (w * t).cos() - k * g0),
            Kind::Sticking { t_d, t_h, .. } => {
                let tau = t_d + (t - t_d).rem_euclid(period);
                if tau < t_h {
                    let s: State = self.free.propagate(t_d, [g0, 0.0], tau);
                    (s[0], s[1], 0.0)
                } else {
                    (g0, 0.0, (f * (w * tau).cos() - k * g0).max(0.0))
                }
            }
            Kind::Impacting { t0, .. } => {
                let tau = t0 + (t - t0).rem_euclid(period);
                let s = self.free.propagate(t0, [g0, 0.0], tau);
                (s[0], s[1], 0.0)
            }
        }
    }

    pub fn regime(&self) -> RigidRegime {
        match self.kind {
            Kind::NoContact => RigidRegime::NoContact,
            Kind::Stuck => RigidRegime::Stuck,
            Kind::Sticking { .. } => RigidRegime::Sticking,
            Kind::Impacting { .. } => RigidRegime::Impacting,
        }
    }
    pub fn has_sticking(&self) -> bool {
        matches!(self.kind, Kind::Sticking { .. } | Kind::Stuck)
    }
    /// Impact instant in [0, T).
    pub fn impact_time(&self) -> Option<f64> {
        let period = self.osc.period();
        match self.kind {
            Kind::Sticking { t_h, .. } => Some(t_h.rem_euclid(period)),
            Kind::Impacting { t0, .. } => Some(t0),
            _ => None,
        }
    }
    /// Incoming velocity v(t_h⁻) ≥ 0.
    pub fn impact_velocity(&self) -> Option<f64> {
        match self.kind {
            Kind::Sticking { v_h, .. } => Some(v_h),
            Kind::Impacting { v_in, .. } => Some(v_in),
            _ => None,
        }
    }
    /// m v(t_h⁻) (0 without impact).
    pub fn impact_impulse(&self) -> f64 {
        self.impact_velocity().map_or(0.0, |v| self.osc.mass * v)
    }
    /// Departure instant Ω t_d = arccos(k g0 / F), for the sticking regime.
    pub fn departure_time(&self) -> Option<f64> {
        match self.kind {
            Kind::Sticking { t_d, .. } => Some(t_d),
            _ => None,
        }
    }
    /// Impact-map multiplier μ of the pure-impact orbit (|μ| < 1: stable).
    pub fn multiplier(&self) -> Option<f64> {
        match self.kind {
            Kind::Impacting { multiplier, .. } => Some(multiplier),
            _ => None,
        }
    }
    /// Impulse per period = m v(t_h⁻) + ∫_{stick} (F cos Ωt − k g0) dt (src/formulation.md §6.3), exact.
    pub fn impulse_per_period(&self) -> f64 {
        let (f, k, w, g0) = (self.osc.force, self.osc.stiffness, self.osc.omega, self.gap);
        let period = self.osc.period();
        match self.kind {
            Kind::NoContact => 0.0,
            Kind::Stuck => -k * g0 * period,
            Kind::Impacting { .. } => self.impact_impulse(),
            Kind::Sticking { t_d, t_h, .. } => {
                let te = t_d + period;
                self.impact_impulse() + f / w * ((w * te).sin() - (w * t_h).sin()) - k * g0 * (te - t_h)
            }
        }
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
    pub fn period(&self) -> f64 {
        self.osc.period()
    }
    pub fn oscillator(&self) -> &Oscillator {
        &self.osc
    }
}
