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
    /// A request that cannot be drawn (an output that is neither `.gif` nor `.png`, a frame asked of a GIF).
    #[error("{0}")]
    Request(String),
    /// A motion file that could not be read.
    #[error("loading {}", path.display())]
    Load {
        path: PathBuf,
        #[source]
        source: inbetween_io::IoError,
    },
    /// Writing an animation failed.
    #[error("writing {}", path.display())]
    Writing {
        path: PathBuf,
        #[source]
        source: Box<RenderError>,
    },
    /// Drawing one frame failed.
    #[error("rendering frame {frame} of {}", file.display())]
    Frame {
        frame: usize,
        file: PathBuf,
        #[source]
        source: Box<RenderError>,
    },
}
