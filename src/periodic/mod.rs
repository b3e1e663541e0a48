//! The periodic contact problem: assembly in the frequency domain, one LCP over the period,
//! recovery of the requested responses (notes §2–3).
mod assembly;
mod fft;
mod recovery;

pub use assembly::Assembly;
pub use fft::PeriodFft;

use crate::lcp::{BlockCirculant, BlockPivoting, CirculantOperator, Lemke, LemkeSettings, LcpOutcome, LcpSolution, PivotingSettings};
use crate::model::{Contact, Model};
use crate::response::Response;
use crate::time::{Discretization, Pairing};
use std::time::Instant;

/// Which responses to recover; nothing else is computed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputSelection {
    pub displacement: Vec<usize>,
    pub velocity: Vec<usize>,
    pub acceleration: Vec<usize>,
    /// Contact forces and gaps.
    pub contacts: bool,
}

impl OutputSelection {
    /// The DOFs whose response must be recovered, sorted and unique.
    pub fn dofs(&self) -> Vec<usize> {
        let mut d: Vec<usize> = self.displacement.iter().chain(&self.velocity).chain(&self.acceleration).copied().collect();
        d.sort_unstable();
        d.dedup();
        d
    }
}

/// Which LCP method to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LcpMethod {
    /// Picks by size and falls back on failure.
    Auto,
    /// Lexicographic Lemke.
    Lemke,
    /// Block principal pivoting on the active set, FFT products (the fast path for large k).
    Pivoting,
}

impl LcpMethod {
    pub fn name(self) -> &'static str {
        match self {
            LcpMethod::Auto => "auto",
            LcpMethod::Lemke => "lemke",
            LcpMethod::Pivoting => "pivoting",
        }
    }
}

/// Solver settings with defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverSettings {
    pub method: LcpMethod,
    /// Certification tolerance of the LCP residual, relative to max(1, ‖q‖∞).
    pub tolerance: f64,
    /// Spread the harmonics over threads (rayon). Off inside an FMU.
    pub parallel: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings { method: LcpMethod::Auto, tolerance: 1e-9, parallel: true }
    }
}

impl SolverSettings {
    pub fn from_spec(spec: Option<&crate::scene::SolverSpec>) -> Result<Self, String> {
        let mut s = SolverSettings::default();
        let Some(spec) = spec else { return Ok(s) };
        if let Some(m) = &spec.method {
            s.method = match m.as_str() {
                "auto" => LcpMethod::Auto,
                "lemke" => LcpMethod::Lemke,
                "pivoting" => LcpMethod::Pivoting,
                other => return Err(format!("solver.method: unknown method \"{other}\"; expected auto, lemke or pivoting")),
            };
        }
        if let Some(t) = spec.tolerance {
            if !(t.is_finite() && t > 0.0 && t < 1.0) {
                return Err(format!("solver.tolerance: is {t}, must be in (0, 1)"));
            }
            s.tolerance = t;
        }
        Ok(s)
    }
}

/// Why a problem could not be set up or solved. Every message says what to change.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SolveError {
    #[error("{0}")]
    Invalid(String),
    #[error(
        "the dynamic operator is singular at harmonic {harmonic} (frequency {frequency} rad/s): an undamped resonance or a rigid-body mode falls on a sampled harmonic; add damping, change steps or the frequency, or clamp the structure"
    )]
    SingularOperator { harmonic: usize, frequency: f64 },
    #[error("the LCP solver ended with {}: {hint} (pivots {}, residual {:.3e})", outcome.name(), info.pivots, info.residual)]
    Lcp { outcome: LcpOutcome, info: crate::lcp::LcpInfo, hint: String },
    #[error("the recovered response is not finite at {0}; the problem is too ill-conditioned to report")]
    NonFinite(String),
}

/// A model with its discretisation, outputs and solver settings, checked and ready to solve.
#[derive(Clone, Debug)]
pub struct PeriodicProblem {
    pub model: Model,
    pub disc: Discretization,
    pub outputs: OutputSelection,
    pub solver: SolverSettings,
}

/// Up to this LCP size `auto` uses lexicographic Lemke directly; above, block pivoting finished
/// by Lemke from its best basis, with full lexicographic Lemke as the fallback.
pub const AUTO_LEMKE_MAX: usize = 256;

/// Fewest instants per period that any scheme needs.
pub const MIN_STEPS: usize = 4;
/// Most instants per period we accept (memory of the recovery grows like k·outputs).
pub const MAX_STEPS: usize = 1 << 22;

