//! The admissibility check's signals in closed form: along a phase with an eigendecomposed Â, a
//! contact's clearance and a stuck contact's force are affine in the state, so each is
//! s(t) = Re Σ_j m_j e^{λ_j (t − a)} + Re Σ_p ĥ_p e^{ipωt} (the phase's transient and its periodic
//! particular solution). Its value and slope cost O(n_a + harmonics), and |s''| has the bound
//! Σ_j |m_j| |λ_j|² e^{Re λ_j τ} + Σ_p |ĥ_p| (pω)² on any interval, so the smallest value is
//! found by sampling coarsely and bisecting only where that bound lets the signal dip below the
//! floor (a certified search; 200 flows per phase and golden sections before).
use num_complex::Complex64 as C;
use std::cell::RefCell;

/// Samples per phase before the bisection.
const FIRST: usize = 16;
/// The deepest bisection: 2⁻⁶⁰ of a sampled interval is below round-off of the time.
const DEPTH: u32 = 60;

/// One signal along one phase (see the module).
#[derive(Clone)]
pub(super) struct Signal {
    start: f64,
    lambda: Vec<C>,
    modal: Vec<C>,
    /// |m_j| (for [`Self::bend`]).
    sizes: Vec<f64>,
    /// (pω, ĥ_p).
    harmonics: Vec<(f64, C)>,
}

/// The first samples of one phase on [a, b] ([`FIRST`] + 1 times), shared by the signals of its
/// contacts (the same times and eigenvalues): e^{λ_j τ_k}, e^{Re λ_j τ_k} and e^{iwt_k} per rate
/// w, each made once per phase instead of once per contact (the check's time went to them).
pub(super) struct Samples {
    times: Vec<f64>,
    modes: Vec<Vec<C>>,
    decay: Vec<Vec<f64>>,
    turns: Vec<(f64, Vec<C>)>,
    lambda: Vec<C>,
    /// Per depth d of [`Signal::minimum_stepped`]: e^{λ_j H/2^{d+1}} and e^{iwH/2^{d+1}} per rate
    /// (H the first samples' spacing), made as a search first goes that deep.
    halves: RefCell<Vec<(Vec<C>, Vec<C>)>>,
}

impl Samples {
    /// The samples of [a, b] for the transient's eigenvalues `lambda` from `start` and the rates `rates`.
    pub fn new(start: f64, lambda: &[C], (a, b): (f64, f64), rates: impl Iterator<Item = f64>) -> Self {
        let times: Vec<f64> = (0..=FIRST).map(|j| if j == FIRST { b } else { a + (b - a) * j as f64 / FIRST as f64 }).collect();
        let modes = times.iter().map(|t| lambda.iter().map(|l| (l * (t - start)).exp()).collect()).collect();
        let decay = times.iter().map(|t| lambda.iter().map(|l| (l.re * (t - start)).exp()).collect()).collect();
        let mut turns: Vec<(f64, Vec<C>)> = Vec::new();
        for w in rates {
            if !turns.iter().any(|(v, _)| *v == w) {
                turns.push((w, times.iter().map(|t| C::from_polar(1.0, w * t)).collect()));
            }
        }
        Samples { times, modes, decay, turns, lambda: lambda.to_vec(), halves: RefCell::new(Vec::new()) }
    }

    /// The first samples' spacing H.
    fn spacing(&self) -> f64 {
        (self.times[FIRST] - self.times[0]) / FIRST as f64
    }

    /// The half steps of depth `depth` ([`Self::halves`]), made up to it.
    fn halves_to(&self, depth: usize) -> std::cell::Ref<'_, Vec<(Vec<C>, Vec<C>)>> {
        {
            let mut halves = self.halves.borrow_mut();
            while halves.len() <= depth {
                let s = self.spacing() / 2f64.powi(halves.len() as i32 + 1);
                let modes = self.lambda.iter().map(|l| (l * s).exp()).collect();
                let turns = self.turns.iter().map(|(w, _)| C::from_polar(1.0, w * s)).collect();
                halves.push((modes, turns));
            }
        }
        self.halves.borrow()
    }
}

/// An interval between two evaluated times: (t, value, slope) at both ends, its depth, and its
/// index among the first samples' intervals (depth 0).
type Interval = ((f64, f64, f64), (f64, f64, f64), u32, Option<usize>);

impl Signal {
    pub fn new(start: f64, lambda: Vec<C>, modal: Vec<C>, harmonics: Vec<(f64, C)>) -> Self {
        let sizes = modal.iter().map(|m| m.norm()).collect();
        Signal { start, lambda, modal, sizes, harmonics }
    }

