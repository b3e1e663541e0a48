//! The scene's errors: [`SceneError`] names the file; [`BuildError`] is what is wrong inside it
//! (a field, the value and the remedy), before the file name is put in front.
use crate::model::ModelError;
use crate::periodic::SolveError;

/// A scene that cannot be used: names the file, the field and the value.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct SceneError {
    pub file: String,
    pub message: String,
}

impl SceneError {
    pub(crate) fn new(file: &str, message: impl Into<String>) -> Self {
        SceneError { file: file.to_string(), message: message.into() }
    }

    /// `error` inside `file`.
    pub fn at(file: &str, error: BuildError) -> Self {
        SceneError::new(file, error.to_string())
    }
}

/// What is wrong with a scene's content, without the file name.
#[derive(Debug, Clone, thiserror::Error)]
pub enum BuildError {
    /// A field of the scene (`contact[0].dof`, `casing.depth`, …): the value and the remedy.
    #[error("{field}: {message}")]
    Field { field: String, message: String },
    /// The built model fails its checks (the field and the value are named).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The problem cannot be set up from the built model.
    #[error(transparent)]
    Problem(#[from] SolveError),
}

impl BuildError {
    /// The field `field` is wrong: `message` says how and what to do.
    pub fn field(field: impl Into<String>, message: impl Into<String>) -> Self {
        BuildError::Field { field: field.into(), message: message.into() }
    }
}

impl From<SceneError> for crate::Error {
    fn from(e: SceneError) -> Self {
        crate::Error::input(e.to_string())
    }
}