impl PeriodicProblem {
    pub fn new(model: Model, disc: Discretization, outputs: OutputSelection, solver: SolverSettings) -> Result<Self, SolveError> {
        model.validate().map_err(|e| SolveError::Invalid(e.to_string()))?;
        let k = disc.steps;
        if !(MIN_STEPS..=MAX_STEPS).contains(&k) {
            return Err(SolveError::Invalid(format!("discretization.steps: is {k}, must be in {MIN_STEPS}..={MAX_STEPS}")));
        }
        // A harmonic h is resolved by k samples only if h < k/2 (Nyquist).
        for (i, f) in model.forces.iter().enumerate() {
            if 2 * f.term.harmonic as usize >= k {
                return Err(SolveError::Invalid(format!(
                    "force[{i}].harmonic: is {}, not resolved by steps = {k} (needs steps > {})",
                    f.term.harmonic,
                    2 * f.term.harmonic
                )));
            }
        }
        for (i, c) in model.contacts.iter().enumerate() {
            for (j, h) in c.motion.iter().enumerate() {
                if 2 * h.harmonic as usize >= k {
                    return Err(SolveError::Invalid(format!(
                        "contact[{i}].motion[{j}].harmonic: is {}, not resolved by steps = {k} (needs steps > {})",
                        h.harmonic,
                        2 * h.harmonic
                    )));
                }
            }
        }
        let n = model.n();
        if let Some(d) = outputs.dofs().into_iter().find(|&d| d >= n) {
            return Err(SolveError::Invalid(format!("output: DOF {d} does not exist, the model has DOFs 0..{}", n - 1)));
        }
        Ok(PeriodicProblem { model, disc, outputs, solver })
    }

    /// The pairing of one contact: the scene's, or the default that converges for it.
    pub fn pairing_of(&self, c: &Contact) -> Pairing {
        match self.disc.pairing {
            Some(p) => p,
            None => self.disc.scheme.default_pairing(c.is_rigid()),
        }
    }

