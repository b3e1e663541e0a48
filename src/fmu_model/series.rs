//! The response between the instants: one [`Series`] per output with its interpolant, and a
//! solved configuration ([`Solution`]). Evaluation is O(1) per output (O(harmonics) for
//! `fourier`) and never allocates.
use super::Config;
use crate::periodic::PeriodFft;
use num_complex::Complex64 as C;

/// One output over the period with its interpolant.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Series {
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

impl Series {
    /// Value and first time derivative at sample j (next j1) and fraction s of the step h.
    #[inline]
    pub(super) fn eval(&self, j: usize, j1: usize, s: f64, h: f64, omega: f64, powers: &[C]) -> (f64, f64) {
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

    /// Trigonometric interpolant of real samples: c_0 = X̂_0/k, c_p = 2X̂_p/k, c_{k/2} = X̂_{k/2}/k,
    /// times `factor(p)` (i p ω for a derivative); negligible harmonics dropped.
    pub(super) fn trig(samples: &[f64], fft: &PeriodFft, factor: impl Fn(usize) -> C) -> Series {
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

/// A solved configuration: one series per output slot.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Solution {
    pub(super) config: Config,
    pub(super) period: f64,
    pub(super) h: f64,
    pub(super) omega: f64,
    pub(super) k: usize,
    pub(super) series: Vec<Series>,
    pub(super) pivots: i32,
    pub(super) residual: f64,
    pub(super) active_set: Vec<usize>,
    pub(super) warnings: Vec<String>,
    /// `continuation::amplitude` of the response (a jump's "before").
    pub(super) amplitude: f64,
    /// Jumps off a branch since initialisation, this solve's included.
    pub(super) jumps: u32,
}

impl Solution {
    pub(super) fn max_harmonic(&self) -> usize {
        self.series.iter().filter_map(|s| if let Series::Trig { p, .. } = s { p.last().copied() } else { None }).max().unwrap_or(0)
    }
}
