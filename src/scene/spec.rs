//! The TOML schema of a scene (serde). Unknown keys are refused with the list of known ones.
use serde::Deserialize;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    pub structure: StructureSpec,
    pub damping: Option<DampingSpec>,
    pub excitation: ExcitationSpec,
    #[serde(default)]
    pub force: Vec<ForceSpec>,
    #[serde(default)]
    pub contact: Vec<ContactSpec>,
    /// Coulomb friction contacts (`[[friction]]`, see [`crate::scene::FrictionSpec`]).
    #[serde(default)]
    pub friction: Vec<super::FrictionSpec>,
    #[serde(default)]
    pub discretization: DiscretizationSpec,
    pub output: Option<OutputSpec>,
    pub solver: Option<SolverSpec>,
    /// Craig–Bampton reduction of the structure before solving.
    pub reduction: Option<ReductionSpec>,
    /// An out-of-round casing: adds obstacle motion to every contact.
    pub casing: Option<CasingSpec>,
    /// The names of the scene's units (labels only; default m, N, s).
    pub units: Option<UnitsSpec>,
}

/// `[units]`: the length, force and time units the scene's numbers are in (see
/// [`crate::model::units`] for the allowed names). Mass is force·time²/length, angles radians.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitsSpec {
    pub length: Option<String>,
    pub force: Option<String>,
    pub time: Option<String>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureSpec {
    /// Mass matrix M: n×n dense rows, or `{ matrix_market = "M.mtx" }`.
    pub mass: Option<MatrixSpec>,
    /// Stiffness matrix K, as `mass`.
    pub stiffness: Option<MatrixSpec>,
    /// A built-in model instead of matrices: `{ kind = "blade", … }` (the rest is a
    /// [`crate::fe::BladeSpec`]).
    pub generator: Option<toml::Table>,
    /// CalculiX's matrix output instead of matrices: the job name, path relative to the scene
    /// (`"blade"` reads `blade.sti`, `blade.mas` and the node map `blade.dof`).
    pub calculix: Option<String>,
    /// DOFs removed (clamped), in the numbering of the matrices (indices, or nodes as in
    /// outputs). Every other DOF index of the scene keeps that numbering.
    #[serde(default)]
    pub fixed: Vec<DofSpec>,
}

/// A structural matrix: dense rows, or a Matrix Market file (path relative to the scene file).
/// Anything else is kept to be refused with a message naming the field.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum MatrixSpec {
    Dense(Vec<Vec<f64>>),
    File(MatrixFileSpec),
    Invalid(toml::Value),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MatrixFileSpec {
    pub matrix_market: String,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// C: dense rows or `{ matrix_market = "C.mtx" }`.
    pub matrix: Option<MatrixSpec>,
    /// C = alpha·M + beta·K (on the full model; projected exactly by a reduction).
    pub rayleigh: Option<[f64; 2]>,
    /// Damping ratios ζ_j of the reduced model's modes, ascending frequency; the last one is
    /// repeated for the remaining modes. Needs `[reduction]`.
    pub modal_ratios: Option<Vec<f64>>,
}

/// A DOF named by index (the matrices' numbering), by a generator's node name (`"LE"`, its
/// radial z DOF, or `"LE:x"`, `"LE:y"`, `"LE:z"`), by an FE node number and direction
/// (`"1234:x"`), or as a table `{ node = 1234, axis = "x" }`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum DofSpec {
    Index(usize),
    Name(String),
    Node {
        node: NodeSpec,
        axis: Option<String>,
    },
    /// Anything else, refused with a message naming the field.
    Invalid(toml::Value),
}

impl std::fmt::Display for DofSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DofSpec::Index(i) => write!(f, "{i}"),
            DofSpec::Name(n) => write!(f, "\"{n}\""),
            DofSpec::Node { node, axis: Some(a) } => write!(f, "{{ node = {node}, axis = \"{a}\" }}"),
            DofSpec::Node { node, axis: None } => write!(f, "{{ node = {node} }}"),
            DofSpec::Invalid(v) => write!(f, "{v}"),
        }
    }
}

/// A node: an FE node number (a CalculiX job's, or the blade generator's: index + 1, the numbering
/// of its CalculiX deck) or a generator's tip name (`"LE"`, `"MC"`, `"TE"`).
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum NodeSpec {
    Number(u64),
    Name(String),
}

