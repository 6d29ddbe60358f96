//! A folder of PNG/JPEG frames as a clip.
//!
//! Frame exporters name files `frame_1.png … frame_10.png` as often as `frame_0001.png`, so files
//! are ordered by natural order (digit runs compared as numbers), not byte order, which would put
//! `frame_10` before `frame_2`. Files with other extensions (a README, a `.DS_Store`) are skipped;
//! a `.png`/`.jpg` that does not decode is an error naming it.

use super::{decode_err, DecodeReport, DEFAULT_FPS};
use crate::VideoError;
use image::RgbImage;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::path::{Path, PathBuf};

/// Image extensions read from a folder.
const IMAGE_EXTENSIONS: [&str; 3] = ["png", "jpg", "jpeg"];

/// Splits a name into runs of digits and runs of non-digits.
fn runs(s: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut start = 0;
    let bytes = s.as_bytes();
    for i in 1..=bytes.len() {
        if i == bytes.len() || bytes[i].is_ascii_digit() != bytes[i - 1].is_ascii_digit() {
            out.push(&s[start..i]);
            start = i;
        }
    }
    out
}

/// Compares two digit runs by value (any length, leading zeros ignored).
fn cmp_numbers(a: &str, b: &str) -> Ordering {
    let (a, b) = (a.trim_start_matches('0'), b.trim_start_matches('0'));
    a.len().cmp(&b.len()).then_with(|| a.cmp(b))
}

/// Natural order of file names: digit runs compare as numbers, text runs case-insensitively; ties
/// fall back to plain byte order so the order is total (`f01` and `f1` both have a place).
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (ra, rb) = (runs(a), runs(b));
    for (x, y) in ra.iter().zip(&rb) {
        let digits = x.as_bytes()[0].is_ascii_digit() && y.as_bytes()[0].is_ascii_digit();
        let ord = if digits { cmp_numbers(x, y) } else { x.to_lowercase().cmp(&y.to_lowercase()) };
        if ord != Ordering::Equal {
            return ord;
        }
    }
    ra.len().cmp(&rb.len()).then_with(|| a.cmp(b))
}

/// The image files of a folder in natural order.
fn image_files(dir: &Path) -> Result<Vec<PathBuf>, VideoError> {
    let entries = std::fs::read_dir(dir).map_err(|e| VideoError::io(dir, e))?;
    let mut files = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| VideoError::io(dir, e))?.path();
        if path.is_file() && IMAGE_EXTENSIONS.contains(&super::extension(&path).as_str()) {
            files.push(path);
        }
    }
    let name = |p: &PathBuf| p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    files.sort_by(|a, b| natural_cmp(&name(a), &name(b)));
    Ok(files)
}

/// Decodes one frame file to RGB, naming the file and its index on failure.
fn load_frame(path: &Path, index: usize) -> Result<RgbImage, VideoError> {
    let img = image::ImageReader::open(path)
        .map_err(|e| VideoError::io(path, e))?
        .with_guessed_format()
        .map_err(|e| VideoError::io(path, e))?
        .decode()
        .map_err(|e| decode_err(path, Some(index), format!("not a readable PNG/JPEG image: {e}")))?;
    Ok(img.to_rgb8())
}

/// Every frame must have the size of the first.
fn check_sizes(files: &[PathBuf], frames: &[RgbImage]) -> Result<(), VideoError> {
    let Some(first) = frames.first() else { return Ok(()) };
    let (w, h) = first.dimensions();
    match frames.iter().position(|f| f.dimensions() != (w, h)) {
        None => Ok(()),
        Some(i) => {
            let (fw, fh) = frames[i].dimensions();
            Err(decode_err(
                &files[i],
                Some(i),
                format!(
                    "is {fw}x{fh} but the first frame ({}) is {w}x{h}; all frames must have one size",
                    files[0].display()
                ),
            ))
        }
    }
}

/// Reads the folder's frames (at most `max_frames`), decoding files in parallel.
pub(crate) fn read_folder(
    dir: &Path,
    max_frames: Option<usize>,
) -> Result<(Vec<RgbImage>, f64, DecodeReport), VideoError> {
    let mut files = image_files(dir)?;
    if files.is_empty() {
        return Err(decode_err(dir, None, "the folder holds no .png/.jpg/.jpeg frames"));
    }
    files.truncate(max_frames.unwrap_or(usize::MAX));
    let frames = files.par_iter().enumerate().map(|(i, p)| load_frame(p, i)).collect::<Result<Vec<_>, _>>()?;
    check_sizes(&files, &frames)?;
    let report = DecodeReport {
        decoder: "image folder (png/jpeg)".into(),
        frames: frames.len(),
        notes: vec![format!("an image folder has no frame rate: assumed {DEFAULT_FPS} fps")],
    };
    Ok((frames, DEFAULT_FPS, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_order_compares_numbers_by_value() {
        let mut names = vec!["f10.png", "f2.png", "F1.png", "f002.png", "a.png", "f1b.png"];
        names.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(names, vec!["a.png", "F1.png", "f1b.png", "f002.png", "f2.png", "f10.png"]);
        assert_eq!(natural_cmp("frame_0099", "frame_100"), Ordering::Less);
        assert_eq!(natural_cmp("x", "x"), Ordering::Equal);
        assert_eq!(natural_cmp("", "1"), Ordering::Less);
    }
}
