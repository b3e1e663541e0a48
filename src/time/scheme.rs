//! Circulant symbols of each time scheme (src/formulation.md §2, table). With the DFT
//! X̂_p = Σ_j x_j e^{−2πi jp/k}, a one-step delay has the symbol z = e^{−iθ}, θ = 2πp/k.
use num_complex::Complex64 as C;
use std::fmt;
use std::str::FromStr;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// First-order backward differences.
    Bds1,
    /// Second-order backward differences (3-point velocity, 4-point acceleration).
    Bds2,
    /// Central differences.
    Cds,
    /// Bubnov–Galerkin in time with periodic linear hats (divided by h).
    Galerkin,
    /// Fourier time collocation (spectral; the HDHBM).
    Fourier,
}

impl Scheme {
    pub const ALL: [Scheme; 5] = [Scheme::Bds1, Scheme::Bds2, Scheme::Cds, Scheme::Galerkin, Scheme::Fourier];

    pub fn name(self) -> &'static str {
        match self {
            Scheme::Bds1 => "bds1",
            Scheme::Bds2 => "bds2",
            Scheme::Cds => "cds",
            Scheme::Galerkin => "galerkin",
            Scheme::Fourier => "fourier",
        }
    }

    /// Order of accuracy on smooth responses (fourier: spectral, reported as `None`).
    pub fn order(self) -> Option<u32> {
        match self {
            Scheme::Bds1 => Some(1),
            Scheme::Bds2 | Scheme::Cds | Scheme::Galerkin => Some(2),
            Scheme::Fourier => None,
        }
    }

    /// The largest ω_max·h (h = T/k, ω_max the model's highest undamped angular frequency) for
    /// which the scheme's recurrence is stable; `None`: no limit (A-stable, or not a time stepper).
    ///
    /// From the symbols of src/formulation.md §2 applied to one mode m x'' + k x = 0, Ω = ω_r·h, z the one-step
    /// shift of x_j = zʲ:
    /// - cds: z − 2 + z⁻¹ + Ω² = 0, so z + z⁻¹ = 2 − Ω²; both roots lie on the unit circle iff
    ///   |2 − Ω²| < 2, i.e. Ω < 2 (explicit central differences, Ω = 2 a double root −1 that
    ///   grows linearly).
    /// - galerkin: M(x_{j+1} − 2x_j + x_{j−1})/h² + K(x_{j+1} + 4x_j + x_{j−1})/6 (the weight
    ///   (2 + cos θ)/3), i.e. Newmark's linear acceleration (β = 1/6): z + z⁻¹ =
    ///   (2 − 2Ω²/3)/(1 + Ω²/6), of modulus < 2 iff Ω² < 12, i.e. Ω < 2√3 ≈ 3.464.
    /// - bds1 (backward Euler) and bds2 (BDF2) are A-stable: no limit.
    /// - fourier does not step in time: no limit (only its resolution: harmonics below k/2).
    pub fn stability_limit(self) -> Option<f64> {
        match self {
            Scheme::Cds => Some(2.0),
            Scheme::Galerkin => Some(2.0 * 3f64.sqrt()),
            Scheme::Bds1 | Scheme::Bds2 | Scheme::Fourier => None,
        }
    }

    /// The pairing that converges for rigid contact (src/formulation.md §3, findings).
    pub fn default_pairing(self, rigid: bool) -> Pairing {
        match self {
            Scheme::Cds | Scheme::Galerkin if rigid => Pairing::Forward,
            _ => Pairing::Same,
        }
    }

    /// Why a (scheme, pairing) choice does not converge for rigid contact, if it does not.
    pub fn rigid_contact_warning(self, pairing: Pairing) -> Option<String> {
        let why = match (self, pairing) {
            (Scheme::Bds1, Pairing::Same) | (Scheme::Cds, Pairing::Forward) | (Scheme::Galerkin, Pairing::Forward) => return None,
            (Scheme::Bds1, Pairing::Forward) => {
                "bds1 with forward pairing shifts every impact by one step; it is not the plastic-impact orbit that same pairing converges to"
            }
            (Scheme::Cds | Scheme::Galerkin, Pairing::Same) => {
                "same-instant pairing is ill-posed for rigid contact under cds and galerkin (ray termination, spurious solutions)"
            }
            (Scheme::Bds2, _) => "bds2 does not converge to the plastic-impact orbit for rigid contact with either pairing",
            (Scheme::Fourier, _) => "fourier does not converge to the plastic-impact orbit for rigid contact with either pairing",
        };
        Some(format!(
            "{why}; for rigid contact use cds or galerkin with pairing = \"forward\" (second order) or bds1 with pairing = \"same\" (first order), or give the contact a stiffness"
        ))
    }

    /// Symbols at θ_p = 2πp/k for p = 0..=k/2 (the distinct harmonics of real data).
    pub fn symbols(self, k: usize, period: f64) -> Symbols {
        let h = period / k as f64;
        let omega = 2.0 * std::f64::consts::PI / period;
        let nh = k / 2 + 1;
        let mut s = Symbols { sigma1: Vec::with_capacity(nh), sigma2: Vec::with_capacity(nh), weight: Vec::with_capacity(nh) };
        for p in 0..nh {
            let theta = 2.0 * std::f64::consts::PI * p as f64 / k as f64;
            // 1 − z (z = e^(−iθ), the delay) without cancellation: 1 − cos θ = 2 sin²(θ/2).
            // Why: at θ = 2π/k the direct form loses ε/θ² relative in the low harmonics (7e-10 at
            // k = 16384), which is then the floor of every LCP residual.
            let half = (theta / 2.0).sin();
            let u = C::new(2.0 * half * half, theta.sin());
            let (s1, s2, w) = match self {
                Scheme::Bds1 => {
                    let s1 = u / h;
                    (s1, s1 * s1, 1.0)
                }
                // 3 − 4z + z² = (1 − z)(2 + (1 − z)); 2 − 5z + 4z² − z³ = (1 − z)²(1 + (1 − z)).
                Scheme::Bds2 => (u * (2.0 + u) / (2.0 * h), u * u * (1.0 + u) / (h * h), 1.0),
                Scheme::Cds | Scheme::Galerkin => {
                    let w = if self == Scheme::Galerkin { 1.0 - 2.0 / 3.0 * half * half } else { 1.0 };
                    // (z⁻¹ − z)/(2h) = i sin θ / h; (z⁻¹ − 2 + z)/h² = −4 sin²(θ/2)/h².
                    (C::new(0.0, theta.sin() / h), C::new(-4.0 * half * half / (h * h), 0.0), w)
                }
                Scheme::Fourier => {
                    // p ≤ k/2 here, so p is already the signed wavenumber's magnitude.
                    let nyquist = k.is_multiple_of(2) && p == k / 2;
                    let pw = p as f64 * omega;
                    (C::new(0.0, if nyquist { 0.0 } else { pw }), C::new(-pw * pw, 0.0), 1.0)
                }
            };
            s.sigma1.push(s1);
            s.sigma2.push(s2);
            s.weight.push(w);
        }
        s
    }
}

