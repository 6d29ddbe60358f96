use std::path::PathBuf;

/// Errors from the nn crate: checkpoint I/O, bad configuration, a diverged loss, backend setup.
#[derive(Debug, thiserror::Error)]
pub enum NnError {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A burn record (module or optimizer state) could not be encoded, decoded or applied.
    #[error("{}: model record: {message}", path.display())]
    Record { path: PathBuf, message: String },
    /// A checkpoint's JSON sidecar is malformed.
    #[error("{}: line {line}, column {column}: {message}", path.display())]
    Metadata { path: PathBuf, line: usize, column: usize, message: String },
    /// A weights file for another model, architecture version or configuration.
    #[error("{}: {message}", path.display())]
    Mismatch { path: PathBuf, message: String },
    /// A configuration value is out of range.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// Training diverged: the objective returned a NaN or infinite loss at this step.
    #[error("loss became {loss} at epoch {epoch}, step {step}: lower lr or clip gradients")]
    NonFiniteLoss { epoch: usize, step: usize, loss: f64 },
    /// The backend could not be set up (e.g. the global thread pool was already built).
    #[error("backend: {0}")]
    Backend(String),
    /// The objective's cancel token stopped training mid-epoch ([`crate::train::Objective::check_cancel`]);
    /// the unfinished epoch is not checkpointed, so a later run resumes from the last whole one.
    #[error("training stopped: {0}")]
    Cancelled(#[from] inbetween_core::cancel::Cancelled),
}
