//! The structure of a scene: dense rows, Matrix Market files or the blade generator, the damping
//! defined on the full model, and the clamping (`structure.fixed`).
use super::contacts::Resolver;
use super::{BuildError, DofSpec, MatrixSpec, Scene, Source};
use crate::fe::{Blade, BladeSpec, DofMap, NodeMap};
use crate::model::{Matrix, Structure};
use std::path::Path;

/// How the damping was given on the full model, as the reduction needs to know it.
#[derive(Default)]
pub(super) struct DampingGiven {
    pub modal_ratios: Option<Vec<f64>>,
    pub rayleigh: Option<(f64, f64)>,
}

impl Scene {
    /// Loads or generates the structure (M, K; no damping yet) in the scene's numbering, with the
    /// node map of a generator or a CalculiX job.
    pub(super) fn structure_source(&self, dir: &Path) -> Result<(Source, Structure, Option<NodeMap>), BuildError> {
        let s = &self.structure;
        let given = [s.generator.is_some(), s.mass.is_some() || s.stiffness.is_some(), s.calculix.is_some()];
        if given.iter().filter(|g| **g).count() > 1 {
            return Err(BuildError::field("structure", "give one of generator = { … }, calculix = \"job\", or mass and stiffness, not several"));
        }
        if let Some(job) = &s.calculix {
            let model = crate::fe::read_calculix(&dir.join(job)).map_err(|e| BuildError::field("structure.calculix", format!("\"{job}\": {e}")))?;
            let structure = Structure { mass: Matrix::Sparse(model.mass), stiffness: Matrix::Sparse(model.stiffness), damping: None };
            return Ok((Source::Files, structure, Some(model.nodes)));
        }
        match (&s.generator, &s.mass, &s.stiffness) {
            (Some(table), _, _) => generate(table),
            (None, Some(m), Some(k)) => {
                let inline = matches!(m, MatrixSpec::Dense(_)) && matches!(k, MatrixSpec::Dense(_));
                let mass = load_matrix("structure.mass", m, dir)?;
                let stiffness = load_matrix("structure.stiffness", k, dir)?;
                Ok((if inline { Source::Inline } else { Source::Files }, Structure { mass, stiffness, damping: None }, None))
            }
            (None, None, _) => {
                Err(BuildError::field("structure.mass", "is missing (give mass and stiffness, generator = { kind = \"blade\", … } or calculix = \"job\")"))
            }
            (None, Some(_), None) => Err(BuildError::field("structure.stiffness", "is missing")),
        }
    }

    /// The blade of `structure.generator`, if the scene has one (`file` names it in messages).
    pub fn generator_blade(&self, file: &str) -> Result<Option<Blade>, super::SceneError> {
        let Some(table) = &self.structure.generator else { return Ok(None) };
        match generate(table).map_err(|e| super::SceneError::at(file, e))? {
            (Source::Blade(blade), _, _) => Ok(Some(*blade)),
            _ => Ok(None),
        }
    }

    /// Adds the `[damping]` section to the structure (full model, scene numbering) and checks
    /// the sizes against structure.mass.
    pub(super) fn damped(&self, mut full: Structure, dir: &Path) -> Result<(Structure, DampingGiven), BuildError> {
        let mut given = DampingGiven::default();
        if let Some(d) = &self.damping {
            let count = [d.matrix.is_some(), d.rayleigh.is_some(), d.modal_ratios.is_some()].iter().filter(|b| **b).count();
            if count > 1 {
                return Err(BuildError::field("damping", "give one of matrix, rayleigh or modal_ratios, not several"));
            }
            if count == 0 {
                return Err(BuildError::field(
                    "damping",
                    "the section needs matrix = [[…]] (or { matrix_market = … }), rayleigh = [alpha, beta] or modal_ratios = [ζ, …]",
                ));
            }
            if let Some(m) = &d.matrix {
                full.damping = Some(load_matrix("damping.matrix", m, dir)?);
            }
            if let Some([alpha, beta]) = d.rayleigh {
                if !(alpha.is_finite() && beta.is_finite()) {
                    return Err(BuildError::field("damping.rayleigh", format!("[{alpha}, {beta}] must be finite")));
                }
                full.damping = Some(full.mass.lincomb(alpha, &full.stiffness, beta));
                given.rayleigh = Some((alpha, beta));
            }
            if let Some(z) = &d.modal_ratios {
                given.modal_ratios = Some(self.modal_ratios(z)?);
            }
        }
        check_sizes(&full)?;
        Ok((full, given))
    }

