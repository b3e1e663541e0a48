//! The response between the instants t_j, from its samples: one [`Series`] per quantity with
//! its interpolant, consistent with the scheme. Used by the front ends (the FMU's outputs at
//! communication points, the C API's `pc_result_state_at` when there is no polished orbit).
//!
//! - `fourier`: the trigonometric interpolant of the samples (exact for the collocation);
//! - the other schemes: displacement by cubic Hermite through (x_j, v_j) with the scheme's own
//!   velocity v_j, velocity as its derivative;
//! - acceleration, contact force and gap: piecewise linear.
//!
//! Evaluation is O(1) per series (O(harmonics) for `fourier`) and never allocates.
use crate::periodic::PeriodFft;
use num_complex::Complex64 as C;

/// One quantity over the period with its interpolant.
#[derive(Clone, Debug, PartialEq)]
pub enum Series {
    /// Cubic Hermite through (x_j, v_j); `level` 0 gives H, 1 gives H'.
    Hermite {
        x: Vec<f64>,
        v: Vec<f64>,
        level: u8,
    },
    Linear(Vec<f64>),
    /// Re Σ c e^{i p ω τ} over the harmonics p kept.
    Trig {
        p: Vec<usize>,
        c: Vec<C>,
    },
    Constant(f64),
}

/// Where τ falls on the grid of `k` instants of step `h`: (j, j+1 mod k, fraction s).
#[inline]
pub fn locate(tau: f64, h: f64, k: usize) -> (usize, usize, f64) {
    let u = tau / h;
    let j = (u.floor().max(0.0) as usize).min(k - 1);
    (j, if j + 1 == k { 0 } else { j + 1 }, u - j as f64)
}

/// e^{i p ω τ} for p = 0..powers.len(), by recurrence restarted from sin/cos every 32
/// harmonics to bound round-off.
pub fn fill_powers(powers: &mut [C], omega: f64, tau: f64) {
    let step = C::from_polar(1.0, omega * tau);
    for p in 0..powers.len() {
        powers[p] = match p {
            0 => C::ONE,
            p if p % 32 == 0 => C::from_polar(1.0, p as f64 * omega * tau),
            p => powers[p - 1] * step,
        };
    }
}

impl Series {
    /// Displacement (`level` 0) or velocity (1) from the samples x_j and v_j: trigonometric with
    /// `fft` (fourier), cubic Hermite otherwise.
    pub fn motion(x: &[f64], v: &[f64], level: u8, fft: Option<&PeriodFft>, omega: f64) -> Series {
        match fft {
            Some(fft) => Series::trig(x, fft, |p| if level == 0 { C::ONE } else { C::new(0.0, p as f64 * omega) }),
            None => Series::Hermite { x: x.to_vec(), v: v.to_vec(), level },
        }
    }

    /// Value and first time derivative at sample j (next j1) and fraction s of the step h;
    /// `powers` from [`fill_powers`] (trigonometric series only).
    #[inline]
    pub fn eval(&self, j: usize, j1: usize, s: f64, h: f64, omega: f64, powers: &[C]) -> (f64, f64) {
        match self {
            Series::Hermite { x, v, level } => {
                let (x0, x1, v0, v1) = (x[j], x[j1], v[j] * h, v[j1] * h);
                let (s2, s3) = (s * s, s * s * s);
                let d1 = ((6.0 * s2 - 6.0 * s) * (x0 - x1) + (3.0 * s2 - 4.0 * s + 1.0) * v0 + (3.0 * s2 - 2.0 * s) * v1) / h;
                if *level == 0 {
                    let val = (2.0 * s3 - 3.0 * s2 + 1.0) * x0 + (s3 - 2.0 * s2 + s) * v0 + (-2.0 * s3 + 3.0 * s2) * x1 + (s3 - s2) * v1;
                    (val, d1)
                } else {
                    let d2 = ((12.0 * s - 6.0) * (x0 - x1) + (6.0 * s - 4.0) * v0 + (6.0 * s - 2.0) * v1) / (h * h);
                    (d1, d2)
                }
            }
            Series::Linear(y) => ((1.0 - s) * y[j] + s * y[j1], (y[j1] - y[j]) / h),
            Series::Trig { p, c } => {
                let (mut val, mut der) = (0.0, 0.0);
                for (&p, c) in p.iter().zip(c) {
                    let z = c * powers[p];
                    val += z.re;
                    der -= p as f64 * omega * z.im;
                }
                (val, der)
            }
            Series::Constant(v) => (*v, 0.0),
        }
    }

    /// The highest harmonic of a trigonometric series (0 otherwise).
    pub fn max_harmonic(&self) -> usize {
        if let Series::Trig { p, .. } = self { p.last().copied().unwrap_or(0) } else { 0 }
    }

    /// Value and derivative at any time τ (taken modulo the period k·h), allocating the powers:
    /// for one-off evaluations (the C API), not for a hot loop.
    pub fn at(&self, tau: f64, h: f64, k: usize, omega: f64) -> (f64, f64) {
        let tau = tau.rem_euclid(h * k as f64);
        let (j, j1, s) = locate(tau, h, k);
        let mut powers = vec![C::ZERO; self.max_harmonic() + 1];
        fill_powers(&mut powers, omega, tau);
        self.eval(j, j1, s, h, omega, &powers)
    }

    /// Trigonometric interpolant of real samples: c_0 = X̂_0/k, c_p = 2X̂_p/k, c_{k/2} = X̂_{k/2}/k,
    /// times `factor(p)` (i p ω for a derivative); negligible harmonics dropped.
    pub fn trig(samples: &[f64], fft: &PeriodFft, factor: impl Fn(usize) -> C) -> Series {
        let k = samples.len();
        let spec = fft.forward(samples);
        let coef: Vec<C> = spec
            .iter()
            .enumerate()
            .map(|(p, x)| {
                let w = if p == 0 || (k.is_multiple_of(2) && p == k / 2) { 1.0 } else { 2.0 };
                let mut c = x * w / k as f64;
                if p == 0 || (k.is_multiple_of(2) && p == k / 2) {
                    c.im = 0.0;
                }
                c * factor(p)
            })
            .collect();
        let big = coef.iter().map(|c| c.norm()).fold(0.0, f64::max);
        let keep: Vec<usize> = (0..coef.len()).filter(|&p| coef[p].norm() > 1e-15 * big).collect();
        Series::Trig { c: keep.iter().map(|&p| coef[p]).collect(), p: keep }
    }
}