impl std::fmt::Display for NodeSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NodeSpec::Number(n) => write!(f, "{n}"),
            NodeSpec::Name(n) => write!(f, "\"{n}\""),
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReductionSpec {
    /// `"craig-bampton"` or `"massless-boundary"`.
    pub method: String,
    /// Fixed-interface (Craig–Bampton) or free-interface (massless boundary) modes η (default [`crate::reduction::DEFAULT_MODES`]).
    pub modes: Option<usize>,
    /// DOFs kept physical besides the contact DOFs.
    #[serde(default)]
    pub extra_boundary: Vec<DofSpec>,
}

/// An out-of-round casing, turning relative to the blade at Ω = excitation.frequency / lobes
/// (see [`crate::scene::casing`] for the formulas and signs). Its shape is one of: `depth` (L
/// cosine lobes), `harmonics` (a Fourier series in the casing's angle) or `profile` (a sampled
/// clearance change over one turn, from a CSV file).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CasingSpec {
    /// Symmetry order L = engine order (≥ 1; default 1 with `harmonics` or `profile`): the
    /// problem's fundamental is ω = L·Ω, and every order of the shape is a multiple of L.
    pub lobes: Option<u32>,
    /// Depth δ ≥ 0 of L cosine lobes (the clearance varies by ±δ around each contact's `gap`).
    pub depth: Option<f64>,
    /// Clearance change Σ amplitude·cos(order·θ + phase) in the casing's angle θ [rad].
    pub harmonics: Option<Vec<CasingHarmonicSpec>>,
    /// A CSV file (path relative to the scene): header `angle_deg,clearance` or
    /// `angle_rad,clearance`, then the clearance change at uniformly spaced angles over one turn.
    pub profile: Option<String>,
    /// Casing radius R [m] (> 0).
    pub radius: f64,
    /// Stagger γ [degrees]: angle between the tip chord and the engine axis (default 0).
    #[serde(default)]
    pub stagger: f64,
    /// Rotation speed Ω [rad/s]; optional, must then equal excitation.frequency / lobes.
    pub speed: Option<f64>,
    /// Phase φ0 of the lobes at t = 0 [rad] (default 0; with `depth` only).
    #[serde(default)]
    pub phase: f64,
    /// Circumferential arc position s [m] of each contact along the direction of rotation;
    /// default: from the blade generator's node positions or the contacts' `position`.
    pub arc: Option<Vec<f64>>,
    /// Matrix Market scenes: the rotation axis's direction (rotation by the right-hand rule),
    /// for `normal = "radial"` and the contacts' angles from their `position`.
    pub axis: Option<[f64; 3]>,
    /// A point of the rotation axis (default the origin).
    pub center: Option<[f64; 3]>,
}

/// One term of `casing.harmonics`: amplitude·cos(order·θ + phase).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CasingHarmonicSpec {
    pub order: u32,
    pub amplitude: f64,
    #[serde(default)]
    pub phase: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExcitationSpec {
    /// Fundamental angular frequency ω [rad/s].
    pub frequency: f64,
}

