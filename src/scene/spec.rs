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
    #[serde(default)]
    pub discretization: DiscretizationSpec,
    pub output: Option<OutputSpec>,
    pub solver: Option<SolverSpec>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureSpec {
    /// Mass matrix M, n×n dense rows.
    pub mass: MatrixSpec,
    /// Stiffness matrix K, n×n dense rows.
    pub stiffness: MatrixSpec,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum MatrixSpec {
    Dense(Vec<Vec<f64>>),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    pub matrix: Option<Vec<Vec<f64>>>,
    /// C = alpha·M + beta·K.
    pub rayleigh: Option<[f64; 2]>,
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
fn plus_one() -> i32 {
    1
}
fn yes() -> bool {
    true
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSpec {
    pub dof: usize,
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
    pub dof: usize,
    #[serde(default = "plus_one")]
    pub direction: i32,
    pub gap: f64,
    pub stiffness: Option<f64>,
    #[serde(default)]
    pub motion: Vec<HarmonicSpec>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscretizationSpec {
    #[serde(default = "default_scheme")]
    pub scheme: String,
    #[serde(default = "default_steps")]
    pub steps: usize,
    pub pairing: Option<String>,
}

fn default_scheme() -> String {
    "cds".into()
}
fn default_steps() -> usize {
    256
}

impl Default for DiscretizationSpec {
    fn default() -> Self {
        DiscretizationSpec { scheme: default_scheme(), steps: default_steps(), pairing: None }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    #[serde(default)]
    pub displacement: Vec<usize>,
    #[serde(default)]
    pub velocity: Vec<usize>,
    #[serde(default)]
    pub acceleration: Vec<usize>,
    /// Contact forces and gaps (default true).
    #[serde(default = "yes")]
    pub contacts: bool,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// "auto" | "lemke".
    pub method: Option<String>,
    /// Certification tolerance of the LCP residual, relative to max(1, ‖q‖∞).
    pub tolerance: Option<f64>,
    /// Opt-in Tikhonov retry when the LCP fails (relative to max|A|); recorded in the result.
    pub regularization: Option<f64>,
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
