//! The periodic contact problem: assembly in the frequency domain, one LCP over the period,
//! recovery of the requested responses (src/formulation.md §2–3).
mod assembly;
/// A massless-boundary test model for the layers above (`analysis`'s sweep tests).
#[cfg(test)]
pub(crate) use assembly::tests::chain_with_massless_boundary;
mod cache;
mod friction;
mod friction_coupled;
mod friction_events;
mod friction_family;
mod friction_half_steps;
mod friction_relay;
mod friction_shooting;
mod gaps;
pub mod limits;
use crate::linalg::fft; // the crate's one FFT plan type, shared with lcp
mod pilot;
mod problem;
mod recovery;
mod rubbing;
mod session;
mod stacked;
mod state_space;
mod tuning;

pub use assembly::Assembly;
pub use fft::PeriodFft;
pub use friction::{FRICTION_DENSE_MAX, FrictionGrid, friction_lcp};
pub use friction_events::RELAY_HALF_STEPS_ENV;
pub use pilot::{PILOT_MIN_STEPS, carried_active_set};
pub use problem::{MAX_DENSE_FLOPS, MAX_LCP_SIZE, MAX_STEPS, MIN_STEPS, PeriodicProblem};
pub use recovery::render_path as render_lcp_path;
pub use rubbing::TangentialRow;
pub use session::{PeriodicSolver, WarmStart};
pub use state_space::{NoStepMap, SHOOTING_MEMORY_MAX, SHOOTING_WORK_MAX, carried_state, shooting_memory, shooting_work, step_map};
pub use tuning::Tuning;

use crate::error::{Error, ErrorKind};
/// The step map's type, for analyses that march it (continuation, stability).
pub use crate::lcp::StepMapLcp;
pub use crate::lcp::{
    AUTO_LEMKE_MAX, DENSE_MAX, DENSE_MEMORY_MAX, LEMKE_AFTER_SHOOTING_MAX, LEMKE_FLOPS_PER_S, LcpMethod, dense_lemke_seconds, dense_memory, progress,
    solve_circulant_lcp,
};
use crate::lcp::{LcpOutcome, LcpSolution};
use crate::model::ModelError;

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

/// Outputs named in the user's numbering when the solved model's DOFs are not the user's: a
/// clamped model (DOFs removed) or a reduced one (x_full = Φ q). Output `label` is the
/// combination Σ c·x_model[d] of the model's DOFs; the result's keys are the labels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputMap {
    /// For each user DOF that may be output: its (model DOF, coefficient) terms.
    pub rows: std::collections::BTreeMap<usize, Vec<(usize, f64)>>,
    /// Each contact's row of B in the user's numbering, in model order (reported as the
    /// contact's `normal`; its label DOF, the largest |coefficient|, as its `dof`).
    pub contact_rows: Vec<Vec<(usize, f64)>>,
    /// Effects named in the result besides the model's own (e.g. `reduction`).
    pub effects: Vec<String>,
}

impl OutputMap {
    /// Contact `a`'s row of B in the user's numbering, if the map has it.
    pub fn contact_row(&self, a: usize) -> Option<&[(usize, f64)]> {
        self.contact_rows.get(a).map(Vec::as_slice)
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
    /// Shooting from a warm start stops where Newton from it misses, without the contact-free
    /// start and the offset homotopy (a guarded sweep's quick tries; default off).
    pub shooting_warm_only: bool,
    /// Shooting may follow the offset homotopy when Newton misses (default on; off for a
    /// guarded sweep's cold try inside a run of failed points).
    pub shooting_homotopy: bool,
    /// Periods marched from a warm start before shooting's Newton (0: none; a lone rubbing
    /// solve's jump past a fold, `rubbing/walk.rs`).
    pub shooting_settle: usize,
    /// The most pivots dense Lemke may take (`None`: its own limit, 20·N + 100). Why: an error
    /// estimate's neighbour solve bounds its dense fallback by its CPU budget
    /// (`analysis::accuracy`).
    pub dense_pivots: Option<usize>,
    /// The orbit state a warm shooting try starts Newton from, with the warm sets (the same orbit
    /// on another grid, [`carried_state`]); `None`: the warm sets' frozen fixed point.
    pub shooting_state: Option<Vec<f64>>,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            method: LcpMethod::Auto,
            tolerance: 1e-9,
            parallel: true,
            shooting_warm_only: false,
            shooting_homotopy: true,
            shooting_settle: 0,
            dense_pivots: None,
            shooting_state: None,
        }
    }
}

/// Why a problem could not be set up or solved. Every message says what to change.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SolveError {
    /// The model fails its checks (the field and the value are named).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A setting of the problem is not usable (field: value: remedy).
    #[error("{0}")]
    Invalid(String),
    /// Legal, but larger than accepted (LCP size, dense work): the message gives the limit.
    #[error("{0}")]
    Limit(String),
    #[error(
        "the dynamic operator is singular at harmonic {harmonic} (frequency {frequency} rad/s): an undamped resonance or a rigid-body mode falls on a sampled harmonic; add damping, change steps or the frequency, or clamp the structure"
    )]
    SingularOperator { harmonic: usize, frequency: f64 },
    #[error("the LCP solver ended with {}: {hint} (pivots {}, residual {:.3e})", outcome.name(), info.pivots, info.residual)]
    Lcp { outcome: LcpOutcome, info: crate::lcp::LcpInfo, hint: String },
    #[error("the recovered response is not finite at {0}; the problem is too ill-conditioned to report")]
    NonFinite(String),
}

impl SolveError {
    /// Input and limits are the caller's to change; the rest is the solver's outcome.
    pub fn kind(&self) -> ErrorKind {
        match self {
            SolveError::Model(_) | SolveError::Invalid(_) => ErrorKind::Input,
            SolveError::Limit(_) => ErrorKind::Limit,
            SolveError::SingularOperator { .. } | SolveError::Lcp { .. } | SolveError::NonFinite(_) => ErrorKind::Solve,
        }
    }
}

impl From<SolveError> for Error {
    fn from(e: SolveError) -> Self {
        Error::new(e.kind(), e.to_string())
    }
}

/// The typed failure of an LCP solve, with the remedies to try. Scheme limits are refused before
/// solving, so the remedies left are the ones of src/formulation.md §3.
pub(crate) fn lcp_failure(sol: LcpSolution) -> SolveError {
    let hint = match sol.outcome {
        LcpOutcome::RayTermination => {
            "no periodic solution was reached (the LCP matrix is not a P-matrix above the first resonance); remedies: for rigid contact use cds or galerkin with pairing = \"forward\" or bds1 with pairing = \"same\" (src/formulation.md §3), add damping, or make the contact compliant (stiffness = …)"
        }
        LcpOutcome::PivotLimit => {
            "the pivot budget ran out (a degenerate or ill-posed LCP); remedies: for rigid contact use cds or galerkin with pairing = \"forward\" or bds1 with pairing = \"same\", add damping, or make the contact compliant (stiffness = …)"
        }
        LcpOutcome::NonFiniteData => "the assembled LCP holds NaN or infinite values; check the model for a singular operator",
        LcpOutcome::Inaccurate => {
            "the final basis is too ill-conditioned to certify the residual; remedies: add damping, make the contact compliant (stiffness = …), or reduce steps"
        }
        LcpOutcome::Solved => unreachable!(),
    };
    SolveError::Lcp { outcome: sol.outcome, info: sol.info, hint: hint.to_string() }
}
