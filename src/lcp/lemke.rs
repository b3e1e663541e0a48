//! Lexicographic Lemke (placeholder: being written).
use super::{LcpMatrix, LcpSolution};

/// Settings with defaults; see [`LemkeSettings::default`].
#[derive(Clone, Debug)]
pub struct LemkeSettings {
    /// Pivot tolerance relative to max|A|, max|q|.
    pub pivot_tol: f64,
    /// The pivot limit is `max_pivots_per_dim · n + 100`.
    pub max_pivots_per_dim: usize,
    /// Steps of iterative refinement of the final basis solve.
    pub refinement_steps: usize,
    /// Certification: solved iff ‖min(z, w)‖∞ ≤ certify_tol · max(1, ‖q‖∞).
    pub certify_tol: f64,
    /// Optional warm start: indices expected to have z > 0.
    pub warm_start: Option<Vec<usize>>,
}

impl Default for LemkeSettings {
    fn default() -> Self {
        LemkeSettings { pivot_tol: 1e-12, max_pivots_per_dim: 20, refinement_steps: 3, certify_tol: 1e-9, warm_start: None }
    }
}

pub struct Lemke {
    pub settings: LemkeSettings,
}

impl Lemke {
    pub fn new(settings: LemkeSettings) -> Self {
        Lemke { settings }
    }
    pub fn solve(&self, a: &dyn LcpMatrix, q: &[f64]) -> LcpSolution {
        let _ = (a, q);
        unimplemented!("lexicographic Lemke is being written")
    }
}