    /// Warnings about choices that do not converge, said before solving.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        for (i, c) in self.model.contacts.iter().enumerate() {
            let p = self.pairing_of(c);
            if c.is_rigid() {
                if let Some(why) = self.disc.scheme.rigid_contact_warning(p) {
                    w.push(format!("contact[{i}] (rigid, {} with pairing {p}): {why}", self.disc.scheme));
                }
            } else if p == Pairing::Forward {
                w.push(format!(
                    "contact[{i}] (compliant): forward pairing makes a compliant force lag one step, so the scheme is first order only; use pairing = \"same\""
                ));
            }
        }
        w
    }

    /// Solves with a fresh FFT plan and no warm start.
    pub fn solve(&self) -> Result<Response, SolveError> {
        self.solve_with(&PeriodFft::new(self.disc.steps), None)
    }

    /// Solves reusing `fft` (planned for k = steps), warm-started from a previous active set.
    pub fn solve_with(&self, fft: &PeriodFft, warm_start: Option<&[usize]>) -> Result<Response, SolveError> {
        let t_start = Instant::now();
        let dofs = self.outputs.dofs();
        let asm = assembly::assemble(&self.model, &self.disc, &dofs, fft, self.solver.parallel)?;
        let (a, q) = self.lcp(&asm, fft);
        let t_assembly = t_start.elapsed().as_secs_f64();

        let t_lcp = Instant::now();
        let sol = self.solve_lcp(&a, &q, warm_start)?;
        let t_lcp = t_lcp.elapsed().as_secs_f64();

        let t_rec = Instant::now();
        let mut response = recovery::recover(self, &asm, fft, &sol)?;
        response.timing_s.assembly = t_assembly;
        response.timing_s.lcp = t_lcp;
        response.timing_s.recovery = t_rec.elapsed().as_secs_f64();
        response.timing_s.total = t_start.elapsed().as_secs_f64();
        Ok(response)
    }

    /// The LCP of the period: A block-circulant from the inverse FFT of Ĝ, and q = gap − B xlin,
    /// each contact row shifted by its pairing offset (λ_j ⊥ gap(t_{j+s})).
    pub fn lcp(&self, asm: &Assembly, fft: &PeriodFft) -> (BlockCirculant, Vec<f64>) {
        let (k, m) = (asm.k, asm.m);
        let nh = k / 2 + 1;
        let mut blocks = vec![0.0; k * m * m];
        let mut q = vec![0.0; k * m];
        let period = self.model.period();
        let mut spec = vec![num_complex::Complex64::ZERO; nh];
        for (a, ca) in self.model.contacts.iter().enumerate() {
            let s = self.pairing_of(ca).offset();
            for b in 0..m {
                for (p, v) in spec.iter_mut().enumerate() {
                    *v = asm.g_hat[(p * m + a) * m + b];
                }
                let col = fft.inverse(&spec);
                for d in 0..k {
                    blocks[(d * m + a) * m + b] = col[(d + s) % k];
                }
            }
            for (p, v) in spec.iter_mut().enumerate() {
                *v = asm.bxlin_hat[p * m + a];
            }
            let bx = fft.inverse(&spec);
            for j in 0..k {
                let jj = (j + s) % k;
                let t = jj as f64 * period / k as f64;
                q[j * m + a] = ca.gap_at(self.model.frequency, t) - bx[jj];
            }
            if let crate::model::Compliance::Compliant { stiffness } = ca.compliance {
                blocks[a * m + a] += 1.0 / stiffness;
            }
        }
        (BlockCirculant::new(k, m, blocks), q)
    }

    /// The LCP (A, q) of the period without solving it (for exports and studies).
    pub fn assemble_lcp(&self, fft: &PeriodFft) -> Result<(BlockCirculant, Vec<f64>), SolveError> {
        let asm = assembly::assemble(&self.model, &self.disc, &[], fft, self.solver.parallel)?;
        Ok(self.lcp(&asm, fft))
    }

    fn solve_lcp(&self, a: &BlockCirculant, q: &[f64], warm_start: Option<&[usize]>) -> Result<LcpSolution, SolveError> {
        let sol = solve_circulant_lcp(a, q, self.solver.method, self.solver.tolerance, warm_start);
        if sol.outcome != LcpOutcome::Solved {
            let hint = match sol.outcome {
                LcpOutcome::RayTermination => {
                    "no periodic solution was reached (the LCP matrix is not a P-matrix above the first resonance); remedies: make the contact compliant (stiffness = …), use cds or galerkin with pairing = \"forward\" or bds1, or add damping"
                }
                LcpOutcome::PivotLimit => "the pivot budget ran out (a degenerate or ill-posed LCP); try compliance, another scheme or pairing, or damping",
                LcpOutcome::NonFiniteData => "the assembled LCP holds NaN or infinite values; check the model for a singular operator",
                LcpOutcome::Inaccurate => "the final basis is too ill-conditioned to certify the residual; add damping or compliance, or reduce steps",
                LcpOutcome::Solved => unreachable!(),
            };
            return Err(SolveError::Lcp { outcome: sol.outcome, info: sol.info, hint: hint.into() });
        }
        Ok(sol)
    }
}

/// Solves a block-circulant LCP with `method` (the engine's logic: `auto` uses lexicographic
/// Lemke up to [`AUTO_LEMKE_MAX`], above it block pivoting with FFT products, falling back to
/// Lemke when that fails). Used by the engine and by `periodic-contact lcp` for a raw LCP whose
/// matrix is block-circulant.
pub fn solve_circulant_lcp(a: &BlockCirculant, q: &[f64], method: LcpMethod, tolerance: f64, warm_start: Option<&[usize]>) -> LcpSolution {
    if q.is_empty() {
        return LcpSolution { outcome: LcpOutcome::Solved, z: vec![], w: vec![], info: Default::default() };
    }
    let lemke = || {
        let settings = LemkeSettings { certify_tol: tolerance, warm_start: warm_start.map(<[usize]>::to_vec), ..LemkeSettings::default() };
        Lemke::new(settings).solve(a, q)
    };
    let pivoting = || {
        let settings = PivotingSettings { certify_tol: tolerance, warm_start: warm_start.map(<[usize]>::to_vec), ..PivotingSettings::default() };
        BlockPivoting::new(settings).solve(&CirculantOperator::new(a), q)
    };
    match method {
        LcpMethod::Lemke => lemke(),
        LcpMethod::Pivoting => pivoting(),
        LcpMethod::Auto if q.len() <= AUTO_LEMKE_MAX => lemke(),
        LcpMethod::Auto => {
            let fast = pivoting();
            if fast.outcome == LcpOutcome::Solved {
                fast
            } else {
                // The robust fallback: lexicographic Lemke; its pivots add to the fast path's.
                let mut sol = lemke();
                sol.info.pivots += fast.info.pivots;
                sol.info.time_s += fast.info.time_s;
                sol
            }
        }
    }
}
