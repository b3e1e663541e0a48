//! Contact-free steady states (src/formulation.md §6.1): x(t) = Re[(K − Ω²M + iΩC)⁻¹ F e^{iΩt}].
use super::{ExactError, Oscillator};
use crate::model::{Force, Model};
use faer::Mat;
use faer::linalg::solvers::Solve;
use num_complex::Complex64 as C64;

/// Steady state of m x'' + c x' + k x = F cos Ωt: x(t) = Re[X e^{iΩt}],
/// X = F / (k − Ω² m + iΩc)  (src/formulation.md §6.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearOrbit {
    osc: Oscillator,
    amp: C64,
}

impl LinearOrbit {
    /// Fails on invalid parameters and at an undamped resonance (c = 0, k = Ω² m).
    pub fn solve(osc: &Oscillator) -> Result<Self, ExactError> {
        osc.validate()?;
        let den = C64::new(osc.stiffness - osc.omega * osc.omega * osc.mass, osc.omega * osc.damping);
        let scale = osc.stiffness + osc.omega * osc.omega * osc.mass + osc.omega * osc.damping;
        if den.norm() <= 1e-14 * scale {
            return Err(ExactError::param(
                "omega",
                format!("is {}, an undamped resonance (k = Ω² m = {}, c = 0): no periodic steady state", osc.omega, osc.stiffness),
            ));
        }
        Ok(LinearOrbit { osc: *osc, amp: osc.force / den })
    }

    /// (x, v, a) at t.
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let w = self.osc.omega;
        let z = self.amp * C64::from_polar(1.0, w * t);
        (z.re, -w * z.im, -w * w * z.re)
    }

    /// The complex amplitude X.
    pub fn complex_amplitude(&self) -> C64 {
        self.amp
    }

    /// |X| = max x = −min x.
    pub fn amplitude(&self) -> f64 {
        self.amp.norm()
    }

    pub fn peak_to_peak(&self) -> f64 {
        2.0 * self.amp.norm()
    }

    pub fn oscillator(&self) -> &Oscillator {
        &self.osc
    }
}

/// Multi-DOF linear steady state: one complex amplitude vector per forcing harmonic,
/// x(t) = Σ_h Re[X_h e^{i h ω t}].
#[derive(Clone, Debug)]
pub struct LinearResponse {
    omega: f64,
    n: usize,
    harmonics: Vec<(u32, Vec<C64>)>,
}

/// Solves (K − (hω)² M + i hω C) X_h = F_h for each harmonic h present in `forces`
/// (F_h = Σ amplitude·e^{i phase} on each DOF; h = 0 is the static K X_0 = F_0).
/// Fails, naming the parameter, on mismatched sizes, non-finite data or a singular dynamic
/// stiffness (undamped resonance, rigid-body mode under a static load).
pub fn linear_response_dense(
    mass: &Mat<f64>,
    damping: Option<&Mat<f64>>,
    stiffness: &Mat<f64>,
    omega: f64,
    forces: &[Force],
) -> Result<LinearResponse, ExactError> {
    let n = mass.nrows();
    if n == 0 || mass.ncols() != n {
        return Err(ExactError::param("mass", format!("is {}×{}, must be square and non-empty", mass.nrows(), mass.ncols())));
    }
    if stiffness.nrows() != n || stiffness.ncols() != n {
        return Err(ExactError::param("stiffness", format!("is {}×{}, expected {n}×{n}", stiffness.nrows(), stiffness.ncols())));
    }
    if let Some(c) = damping
        && (c.nrows() != n || c.ncols() != n)
    {
        return Err(ExactError::param("damping", format!("is {}×{}, expected {n}×{n}", c.nrows(), c.ncols())));
    }
    if !(omega.is_finite() && omega > 0.0) {
        return Err(ExactError::param("omega", format!("is {omega}, must be finite and > 0")));
    }
    let mut hs: Vec<u32> = Vec::new();
    for (i, f) in forces.iter().enumerate() {
        if f.dof >= n {
            return Err(ExactError::param(format!("forces[{i}].dof"), format!("is {}, the model has DOFs 0 to {} (use one of them)", f.dof, n - 1)));
        }
        if !(f.term.amplitude.is_finite() && f.term.phase.is_finite()) {
            return Err(ExactError::param(format!("forces[{i}]"), format!("amplitude {} and phase {} must be finite", f.term.amplitude, f.term.phase)));
        }
        if !hs.contains(&f.term.harmonic) {
            hs.push(f.term.harmonic);
        }
    }
    hs.sort_unstable();
    let mut harmonics = Vec::with_capacity(hs.len());
    for &h in &hs {
        let w = h as f64 * omega;
        let z = Mat::<C64>::from_fn(n, n, |i, j| {
            let c = damping.map_or(0.0, |c| c[(i, j)]);
            C64::new(stiffness[(i, j)] - w * w * mass[(i, j)], w * c)
        });
        let mut rhs = Mat::<C64>::zeros(n, 1);
        for f in forces.iter().filter(|f| f.term.harmonic == h) {
            rhs[(f.dof, 0)] += C64::from_polar(f.term.amplitude, f.term.phase);
        }
        let x = z.partial_piv_lu().solve(&rhs);
        // Residual check: a singular Z gives non-finite or inaccurate X.
        let r = &z * &x - &rhs;
        let zn = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| z[(i, j)].norm()).fold(0.0, f64::max);
        let xn = (0..n).map(|i| x[(i, 0)].norm()).fold(0.0, f64::max);
        let bn = (0..n).map(|i| rhs[(i, 0)].norm()).fold(0.0, f64::max);
        let rn = (0..n).map(|i| r[(i, 0)].norm()).fold(0.0, f64::max);
        if !(xn.is_finite() && rn <= 1e-8 * (zn * xn + bn)) || (bn > 0.0 && zn * xn > 1e12 * bn) {
            return Err(ExactError::param("omega", format!("harmonic {h} of ω = {omega} makes K − (hω)²M + i hω C singular (resonance or rigid-body mode)")));
        }
        harmonics.push((h, (0..n).map(|i| x[(i, 0)]).collect()));
    }
    Ok(LinearResponse { omega, n, harmonics })
}

impl LinearResponse {
    /// The contact-free response of a model (its contacts are ignored).
    pub fn from_model(model: &Model) -> Result<Self, ExactError> {
        let s = &model.structure;
        let c = s.damping.as_ref().map(|c| c.to_dense());
        linear_response_dense(&s.mass.to_dense(), c.as_ref(), &s.stiffness.to_dense(), model.frequency, &model.forces)
    }

    fn derivative(&self, t: f64, order: u32) -> Vec<f64> {
        let mut x = vec![0.0; self.n];
        for (h, amp) in &self.harmonics {
            let w = *h as f64 * self.omega;
            let d = C64::new(0.0, w).powu(order) * C64::from_polar(1.0, w * t);
            for (xi, a) in x.iter_mut().zip(amp) {
                *xi += (a * d).re;
            }
        }
        x
    }

    pub fn displacement(&self, t: f64) -> Vec<f64> {
        self.derivative(t, 0)
    }
    pub fn velocity(&self, t: f64) -> Vec<f64> {
        self.derivative(t, 1)
    }
    pub fn acceleration(&self, t: f64) -> Vec<f64> {
        self.derivative(t, 2)
    }
    /// (harmonic, complex amplitude per DOF).
    pub fn harmonics(&self) -> &[(u32, Vec<C64>)] {
        &self.harmonics
    }
}
