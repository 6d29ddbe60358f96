//! [`FaceError`]: the face engine's error (re-exported as `data::FaceError`, where the readers
//! produce most of them). Parse errors name the file, the 1-based line, the 1-based column with its
//! header name where there is one, and what was expected.

use std::fmt;

/// A column of a CSV file: 1-based position and, where the header gave one, its name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Column {
    /// 1-based field position on the line.
    pub index: usize,
    /// The header name of that field (empty when unknown, e.g. a field past the header's end).
    pub name: String,
}

impl fmt::Display for Column {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.name.is_empty() {
            write!(f, "column {}", self.index)
        } else {
            write!(f, "column {} ({})", self.index, self.name)
        }
    }
}

fn column_prefix(c: &Option<Column>) -> String {
    match c {
        Some(c) => format!("{c}: "),
        None => String::new(),
    }
}

/// Errors of the face data layer.
#[derive(Debug, thiserror::Error)]
pub enum FaceError {
    /// Reading or writing a file failed.
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// The file holds no header (nothing but blank lines or comments).
    #[error("{file}: empty file; expected {expected}")]
    Empty { file: String, expected: String },
    /// A problem at one line (and column) of a text file.
    #[error("{file}:{line}: {col}{message}", col = column_prefix(.column))]
    Parse { file: String, line: usize, column: Option<Column>, message: String },
    /// A problem with the file as a whole (JSON structure, UTF-8).
    #[error("{file}: {message}")]
    File { file: String, message: String },
    /// An argument out of range, or a clip that breaks the rules of [`crate::data::BlendshapeClip`]
    /// (those messages start "invalid clip: ", [`FaceError::clip`]).
    #[error("{0}")]
    Invalid(String),
    /// Weights could not be loaded or saved.
    #[error(transparent)]
    Weights(#[from] inbetween_nn::NnError),
    /// An input over one of the job's stated limits (the error names the limit's field).
    #[error("{0}")]
    Limit(#[from] inbetween_io::LimitExceeded),
    /// The job's cancel token stopped it (cancelled, or its time limit passed).
    #[error("face job stopped: {0}")]
    Cancelled(#[from] inbetween_core::cancel::Cancelled),
    /// Staging, writing or moving an output into place failed (`what`: the step and the file).
    #[error("{what}")]
    Output {
        what: String,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

impl FaceError {
    /// A clip that breaks the rules of [`crate::data::BlendshapeClip`].
    pub(crate) fn clip(message: impl std::fmt::Display) -> Self {
        FaceError::Invalid(format!("invalid clip: {message}"))
    }

    pub(crate) fn parse(file: &str, line: usize, column: Option<Column>, message: impl Into<String>) -> Self {
        FaceError::Parse { file: file.to_string(), line, column, message: message.into() }
    }
}

/// A field as it appears in an error message: quoted, at most 40 characters.
pub(crate) fn shown(field: &str) -> String {
    let mut s: String = field.chars().take(40).collect();
    if field.chars().count() > 40 {
        s.push('…');
    }
    format!("'{s}'")
}
