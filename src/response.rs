//! The periodic response, as written to JSON (the result contract in the README).
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize)]
pub struct ContactResponse {
    /// The DOF that labels the contact: its normal's largest |coefficient| (the first of equals),
    /// in the scene's numbering; for a contact on one DOF, that DOF.
    pub dof: usize,
    /// The sign (+1 or −1) of the normal's coefficient on `dof`.
    pub direction: i32,
    /// The contact's unit normal, row of B: [DOF, coefficient] pairs in the scene's numbering.
    pub normal: Vec<(usize, f64)>,
    /// The normal displacement B_i x at each instant (= gap(t) − clearance): the displacement
    /// reported for the contact, along its normal, whatever DOFs the normal mixes.
    pub normal_displacement: Vec<f64>,
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

/// One Coulomb friction contact at the instants (src/formulation.md §9). The force f acts on the
/// structure as −bᵀf (like a contact force), so it has the sign of the slip: f = μN·sign(v) while
/// slipping, |f| < μN while stuck, and f·v ≥ 0.
#[derive(Clone, Debug, Serialize)]
pub struct FrictionResponse {
    /// μ.
    pub coefficient: f64,
    /// N (constant; 0 for a coupled contact, see `contact`).
    pub normal_force: f64,
    /// Coupled normal–tangential friction: the index of the contact whose force λ_n (its
    /// `contacts[i].force`) bounds |f| ≤ μ·λ_n at each instant; absent under a constant load.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact: Option<usize>,
    /// k_t of a Jenkins element; null for rigid Coulomb friction.
    pub stiffness: Option<f64>,
    /// Friction force f ∈ [−μN, μN] at each instant.
    pub force: Vec<f64>,
    /// Slip velocity v at each instant: b ẋ by bds1's backward difference, or the slider's velocity
    /// b ẋ − ḟ/k_t of a Jenkins element; 0 while stuck.
    pub slip_velocity: Vec<f64>,
    /// Whether the contact sticks (|f| < μN) at each instant.
    pub stuck: Vec<bool>,
    /// Tangential displacement u = b x at each instant (for force–displacement loops).
    pub displacement: Vec<f64>,
    /// Energy dissipated per period, h·Σ f_j v_j = ∮ f v dt ≥ 0.
    pub dissipated_energy: f64,
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
    /// The orbit's period p·T, T = 2π/ω [s].
    pub period: f64,
    /// Instants over `period`: k per forcing period times `period_multiple`.
    pub steps: usize,
    /// p: the orbit repeats every p forcing periods (1: T-periodic; 2: period doubled).
    pub period_multiple: usize,
    pub scheme: String,
    pub pairing: String,
    pub effects: Vec<String>,
    /// t_j = j·T/k.
    pub time: Vec<f64>,
    pub displacement: BTreeMap<String, Vec<f64>>,
    pub velocity: BTreeMap<String, Vec<f64>>,
    pub acceleration: BTreeMap<String, Vec<f64>>,
    pub contacts: Vec<ContactResponse>,
    /// Coulomb friction contacts, in scene order (absent without `[[friction]]`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub friction: Vec<FrictionResponse>,
    pub lcp: LcpSummary,
    pub warnings: Vec<String>,
    pub timing_s: Timing,
    /// What the result says of its own error (`analysis::accuracy`, or the polish).
    pub accuracy: Accuracy,
    /// The event-fitted polish (`--polish`, `[discretization] polish = true`), when it ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub polish: Option<PolishSummary>,
    /// `scheme = "auto"`: the scheme and k chosen for the tolerance, and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scheme_choice: Option<SchemeChoice>,
    /// The contact-free (linear) response at the displacement outputs, same keys: a by-product
    /// of the assembly, for frequency-response curves.
    #[serde(skip)]
    pub linear_displacement: BTreeMap<String, Vec<f64>>,
    /// Indices of the LCP unknowns with z > 0 (time-major j·m + i): a warm start for the next solve.
    #[serde(skip)]
    pub active_set: Vec<usize>,
    /// The closed orbit's initial state when shooting solved it (its step map's state,
    /// `periodic::state_space`): a warm start for the same orbit on another grid.
    #[serde(skip)]
    pub orbit_state: Option<Vec<f64>>,
}

/// What `scheme = "auto"` chose and why (`analysis::scheme_auto`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SchemeChoice {
    /// The wanted error relative to the peak-to-peak amplitude.
    pub tolerance: f64,
    /// Whether the error estimate of the result met it.
    pub met: bool,
    pub scheme: String,
    pub pairing: String,
    /// The k of the result.
    pub steps: usize,
    /// The result's relative error bound (the envelope of the Richardson estimates, at least
    /// `accuracy.relative`), compared with the tolerance.
    pub estimate: Option<f64>,
    /// Why this scheme, why this k, and if `met` is false why the refinement stopped.
    pub why: String,
    /// Every k solved, in order.
    pub tried: Vec<SchemeTrial>,
}