fn one() -> u32 {
    1
}
fn yes() -> bool {
    true
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSpec {
    pub dof: Option<usize>,
    /// A node instead of `dof`: a generator's `"LE"`, `"MC"`, `"TE"`, or an FE node number.
    pub node: Option<NodeSpec>,
    /// With `node`: `"x"`, `"y"` or `"z"` (default `"z"`, radial, for a named node; required
    /// with a node number).
    pub axis: Option<String>,
    pub amplitude: f64,
    #[serde(default = "one")]
    pub harmonic: u32,
    #[serde(default)]
    pub phase: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HarmonicSpec {
    pub amplitude: f64,
    #[serde(default = "one")]
    pub harmonic: u32,
    #[serde(default)]
    pub phase: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    pub dof: Option<usize>,
    /// A node instead of `dof`: a generator's `"LE"`, `"MC"`, `"TE"`, or an FE node number.
    pub node: Option<NodeSpec>,
    /// `"tip"`: one contact on every mid-thickness tip node of the generated blade (LE to TE),
    /// each along its radial normal.
    pub nodes: Option<String>,
    /// With `node`: `"x"`, `"y"` or `"z"` (default `"z"`, radial).
    pub axis: Option<String>,
    /// A node's DOFs (x, y, z) by index, for a `normal` in Matrix Market scenes.
    pub dofs: Option<Vec<usize>>,
    /// The contact's normal over the node's DOFs: `[nx, ny, nz]` (normalised) or `"radial"`.
    pub normal: Option<NormalSpec>,
    /// The node's coordinates (Matrix Market scenes), for `normal = "radial"` and the casing.
    pub position: Option<[f64; 3]>,
    /// +1 or −1 along a single DOF (default +1).
    pub direction: Option<i32>,
    pub gap: f64,
    pub stiffness: Option<f64>,
    #[serde(default)]
    pub motion: Vec<HarmonicSpec>,
    /// `"same"` or `"forward"`: this contact's pairing, over `discretization.pairing`.
    pub pairing: Option<String>,
}

/// A contact normal: components, or a name (`"radial"`); anything else is refused by name.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum NormalSpec {
    Vector(Vec<f64>),
    Name(String),
    Invalid(toml::Value),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscretizationSpec {
    #[serde(default = "default_scheme")]
    pub scheme: String,
    /// Instants per period k, or `"auto"`: the smallest power of two within the scheme's
    /// stability limit (see `periodic::limits::auto_steps`).
    #[serde(default = "default_steps")]
    pub steps: StepsSpec,
    pub pairing: Option<String>,
    /// `"richardson"` (default: a second solve at k/2 estimates the error of every result) or
    /// `"none"` (skip it, for speed).
    pub error_estimate: Option<String>,
    /// Refine the LCP's orbit by the event-fitted polish (default false).
    #[serde(default)]
    pub polish: bool,
    /// Orbits of period p·T (default 1): the LCP over p forcing periods, `steps` per forcing
    /// period (`PeriodicProblem::set_period_multiple`).
    pub period_multiple: Option<i64>,
    /// With `scheme = "auto"`: the wanted error relative to the peak-to-peak amplitude
    /// (default `periodic::limits::AUTO_TOLERANCE`).
    pub tolerance: Option<f64>,
    /// With `scheme = "auto"`: the largest k the refinement may reach.
    pub max_steps: Option<i64>,
    /// With `scheme = "auto"`: stop refining when the next solve is projected past this [s].
    pub time_budget: Option<f64>,
    /// With `scheme = "auto"`: what `tolerance` is relative to, `"largest"` (default) or `"own"`
    /// (`periodic::limits::AmplitudeMeasure`).
    pub tolerance_of: Option<String>,
}

/// `steps = 512` or `steps = "auto"`; anything else is kept to be refused naming the field.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum StepsSpec {
    Count(usize),
    Named(String),
    Invalid(toml::Value),
}

impl StepsSpec {
    /// The explicit count, `None` for `"auto"` (or an invalid value, refused when building).
    pub fn count(&self) -> Option<usize> {
        match self {
            StepsSpec::Count(k) => Some(*k),
            _ => None,
        }
    }
}

fn default_scheme() -> String {
    "cds".into()
}
fn default_steps() -> StepsSpec {
    StepsSpec::Count(256)
}

impl Default for DiscretizationSpec {
    fn default() -> Self {
        DiscretizationSpec {
            scheme: default_scheme(),
            steps: default_steps(),
            pairing: None,
            error_estimate: None,
            polish: false,
            tolerance: None,
            max_steps: None,
            time_budget: None,
            tolerance_of: None,
            period_multiple: None,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    #[serde(default)]
    pub displacement: Vec<DofSpec>,
    #[serde(default)]
    pub velocity: Vec<DofSpec>,
    #[serde(default)]
    pub acceleration: Vec<DofSpec>,
    /// Contact forces and gaps (default true).
    #[serde(default = "yes")]
    pub contacts: bool,
    /// The Floquet stability of every result (front ends: FMU outputs `stable` and `multiplier`,
    /// C API `pc_result_stability`; default false).
    #[serde(default)]
    pub stability: bool,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// "auto" | "lemke".
    pub method: Option<String>,
    /// Certification tolerance of the LCP residual, relative to max(1, ‖q‖∞).
    pub tolerance: Option<f64>,
    /// Removed (it solved a compliant contact in disguise); kept only to refuse it with the
    /// remedy, whatever its value.
    pub regularization: Option<serde::de::IgnoredAny>,
}

/// toml's message already carries the line, column and the offending text; add the closest
/// known key when the error is an unknown field.
pub fn explain_toml_error(e: &toml::de::Error) -> String {
    let msg = e.to_string();
    let Some(start) = msg.find("unknown field `") else { return msg };
    let rest = &msg[start + 15..];
    let Some(end) = rest.find('`') else { return msg };
    let unknown = &rest[..end];
    let expected: Vec<&str> = rest.split('`').skip(2).step_by(2).collect();
    match expected.iter().min_by_key(|k| edit_distance(unknown, k)) {
        Some(best) if edit_distance(unknown, best) <= 3 => format!("{msg}\ndid you mean `{best}`?"),
        _ => msg,
    }
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            cur.push((prev[j] + usize::from(ca != *cb)).min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}