    fn modal_ratios(&self, z: &[f64]) -> Result<Vec<f64>, BuildError> {
        if self.reduction.is_none() {
            return Err(BuildError::field(
                "damping.modal_ratios",
                "needs a [reduction] section (the ratios apply to the reduced model's modes); use rayleigh or matrix on an unreduced model",
            ));
        }
        if z.is_empty() {
            return Err(BuildError::field("damping.modal_ratios", "is empty, give at least one ratio"));
        }
        // Written to refuse NaN as well.
        if let Some((i, v)) = z.iter().enumerate().find(|(_, v)| !(v.is_finite() && **v >= 0.0)) {
            return Err(BuildError::field(format!("damping.modal_ratios[{i}]"), format!("is {v}, must be finite and ≥ 0")));
        }
        Ok(z.to_vec())
    }

    /// Removes the DOFs of `structure.fixed` (indices, or nodes through `nodes`); the map goes
    /// from the scene's numbering to the clamped one.
    pub(super) fn clamp(&self, full: Structure, source: &Source, nodes: Option<&NodeMap>) -> Result<(Structure, DofMap), BuildError> {
        let n = full.mass.nrows();
        if self.structure.fixed.is_empty() {
            return Ok((full, DofMap::identity(n)));
        }
        let identity = DofMap::identity(n);
        let resolver = Resolver { source, dofs: &identity, n_user: n, nodes };
        let mut fixed = Vec::with_capacity(self.structure.fixed.len());
        for (i, d) in self.structure.fixed.iter().enumerate() {
            fixed.push(match d {
                DofSpec::Index(d) => *d,
                other => resolver.output(&format!("structure.fixed[{i}]"), other)?,
            });
        }
        crate::fe::clamp_structure(&full, &fixed).map_err(|e| BuildError::field("structure.fixed", e.to_string()))
    }
}

/// The blade generator: `structure.generator = { kind = "blade", … }`.
fn generate(table: &toml::Table) -> Result<(Source, Structure, Option<NodeMap>), BuildError> {
    let field = "structure.generator";
    let mut table = table.clone();
    let kind = table.remove("kind");
    match kind.as_ref().map(|k| k.as_str()) {
        Some(Some("blade")) => {}
        Some(Some(other)) => return Err(BuildError::field("structure.generator.kind", format!("is \"{other}\", expected \"blade\""))),
        Some(None) => return Err(BuildError::field("structure.generator.kind", format!("is {}, expected \"blade\"", kind.expect("some")))),
        None => return Err(BuildError::field(field, "needs kind = \"blade\"")),
    }
    let spec: BladeSpec =
        serde::Deserialize::deserialize(toml::Value::Table(table)).map_err(|e: toml::de::Error| BuildError::field(field, e.to_string().trim()))?;
    let params = spec.params().map_err(|e| BuildError::field(field, e.to_string().trim_start_matches("blade generator: ")))?;
    let blade = Blade::generate(&params).map_err(|e| BuildError::field(field, e.to_string()))?;
    let structure = blade.structure();
    let nodes = blade.node_map();
    Ok((Source::Blade(Box::new(blade)), structure, Some(nodes)))
}

/// Damping and stiffness must have the size of the mass matrix.
fn check_sizes(full: &Structure) -> Result<(), BuildError> {
    let n = full.mass.nrows();
    if let Some(c) = &full.damping
        && (c.nrows() != n || c.ncols() != n)
    {
        return Err(BuildError::field("damping.matrix", format!("is {}×{}, expected {n}×{n} (the size of structure.mass)", c.nrows(), c.ncols())));
    }
    let k = &full.stiffness;
    if k.nrows() != n || k.ncols() != n {
        return Err(BuildError::field("structure.stiffness", format!("is {}×{}, expected {n}×{n} (the size of structure.mass)", k.nrows(), k.ncols())));
    }
    Ok(())
}

/// A matrix from dense rows or a Matrix Market file.
pub(super) fn load_matrix(field: &str, spec: &MatrixSpec, dir: &Path) -> Result<Matrix, BuildError> {
    match spec {
        MatrixSpec::Dense(rows) => dense(field, rows),
        MatrixSpec::File(f) => {
            let path = dir.join(&f.matrix_market);
            crate::fe::read_matrix_market(&path)
                .map(Matrix::Sparse)
                .map_err(|e| BuildError::field(format!("{field}.matrix_market"), format!("\"{}\": {e}", f.matrix_market)))
        }
        MatrixSpec::Invalid(v) => Err(BuildError::field(field, format!("is {v}, expected n rows of n numbers [[…], …] or {{ matrix_market = \"file.mtx\" }}"))),
    }
}

fn dense(field: &str, rows: &[Vec<f64>]) -> Result<Matrix, BuildError> {
    let n = rows.len();
    if n == 0 {
        return Err(BuildError::field(field, "is empty, expected n rows of n numbers"));
    }
    if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != n) {
        return Err(BuildError::field(format!("{field}[{i}]"), format!("has {} values, expected {n} (a square matrix of {n} rows)", r.len())));
    }
    Ok(Matrix::from_rows(rows))
}