    /// The sum of its terms' sizes Σ|m_j| + Σ|ĥ_p| (a scale for its tolerances).
    pub fn size(&self) -> f64 {
        self.sizes.iter().sum::<f64>() + self.harmonics.iter().map(|(_, h)| h.norm()).sum::<f64>()
    }

    /// −s (its maxima as minima).
    pub fn negated(&self) -> Signal {
        let modal = self.modal.iter().map(|m| -m).collect();
        Signal::new(self.start, self.lambda.clone(), modal, self.harmonics.iter().map(|&(w, h)| (w, -h)).collect())
    }

    /// The signal's harmonic rates pω.
    pub fn rates(&self) -> impl Iterator<Item = f64> + '_ {
        self.harmonics.iter().map(|(w, _)| *w)
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

    /// [`Self::jet`] at the first sample `k` of `s` (its exponentials made once per phase).
    fn jet_at(&self, s: &Samples, turns: &[usize], k: usize) -> (f64, f64, f64) {
        let (mut v, mut d) = (0.0, 0.0);
        for ((l, m), e) in self.lambda.iter().zip(&self.modal).zip(&s.modes[k]) {
            let z = m * e;
            v += z.re;
            d += (l * z).re;
        }
        for (&(w, h), &r) in self.harmonics.iter().zip(turns) {
            let z = h * s.turns[r].1[k];
            v += z.re;
            d -= w * z.im;
        }
        (s.times[k], v, d)
    }

    /// A bound on |s''| over [t0, t1] (see the module); over the first samples' interval `k` of
    /// `s` from their exponentials.
    pub fn bend(&self, (t0, t1): (f64, f64), first: Option<(&Samples, usize)>) -> f64 {
        let modal: f64 = match first {
            Some((s, k)) => self.lambda.iter().zip(&self.sizes).enumerate().map(|(j, (l, m))| m * l.norm_sqr() * s.decay[k][j].max(s.decay[k + 1][j])).sum(),
            None => {
                let (a, b) = (t0 - self.start, t1 - self.start);
                self.lambda.iter().zip(&self.sizes).map(|(l, m)| m * l.norm_sqr() * (l.re * a).exp().max((l.re * b).exp())).sum()
            }
        };
        modal + self.harmonics.iter().map(|(w, h)| h.norm() * w * w).sum::<f64>()
    }

    /// The smallest value of the signal on the span of `samples` and its time, exact where it is
    /// below `floor` (to 1e-9 of itself), else any value ≥ `floor` met: bisection of every
    /// interval whose lower bound from the values, slopes and [`Self::bend`] (each end's Taylor
    /// bound over its half, s(t0 + τ) ≥ s0 + s0'τ − Mτ²/2) is below the floor, or below the lowest
    /// value met once that is below the floor. The samples' rates must hold the signal's.
    pub fn lowest(&self, samples: &Samples, floor: f64) -> (f64, f64) {
        self.descend(samples, &|best| if best < floor { best - 1e-9 * best.abs() } else { floor })
    }

    /// The smallest value of the signal on the span of `samples` and its time, to `tol`: as
    /// [`Self::lowest`], every interval whose lower bound is below the lowest value met less `tol`
    /// bisected (the rigid margin's search: a certified minimum, not a floor's check).
    pub fn minimum(&self, samples: &Samples, tol: f64) -> (f64, f64) {
        self.descend(samples, &|best| best - tol)
    }

