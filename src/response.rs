//! The periodic response, as written to JSON (the result contract in the README).
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize)]
pub struct ContactResponse {
    pub dof: usize,
    pub direction: i32,
    /// Contact stiffness of a compliant contact; null for a rigid one (whose gap never goes
    /// below 0, while a compliant contact's gap is negative when it penetrates).
    pub stiffness: Option<f64>,
    /// Which gap sample each force sample is complementary to.
    pub pairing: String,
    /// Compressive force ≥ 0 at each instant (the paper's λ = −force).
    pub force: Vec<f64>,
    /// Clearance ≥ 0 at each instant.
    pub gap: Vec<f64>,
    /// The gap sample each force sample is complementary to: `paired_gap[j]` is `gap[j]` for
    /// same-instant pairing and `gap[(j + 1) mod k]` for forward pairing, so a rigid contact has
    /// `force[j]·paired_gap[j] = 0` and `paired_gap ≥ 0` (a compliant one:
    /// `force[j]·(paired_gap[j] + force[j]/stiffness) = 0`).
    pub paired_gap: Vec<f64>,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct LcpSummary {
    /// k·m; 0 without contact.
    pub size: usize,
    pub status: String,
    pub pivots: usize,
    /// ‖min(z, Az + q)‖∞.
    pub residual: f64,
    /// Siconos' ‖z − max(0, z − w)‖₂/‖q‖₂.
    pub relative_error: f64,
    /// True when the solve started from a warm start and kept it (`warm_start.outcome` is
    /// "accepted" or "repaired").
    pub warm_start_used: bool,
    /// What became of the warm start.
    pub warm_start: WarmStartSummary,
    /// The methods that ran and the fallbacks taken, one line (e.g. "auto (N = 2048 > 256: block
    /// pivoting first): block pivoting, 9 pivots → ray termination; fallback: dense
    /// lexicographic Lemke, 3100 pivots → solved").
    pub path: String,
}

/// What became of the warm start of a solve.
#[derive(Clone, Debug, Default, Serialize)]
pub struct WarmStartSummary {
    /// "cold" (none offered), "accepted" (the guess was the answer), "repaired" (the solve
    /// started from the guess and fixed it in `pivots` pivots) or "rejected" (the guess was
    /// discarded and the solve ran cold).
    pub outcome: String,
    /// Pivots of the solve that gave the answer (for "rejected": the cold solve's).
    pub pivots: usize,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct Timing {
    pub assembly: f64,
    pub lcp: f64,
    pub recovery: f64,
    pub total: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Response {
    /// T = 2π/ω [s].
    pub period: f64,
    pub steps: usize,
    pub scheme: String,
    pub pairing: String,
    pub effects: Vec<String>,
    /// t_j = j·T/k.
    pub time: Vec<f64>,
    pub displacement: BTreeMap<String, Vec<f64>>,
    pub velocity: BTreeMap<String, Vec<f64>>,
    pub acceleration: BTreeMap<String, Vec<f64>>,
    pub contacts: Vec<ContactResponse>,
    pub lcp: LcpSummary,
    pub warnings: Vec<String>,
    pub timing_s: Timing,
    /// The contact-free (linear) response at the displacement outputs, same keys: a by-product
    /// of the assembly, for frequency-response curves.
    #[serde(skip)]
    pub linear_displacement: BTreeMap<String, Vec<f64>>,
    /// Indices of the LCP unknowns with z > 0 (time-major j·m + i): a warm start for the next solve.
    #[serde(skip)]
    pub active_set: Vec<usize>,
}

impl Response {
    /// Peak-to-peak amplitude of one series.
    pub fn peak_to_peak(series: &[f64]) -> f64 {
        let (lo, hi) = series.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
        if series.is_empty() { 0.0 } else { hi - lo }
    }
    /// Fraction of the instants at which contact `i` carries force.
    pub fn contact_fraction(&self, i: usize) -> f64 {
        let f = &self.contacts[i].force;
        f.iter().filter(|&&v| v > 0.0).count() as f64 / f.len().max(1) as f64
    }
    /// Impulse per period of contact `i`: h·Σ force.
    pub fn impulse_per_period(&self, i: usize) -> f64 {
        self.period / self.steps as f64 * self.contacts[i].force.iter().sum::<f64>()
    }
}
