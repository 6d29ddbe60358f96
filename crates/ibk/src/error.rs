//! Errors of the runtime reader: each names the byte or field that was wrong and what was expected.

/// Why a file could not be opened or a pose not sampled.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum IbkError {
    /// The bytes are not a readable version 4 `.ibk` file.
    #[error("{0}")]
    Format(String),
    /// A caller's buffer does not fit the clip.
    #[error("{0}")]
    Buffer(String),
}

pub type Result<T> = std::result::Result<T, IbkError>;

pub(crate) fn format_err<T>(msg: impl Into<String>) -> Result<T> {
    Err(IbkError::Format(msg.into()))
}
