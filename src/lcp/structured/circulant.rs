//! Products with a block-circulant matrix by FFT: O(m²·k log k) instead of O(m²k²).
//! A z = IDFT(Ĝ_p ẑ_p) per harmonic, with Ĝ the DFT of the first block column.
use crate::lcp::{BlockCirculant, LcpMatrix};
use num_complex::Complex64 as C;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::sync::Arc;

/// A [`BlockCirculant`] with its block spectrum and FFT plans, for fast products.
pub struct CirculantOperator<'a> {
    a: &'a BlockCirculant,
    /// Ĝ_p row-major m×m for p = 0..=k/2.
    spectrum: Vec<C>,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
}

impl<'a> CirculantOperator<'a> {
    pub fn new(a: &'a BlockCirculant) -> Self {
        let (k, m) = (a.k(), a.m());
        let mut planner = RealFftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(k);
        let inverse = planner.plan_fft_inverse(k);
        let nh = k / 2 + 1;
        let mut spectrum = vec![C::ZERO; nh * m * m];
        let mut series = vec![0.0; k];
        let mut out = forward.make_output_vec();
        for i in 0..m {
            for j in 0..m {
                for (d, s) in series.iter_mut().enumerate() {
                    *s = a.blocks()[(d * m + i) * m + j];
                }
                forward.process(&mut series, &mut out).expect("plan length");
                for p in 0..nh {
                    spectrum[(p * m + i) * m + j] = out[p];
                }
            }
        }
        CirculantOperator { a, spectrum, forward, inverse }
    }
}

impl LcpMatrix for CirculantOperator<'_> {
    fn dim(&self) -> usize {
        self.a.dim()
    }
    fn entry(&self, i: usize, j: usize) -> f64 {
        self.a.entry(i, j)
    }
    fn column_into(&self, j: usize, out: &mut [f64]) {
        self.a.column_into(j, out)
    }
    fn mul_into(&self, z: &[f64], out: &mut [f64]) {
        let (k, m) = (self.a.k(), self.a.m());
        let nh = k / 2 + 1;
        let mut series = vec![0.0; k];
        let mut zh = vec![C::ZERO; nh * m];
        let mut buf = self.forward.make_output_vec();
        for b in 0..m {
            for (j, s) in series.iter_mut().enumerate() {
                *s = z[j * m + b];
            }
            self.forward.process(&mut series, &mut buf).expect("plan length");
            for p in 0..nh {
                zh[p * m + b] = buf[p];
            }
        }
        for a in 0..m {
            for p in 0..nh {
                buf[p] = (0..m).map(|b| self.spectrum[(p * m + a) * m + b] * zh[p * m + b]).sum();
            }
            buf[0].im = 0.0;
            if k % 2 == 0 {
                buf[k / 2].im = 0.0;
            }
            self.inverse.process(&mut buf, &mut series).expect("plan length");
            for j in 0..k {
                out[j * m + a] = series[j] / k as f64;
            }
        }
    }
    fn max_abs(&self) -> (f64, bool) {
        self.a.max_abs()
    }
}
