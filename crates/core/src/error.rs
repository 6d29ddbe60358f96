//! The error type of core.

/// Errors from building core types out of invalid values.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum CoreError {
    #[error("invalid skeleton: {0}")]
    InvalidSkeleton(String),
    #[error("invalid motion: {0}")]
    InvalidMotion(String),
    #[error("invalid curve: {0}")]
    InvalidCurve(String),
    #[error("invalid keyframes: {0}")]
    InvalidKeyframes(String),
}
