//! The periodic LCP against explicit time marching ([`crate::marching::march`]) on the same
//! (reduced) model at one frequency: agreement, accuracy against a finer LCP reference, costs.
//!
//! Both discretisations converge to the same periodic orbit: the LCP with k instants (O(h²) for
//! compliant contacts with same-instant pairing under cds or galerkin), the march with N steps
//! per period (central differences, N above the stability limit 2/ω_max, which the stiff static
//! modes of a Craig–Bampton model and the contact stiffness set) and a stopping tolerance on the
//! periodicity defect. Errors are measured at the k instants of the LCP against the LCP with
//! `reference_factor`·k instants, and divided by the reference amplitude (peak-to-peak/2).
use crate::Error;
use crate::marching::{MarchSettings, march};
use crate::periodic::{PeriodicProblem, PeriodicSolver};
use crate::response::Response;
use crate::time::Discretization;
use std::time::Instant;

/// Settings of [`compare`].
#[derive(Clone, Debug, PartialEq)]
pub struct MarchOptions {
    /// Steps per period; `None`: the smallest multiple of [`STEP_GRAIN`] that is at least
    /// `stability_margin` times the central-difference limit.
    pub steps_per_period: Option<usize>,
    pub stability_margin: f64,
    /// One march per periodicity-defect tolerance (see [`MarchSettings::tolerance`]).
    pub tolerances: Vec<f64>,
    pub max_periods: usize,
    /// The reference LCP has this many times the steps of the problem (0: no reference).
    pub reference_factor: usize,
}

impl Default for MarchOptions {
    fn default() -> Self {
        MarchOptions { steps_per_period: None, stability_margin: 1.05, tolerances: vec![1e-6], max_periods: 20_000, reference_factor: 4 }
    }
}

/// One march from rest.
#[derive(Clone, Debug)]
pub struct MarchRun {
    pub tolerance: f64,
    pub periods: usize,
    pub converged: bool,
    pub defect: f64,
    /// Wall time of the march (one thread) [s].
    pub time_s: f64,
    /// Per displacement output: max |x_march − x_LCP| / amplitude (`None` for an output whose
    /// amplitude is below 1e-6 of the largest output's).
    pub error_vs_lcp: Vec<Option<f64>>,
    /// The same against the reference LCP (empty without reference).
    pub error_vs_reference: Vec<Option<f64>>,
}

/// One frequency, both ways.
#[derive(Clone, Debug)]
pub struct MarchComparison {
    pub frequency: f64,
    pub steps_per_period: usize,
    /// Wall time of the cold LCP solve [s].
    pub lcp_time_s: f64,
    /// The LCP against the reference, per displacement output (empty without reference).
    pub lcp_error_vs_reference: Vec<Option<f64>>,
    pub reference_steps: usize,
    pub amplitude_lcp: Vec<f64>,
    pub runs: Vec<MarchRun>,
    /// The LCP response.
    pub response: Response,
}

/// The default steps per period of a march are a multiple of this; the errors are measured at
/// the gcd(N, k) instants common to the march and the LCP.
pub const STEP_GRAIN: usize = 128;

/// Smallest steps per period, multiple of [`STEP_GRAIN`], at `margin` × the stability limit of
/// the model (compliant contacts closed) at frequency ω.
pub fn stable_steps(problem: &PeriodicProblem, frequency: f64, margin: f64) -> Result<usize, Error> {
    let wmax = crate::marching::stable_omega_max(problem.model()).map_err(|e| Error::solve(format!("the stability limit of time marching: {e}")))?;
    let period = 2.0 * std::f64::consts::PI / frequency;
    let n_min = (margin * period * wmax / 2.0).ceil() as usize;
    Ok(n_min.div_ceil(STEP_GRAIN).max(1) * STEP_GRAIN)
}

/// Relative errors of `x` (sampled every `stride` from index 0) against `reference` (every
/// `rstride`) at `k` instants, per output, `None` for negligible outputs.
fn errors(x: &[Vec<f64>], stride: usize, reference: &[Vec<f64>], rstride: usize, k: usize) -> Vec<Option<f64>> {
    let amps: Vec<f64> = reference.iter().map(|r| Response::peak_to_peak(r) / 2.0).collect();
    let top = amps.iter().copied().fold(0.0, f64::max);
    x.iter()
        .zip(reference)
        .zip(&amps)
        .map(|((x, r), &a)| {
            if !(a > 1e-6 * top) {
                return None;
            }
            Some((0..k).map(|j| (x[j * stride] - r[j * rstride]).abs()).fold(0.0, f64::max) / a)
        })
        .collect()
}

