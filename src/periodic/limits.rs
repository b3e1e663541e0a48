//! Scheme limits known before solving: the stability of the time scheme
//! ([`Scheme::stability_limit`], ω_max·h below a bound) and the choice of k for `steps = "auto"`.
//!
//! Why refuse rather than try: past its limit a scheme's recurrence is unstable, its periodic
//! operator has near-singular harmonics and the LCP is ill-posed (the coarse rigid blade at
//! ω = 2300 rad/s, k = 512 under cds: ω_max·h ≈ 3.2, Lemke wanders for 31 477 pivots; src/formulation.md §7).
use super::SolveError;
use crate::model::Model;
use crate::time::{Discretization, Pairing, Scheme};

/// `steps = "auto"` keeps ω_max·h at most this fraction of the scheme's limit.
pub const AUTO_MARGIN: f64 = 0.9;
/// The fewest steps `steps = "auto"` chooses (the scenes' default steps).
pub const AUTO_FLOOR: usize = 256;

/// h = T/k at frequency ω.
fn step(frequency: f64, k: usize) -> f64 {
    2.0 * std::f64::consts::PI / (frequency * k as f64)
}

/// The smallest k with ω_max·h ≤ `fraction`·limit (strictly below the limit when `fraction` is
/// 1), `None` without a limit.
pub fn smallest_stable_steps(scheme: Scheme, omega_max: f64, frequency: f64, fraction: f64) -> Option<usize> {
    let limit = scheme.stability_limit()? * fraction;
    // ω_max·T/k < limit  ⇔  k > ω_max·T/limit.
    let bound = omega_max * 2.0 * std::f64::consts::PI / (frequency * limit);
    let k = if fraction < 1.0 { bound.ceil() } else { bound.floor() + 1.0 };
    Some(k.max(1.0) as usize)
}

/// Refuses a scheme past its stability limit, naming ω_max, h, ω_max·h, the limit, the smallest
/// k that satisfies it and the schemes that would work at this k.
pub(crate) fn check_stability(model: &Model, disc: &Discretization, omega_max: f64) -> Result<(), SolveError> {
    let Some(limit) = disc.scheme.stability_limit() else { return Ok(()) };
    let (k, w) = (disc.steps, model.frequency);
    let h = step(w, k);
    let wh = omega_max * h;
    if wh < limit {
        return Ok(());
    }
    let k_min = smallest_stable_steps(disc.scheme, omega_max, w, 1.0).unwrap_or(k);
    let fits: Vec<String> = Scheme::ALL
        .into_iter()
        .filter_map(|s| match s.stability_limit() {
            None => Some(s.name().to_string()),
            Some(l) if wh < l => Some(format!("{s} (ω_max·h = {wh:.3} < {l:.3})")),
            Some(_) => None,
        })
        .collect();
    Err(SolveError::Limit(format!(
        "discretization.steps: {scheme} is stable only for ω_max·h < {limit:.3}, but ω_max = {omega_max:.4e} rad/s (the model as solved, compliant contacts closed) and h = T/k = {h:.4e} s (ω = {w} rad/s, k = {k}) give ω_max·h = {wh:.3}; \
         use steps ≥ {k_min} with {scheme} at this frequency (or steps = \"auto\"), or at k = {k} one of: {}",
        fits.join(", "),
        scheme = disc.scheme,
    )))
}

/// `steps = "auto"`: the smallest power of two (FFT-friendly) that keeps ω_max·h ≤
/// [`AUTO_MARGIN`]·limit at `frequency`, resolves the highest forced harmonic (k ≥ 2·harmonic + 2)
/// and is at least [`AUTO_FLOOR`]. Returns k and the note reported with the result.
pub fn auto_steps(model: &Model, scheme: Scheme, omega_max: f64, frequency: f64) -> (usize, String) {
    let resolution = 2 * model.highest_harmonic() as usize + 2;
    let stable = smallest_stable_steps(scheme, omega_max, frequency, AUTO_MARGIN).unwrap_or(0);
    let k = AUTO_FLOOR.max(resolution).max(stable).next_power_of_two();
    let wh = omega_max * step(frequency, k);
    let why = match scheme.stability_limit() {
        Some(l) => format!("ω_max·h = {wh:.3} ≤ {:.3} = {AUTO_MARGIN}·{l:.3}", AUTO_MARGIN * l),
        None => format!("no stability limit, ω_max·h = {wh:.3}; the floor {AUTO_FLOOR}"),
    };
    (k, format!("steps = \"auto\": k = {k} ({scheme}, ω = {frequency} rad/s, ω_max = {omega_max:.4e} rad/s, {why}; a power of two)"))
}

