//! The camera engine's error type.

use crate::toric;
use std::path::{Path, PathBuf};

/// Errors of the camera engine; every one names the file (and line, frame or key) at fault.
#[derive(Debug, thiserror::Error)]
pub enum CameraError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}:{line}:{column}: {message}")]
    Parse { path: PathBuf, line: usize, column: usize, message: String },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    #[error("{0}")]
    Toric(#[from] toric::ToricError),
    #[error("model: {0}")]
    Model(String),
    /// What was asked cannot be had: an unknown style name, a card without the style's code, a
    /// reference clip or two takes that cannot make what is asked of them.
    #[error("{0}")]
    Request(String),
    /// A motion file that could not be read.
    #[error(transparent)]
    Motion(#[from] inbetween_io::IoError),
    #[error("{0}")]
    Weights(#[from] inbetween_nn::NnError),
    /// An input over one of the job's stated limits (the error names the limit's field).
    #[error("{0}")]
    Limit(#[from] inbetween_io::LimitExceeded),
    /// The job's cancel token stopped it (cancelled, or its time limit passed).
    #[error("camera job stopped: {0}")]
    Cancelled(#[from] inbetween_core::cancel::Cancelled),
}

impl CameraError {
    pub fn invalid(path: &Path, message: impl Into<String>) -> CameraError {
        CameraError::Invalid { path: path.to_path_buf(), message: message.into() }
    }
}