/// The displacement outputs of a response, in the problem's order.
fn outputs(p: &PeriodicProblem, r: &Response) -> Vec<Vec<f64>> {
    p.outputs().displacement.iter().map(|d| r.displacement[&d.to_string()].clone()).collect()
}

/// Solves the LCP (cold) at `frequency`, a reference LCP with more instants, and marches from
/// rest once per tolerance; compares the displacement outputs at the LCP's instants.
pub fn compare(problem: &PeriodicProblem, frequency: f64, opts: &MarchOptions) -> Result<MarchComparison, Error> {
    if problem.period_multiple() != 1 {
        return Err(Error::input(format!(
            "--march-at: the scene seeks orbits of period_multiple = {} forcing periods; the march comparison reads one period T: remove period_multiple for it",
            problem.period_multiple()
        )));
    }
    let mut p = problem.clone();
    p.set_frequency(frequency).map_err(|e| Error::from(e).context("LCP"))?;
    p.set_parallel(false);
    let k = p.discretization().steps;
    let t = Instant::now();
    let response = PeriodicSolver::new(p.clone()).solve().map_err(|e| Error::from(e).context("LCP"))?;
    let lcp_time_s = t.elapsed().as_secs_f64();
    let lcp = outputs(&p, &response);

    let reference = if opts.reference_factor > 1 {
        let kr = k * opts.reference_factor;
        let what = format!("reference LCP (k = {kr})");
        let mut reference = PeriodicSolver::new(p.clone());
        reference.update_discretization(Discretization { steps: kr, ..p.discretization() }).map_err(|e| Error::from(e).context(&what))?;
        // Warm start: the coarse active set, each instant repeated.
        let m = p.model().contacts.len();
        let warm: Vec<usize> = response
            .active_set
            .iter()
            .flat_map(|&i| {
                let (j, a) = (i / m.max(1), i % m.max(1));
                (0..opts.reference_factor).map(move |s| (j * opts.reference_factor + s) * m + a)
            })
            .collect();
        reference.set_warm_start(&warm);
        let r = reference.solve().map_err(|e| Error::from(e).context(&what))?;
        Some(outputs(reference.problem(), &r))
    } else {
        None
    };
    let lcp_error_vs_reference = reference.as_ref().map_or(vec![], |r| errors(&lcp, 1, r, opts.reference_factor, k));

    let n = match opts.steps_per_period {
        Some(n) => n,
        None => stable_steps(&p, frequency, opts.stability_margin)?,
    };
    // The instants common to both grids.
    let common = gcd(n, k);
    if common < 16 {
        return Err(Error::input(format!(
            "steps_per_period: is {n}, shares only {common} instants with the LCP's {k}; use a multiple of {}",
            k.min(STEP_GRAIN)
        )));
    }
    let (stride, lstride) = (n / common, k / common);
    let mut runs = Vec::new();
    for &tolerance in &opts.tolerances {
        let settings = MarchSettings { steps_per_period: n, max_periods: opts.max_periods, tolerance, ..Default::default() };
        let t = Instant::now();
        let m = march(p.model(), &settings).map_err(|e| Error::solve(format!("time marching: {e}")))?;
        let time_s = t.elapsed().as_secs_f64();
        let xm: Vec<Vec<f64>> = p
            .outputs()
            .displacement
            .iter()
            .map(|d| {
                let terms: Vec<(usize, f64)> = match p.output_map() {
                    Some(map) => map.rows[d].clone(),
                    None => vec![(*d, 1.0)],
                };
                m.displacement.iter().map(|x| terms.iter().map(|&(q, c)| c * x[q]).sum()).collect()
            })
            .collect();
        runs.push(MarchRun {
            tolerance,
            periods: m.periods,
            converged: m.converged,
            defect: m.defect,
            time_s,
            error_vs_lcp: errors(&xm, stride, &lcp, lstride, common),
            error_vs_reference: reference.as_ref().map_or(vec![], |r| errors(&xm, stride, r, lstride * opts.reference_factor, common)),
        });
    }
    Ok(MarchComparison {
        frequency,
        steps_per_period: n,
        lcp_time_s,
        lcp_error_vs_reference,
        reference_steps: if reference.is_some() { k * opts.reference_factor } else { 0 },
        amplitude_lcp: lcp.iter().map(|x| Response::peak_to_peak(x) / 2.0).collect(),
        runs,
        response,
    })
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// The largest of the defined errors (NaN if none).
pub fn worst(errors: &[Option<f64>]) -> f64 {
    errors.iter().flatten().copied().fold(f64::NAN, f64::max)
}
