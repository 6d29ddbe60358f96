//! Errors of the script engine.

use std::path::PathBuf;

/// Where in the script a problem is: 1-based line and sentence number plus the sentence itself.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct SentenceRef {
    /// 1-based line of the script file where the sentence starts.
    pub line: usize,
    /// 1-based index of the sentence in the script.
    pub sentence: usize,
    pub text: String,
}

impl std::fmt::Display for SentenceRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}, sentence {} (\"{}\")", self.line, self.sentence, self.text)
    }
}

/// A problem with one sentence. The rest of the script still runs; these are collected and shown.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Diagnostic {
    pub at: SentenceRef,
    /// The word the problem is about, when there is one.
    pub word: Option<String>,
    pub message: String,
    /// Closest known words, for unknown words.
    pub suggestions: Vec<String>,
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.at, self.message)?;
        if !self.suggestions.is_empty() {
            write!(f, " (did you mean {}?)", self.suggestions.join(", "))?;
        }
        Ok(())
    }
}

/// What stops the whole run (as opposed to a [`Diagnostic`] on one sentence).
#[derive(Debug, thiserror::Error)]
pub enum ScriptError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// The script holds no usable sentence at all.
    #[error("{path}: the script is empty (write sentences such as \"In the room, a desk is near a bed$\")")]
    Empty { path: PathBuf },
    /// A model or asset file that could not be read.
    #[error("{path}: {message}")]
    Asset { path: PathBuf, message: String },
    #[error("{0}")]
    Invalid(String),
    /// The script asks for more than one of the job's stated limits (the error names the field).
    #[error("{0}")]
    Limit(#[from] inbetween_io::LimitExceeded),
    /// The job's cancel token was cancelled or its time limit passed; nothing was written.
    #[error("script job stopped: {0}")]
    Cancelled(#[from] inbetween_core::cancel::Cancelled),
}

impl ScriptError {
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> ScriptError {
        ScriptError::Io { path: path.into(), source }
    }
}
