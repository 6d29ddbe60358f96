//! The render crate's error type.

use std::path::PathBuf;

/// Errors from rendering or writing a preview.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("invalid render input: {0}")]
    InvalidInput(String),
    #[error("encoding failed: {0}")]
    Encode(String),
    #[error("plot '{title}': {message}")]
    Plot { title: String, message: String },
}