impl fmt::Display for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A scheme or pairing name that is not one of ours; the message lists the known ones.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SchemeParseError {
    #[error("unknown scheme \"{0}\"; expected one of bds1, bds2, cds, galerkin, fourier")]
    Scheme(String),
    #[error("unknown pairing \"{0}\"; expected same or forward")]
    Pairing(String),
}

impl FromStr for Scheme {
    type Err = SchemeParseError;
    fn from_str(s: &str) -> Result<Self, SchemeParseError> {
        Scheme::ALL.into_iter().find(|x| x.name() == s).ok_or_else(|| SchemeParseError::Scheme(s.to_string()))
    }
}

/// Which gap sample each force sample is complementary to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pairing {
    /// λ_j ⊥ gap(t_j): the paper's.
    Same,
    /// λ_j ⊥ gap(t_{j+1}), the first instant λ_j influences (Carpenter's forward increment).
    Forward,
}

impl Pairing {
    pub fn name(self) -> &'static str {
        match self {
            Pairing::Same => "same",
            Pairing::Forward => "forward",
        }
    }
    /// Index offset of the paired gap sample.
    pub fn offset(self) -> usize {
        match self {
            Pairing::Same => 0,
            Pairing::Forward => 1,
        }
    }
}

impl fmt::Display for Pairing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Pairing {
    type Err = SchemeParseError;
    fn from_str(s: &str) -> Result<Self, SchemeParseError> {
        match s {
            "same" => Ok(Pairing::Same),
            "forward" => Ok(Pairing::Forward),
            _ => Err(SchemeParseError::Pairing(s.to_string())),
        }
    }
}

/// σ1, σ2 and the Galerkin weight w at the k/2+1 distinct harmonics.
#[derive(Clone, Debug)]
pub struct Symbols {
    pub sigma1: Vec<C>,
    pub sigma2: Vec<C>,
    pub weight: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;
    /// Every finite-difference symbol tends to iω, −ω² for a resolved harmonic, at its order.
    #[test]
    fn symbols_converge_at_scheme_order() {
        let period = 2.0 * std::f64::consts::PI;
        for scheme in [Scheme::Bds1, Scheme::Bds2, Scheme::Cds, Scheme::Galerkin] {
            let err = |k: usize| {
                let s = scheme.symbols(k, period);
                // harmonic p = 1 has ω = 1: σ1 → i, σ2 → −1
                (s.sigma1[1] - C::new(0.0, 1.0)).norm() + (s.sigma2[1] + 1.0).norm() + (s.weight[1] - 1.0).abs()
            };
            let order = (err(64) / err(128)).log2();
            assert!((order - scheme.order().unwrap() as f64).abs() < 0.1, "{scheme}: order {order}");
        }
    }
}
