//! Closed-form flow of one linear phase  m x'' + c x' + κ x = F cos Ωt + b  (src/formulation.md §6.2).
//!
//! The state s = (x, v) is split into the particular periodic solution
//! P(t) = (Re[X e^{iΩt}] + b/κ, Re[iΩ X e^{iΩt}]), X = F / (κ − Ω² m + iΩc),
//! and the homogeneous part y = s − P(t), which evolves with the 2×2 matrix exponential
//! Φ(τ) = e^{Aτ}, A = [[0, 1], [−κ/m, −c/m]].
//!
//! With α = c/(2m), ω0² = κ/m and δ = α² − ω0², (A + αI)² = δ I, hence
//! e^{Aτ} = e^{−ατ} [ C(τ) I + S(τ) (A + αI) ] with
//! C = cosh(√δ τ), S = sinh(√δ τ)/√δ (over-damped), C = cos(√−δ τ), S = sin(√−δ τ)/√−δ
//! (under-damped) and C = 1, S = τ (critically damped). One formula covers the three cases.
use super::ExactError;
use num_complex::Complex64 as C64;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PhaseFlow {
    pub m: f64,
    pub c: f64,
    pub kappa: f64,
    pub f: f64,
    pub omega: f64,
    pub b: f64,
    /// Complex amplitude X of the particular solution.
    pub amp: C64,
    alpha: f64,
    w0sq: f64,
    delta: f64,
}

pub(crate) type State = [f64; 2];
pub(crate) type Mat2 = [[f64; 2]; 2];

impl PhaseFlow {
    /// `m > 0`, `c ≥ 0`, `κ ≥ 0` (κ > 0 when b ≠ 0), Ω > 0 are checked by the callers.
    pub fn new(m: f64, c: f64, kappa: f64, f: f64, omega: f64, b: f64) -> Result<Self, ExactError> {
        let den = C64::new(kappa - omega * omega * m, omega * c);
        let scale = kappa.abs() + omega * omega * m + omega * c;
        if den.norm() <= 1e-14 * scale {
            return Err(ExactError::NoSolution(format!(
                "undamped resonance: stiffness {kappa} = Ω² m = {} with damping {c}; the periodic particular solution does not exist",
                omega * omega * m
            )));
        }
        if b != 0.0 && kappa <= 0.0 {
            return Err(ExactError::NoSolution(format!("a constant load {b} needs a stiffness > 0, got {kappa}")));
        }
        let alpha = c / (2.0 * m);
        let w0sq = kappa / m;
        Ok(PhaseFlow { m, c, kappa, f, omega, b, amp: f / den, alpha, w0sq, delta: alpha * alpha - w0sq })
    }

    fn static_offset(&self) -> f64 {
        if self.b == 0.0 { 0.0 } else { self.b / self.kappa }
    }

    /// Particular periodic solution (x_p, v_p) at t.
    pub fn particular(&self, t: f64) -> State {
        let e = C64::from_polar(1.0, self.omega * t);
        let z = self.amp * e;
        [z.re + self.static_offset(), -self.omega * z.im]
    }

    /// e^{Aτ}.
    pub fn phi(&self, tau: f64) -> Mat2 {
        let (a, d) = (self.alpha, self.delta);
        // e^{−ατ}·C and e^{−ατ}·S without overflow for long over-damped spans.
        let (ec, es) = if d > 0.0 {
            let r = d.sqrt();
            if r * tau.abs() < 1.0 {
                let e = (-a * tau).exp();
                (e * (r * tau).cosh(), e * (r * tau).sinh() / r)
            } else {
                let p = ((r - a) * tau).exp();
                let q = (-(r + a) * tau).exp();
                (0.5 * (p + q), 0.5 * (p - q) / r)
            }
        } else if d < 0.0 {
            let r = (-d).sqrt();
            let e = (-a * tau).exp();
            (e * (r * tau).cos(), e * (r * tau).sin() / r)
        } else {
            let e = (-a * tau).exp();
            (e, e * tau)
        };
        [[ec + es * a, es], [-es * self.w0sq, ec - es * a]]
    }

    /// State at `t` of the trajectory through `s0` at `t0`.
    pub fn propagate(&self, t0: f64, s0: State, t: f64) -> State {
        let p0 = self.particular(t0);
        let p = self.particular(t);
        let y = [s0[0] - p0[0], s0[1] - p0[1]];
        let f = self.phi(t - t0);
        [p[0] + f[0][0] * y[0] + f[0][1] * y[1], p[1] + f[1][0] * y[0] + f[1][1] * y[1]]
    }

