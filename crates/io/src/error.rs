//! The io crate's error type.

use std::path::PathBuf;

/// Everything that can go wrong reading or writing a motion file.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The operating system refused a read or write.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The text does not follow the format: `file:line: expected …, found …`.
    #[error("{file}:{line}: expected {expected}, found {found}")]
    Syntax { file: String, line: usize, expected: String, found: String },
    /// The text parses but describes an invalid skeleton or motion.
    #[error("{file}:{line}: {message}")]
    Invalid { file: String, line: usize, message: String },
    /// A step on a motion read (cropping, resampling) failed: `what` names the step.
    #[error("{what}")]
    Motion {
        what: String,
        #[source]
        source: inbetween_core::CoreError,
    },
    /// `load_motion` cannot tell the format from the file name.
    #[error("{}: unknown motion format; expected a .bvh or .amc file", path.display())]
    UnknownFormat { path: PathBuf },
    /// An `.amc` file whose skeleton `.asf` is not beside it.
    #[error("{}: no skeleton file found; expected one of {}", amc.display(), list_paths(tried))]
    MissingAsf { amc: PathBuf, tried: Vec<PathBuf> },
}

fn list_paths(paths: &[PathBuf]) -> String {
    paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
}
