//! Real FFT plans for one period of k samples: the one plan type of the crate.
//!
//! Every plan comes from one process-wide [`RealFftPlanner`], which caches plans by length: the
//! engine's [`PeriodFft`] and the LCP's circulant operator asking for the same k share the same
//! twiddles and algorithms. A [`PeriodFft`] is a pair of shared plans (cheap to clone).
//!
//! Hot paths use the `*_with_scratch` methods (after rustfft's `process_with_scratch`): input,
//! output and scratch are the caller's buffers, nothing is allocated per transform. The
//! convenience methods [`PeriodFft::forward`] and [`PeriodFft::inverse`] allocate their result.
use num_complex::Complex64 as C;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::sync::{Arc, Mutex, OnceLock};

/// The process-wide planner (plans are cached by length inside it); `None` once unloaded.
static PLANNER: OnceLock<Mutex<Option<RealFftPlanner<f64>>>> = OnceLock::new();

fn planner() -> &'static Mutex<Option<RealFftPlanner<f64>>> {
    PLANNER.get_or_init(|| Mutex::new(None))
}

/// Drops the planner's cache when the library is unloaded. Why: an FMU is `dlclose`d by its
/// importer, and a cache held by a static of an unmapped library can never be freed (valgrind:
/// definitely lost, tests/boundary_stress.rs). Run by the dynamic loader from `.fini_array`.
#[cfg(target_os = "linux")]
#[used]
#[unsafe(link_section = ".fini_array")]
static DROP_PLANNER_AT_UNLOAD: extern "C" fn() = drop_planner;

#[cfg(target_os = "linux")]
extern "C" fn drop_planner() {
    // try_lock: never wait at exit on a thread that is still planning (then the cache stays).
    if let Some(m) = PLANNER.get() {
        match m.try_lock() {
            Ok(mut planner) => *planner = None,
            Err(std::sync::TryLockError::Poisoned(e)) => *e.into_inner() = None,
            Err(std::sync::TryLockError::WouldBlock) => {}
        }
    }
}

/// Forward (r2c) and inverse (c2r) plans of length k.
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
        // A panic while planning cannot leave the planner's cache half-written in a way that
        // matters (it only ever adds plans), so a poisoned lock is still usable.
        let mut guard = planner().lock().unwrap_or_else(|e| e.into_inner());
        let planner = guard.get_or_insert_with(RealFftPlanner::new);
        PeriodFft { k, forward: planner.plan_fft_forward(k), inverse: planner.plan_fft_inverse(k) }
    }
    pub fn k(&self) -> usize {
        self.k
    }
    /// Number of spectral bins of a real series: k/2 + 1 (p = 0..=k/2).
    pub fn bins(&self) -> usize {
        self.k / 2 + 1
    }
    /// Length of the scratch buffer that both `*_with_scratch` methods accept.
    pub fn scratch_len(&self) -> usize {
        self.forward.get_scratch_len().max(self.inverse.get_scratch_len())
    }
    /// A zeroed scratch buffer of [`PeriodFft::scratch_len`].
    pub fn make_scratch(&self) -> Vec<C> {
        vec![C::ZERO; self.scratch_len()]
    }

    /// X̂_p = Σ_j x_j e^{−2πi jp/k}, p = 0..=k/2, into `out` (length k/2 + 1). `samples` (length k)
    /// is used as workspace and left unspecified; `scratch` has at least [`PeriodFft::scratch_len`].
    /// Panics on wrong lengths (a programming error).
    pub fn forward_with_scratch(&self, samples: &mut [f64], out: &mut [C], scratch: &mut [C]) {
        self.forward.process_with_scratch(samples, out, scratch).expect("r2c lengths match the plan");
    }

    /// The unnormalised c2r transform Σ_p X̂_p e^{+2πi jp/k} over the Hermitian extension, into `out`
    /// (length k). The imaginary parts of the DC and Nyquist bins of `spectrum` are set to zero first
    /// (they are round-off for real data); `spectrum` is then used as workspace. The caller scales by
    /// 1/k. Panics on wrong lengths (a programming error).
    pub fn inverse_unscaled_with_scratch(&self, spectrum: &mut [C], out: &mut [f64], scratch: &mut [C]) {
        spectrum[0].im = 0.0;
        if self.k.is_multiple_of(2) {
            spectrum[self.k / 2].im = 0.0;
        }
        self.inverse.process_with_scratch(spectrum, out, scratch).expect("c2r lengths match the plan");
    }

    /// X̂_p = Σ_j x_j e^{−2πi jp/k}, p = 0..=k/2.
    pub fn forward(&self, samples: &[f64]) -> Vec<C> {
        let mut input = samples.to_vec();
        let mut out = self.forward.make_output_vec();
        let mut scratch = self.forward.make_scratch_vec();
        self.forward_with_scratch(&mut input, &mut out, &mut scratch);
        out
    }

    /// x_j = (1/k) Σ_p X̂_p e^{+2πi jp/k} over the Hermitian extension of p = 0..=k/2.
    /// The imaginary parts of the DC and Nyquist bins are dropped (they are round-off for real data).
    pub fn inverse(&self, spectrum: &[C]) -> Vec<f64> {
        let mut input = spectrum.to_vec();
        let mut out = self.inverse.make_output_vec();
        let mut scratch = self.inverse.make_scratch_vec();
        self.inverse_unscaled_with_scratch(&mut input, &mut out, &mut scratch);
        let scale = 1.0 / self.k as f64;
        out.iter_mut().for_each(|v| *v *= scale);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scratch path and the convenience path agree bit for bit, and inverse ∘ forward = id.
    #[test]
    fn round_trip_and_scratch_path() {
        for k in [1usize, 2, 7, 16, 30] {
            let fft = PeriodFft::new(k);
            let x: Vec<f64> = (0..k).map(|j| (j as f64 * 0.7).sin() + 0.1 * j as f64).collect();
            let spec = fft.forward(&x);
            let mut input = x.clone();
            let mut out = vec![C::ZERO; fft.bins()];
            let mut scratch = fft.make_scratch();
            fft.forward_with_scratch(&mut input, &mut out, &mut scratch);
            assert_eq!(spec, out);
            let back = fft.inverse(&spec);
            for (a, b) in x.iter().zip(&back) {
                assert!((a - b).abs() <= 1e-12, "k={k}: {a} vs {b}");
            }
        }
    }
}