    /// [`Self::minimum`] with each midpoint's exponentials stepped from its interval's start,
    /// e^{λ(τ + h/2)} = e^{λτ} e^{λh/2} (and likewise e^{iwt}), the steps made once per depth for
    /// every signal of the samples ([`Samples::halves`]): a complex product per mode where
    /// [`Self::minimum`] makes an exponential and a sine and cosine (most of the rigid margin's
    /// time). Its values differ from [`Self::jet`]'s by round-off, at most
    /// [`Self::stepped_error`]; over a first interval the bend is its bound there.
    pub fn minimum_stepped(&self, samples: &Samples, tol: f64) -> (f64, f64) {
        let turns: Vec<usize> =
            self.harmonics.iter().map(|(w, _)| samples.turns.iter().position(|(v, _)| v == w).expect("the samples hold every rate")).collect();
        let (nl, width) = (self.lambda.len(), self.lambda.len() + turns.len());
        // Per point evaluated: its exponentials (modes, then the harmonics' turns) and (t, value, slope).
        let mut zs: Vec<C> = Vec::with_capacity(64 * width);
        let mut pts: Vec<(f64, f64, f64)> = Vec::with_capacity(64);
        for k in 0..=FIRST {
            zs.extend_from_slice(&samples.modes[k]);
            zs.extend(turns.iter().map(|&r| samples.turns[r].1[k]));
            pts.push(self.jet_at(samples, &turns, k));
        }
        let bends: Vec<f64> = (0..FIRST).map(|k| self.bend((samples.times[k], samples.times[k + 1]), Some((samples, k)))).collect();
        let spacing = samples.spacing();
        let mut best = pts.iter().map(|&(t, v, _)| (v, t)).fold((f64::INFINITY, samples.times[0]), |m, x| if x.0 < m.0 { x } else { m });
        // (start point, end point, depth, first interval).
        let mut stack: Vec<(usize, usize, u32, usize)> = (0..FIRST).map(|k| (k, k + 1, 0, k)).collect();
        let mut mid = vec![C::new(0.0, 0.0); width];
        while let Some((i0, i1, depth, k)) = stack.pop() {
            let ((t0, v0, d0), (t1, v1, d1)) = (pts[i0], pts[i1]);
            let (h, m) = (t1 - t0, bends[k]);
            let lower = v0.min(v1).min(v0 + 0.5 * d0 * h - m * h * h / 8.0).min(v1 - 0.5 * d1 * h - m * h * h / 8.0);
            if lower >= best.0 - tol || depth >= DEPTH {
                continue;
            }
            let halves = samples.halves_to(depth as usize);
            let (hm, ht) = &halves[depth as usize];
            let (mut v, mut d) = (0.0, 0.0);
            let start = &zs[i0 * width..(i0 + 1) * width];
            for j in 0..nl {
                mid[j] = start[j] * hm[j];
                let z = self.modal[j] * mid[j];
                v += z.re;
                d += (self.lambda[j] * z).re;
            }
            for (q, (&(w, hh), &r)) in self.harmonics.iter().zip(&turns).enumerate() {
                mid[nl + q] = start[nl + q] * ht[r];
                let z = hh * mid[nl + q];
                v += z.re;
                d -= w * z.im;
            }
            drop(halves);
            let t = t0 + spacing / 2f64.powi(depth as i32 + 1);
            zs.extend_from_slice(&mid);
            pts.push((t, v, d));
            if v < best.0 {
                best = (v, t);
            }
            let i = pts.len() - 1;
            stack.push((i0, i, depth + 1, k));
            stack.push((i, i1, depth + 1, k));
        }
        best
    }

    /// A bound on how far [`Self::minimum_stepped`]'s values, and its lower bounds over an
    /// interval, lie from [`Self::jet`]'s: each of its ≤ 60 chained products and the sums round
    /// (≤ 1024 ε relative, Higham, "Accuracy and Stability of Numerical Algorithms", §3.6), on
    /// each term's size over the span with its slope over a first interval.
    pub fn stepped_error(&self, samples: &Samples) -> f64 {
        let h = samples.spacing();
        let decay = |j: usize| samples.decay.iter().map(|d| d[j]).fold(0.0, f64::max);
        let modal: f64 = self.lambda.iter().zip(&self.sizes).enumerate().map(|(j, (l, m))| m * decay(j) * (1.0 + l.norm() * h)).sum();
        let harmonic: f64 = self.harmonics.iter().map(|(w, z)| z.norm() * (1.0 + w.abs() * h)).sum();
        1024.0 * f64::EPSILON * (modal + harmonic)
    }

