//! Real FFT plans for one period of k samples, planned once and reused (rustfft's planner).
use num_complex::Complex64 as C;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::sync::Arc;

/// Forward (r2c) and inverse (c2r) plans of length k, with scratch.
#[derive(Clone)]
pub struct PeriodFft {
    k: usize,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
}

impl std::fmt::Debug for PeriodFft {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PeriodFft(k={})", self.k)
    }
}

impl PeriodFft {
    pub fn new(k: usize) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        PeriodFft { k, forward: planner.plan_fft_forward(k), inverse: planner.plan_fft_inverse(k) }
    }
    pub fn k(&self) -> usize {
        self.k
    }
    /// X̂_p = Σ_j x_j e^{−2πi jp/k}, p = 0..=k/2.
    pub fn forward(&self, samples: &[f64]) -> Vec<C> {
        let mut input = samples.to_vec();
        let mut out = self.forward.make_output_vec();
        self.forward.process(&mut input, &mut out).expect("r2c lengths match the plan");
        out
    }
    /// x_j = (1/k) Σ_p X̂_p e^{+2πi jp/k} over the Hermitian extension of p = 0..=k/2.
    /// The imaginary parts of the DC and Nyquist bins are dropped (they are round-off for real data).
    pub fn inverse(&self, spectrum: &[C]) -> Vec<f64> {
        let mut input = spectrum.to_vec();
        input[0].im = 0.0;
        if self.k % 2 == 0 {
            input[self.k / 2].im = 0.0;
        }
        let mut out = self.inverse.make_output_vec();
        self.inverse.process(&mut input, &mut out).expect("c2r lengths match the plan");
        let scale = 1.0 / self.k as f64;
        out.iter_mut().for_each(|v| *v *= scale);
        out
    }
}