    /// Acceleration from the equation of motion.
    pub fn accel(&self, t: f64, s: State) -> f64 {
        (self.f * (self.omega * t).cos() + self.b - self.c * s[1] - self.kappa * s[0]) / self.m
    }

    /// ∫_{t0}^{t} x dt along the trajectory through `s0` at `t0` (κ > 0).
    pub fn integral_x(&self, t0: f64, s0: State, t: f64) -> f64 {
        let p0 = self.particular(t0);
        let y = [s0[0] - p0[0], s0[1] - p0[1]];
        let f = self.phi(t - t0);
        let u = [f[0][0] * y[0] + f[0][1] * y[1] - y[0], f[1][0] * y[0] + f[1][1] * y[1] - y[1]];
        // y'' + 2α y' + ω0² y = 0 integrated: ∫y = −([y'] + 2α [y]) / ω0².
        let hom = -(u[1] + 2.0 * self.alpha * u[0]) / self.w0sq;
        let iw = C64::new(0.0, self.omega);
        let part = (self.amp * (C64::from_polar(1.0, self.omega * t) - C64::from_polar(1.0, self.omega * t0)) / iw).re + self.static_offset() * (t - t0);
        hom + part
    }
}

/// Sign-change root of `g` in [a, b] (g(a), g(b) of opposite signs or zero) by bisection to
/// machine precision.
pub(crate) fn bisect(g: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let mut ga = g(a);
    if ga == 0.0 {
        return a;
    }
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let gm = g(m);
        if gm == 0.0 {
            return m;
        }
        if (gm > 0.0) == (ga > 0.0) {
            a = m;
            ga = gm;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Minimum and maximum of x over [a, b] for a smooth trajectory `xv(t) = (x, v)`: samples,
/// then bisection on the sign changes of v (the interior extrema).
pub(crate) fn extrema(xv: impl Fn(f64) -> State, a: f64, b: f64, samples: usize) -> (f64, f64) {
    let n = samples.max(2);
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut prev: Option<(f64, State)> = None;
    for i in 0..=n {
        let t = a + (b - a) * i as f64 / n as f64;
        let s = xv(t);
        lo = lo.min(s[0]);
        hi = hi.max(s[0]);
        if let Some((tp, sp)) = prev
            && ((sp[1] > 0.0 && s[1] < 0.0) || (sp[1] < 0.0 && s[1] > 0.0))
        {
            let r = bisect(|t| xv(t)[1], tp, t);
            let x = xv(r)[0];
            lo = lo.min(x);
            hi = hi.max(x);
        }
        prev = Some((t, s));
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form flow satisfies its ODE (finite-difference residual) in all three damping
    /// regimes, and the integral agrees with Simpson's rule.
    #[test]
    fn flow_satisfies_ode_all_regimes() {
        for &(m, c, k) in &[(1.0, 0.05, 1.0), (1.0, 2.0, 1.0), (2.0, 7.0, 1.5), (1.0, 0.0, 4.0)] {
            let fl = PhaseFlow::new(m, c, k, 0.7, 1.3, 0.4).unwrap();
            let s0 = [0.3, -1.1];
            let (t0, h) = (0.2, 1e-4);
            for i in 1..40 {
                let t = t0 + 0.17 * i as f64;
                let xp = fl.propagate(t0, s0, t + h)[0];
                let x = fl.propagate(t0, s0, t);
                let xm = fl.propagate(t0, s0, t - h)[0];
                let acc = (xp - 2.0 * x[0] + xm) / (h * h);
                let vel = (xp - xm) / (2.0 * h);
                assert!((vel - x[1]).abs() < 1e-6, "v {vel} vs {}", x[1]);
                assert!((acc - fl.accel(t, x)).abs() < 1e-5, "a {acc} vs {}", fl.accel(t, x));
            }
            let n = 2000;
            let (a, b) = (t0, t0 + 3.7);
            let mut s = 0.0;
            for i in 0..=n {
                let t = a + (b - a) * i as f64 / n as f64;
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                s += w * fl.propagate(t0, s0, t)[0];
            }
            s *= (b - a) / n as f64 / 3.0;
            assert!((s - fl.integral_x(t0, s0, b)).abs() < 1e-10, "{s} vs {}", fl.integral_x(t0, s0, b));
        }
    }
}
