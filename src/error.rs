//! The crate's error: a kind that every front end maps to its own status, and a message that
//! names the file or field, the value and the remedy.
//!
//! Each room keeps its own typed error (`ModelError`, `SceneError`, `SolveError`, `DatError`, …);
//! they convert into [`Error`] at the edges, where only the kind and the message matter:
//!
//! | kind | CLI exit status | C API | FMI |
//! |---|---|---|---|
//! | `Input` | 2 | `PC_ERROR_INPUT` | `fmi2Error` |
//! | `Limit` | 2 | `PC_ERROR_INPUT` | `fmi2Error` |
//! | `Io` | 2 | `PC_ERROR_INPUT` | `fmi2Error` |
//! | `Solve` | 1 | `PC_ERROR_SOLVER` | `fmi2Error` (the instance may retry after a change) |

/// What went wrong, as far as the caller's next move is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// The input is wrong: a file, a field or a value; the message says which and what is allowed.
    Input,
    /// The input is legal but larger than we accept (LCP size, dense work, matrix order).
    Limit,
    /// A file could not be read or written.
    Io,
    /// The solver ran and did not reach a certified answer (typed outcome and remedy).
    Solve,
}

impl ErrorKind {
    /// The CLI's exit status: 1 a solver failure, 2 bad input (README, "Exit status").
    pub fn exit_status(self) -> u8 {
        match self {
            ErrorKind::Solve => 1,
            ErrorKind::Input | ErrorKind::Limit | ErrorKind::Io => 2,
        }
    }
}

/// A failure with its kind and a message for a person.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct Error {
    kind: ErrorKind,
    message: String,
}

impl Error {
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Self {
        Error { kind, message: message.into() }
    }
    pub fn input(message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Input, message)
    }
    pub fn limit(message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Limit, message)
    }
    pub fn io(message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Io, message)
    }
    pub fn solve(message: impl Into<String>) -> Self {
        Error::new(ErrorKind::Solve, message)
    }
    pub fn kind(&self) -> ErrorKind {
        self.kind
    }
    pub fn message(&self) -> &str {
        &self.message
    }
    /// The same error with `what` in front ("sweep point 3: …"), kind kept.
    pub fn context(self, what: impl std::fmt::Display) -> Self {
        Error { kind: self.kind, message: format!("{what}: {}", self.message) }
    }
}

/// A result whose error carries its kind.
pub type Result<T, E = Error> = std::result::Result<T, E>;
