//! Persistent contact with a moving obstacle (src/formulation.md §6.4): the obstacle clearance
//! gap(t) = g0 + Σ a_h cos(hΩt + φ_h) keeps a rigid contact closed on the 1-DOF oscillator.
//!
//! Contact direction s ∈ {+1, −1} (s·x ≤ gap(t)); closed contact: x(t) = s·gap(t). The
//! compressive force z ≥ 0 pushes the mass by −s·z, so from m x'' + c x' + k x = F cos Ωt − s z:
//!
//!   z(t) = s·[F cos Ωt − (m x'' + c x' + k x)].
//!
//! The orbit is physical only if z(t) ≥ 0 for all t ([`PersistentContact::is_persistent`]).
use super::flow::{bisect, extrema};
use super::{ExactError, Oscillator, check_finite};
use crate::model::Harmonic;

#[derive(Clone, Debug, PartialEq)]
pub struct PersistentContact {
    osc: Oscillator,
    direction: f64,
    gap: f64,
    motion: Vec<Harmonic>,
    min_force: f64,
    min_force_time: f64,
}

/// n-th time derivative of a·cos(wt + φ) = a wⁿ cos(wt + φ + nπ/2).
fn dn(h: &Harmonic, omega: f64, t: f64, n: u32) -> f64 {
    let w = h.harmonic as f64 * omega;
    if n > 0 && h.harmonic == 0 {
        return 0.0;
    }
    h.amplitude * w.powi(n as i32) * (w * t + h.phase + n as f64 * std::f64::consts::FRAC_PI_2).cos()
}

impl PersistentContact {
    /// `direction` ±1, `gap` the static clearance g0, `motion` the obstacle harmonics.
    pub fn solve(osc: &Oscillator, direction: f64, gap: f64, motion: &[Harmonic]) -> Result<Self, ExactError> {
        osc.validate()?;
        if direction != 1.0 && direction != -1.0 {
            return Err(ExactError::param("direction", format!("is {direction}, must be +1 or -1")));
        }
        check_finite("gap", gap)?;
        for (i, h) in motion.iter().enumerate() {
            check_finite(&format!("motion[{i}].amplitude"), h.amplitude)?;
            check_finite(&format!("motion[{i}].phase"), h.phase)?;
        }
        let mut p = PersistentContact { osc: *osc, direction, gap, motion: motion.to_vec(), min_force: 0.0, min_force_time: 0.0 };
        // Minimum of z: samples, then bisection on the sign changes of z'.
        let period = osc.period();
        let hmax = motion.iter().map(|h| h.harmonic).max().unwrap_or(1).max(1) as usize;
        let n = 256 * hmax;
        let mut best = (f64::INFINITY, 0.0);
        let mut prev: Option<(f64, f64)> = None;
        for i in 0..=n {
            let t = period * i as f64 / n as f64;
            let z = p.force_derivative(t, 0);
            if z < best.0 {
                best = (z, t);
            }
            let dz = p.force_derivative(t, 1);
            if let Some((tp, dzp)) = prev
                && dzp < 0.0
                && dz >= 0.0
            {
                let r = bisect(|t| p.force_derivative(t, 1), tp, t);
                let zr = p.force_derivative(r, 0);
                if zr < best.0 {
                    best = (zr, r);
                }
            }
            prev = Some((t, dz));
        }
        p.min_force = best.0;
        p.min_force_time = best.1.rem_euclid(period);
        Ok(p)
    }

    /// n-th derivative of x(t) = s·gap(t).
    fn x_derivative(&self, t: f64, n: u32) -> f64 {
        let w = self.osc.omega;
        let g = if n == 0 { self.gap } else { 0.0 } + self.motion.iter().map(|h| dn(h, w, t, n)).sum::<f64>();
        self.direction * g
    }

    /// n-th derivative of z(t) = s·[F cos Ωt − (m x'' + c x' + k x)].
    fn force_derivative(&self, t: f64, n: u32) -> f64 {
        let o = &self.osc;
        let f = Harmonic { amplitude: o.force, harmonic: 1, phase: 0.0 };
        let lhs = o.mass * self.x_derivative(t, n + 2) + o.damping * self.x_derivative(t, n + 1) + o.stiffness * self.x_derivative(t, n);
        self.direction * (dn(&f, o.omega, t, n) - lhs)
    }

    /// (x, v, force) at t.
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        (self.x_derivative(t, 0), self.x_derivative(t, 1), self.force_derivative(t, 0))
    }
    pub fn acceleration(&self, t: f64) -> f64 {
        self.x_derivative(t, 2)
    }
    /// True when the contact force is ≥ 0 over the whole period.
    pub fn is_persistent(&self) -> bool {
        self.min_force >= 0.0
    }
    /// min over the period of the contact force, and where it occurs (in [0, T)).
    pub fn min_force(&self) -> (f64, f64) {
        (self.min_force, self.min_force_time)
    }
    /// ∫ over one period of the force = −k T · (g0 + Σ_{h = 0} a_h cos φ_h), exact.
    pub fn impulse_per_period(&self) -> f64 {
        let mean = self.gap + self.motion.iter().filter(|h| h.harmonic == 0).map(|h| h.amplitude * h.phase.cos()).sum::<f64>();
        -self.osc.stiffness * self.osc.period() * mean
    }
    pub fn peak_to_peak(&self) -> f64 {
        let hmax = self.motion.iter().map(|h| h.harmonic).max().unwrap_or(1).max(1) as usize;
        let (lo, hi) = extrema(|t| [self.x_derivative(t, 0), self.x_derivative(t, 1)], 0.0, self.osc.period(), 256 * hmax);
        hi - lo
    }
    pub fn period(&self) -> f64 {
        self.osc.period()
    }
}
