//! The admissibility check's signals in closed form: along a phase with an eigendecomposed Â, a
//! contact's clearance and a stuck contact's force are affine in the state, so each is
//! s(t) = Re Σ_j m_j e^{λ_j (t − a)} + Re Σ_p ĥ_p e^{ipωt} (the phase's transient and its periodic
//! particular solution). Its value and slope cost O(n_a + harmonics), and |s''| has the bound
//! Σ_j |m_j| |λ_j|² e^{Re λ_j τ} + Σ_p |ĥ_p| (pω)² on any interval, so the smallest value is
//! found by sampling coarsely and bisecting only where that bound lets the signal dip below the
//! floor (a certified search; 200 flows per phase and golden sections before).
use num_complex::Complex64 as C;

/// Samples per phase before the bisection.
const FIRST: usize = 16;
/// The deepest bisection: 2⁻⁶⁰ of a sampled interval is below round-off of the time.
const DEPTH: u32 = 60;

/// One signal along one phase (see the module).
pub(super) struct Signal {
    start: f64,
    lambda: Vec<C>,
    modal: Vec<C>,
    /// (pω, ĥ_p).
    harmonics: Vec<(f64, C)>,
}

/// An interval between two evaluated times: (t, value, slope) at both ends and its depth.
type Interval = ((f64, f64, f64), (f64, f64, f64), u32);

impl Signal {
    pub fn new(start: f64, lambda: Vec<C>, modal: Vec<C>, harmonics: Vec<(f64, C)>) -> Self {
        Signal { start, lambda, modal, harmonics }
    }

    /// The signal's value at `t`.
    pub fn value(&self, t: f64) -> f64 {
        self.jet(t).1
    }

    /// The values of `signals` (one phase's: the same start and λ_j) at the times `ts`, the
    /// exponentials e^{λ_j (t − a)} and e^{iwt} made once per time for all of them.
    pub fn values(signals: &[Signal], ts: &[f64]) -> Vec<Vec<f64>> {
        let Some(first) = signals.first() else { return Vec::new() };
        let mut freqs: Vec<f64> = signals.iter().flat_map(|s| s.harmonics.iter().map(|h| h.0)).collect();
        freqs.sort_by(f64::total_cmp);
        freqs.dedup();
        // Each signal's harmonics summed per distinct frequency.
        let coefficients: Vec<Vec<C>> = signals
            .iter()
            .map(|s| {
                let mut c = vec![C::new(0.0, 0.0); freqs.len()];
                for &(w, h) in &s.harmonics {
                    c[freqs.partition_point(|&f| f < w)] += h;
                }
                c
            })
            .collect();
        let mut out = vec![Vec::with_capacity(ts.len()); signals.len()];
        for &t in ts {
            let modes: Vec<C> = first.lambda.iter().map(|l| (l * (t - first.start)).exp()).collect();
            let waves: Vec<C> = freqs.iter().map(|&w| C::from_polar(1.0, w * t)).collect();
            for ((s, c), o) in signals.iter().zip(&coefficients).zip(&mut out) {
                let re = |a: &C, b: &C| a.re * b.re - a.im * b.im;
                o.push(s.modal.iter().zip(&modes).map(|(m, e)| re(m, e)).sum::<f64>() + c.iter().zip(&waves).map(|(h, e)| re(h, e)).sum::<f64>());
            }
        }
        out
    }

    /// (t, value, slope).
    fn jet(&self, t: f64) -> (f64, f64, f64) {
        let tau = t - self.start;
        let (mut v, mut d) = (0.0, 0.0);
        for (l, m) in self.lambda.iter().zip(&self.modal) {
            let z = m * (l * tau).exp();
            v += z.re;
            d += (l * z).re;
        }
        for &(w, h) in &self.harmonics {
            let z = h * C::from_polar(1.0, w * t);
            v += z.re;
            d -= w * z.im;
        }
        (t, v, d)
    }

    /// A bound on |s''| over [t0, t1] (see the module).
    pub fn bend(&self, t0: f64, t1: f64) -> f64 {
        let (a, b) = (t0 - self.start, t1 - self.start);
        let modal: f64 = self.lambda.iter().zip(&self.modal).map(|(l, m)| m.norm() * l.norm_sqr() * (l.re * a).exp().max((l.re * b).exp())).sum();
        modal + self.harmonics.iter().map(|(w, h)| h.norm() * w * w).sum::<f64>()
    }

    /// The smallest value of the signal on [a, b] and its time, exact where it is below `floor`
    /// (to 1e-9 of itself), else any value ≥ `floor` met: bisection of every interval whose lower
    /// bound from the values, slopes and [`Self::bend`] (each end's Taylor bound over its half,
    /// s(t0 + τ) ≥ s0 + s0'τ − Mτ²/2) is below the floor, or below the lowest value met once that
    /// is below the floor.
    pub fn lowest(&self, a: f64, b: f64, floor: f64) -> (f64, f64) {
        let pts: Vec<(f64, f64, f64)> = (0..=FIRST).map(|j| self.jet(if j == FIRST { b } else { a + (b - a) * j as f64 / FIRST as f64 })).collect();
        let mut best = pts.iter().map(|&(t, v, _)| (v, t)).fold((f64::INFINITY, a), |m, x| if x.0 < m.0 { x } else { m });
        let mut stack: Vec<Interval> = pts.windows(2).map(|w| (w[0], w[1], 0)).collect();
        while let Some(((t0, v0, d0), (t1, v1, d1), depth)) = stack.pop() {
            let (h, m) = (t1 - t0, self.bend(t0, t1));
            let lower = v0.min(v1).min(v0 + 0.5 * d0 * h - m * h * h / 8.0).min(v1 - 0.5 * d1 * h - m * h * h / 8.0);
            let target = if best.0 < floor { best.0 - 1e-9 * best.0.abs() } else { floor };
            if lower >= target || depth >= DEPTH {
                continue;
            }
            let mid = self.jet(0.5 * (t0 + t1));
            if mid.1 < best.0 {
                best = (mid.1, mid.0);
            }
            stack.push(((t0, v0, d0), mid, depth + 1));
            stack.push((mid, (t1, v1, d1), depth + 1));
        }
        best
    }
}