/// One k of the refinement.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SchemeTrial {
    pub steps: usize,
    /// Relative error estimate at this k (`None`: none could be made, see `why`).
    pub estimate: Option<f64>,
    /// The relative error bound at this k that "auto" compares with the tolerance: the envelope
    /// of the estimates so far (`analysis::scheme_auto::envelope`).
    pub bound: Option<f64>,
    /// Wall time of this k's solve and its estimate [s].
    pub seconds: f64,
}

/// An estimate of the result's own error.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Accuracy {
    /// Estimated max over the instants of |x_j − x(t_j)| over the displacement outputs, in the
    /// length unit; `None` when not estimated (`method` says why).
    pub estimate: Option<f64>,
    /// `estimate` divided by the largest peak-to-peak amplitude of the displacement outputs.
    pub relative: Option<f64>,
    /// The largest over the displacement outputs of each one's estimate divided by its own
    /// peak-to-peak amplitude (≥ `relative`: a small output counts as much as the largest).
    pub relative_own: Option<f64>,
    /// How it was obtained, e.g. "richardson: k/2 = 256, order 2 (cds, forward, rigid contact with sticking)".
    pub method: String,
    /// Why there is no estimate when the neighbour grid's solve was not had (its cause and the
    /// remedy); absent when estimated, or when no estimate applies (`method` says why).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub missing: Option<Box<EstimateMissing>>,
}

/// Why the error estimate's neighbour grid was not solved: the point's own answer stands,
/// certified, without an estimate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EstimateMissing {
    /// What stopped it.
    pub cause: MissingCause,
    /// The neighbour grid ("k/2 = 512") and what was tried, with figures.
    pub detail: String,
    /// What the user can do.
    pub remedy: String,
}

/// What stopped an error estimate's neighbour solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MissingCause {
    /// Shooting missed and the dense fallback would pass the estimate's CPU budget (projected,
    /// or its pivot cap ran out).
    Budget,
    /// Every try missed within the budget (or the neighbour's LCP has no dense fallback).
    Missed,
}

/// One event of a polished orbit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EventRecord {
    /// Time in [0, T) [s].
    pub time: f64,
    /// Contact index (the friction contact's index for "stick", "slip", "reversal").
    pub contact: usize,
    /// "impact", "release", "contact_on" (compliant), "contact_off" (compliant); friction:
    /// "stick" (onset), "slip" (release), "reversal" (slip direction flips at v = 0).
    pub kind: String,
    /// Impulse of an impact ≥ 0 [force·time]; 0 for the other kinds.
    pub impulse: f64,
}

/// What the event-fitted polish did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PolishSummary {
    /// "polished" (the orbit above is the polished one) or "fallback" (the LCP's orbit is kept,
    /// `reason` says why).
    pub status: String,
    pub reason: String,
    pub events: Vec<EventRecord>,
    /// Newton iterations and the final residual (max norm of the shooting equations).
    pub iterations: usize,
    pub residual: f64,
    /// Wall time of the polish [s].
    pub time_s: f64,
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
