//! Event-fitted laws for the half-step friction pairing (src/formulation.md §9 "Event-fitted half
//! steps"): cds's and galerkin's friction law at each slip end (off with [`RELAY_HALF_STEPS_ENV`]).
//!
//! The half-step sample f_j is the mean force over (t_j, t_(j+1)) and pairs with the mean slip
//! velocity v̄_j. Where the slip ends inside a step the exact mean force lies inside the box while
//! v̄_j ≠ 0, so the relay's v̄_j = 0 misplaces it by O(1) (an O(h) impulse). For a velocity with
//! slopes a0 ∓ g around the event (a0 the acceleration without friction, g = μN/m the
//! friction's), the scheme's v̄_j at the exact mean s = f_j/μN is linear in s (derived in §9):
//!
//! ```text
//!   reversal (|a0| > g):  v̄ = (h/2)(|a0| s − g sign a0)
//!   stop     (|a0| ≤ g):  v̄ = (h/2)(g s − a0)
//! ```
//!
//! so the relay holds for v̄ − c − ε s (offset c, width ε ≥ 0): the box LCP gains ε/μN on its
//! diagonal and c − ε in q, and stays positive semi-definite. a0 comes from the previous solve's
//! velocities before the event, g from the receptance at the Nyquist harmonic (−h²/(4m) under
//! cds); the laws are refitted until they repeat (a fixed point: no existence theorem covers it).
use super::Assembly;

/// Set (to anything) to solve cds and galerkin friction on the plain relay half steps, without
/// the laws: a diagnostic of src/formulation.md §9 "Why not a second-order pairing" only.
pub const RELAY_HALF_STEPS_ENV: &str = "PERIODIC_CONTACT_FRICTION_RELAY_HALF_STEPS";

/// The receptance of each friction row (after `mc` contact rows) at the Nyquist harmonic.
pub(super) fn nyquist(asm: &Assembly, mc: usize, mf: usize) -> Vec<f64> {
    let (k, m) = (asm.k, asm.m);
    (0..mf).map(|t| if k.is_multiple_of(2) { asm.g_hat[((k / 2) * m + mc + t) * m + mc + t].re } else { 0.0 }).collect()
}

/// Refits of the laws at most. Why: measured (validation/peers/friction_event_fitted.py) they
/// repeat after 4–8 rounds; a law set that keeps moving ends the loop with the last one.
pub(super) const MAX_ROUNDS: usize = 12;

/// Steps around each slip end that take its law. Why: the event may fall in the step before or
/// after the one the previous solve showed; at a step without the event the law agrees with the
/// relay (full slip beyond its ends, the stuck force at v̄ = 0 for a stop).
const WINDOW: usize = 1;

/// The law (offset c, width ε) of each friction sample, `mf × k` (row-major by contact); `None`:
/// the relay.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct EventLaws {
    k: usize,
    laws: Vec<Option<(f64, f64)>>,
}

impl EventLaws {
    pub(super) fn none(k: usize, mf: usize) -> Self {
        EventLaws { k, laws: vec![None; k * mf] }
    }

    /// The law of friction `t`'s sample `j`.
    pub(super) fn at(&self, t: usize, j: usize) -> Option<(f64, f64)> {
        self.laws[t * self.k + j]
    }

    /// Whether `other` holds the same laws to `rel` of each width.
    pub(super) fn repeats(&self, other: &EventLaws, rel: f64) -> bool {
        self.laws.iter().zip(&other.laws).all(|(a, b)| match (a, b) {
            (None, None) => true,
            (Some((c, e)), Some((c2, e2))) => (c - c2).abs() <= rel * e.abs() && (e - e2).abs() <= rel * e.abs(),
            _ => false,
        })
    }

    /// The laws fitted to one solution: `forces` and mean slip velocities `velocity` (k × mf,
    /// time-major), μN and the receptance at the Nyquist harmonic G(π) per contact, step h.
    pub(super) fn fit(nyquist: &[f64], slip: &[f64], (forces, velocity): (&[f64], &[f64]), h: f64) -> Self {
        let mf = slip.len();
        let k = forces.len() / mf.max(1);
        let mut out = EventLaws::none(k, mf);
        for (t, (&mu_n, &g_nyquist)) in slip.iter().zip(nyquist).enumerate() {
            // cds: G(π) = 1/(k_s − 4m/h²), so 1/m = −4G(π)/h² up to O(h²); a massless or
            // statically condensed row has G(π) ≥ 0 and no finite g: the relay stays (μN = 0 too).
            if !k.is_multiple_of(2) || g_nyquist >= 0.0 || mu_n <= 0.0 {
                continue;
            }
            let g = -4.0 * g_nyquist / (h * h) * mu_n;
            let s = |j: usize| forces[(j % k) * mf + t] / mu_n;
            let v = |j: usize| velocity[(j % k) * mf + t];
            let phase = |j: usize| {
                let s = s(j);
                if s > 1.0 - 1e-9 {
                    1
                } else if s < -1.0 + 1e-9 {
                    -1
                } else {
                    0
                }
            };
            for j in k..2 * k {
                let (p, next) = (phase(j), phase(j + 1));
                if p == 0 || next == p {
                    continue;
                }
                // The velocity's slope in slip before the event, a0 − g·p.
                let before = if phase(j - 1) == p { (v(j) - v(j - 1)) / h } else { (v(j - 1) - v(j - 2)) / h };
                let a0 = before + g * f64::from(p);
                if a0.abs() > g {
                    let law = (-0.5 * h * g * a0.signum(), 0.5 * h * a0.abs());
                    for i in j + 1 - WINDOW..=j + 1 + WINDOW {
                        out.laws[t * k + i % k] = Some(law);
                    }
                    continue;
                }
                // A stop: each window step's law holds its own a0 (at its middle, t_(i+1/2)), so a
                // stuck step's law gives the stuck force there. Why: with a0 frozen at the event
                // the steps after it leave the stuck force by ȧ0·h per step, and the half steps
                // carry that misfit on as the unfelt mode f_j + (−1)ʲc through the whole stick
                // phase, which then releases early (measured, src/formulation.md §9).
                let drift = if (j + 3..=j + 5).all(|i| phase(i) == 0) { g * (s(j + 5) - s(j + 3)) / (2.0 * h) } else { 0.0 };
                for i in j + 1 - WINDOW..=j + 1 + WINDOW {
                    let a0_i = a0 + drift * (i as f64 + 0.5 - j as f64) * h;
                    out.laws[t * k + i % k] = Some((-0.5 * h * a0_i, 0.5 * h * g));
                }
            }
        }
        out
    }
}
