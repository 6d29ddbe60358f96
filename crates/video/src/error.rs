//! Errors of the video engine.

use inbetween_io::LimitExceeded;
use std::path::PathBuf;

/// What went wrong, naming the file (and frame) where there is one.
#[derive(Debug, thiserror::Error)]
pub enum VideoError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// A file that could not be read as a clip: which file, which frame (if known), what was expected.
    #[error("{path}{}: {message}", frame.map(|f| format!(" (frame {f})")).unwrap_or_default())]
    Decode { path: PathBuf, frame: Option<usize>, message: String },
    /// Writing a clip failed.
    #[error("{path}: {message}")]
    Encode { path: PathBuf, message: String },
    /// Neither the bundled decoder nor an ffmpeg on PATH can read the stream.
    #[error("{path}: {message}")]
    Unsupported { path: PathBuf, message: String },
    /// Bad arguments or inconsistent inputs.
    #[error("{0}")]
    Invalid(String),
    /// An input or request beyond one of the limits of
    /// [`VideoLimits`](crate::pipeline::VideoLimits), refused before the heavy work. Its `field`
    /// names the limit (a field of `VideoLimits`), so that a front end can name its own way to
    /// raise it ([`inbetween_io::limits::raise_hint`]).
    #[error("{0}")]
    Limit(#[source] LimitExceeded),
    /// A clip read from a file has more frames than
    /// [`VideoLimits::max_frames`](crate::pipeline::VideoLimits) (decoding stops one frame past
    /// the limit); reading only the first frames (`read.max_frames`, the job's
    /// [`ReadOptions::max_frames`](crate::frames::ReadOptions)) is the other way out.
    #[error("{0}; or read only the first frames with `read.max_frames`")]
    TooManyFrames(#[source] LimitExceeded),
    /// A start frame past the clip's last frame (`frames` frames).
    #[error("start frame {start} is outside the clip (frames 0..{})", frames.saturating_sub(1))]
    StartOutside { start: usize, frames: usize },
    #[error(transparent)]
    Nn(#[from] inbetween_nn::NnError),
    /// The job's [`Cancel`](inbetween_core::cancel::Cancel) token was cancelled or its time limit passed.
    #[error(transparent)]
    Cancelled(#[from] inbetween_core::cancel::Cancelled),
}

impl VideoError {
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> VideoError {
        VideoError::Io { path: path.into(), source }
    }
}
