//! The mocap engine's error type.

/// Errors of the mocap engine.
#[derive(Debug, thiserror::Error)]
pub enum MocapError {
    #[error("invalid input: {0}")]
    Invalid(String),
    #[error(transparent)]
    Core(#[from] inbetween_core::CoreError),
    #[error("codec: {0}")]
    Codec(String),
    #[error("i/o error on {path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error(transparent)]
    Format(#[from] inbetween_io::IoError),
    #[error("model: {0}")]
    Model(String),
    /// Weights or training (files named in the message).
    #[error(transparent)]
    Nn(#[from] inbetween_nn::NnError),
    #[error("stream: {0}")]
    Stream(String),
    /// A file given with another does not belong with it (the message names both).
    #[error("{0}")]
    Mismatch(String),
    /// Drawing or writing a preview failed.
    #[error(transparent)]
    Render(#[from] inbetween_render::RenderError),
    /// What became of a job's work (`context`: "listening on …", "the 40 frames received were
    /// kept in …"), then why it failed.
    #[error("{context}")]
    Context { context: String, source: Box<dyn std::error::Error + Send + Sync> },
    /// The caller's cancel token was cancelled (or its time limit passed).
    #[error("stopped: {0}")]
    Cancelled(#[from] inbetween_core::cancel::Cancelled),
}

pub type Result<T> = std::result::Result<T, MocapError>;