/// `scheme = "auto"`: what the user asks of the result. The scheme and k are chosen to meet it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccuracyTarget {
    /// Wanted error, relative to the peak-to-peak amplitude (`[discretization] tolerance`).
    pub tolerance: f64,
    /// Largest k the refinement may reach (`[discretization] max_steps`).
    pub max_steps: usize,
    /// The refinement stops when the next solve is projected to take longer than this [s]
    /// (`[discretization] time_budget`).
    pub time_budget: f64,
    /// What the tolerance is relative to (`[discretization] tolerance_of`).
    pub measure: AmplitudeMeasure,
}

/// What a relative error estimate divides by when compared with a tolerance
/// (`[discretization] tolerance_of`, `sweep --tolerance-of`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AmplitudeMeasure {
    /// The largest peak-to-peak amplitude of the displacement outputs (`"largest"`, the default):
    /// an output that barely moves (a node near the root) does not ask for unbounded accuracy.
    #[default]
    Largest,
    /// Each output's own peak-to-peak amplitude (`"own"`): the small outputs (the real blade's
    /// radial tip outputs, 1/11 of the largest) are held to the same relative accuracy.
    Own,
}

impl AmplitudeMeasure {
    /// The scene's and the CLI's spelling.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "largest" => Some(Self::Largest),
            "own" => Some(Self::Own),
            _ => None,
        }
    }
    /// The estimate of `a` in this measure.
    pub fn of(self, a: &crate::response::Accuracy) -> Option<f64> {
        match self {
            Self::Largest => a.relative,
            Self::Own => a.relative_own,
        }
    }
}

/// Default `[discretization] tolerance` with `scheme = "auto"`: 1e-3 of the peak-to-peak
/// amplitude, the figure issue 23 asks of the blade sweeps.
pub const AUTO_TOLERANCE: f64 = 1e-3;
/// Default `[discretization] max_steps`: 16 384 (N = 16 384·m; the largest k our measured stiff
/// blades needed under cds/galerkin, README "What accuracy costs").
pub const AUTO_MAX_STEPS: usize = 16_384;
/// Default `[discretization] time_budget` [s] for one solve of the refinement.
pub const AUTO_TIME_BUDGET: f64 = 600.0;
/// The first k of `scheme = "auto"` (unless stability or the harmonics need more): below it the
/// k/2 of the Richardson estimate is pre-asymptotic on our families (README "What accuracy costs").
pub const AUTO_FIRST_STEPS: usize = 128;

impl Default for AccuracyTarget {
    fn default() -> Self {
        AccuracyTarget { tolerance: AUTO_TOLERANCE, max_steps: AUTO_MAX_STEPS, time_budget: AUTO_TIME_BUDGET, measure: AmplitudeMeasure::Largest }
    }
}

/// The contact regimes that decide the scheme (src/formulation.md §3–§4.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContactClass {
    pub compliant: usize,
    /// Rigid on a massless DOF: a finite force through the static stiffness, like a compliant one.
    pub rigid_massless: usize,
    /// Rigid on a DOF with mass: plastic impacts, impulses.
    pub rigid_massive: usize,
}

impl ContactClass {
    pub fn of(model: &Model) -> Self {
        let mut c = ContactClass::default();
        for contact in &model.contacts {
            match contact.compliance {
                crate::model::Compliance::Compliant { .. } => c.compliant += 1,
                crate::model::Compliance::Rigid if model.contact_is_massless(contact) => c.rigid_massless += 1,
                crate::model::Compliance::Rigid => c.rigid_massive += 1,
            }
        }
        c
    }
}

