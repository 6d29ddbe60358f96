use std::path::PathBuf;

/// Errors from the nn crate: checkpoint I/O, bad configuration, backend setup.
#[derive(Debug, thiserror::Error)]
pub enum NnError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A burn record (module or optimizer state) could not be encoded, decoded or applied.
    #[error("{path}: model record: {message}")]
    Record { path: PathBuf, message: String },
    /// A checkpoint's JSON sidecar is malformed.
    #[error("{path}: line {line}, column {column}: invalid checkpoint metadata: {message}")]
    Metadata {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// A configuration value is out of range.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// The backend could not be set up (e.g. the global thread pool was already built).
    #[error("backend: {0}")]
    Backend(String),
}