    /// The bisection of [`Self::lowest`] and [`Self::minimum`]: an interval is split while its
    /// lower bound is below `target` of the lowest value met.
    fn descend(&self, samples: &Samples, target: &dyn Fn(f64) -> f64) -> (f64, f64) {
        let turns: Vec<usize> =
            self.harmonics.iter().map(|(w, _)| samples.turns.iter().position(|(v, _)| v == w).expect("the samples hold every rate")).collect();
        let pts: Vec<(f64, f64, f64)> = (0..=FIRST).map(|k| self.jet_at(samples, &turns, k)).collect();
        let a = samples.times[0];
        let mut best = pts.iter().map(|&(t, v, _)| (v, t)).fold((f64::INFINITY, a), |m, x| if x.0 < m.0 { x } else { m });
        let mut stack: Vec<Interval> = pts.windows(2).enumerate().map(|(k, w)| (w[0], w[1], 0, Some(k))).collect();
        while let Some(((t0, v0, d0), (t1, v1, d1), depth, first)) = stack.pop() {
            let (h, m) = (t1 - t0, self.bend((t0, t1), first.map(|k| (samples, k))));
            let lower = v0.min(v1).min(v0 + 0.5 * d0 * h - m * h * h / 8.0).min(v1 - 0.5 * d1 * h - m * h * h / 8.0);
            if lower >= target(best.0) || depth >= DEPTH {
                continue;
            }
            let mid = self.jet(0.5 * (t0 + t1));
            if mid.1 < best.0 {
                best = (mid.1, mid.0);
            }
            stack.push(((t0, v0, d0), mid, depth + 1, None));
            stack.push((mid, (t1, v1, d1), depth + 1, None));
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::{C, Samples, Signal};

    /// A plastic impact's ringing (a stiff decaying pair, 6e5 rad/s) on a slow mode and three
    /// harmonics of 2300 rad/s, over one period from 1e-4 after its start: the signal, its span, its
    /// eigenvalues and its size.
    fn ringing() -> (Signal, (f64, f64), Vec<C>, f64) {
        let w = 2300.0;
        let lambda = vec![C::new(-900.0, 6.0e5), C::new(-900.0, -6.0e5), C::new(-3.0, 2.1e3), C::new(-3.0, -2.1e3), C::new(-40.0, 0.0)];
        let modal = vec![C::new(1e-6, 2e-6), C::new(1e-6, -2e-6), C::new(3e-5, 1e-5), C::new(3e-5, -1e-5), C::new(-2e-5, 0.0)];
        let harmonics = vec![(w, C::new(1e-4, -2e-5)), (2.0 * w, C::new(-3e-6, 4e-6)), (3.0 * w, C::new(5e-7, 1e-7))];
        let start = 0.37;
        let span = (start + 1e-4, start + 1e-4 + 2.0 * std::f64::consts::PI / w);
        (Signal::new(start, lambda.clone(), modal, harmonics), span, lambda, 2e-4)
    }

    /// The reference minimum of `signal` on [a, b]: 600 000 direct values (4.6e-9 s apart on
    /// [`ringing`], 2 300 a stiff period) and a golden section around each sampled local minimum
    /// within the samples' reach of the lowest (bend · h²/8: another lobe's may be the lowest).
    fn brute_minimum(signal: &Signal, (a, b): (f64, f64)) -> f64 {
        let n = 600_000;
        let h = (b - a) / n as f64;
        let value = |t: f64| signal.jet(t).1;
        let values: Vec<f64> = (0..=n).map(|i| value(a + h * i as f64)).collect();
        let floor = values.iter().fold(f64::INFINITY, |m, &v| m.min(v)) + signal.bend((a, b), None) * h * h / 8.0;
        let lows = (0..=n).filter(|&i| values[i] <= floor && (i == 0 || values[i] <= values[i - 1]) && (i == n || values[i] <= values[i + 1]));
        lows.map(|k| super::super::verify::golden(a + h * k.max(1).saturating_sub(1) as f64, a + h * (k + 1).min(n) as f64, 60, &value).1)
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn minimum_finds_a_stiff_dip_between_its_first_samples() {
        // 17 first samples step over the ringing's dips.
        let (signal, (a, b), lambda, size) = ringing();
        let (v, t) = signal.minimum(&Samples::new(signal.start, &lambda, (a, b), signal.rates()), 1e-15 * size);
        let value = |t: f64| signal.jet(t).1;
        let reference = brute_minimum(&signal, (a, b));
        assert!((v - reference).abs() <= 1e-14 * size, "minimum {v:e} at {t}, the reference {reference:e}");
        assert!((value(t) - v).abs() <= 1e-15 * size && (a..=b).contains(&t), "the minimum's time {t} does not give its value");
        // Its dip is the ringing's, not the slow part's: 17 samples alone miss it.
        let coarse = (0..=16).map(|j| value(a + (b - a) * j as f64 / 16.0)).fold(f64::INFINITY, f64::min);
        assert!(coarse - v > 1e-3 * size, "the 17 samples' lowest {coarse:e} already holds the minimum {v:e}");
    }

    /// The stepped search (each midpoint's exponentials a product from its interval's start, the
    /// amplitudes' and most rigid margins' search) finds the same minimum and maximum as 600 000
    /// direct values and as the direct search, to its chained products' round-off (≈ 1e-14 of the size).
    #[test]
    fn the_stepped_search_finds_the_extrema_of_direct_values() {
        let (signal, span, lambda, size) = ringing();
        let samples = Samples::new(signal.start, &lambda, span, signal.rates());
        for (name, s) in [("minimum", signal.clone()), ("maximum", signal.negated())] {
            let (v, t) = s.minimum_stepped(&samples, 1e-15 * size);
            let reference = brute_minimum(&s, span);
            let direct = s.minimum(&samples, 1e-15 * size).0;
            eprintln!("{name}: stepped {v:e} at {t}, brute force {reference:e}, direct search {direct:e}");
            assert!((v - reference).abs() <= 5e-14 * size, "{name}: stepped {v:e}, the brute force's {reference:e}");
            assert!((v - direct).abs() <= 5e-14 * size, "{name}: stepped {v:e}, the direct search's {direct:e}");
            assert!((s.jet(t).1 - v).abs() <= s.stepped_error(&samples), "{name}: its time {t} does not give its value within the bound");
        }
    }
}