/// `scheme = "auto"`: the scheme, its pairing and the first k, with the reasons. The policy
/// (README "Scheme limits", the tables of README "Accuracy", "Which scheme and pairing converge"
/// and "Exact-flow reference for compliant contact"):
/// - no contact: fourier, exact for a linear response once its harmonics are below k/2;
/// - the second-order time stepper: galerkin when every DOF carries mass (its stability limit
///   ω_max·h < 2√3 is 1.73× looser than cds's 2, and its error on the compliant stop is half
///   cds's), cds when some DOF is massless (a massless-boundary reduction: galerkin has no step
///   map there and measured order 1.37 on the two-lobe blade, cds order 1.95 and 1e-4 at
///   k = 2048);
/// - rigid contact on a DOF with mass: that stepper with forward pairing on it (second order with
///   sticking, first for pure impacts; the only second-order choice that converges to the
///   plastic-impact orbit), or bds1 with same pairing (first order, A-stable) when the stepper's
///   stable k passes `max_steps`;
/// - compliant contacts and rigid ones on massless DOFs (finite forces): the stepper with same
///   pairing, or bds2 (second order, A-stable) when its stable k passes `max_steps`. Not fourier:
///   at the force's kink its error is not C·h^p (observed orders −0.6 … 5.7), so its own estimate
///   reads 0.11–17× the error and cannot certify a tolerance.
pub fn auto_scheme(model: &Model, omega_max: f64, target: &AccuracyTarget) -> (Discretization, String) {
    let frequency = model.frequency;
    let class = ContactClass::of(model);
    let resolution = (2 * model.highest_harmonic() as usize + 2).next_power_of_two();
    let first = AUTO_FIRST_STEPS.max(resolution);
    let mass = &model.structure.mass;
    let massless = (0..model.n()).any(|i| mass.get(i, i) <= 0.0);
    let stepper = if massless { Scheme::Cds } else { Scheme::Galerkin };
    let stable_k = smallest_stable_steps(stepper, omega_max, frequency, AUTO_MARGIN).unwrap_or(0).next_power_of_two();
    let limit = stepper.stability_limit().unwrap_or(f64::INFINITY);
    let stiff = format!(
        "{stepper} ({}) needs k ≥ {stable_k} for ω_max = {omega_max:.3e} rad/s (ω_max·h ≤ {AUTO_MARGIN}·{limit:.3}), max_steps = {}",
        if massless { "the model has massless DOFs" } else { "every DOF carries mass" },
        target.max_steps
    );
    let fits = stable_k <= target.max_steps;
    let (scheme, pairing, k, why) = if model.contacts.is_empty() {
        (Scheme::Fourier, Some(Pairing::Same), first, "no contact: fourier is exact for the linear response once its harmonics are below k/2".to_string())
    } else if class.rigid_massive > 0 {
        let what = format!("{} rigid contact(s) on DOFs with mass", class.rigid_massive);
        if fits {
            // Per contact: forward for rigid, same for compliant (rigid-on-massless: the caller).
            let why = format!(
                "{what}: {stepper} with forward pairing on them (second order with sticking, first order for pure impacts), same on the others; {stiff}"
            );
            (stepper, None, first.max(stable_k), why)
        } else {
            (Scheme::Bds1, Some(Pairing::Same), first, format!("{what} and a stiff model: bds1 with same pairing (first order, A-stable); {stiff}"))
        }
    } else {
        let what = format!("{} compliant and {} rigid-on-massless contact(s) (finite forces)", class.compliant, class.rigid_massless);
        if fits {
            (stepper, Some(Pairing::Same), first.max(stable_k), format!("{what}: {stepper} with same pairing (second order); {stiff}"))
        } else {
            (Scheme::Bds2, Some(Pairing::Same), first, format!("{what} and a stiff model: bds2 with same pairing (second order, A-stable); {stiff}"))
        }
    };
    (Discretization { scheme, steps: k, pairing }, why)
}
