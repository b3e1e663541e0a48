//! Scene files (TOML): the user's description of a periodic contact problem.
//! Parsing checks types and keys; [`Scene::to_problem`] checks values and builds the model.
mod spec;

pub use spec::*;

use crate::model::{Compliance, Contact, Force, Harmonic, Matrix, Model};
use crate::periodic::{OutputSelection, PeriodicProblem, SolverSettings};
use crate::time::{Discretization, Pairing, Scheme};
use std::path::{Path, PathBuf};

/// A scene that cannot be used: names the file, the field and the value.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct SceneError {
    pub file: String,
    pub message: String,
}

impl SceneError {
    fn new(file: &str, message: impl Into<String>) -> Self {
        SceneError { file: file.to_string(), message: message.into() }
    }
}

impl Scene {
    /// Reads and parses a scene file. Relative paths inside it resolve against its folder.
    pub fn load(path: &Path) -> Result<(Scene, PathBuf), SceneError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::new(&file, format!("cannot read the scene file: {e}")))?;
        let scene = Scene::parse(&text, &file)?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok((scene, dir))
    }

    /// Parses scene text; `file` names the source in messages.
    pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
        toml::from_str::<Scene>(text).map_err(|e| SceneError::new(file, spec::explain_toml_error(&e)))
    }

    /// Builds the model and the problem, checking every value. `file` names the source in messages.
    pub fn to_problem(&self, file: &str) -> Result<PeriodicProblem, SceneError> {
        let err = |m: String| SceneError::new(file, m);
        let mass = dense("structure.mass", &self.structure.mass).map_err(err)?;
        let stiffness = dense("structure.stiffness", &self.structure.stiffness).map_err(err)?;
        let damping = match &self.damping {
            None => None,
            Some(d) => Some(d.to_matrix(&mass, &stiffness).map_err(err)?),
        };
        let forces = self
            .force
            .iter()
            .map(|f| Force { dof: f.dof, term: Harmonic { amplitude: f.amplitude, harmonic: f.harmonic, phase: f.phase } })
            .collect();
        let contacts = self
            .contact
            .iter()
            .map(|c| Contact {
                dof: c.dof,
                direction: c.direction as f64,
                gap: c.gap,
                compliance: c.stiffness.map_or(Compliance::Rigid, |stiffness| Compliance::Compliant { stiffness }),
                motion: c.motion.iter().map(|h| Harmonic { amplitude: h.amplitude, harmonic: h.harmonic, phase: h.phase }).collect(),
            })
            .collect();
        let model = Model {
            structure: crate::model::Structure { mass, stiffness, damping },
            forces,
            contacts,
            frequency: self.excitation.frequency,
        };
        model.validate().map_err(|e| err(e.to_string()))?;

        let d = &self.discretization;
        let scheme: Scheme = d.scheme.parse().map_err(|m: String| err(format!("discretization.scheme: {m}")))?;
        let pairing = match &d.pairing {
            Some(p) => Some(p.parse::<Pairing>().map_err(|m| err(format!("discretization.pairing: {m}")))?),
            None => None,
        };
        let disc = Discretization { scheme, steps: d.steps, pairing };
        let n = model.n();
        let outputs = match &self.output {
            None => OutputSelection { displacement: (0..n).collect(), velocity: vec![], acceleration: vec![], contacts: true },
            Some(o) => OutputSelection {
                displacement: o.displacement.clone(),
                velocity: o.velocity.clone(),
                acceleration: o.acceleration.clone(),
                contacts: o.contacts,
            },
        };
        for (name, list) in [("displacement", &outputs.displacement), ("velocity", &outputs.velocity), ("acceleration", &outputs.acceleration)] {
            if let Some((i, d)) = list.iter().enumerate().find(|(_, d)| **d >= n) {
                return Err(err(format!("output.{name}[{i}]: DOF {d} does not exist, the model has DOFs 0..{}", n - 1)));
            }
        }
        let solver = SolverSettings::from_spec(self.solver.as_ref()).map_err(err)?;
        PeriodicProblem::new(model, disc, outputs, solver).map_err(|e| err(e.to_string()))
    }
}

fn dense(field: &str, spec: &MatrixSpec) -> Result<Matrix, String> {
    match spec {
        MatrixSpec::Dense(rows) => {
            let n = rows.len();
            if n == 0 {
                return Err(format!("{field}: is empty, expected n rows of n numbers"));
            }
            if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != n) {
                return Err(format!("{field}[{i}]: has {} values, expected {n} (a square matrix of {n} rows)", r.len()));
            }
            Ok(Matrix::from_rows(rows))
        }
    }
}

impl DampingSpec {
    fn to_matrix(&self, mass: &Matrix, stiffness: &Matrix) -> Result<Matrix, String> {
        match (&self.matrix, &self.rayleigh) {
            (Some(_), Some(_)) => Err("damping: give either matrix or rayleigh, not both".into()),
            (None, None) => Err("damping: the section needs matrix = [[…]] or rayleigh = [alpha, beta]".into()),
            (Some(rows), None) => dense("damping.matrix", &MatrixSpec::Dense(rows.clone())),
            (None, Some([alpha, beta])) => {
                if !(alpha.is_finite() && beta.is_finite()) {
                    return Err(format!("damping.rayleigh: [{alpha}, {beta}] must be finite"));
                }
                Ok(mass.lincomb(*alpha, stiffness, *beta))
            }
        }
    }
}
