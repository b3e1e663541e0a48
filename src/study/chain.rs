//! The 2-DOF compliant chain of tests/polish.rs (M = I, K = [[2, −1], [−1, 2]], C = 0.1·I,
//! 1.0·cos 1.2t on DOF 0, a stop of stiffness 20 at 0.3 on DOF 1) and its reference: no closed
//! form, so long explicit time integration (src/formulation.md §5, `marching::march`, independent of the
//! periodic LCP), Richardson-extrapolated over the marcher's O(h²) error. Finer marches do not
//! help: past 2^15 steps per period the marcher's round-off grows (measured: |polish − march| =
//! 1.9e-6, 5.4e-7, 1.5e-7, 2.0e-7 at 2^13 … 2^16, and no steady state to 1e-10 at 2^17).
use crate::Error;
use crate::marching::{MarchSettings, march};
use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Model, Structure};

/// Steps per period of the two marches: N and 2N (every k of the study divides N).
pub const MARCH_STEPS: usize = 1 << 14;

pub fn model() -> Model {
    Model {
        structure: Structure {
            mass: Matrix::from_rows(&[vec![1.0, 0.0], vec![0.0, 1.0]]),
            stiffness: Matrix::from_rows(&[vec![2.0, -1.0], vec![-1.0, 2.0]]),
            damping: Some(Matrix::from_rows(&[vec![0.1, 0.0], vec![0.0, 0.1]])),
        },
        forces: vec![Force { dof: 0, term: Harmonic { amplitude: 1.0, harmonic: 1, phase: 0.0 } }],
        contacts: vec![Contact::on_dof(1, 1.0, 0.3, Compliance::Compliant { stiffness: 20.0 })],
        frequency: 1.2,
        frictions: Vec::new(),
        rubbing: Vec::new(),
    }
}

/// The steady state of long time integration at N and 2N steps per period, extrapolated
/// (x_2N + (x_2N − x_N)/3), on the grid of N instants.
#[derive(Clone, Debug)]
pub struct MarchedReference {
    period: f64,
    /// samples[j][dof] at t_j = j T / N.
    samples: Vec<Vec<f64>>,
    ptp: f64,
    uncertainty: f64,
    /// Wall time of the two marches [s].
    pub cpu_s: f64,
}

impl MarchedReference {
    /// x_dof(t) at an instant of the grid (t = j T / N for an integer j, as every k of the study gives).
    pub fn displacement(&self, dof: usize, t: f64) -> f64 {
        let n = self.samples.len();
        let s = t / self.period * n as f64;
        let j = s.round();
        debug_assert!((s - j).abs() < 1e-6, "t = {t} is not on the reference's grid of {n} instants");
        self.samples[(j as usize) % n][dof]
    }
    pub fn peak_to_peak(&self) -> f64 {
        self.ptp
    }
    /// The Richardson correction |x_2N − x_N| / 3: the error estimate of the finer march, taken as
    /// the bound of the extrapolated reference's own error [same unit as x].
    pub fn uncertainty(&self) -> f64 {
        self.uncertainty
    }
}

/// The marches at N and 2N steps per period (from rest, to a periodicity defect < 1e-10).
pub fn reference() -> Result<MarchedReference, Error> {
    let model = model();
    let start = std::time::Instant::now();
    let mut runs = Vec::new();
    for n in [MARCH_STEPS, 2 * MARCH_STEPS] {
        let s = MarchSettings { steps_per_period: n, max_periods: 5000, tolerance: 1e-10, ..MarchSettings::default() };
        let r = march(&model, &s).map_err(|e| Error::solve(format!("the chain's marched reference at N = {n}: {e}")))?;
        if !r.converged {
            return Err(Error::solve(format!("the chain's marched reference at N = {n}: no steady state (defect {:.2e})", r.defect)));
        }
        runs.push(r);
    }
    let at = |r: usize, j: usize, d: usize| runs[r].displacement[j << r][d];
    let dofs = model.n();
    let mut samples = Vec::with_capacity(MARCH_STEPS);
    let mut uncertainty = 0.0f64;
    for j in 0..MARCH_STEPS {
        let mut x = Vec::with_capacity(dofs);
        for d in 0..dofs {
            let correction = (at(1, j, d) - at(0, j, d)) / 3.0;
            uncertainty = uncertainty.max(correction.abs());
            x.push(at(1, j, d) + correction);
        }
        samples.push(x);
    }
    let ptp = (0..dofs)
        .map(|d| {
            let (lo, hi) = samples.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x[d]), h.max(x[d])));
            hi - lo
        })
        .fold(0.0, f64::max);
    Ok(MarchedReference { period: model.period(), samples, ptp, uncertainty, cpu_s: start.elapsed().as_secs_f64() })
}
