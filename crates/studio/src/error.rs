//! Errors of the studio server.

use std::path::PathBuf;

/// What stops the studio or one of its requests. Request errors reach the page as JSON
/// (`{"error": "..."}`) with the status code of [`StudioError::status`].
#[derive(Debug, thiserror::Error)]
pub enum StudioError {
    /// The listening socket could not be opened.
    #[error("cannot listen on {addr}: {source}")]
    Bind { addr: String, source: std::io::Error },
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// The request itself is malformed (bad JSON field, bad file name, …).
    #[error("{0}")]
    BadRequest(String),
    /// A path outside `--root`, or no `--root` at all.
    #[error("{0}")]
    Forbidden(String),
    #[error("{0}")]
    NotFound(String),
    /// The engine refused the input (its message names file, line and what was expected).
    #[error("{0}")]
    Engine(String),
    #[error(transparent)]
    Script(#[from] inbetween_script::ScriptError),
    #[error(transparent)]
    Mocap(#[from] inbetween_mocap::MocapError),
    #[error(transparent)]
    Format(#[from] inbetween_io::IoError),
    #[error(transparent)]
    Core(#[from] inbetween_core::CoreError),
    /// The headless browser (tests and bench).
    #[error("browser: {0}")]
    Browser(String),
    #[error("runtime: {0}")]
    Runtime(String),
}

impl StudioError {
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> StudioError {
        StudioError::Io { path: path.into(), source }
    }

    /// HTTP status for this error.
    pub fn status(&self) -> u16 {
        match self {
            StudioError::BadRequest(_) => 400,
            StudioError::Forbidden(_) => 403,
            StudioError::NotFound(_) => 404,
            StudioError::Engine(_)
            | StudioError::Script(_)
            | StudioError::Mocap(_)
            | StudioError::Format(_)
            | StudioError::Core(_) => 422,
            _ => 500,
        }
    }
}

pub type Result<T> = std::result::Result<T, StudioError>;
