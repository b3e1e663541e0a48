//! The files a scene references (matrices, an FE code's output, …): one list, so that every front
//! end finds them the same way. Paths are relative to the scene file's folder unless absolute.
use super::{MatrixSpec, Scene};
use crate::model::ModelError;

/// One scene field that names files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileReference {
    /// The field in the scene's words, e.g. `structure.mass.matrix_market`.
    pub field: String,
    /// The value as written in the scene (a path, or a job name standing for several files).
    pub value: String,
    /// The files the value stands for, as paths relative to the scene's folder (or absolute).
    pub files: Vec<String>,
}

impl FileReference {
    fn single(field: String, value: &str) -> Self {
        FileReference { field, value: value.to_string(), files: vec![value.to_string()] }
    }
}

impl Scene {
    /// Every file the scene reads when it is built, in the order the fields appear in the scene's
    /// schema. A new key that reads a file adds itself here and is then packaged into the FMU.
    pub fn referenced_files(&self) -> Vec<FileReference> {
        let mut refs = Vec::new();
        let mut matrix = |field: &str, spec: Option<&MatrixSpec>| {
            if let Some(MatrixSpec::File(f)) = spec {
                refs.push(FileReference::single(format!("{field}.matrix_market"), &f.matrix_market));
            }
        };
        matrix("structure.mass", self.structure.mass.as_ref());
        matrix("structure.stiffness", self.structure.stiffness.as_ref());
        matrix("damping.matrix", self.damping.as_ref().and_then(|d| d.matrix.as_ref()));
        if let Some(profile) = self.casing.as_ref().and_then(|c| c.profile.as_ref()) {
            refs.push(FileReference::single("casing.profile".into(), profile));
        }
        if let Some(job) = &self.structure.calculix {
            let files = ["sti", "mas", "dof"].iter().map(|ext| format!("{job}.{ext}")).collect();
            refs.insert(0, FileReference { field: "structure.calculix".into(), value: job.clone(), files });
        }
        refs
    }
}

impl Scene {
    /// `e` about the mass or the stiffness with the file that matrix was read from named
    /// (Matrix Market, or the CalculiX job's `.mas`/`.sti`), so that the user knows which file to
    /// correct. A reduced model's matrices are not the file's: `e` is returned as is.
    pub(super) fn name_matrix_file(&self, e: ModelError) -> ModelError {
        let (spec, ext) = match e.field.split('[').next() {
            Some("structure.mass") => (self.structure.mass.as_ref(), "mas"),
            Some("structure.stiffness") => (self.structure.stiffness.as_ref(), "sti"),
            _ => return e,
        };
        let file = match (spec, &self.structure.calculix) {
            _ if self.reduction.is_some() => return e,
            (Some(MatrixSpec::File(f)), _) => f.matrix_market.clone(),
            (_, Some(job)) => format!("{job}.{ext}"),
            _ => return e,
        };
        ModelError::new(format!("{} (read from {file}; DOFs numbered from 0)", e.field), e.message)
    }
}
