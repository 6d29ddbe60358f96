//! File formats: BVH, ASF/AMC, and the shared file helpers: atomic writes ([`write_atomic`]), whole-or-none
//! output sets ([`OutputSet`]), the error for inputs over a job's stated limits ([`LimitExceeded`]), locating
//! shared data ([`data`]), the progress bar every long job uses ([`progress::Progress`]), the
//! bench/report harness ([`report`]: tables, reports, timings), scaling runs ([`scale`]: a child's time
//! and peak memory), UTF-8 decoding with the failing line ([`text`]) and a motion file described in
//! words ([`info`]).
//!
//! Every reader returns [`IoError`] on bad input (never panics); its message names the file, the
//! 1-based line and what was expected there.

pub mod asf;
pub mod bvh;
pub mod convert;
pub mod data;
mod error;
pub mod fsutil;
pub mod gltf_buffer;
pub mod info;
mod lexer;
pub mod limits;
pub mod motion_gltf;
pub mod output_set;
pub mod progress;
pub mod report;
pub mod scale;
pub mod text;

pub use asf::{parse_asf_amc, read_asf_amc};
pub use bvh::{parse_bvh, read_bvh, to_bvh_string, write_bvh};
pub use data::shared_data_dir;
pub use error::IoError;
pub use fsutil::{write_atomic, write_atomic_with};
pub use limits::LimitExceeded;
pub use output_set::OutputSet;
pub use progress::Progress;

use inbetween_core::Motion;
use std::path::Path;

/// An error and its sources as one line (`a: b: c`), as the CLI prints them; a source whose text the
/// message already holds (thiserror messages often embed it) is not said twice. Front ends that
/// report errors as text (result lines, Python exceptions) use it.
pub fn with_causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let part = s.to_string();
        if !text.contains(&part) {
            text.push_str(": ");
            text.push_str(&part);
        }
        source = s.source();
    }
    text
}

/// Reads a whole file as UTF-8 text; invalid UTF-8 is a syntax error at the line where it occurs.
pub(crate) fn read_text(path: &Path) -> Result<String, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Io { path: path.to_path_buf(), source })?;
    text::utf8(bytes).map_err(|e| IoError::Syntax {
        file: path.display().to_string(),
        line: e.line,
        expected: "UTF-8 text".into(),
        found: format!("invalid byte 0x{:02x}", e.byte),
    })
}

/// Loads a motion file by extension: `.bvh`, or `.amc` with its `.asf` beside it (CMU naming
/// `01_01.amc` → `01.asf`, or the same stem `walk.amc` → `walk.asf`).
pub fn load_motion(path: &Path) -> Result<Motion, IoError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("bvh") => bvh::read_bvh(path),
        Some("amc") => {
            if !path.is_file() {
                return Err(IoError::Io { path: path.to_path_buf(), source: std::io::ErrorKind::NotFound.into() });
            }
            let asf = asf::find_asf_for(path)?;
            asf::read_asf_amc(&asf, path)
        }
        _ => Err(IoError::UnknownFormat { path: path.to_path_buf() }),
    }
}
