//! Products with a block-circulant matrix by FFT: O(m²·k log k) instead of O(m²k²).
//! A z = IDFT(Ĝ_p ẑ_p) per harmonic, with Ĝ the DFT of the first block column.
//!
//! The operator owns its FFT plans ([`PeriodFft`], shared with the engine through the one planner)
//! and the work buffers of a product, so `mul_into` allocates nothing. The buffers sit behind a
//! mutex because [`LcpMatrix`] takes `&self` and must be `Sync`: the solvers call it from one
//! thread, so the lock is uncontended; a concurrent caller that finds it taken gets buffers of
//! its own for that product rather than waiting.
use std::sync::Mutex;

use crate::lcp::{BlockCirculant, LcpMatrix};
use crate::linalg::fft::PeriodFft;
use num_complex::Complex64 as C;

/// A [`BlockCirculant`] with its block spectrum and FFT plans, for fast products.
pub struct CirculantOperator<'a> {
    a: &'a BlockCirculant,
    /// Ĝ_p row-major m×m for p = 0..=k/2 (the matrix's own when it came with one).
    spectrum: std::borrow::Cow<'a, [C]>,
    fft: PeriodFft,
    work: Mutex<Work>,
}

/// The buffers of one product.
struct Work {
    /// One real series of length k.
    series: Vec<f64>,
    /// ẑ_p for p = 0..=k/2, m values each.
    zh: Vec<C>,
    /// One harmonic's Ĝ_p ẑ_p (m values).
    gz: Vec<C>,
    /// One spectrum of k/2 + 1 bins.
    buf: Vec<C>,
    scratch: Vec<C>,
}

impl Work {
    fn new(fft: &PeriodFft, m: usize) -> Self {
        Work {
            series: vec![0.0; fft.k()],
            zh: vec![C::ZERO; fft.bins() * m],
            gz: vec![C::ZERO; m],
            buf: vec![C::ZERO; fft.bins()],
            scratch: fft.make_scratch(),
        }
    }
}

impl<'a> CirculantOperator<'a> {
    /// Plans (or takes from the planner's cache) the FFTs of length k and transforms the blocks.
    pub fn new(a: &'a BlockCirculant) -> Self {
        Self::with_fft(a, &PeriodFft::new(a.k()))
    }

    /// The same with plans the caller already has. Panics if `fft.k() != a.k()`.
    pub fn with_fft(a: &'a BlockCirculant, fft: &PeriodFft) -> Self {
        let (k, m) = (a.k(), a.m());
        assert_eq!(fft.k(), k, "CirculantOperator: FFT of length {} for k = {k}", fft.k());
        let fft = fft.clone();
        let nh = fft.bins();
        let mut work = Work::new(&fft, m);
        if let Some(spectrum) = a.spectrum() {
            return CirculantOperator { a, spectrum: spectrum.into(), fft, work: Mutex::new(work) };
        }
        let mut spectrum = vec![C::ZERO; nh * m * m];
        for i in 0..m {
            for j in 0..m {
                for (d, s) in work.series.iter_mut().enumerate() {
                    *s = a.blocks()[(d * m + i) * m + j];
                }
                fft.forward_with_scratch(&mut work.series, &mut work.buf, &mut work.scratch);
                for p in 0..nh {
                    spectrum[(p * m + i) * m + j] = work.buf[p];
                }
            }
        }
        CirculantOperator { a, spectrum: spectrum.into(), fft, work: Mutex::new(work) }
    }

    /// out = A z with the buffers `w`.
    fn product(&self, z: &[f64], out: &mut [f64], w: &mut Work) {
        let (k, m) = (self.a.k(), self.a.m());
        if m == 0 {
            return;
        }
        let nh = self.fft.bins();
        let Work { series, zh, gz, buf, scratch } = w;
        for b in 0..m {
            for (j, s) in series.iter_mut().enumerate() {
                *s = z[j * m + b];
            }
            self.fft.forward_with_scratch(series, buf, scratch);
            for p in 0..nh {
                zh[p * m + b] = buf[p];
            }
        }
        // Ĝ_p ẑ_p harmonic by harmonic, each block read once in storage order (row by row, m strided
        // passes over the whole spectrum: the product was 7 % of the real blade's sweep, issue 23).
        // The sums run over b in the order of `Iterator::sum`, so the products are unchanged.
        for (p, (g, zp)) in self.spectrum.chunks_exact(m * m).zip(zh.chunks_exact_mut(m)).take(nh).enumerate() {
            // The DC and Nyquist blocks as if their imaginary parts were zeroed (`real_ends`).
            let real = self.a.real_ends() && (p == 0 || 2 * p == k);
            let read = |x: C| if real { C::new(x.re, 0.0) } else { x };
            for (s, row) in gz.iter_mut().zip(g.chunks_exact(m)) {
                *s = row.iter().zip(zp.iter()).fold(C::ZERO, |acc, (&x, &y)| acc + read(x) * y);
            }
            zp.copy_from_slice(gz);
        }
        for a in 0..m {
            for p in 0..nh {
                buf[p] = zh[p * m + a];
            }
            self.fft.inverse_unscaled_with_scratch(buf, series, scratch);
            for j in 0..k {
                out[j * m + a] = series[j] / k as f64;
            }
        }
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
    fn direct_mul_add(&self, z: &[f64], rows: &[bool], w: &mut [f64]) {
        self.a.direct_mul_add(z, rows, w)
    }
    fn mul_into(&self, z: &[f64], out: &mut [f64]) {
        match self.work.try_lock() {
            Ok(mut w) => self.product(z, out, &mut w),
            // Taken by another thread (or poisoned by a panic in one): buffers of our own.
            Err(_) => self.product(z, out, &mut Work::new(&self.fft, self.a.m())),
        }
    }
    /// An upper bound where the blocks were not formed ([`BlockCirculant::max_abs_bound`]): its
    /// callers (the certification's round-off bound, finiteness checks) need no more.
    fn max_abs(&self) -> (f64, bool) {
        self.a.max_abs_bound()
    }
}
