//! The data layer of the face engine: blendshape clips, their file formats and resampling.
//!
//! * [`BlendshapeClip`]: frame times plus, per frame, the 52 ARKit weights ([`ARKIT_NAMES`] order),
//!   optionally the 9 head/eye rotations ([`HEAD_EYE_NAMES`]) and any extra channels by name.
//! * [`livelink`]: the Live Link Face CSV layout (`Timecode`, `BlendshapeCount`, values), as in
//!   `../shared/data/face/neurosync`.
//! * [`curves`]: a plain curve format, CSV (`time_s` + named columns) and JSON.
//! * [`resample`](BlendshapeClip::resample): linear resampling to the model rate ([`MODEL_FPS`], the
//!   paper's 25 fps, §4.1) and back ([`BlendshapeClip::resample_at`]).
//!
//! Every reader returns [`FaceError`] on bad input, naming file, line and column; none panics
//! (property tests here, `fuzz/fuzz_targets/face_csv.rs`). Every writer is atomic
//! (`inbetween_io::write_atomic`).

mod clip;
pub mod curves;
pub mod livelink;
mod names;
mod resample;
pub mod split;
pub(crate) mod text;

pub use crate::error::{Column, FaceError};
pub use clip::BlendshapeClip;
pub use curves::{
    parse_curve_csv, parse_curve_json, read_curves, to_curve_csv_string, to_curve_json_string, write_curves,
};
pub use livelink::{parse_live_link, read_live_link, to_live_link_string, write_live_link};
pub use names::{
    arkit_index, head_eye_index, is_emotion, ARKIT_NAMES, EMOTION_NAMES, HEAD_EYE_NAMES, NUM_ARKIT, NUM_HEAD_EYE,
};
pub use resample::MODEL_FPS;

/// Live Link Face timecode rate: the `FF` field counts frames at 60 per second.
pub const LIVE_LINK_FPS: f64 = 60.0;

#[cfg(test)]
mod robustness;

/// Reads a clip in any format the engine knows: `.json` is the plain curve JSON; a CSV whose header
/// starts with `Timecode` is Live Link Face, any other CSV the plain curve CSV.
pub fn read_clip(path: &std::path::Path) -> Result<BlendshapeClip, FaceError> {
    let text = text::read_text(path)?;
    let file = path.display().to_string();
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json")) {
        return parse_curve_json(&text, &file);
    }
    let header =
        text.lines().map(|l| l.trim_start_matches('\u{feff}').trim()).find(|l| !l.is_empty() && !l.starts_with('#'));
    if header.is_some_and(|h| h.to_ascii_lowercase().starts_with("timecode")) {
        parse_live_link(&text, &file)
    } else {
        parse_curve_csv(&text, &file)
    }
}

/// [`read_clip`] for inputs of a job with a row limit: a CSV with more than `max_rows` data rows
/// (non-blank, non-comment lines after the header) is refused before it is parsed, a JSON clip once
/// parsed. The error ([`FaceError::Limit`]) names the file and the limit's field, `max_rows`.
pub fn read_clip_limited(path: &std::path::Path, max_rows: usize) -> Result<BlendshapeClip, FaceError> {
    let file = path.display().to_string();
    let check =
        |rows: usize| inbetween_io::LimitExceeded::check_count(file.as_str(), rows, max_rows, "rows", "max_rows");
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json")) {
        let text = text::read_text(path)?;
        let rows = text::lines(&text).filter(|(_, l)| !l.trim_start().starts_with('#')).count().saturating_sub(1);
        check(rows)?;
        drop(text);
    }
    let clip = read_clip(path)?;
    check(clip.num_frames())?;
    Ok(clip)
}

/// Whether the file at `path` is a Live Link Face CSV (its header starts with `Timecode`), so that an
/// edit of it is written back in that layout rather than as a plain curve file.
pub fn is_live_link(path: &std::path::Path) -> bool {
    std::fs::read_to_string(path)
        .map(|t| t.trim_start_matches('\u{feff}').trim_start().to_ascii_lowercase().starts_with("timecode"))
        .unwrap_or(false)
}

/// Writes a clip as Live Link Face CSV when `live_link`, else in the plain curve format chosen by the
/// extension (`.json` or CSV). Atomic, like every writer here.
pub fn write_clip(path: &std::path::Path, clip: &BlendshapeClip, live_link: bool) -> Result<(), FaceError> {
    if live_link {
        write_live_link(path, clip)
    } else {
        write_curves(path, clip)
    }
}
