//! Clips in and out: MP4 (H.264), animated GIF and folders of PNG/JPEG frames are read into a
//! [`Clip`] of RGB frames; a clip is written as MP4 (H.264 Baseline) or GIF; and
//! [`procedural_clip`] renders test clips (pendulum, walker, linear slider, a mix with a scene cut)
//! so that tests and the demo need no files.
//!
//! The paper (§3) takes "a video" as input and works on its frames one by one; everything after
//! this module sees only `Vec<RgbImage>` plus the frame rate.
//!
//! Decoding H.264 is done in-process with the bundled Cisco openh264 decoder (pure build, no system
//! library) after demuxing with the `mp4` crate. Streams with B-frames (a `ctts` box whose offsets
//! reorder frames) go to an `ffmpeg` subprocess when one is on `PATH`, and so does anything openh264
//! fails on; without ffmpeg, B-frame streams are tried with openh264 (the bundled version decodes
//! them in display order when not flushed after each packet, measured on `carphone_pristine.mp4`),
//! and a stream it cannot finish gives [`VideoError::Unsupported`] saying what to install or how to
//! convert the file (see `../shared/notes/video-decode.md` and [`probe_openh264`]).

mod ffmpeg;
mod folder;
mod gif_io;
mod gray;
mod mp4_in;
mod mp4_out;
mod procedural;
#[cfg(test)]
mod tests;

pub use ffmpeg::ffmpeg_available;
pub use folder::natural_cmp;
pub(crate) use gray::gray_downscaled;
pub use mp4_in::{probe_openh264, OpenH264Probe, SampleOutcome};
pub use procedural::{multi_shot_clip, procedural_clip, procedural_truth, ProceduralKind, ProceduralTruth, SynthJob};

use crate::VideoError;
use image::RgbImage;
use std::path::Path;

/// Frame rate given to clips whose source carries none (a folder of images).
pub const DEFAULT_FPS: f64 = 25.0;

/// A clip: RGB frames of one size, in display order, and the rate they play at.
#[derive(Clone, Debug)]
pub struct Clip {
    pub frames: Vec<RgbImage>,
    pub fps: f64,
    /// Where the frames came from (a path, or `procedural:…`), for reports.
    pub source: String,
}

impl Clip {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True when the clip has no frames.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Frame width in pixels (0 for an empty clip).
    pub fn width(&self) -> u32 {
        self.frames.first().map_or(0, |f| f.width())
    }

    /// Frame height in pixels (0 for an empty clip).
    pub fn height(&self) -> u32 {
        self.frames.first().map_or(0, |f| f.height())
    }

    /// Luma (Rec. 601) of every frame, area-averaged down so that the longer side is at most
    /// `max_side` (never upscaled): the input of the optical flow of §5.2, which needs neither
    /// colour nor full resolution. See [`gray::gray_downscaled`].
    pub fn gray_downscaled(&self, max_side: u32) -> Vec<image::GrayImage> {
        gray::gray_downscaled(&self.frames, max_side)
    }
}

/// Which H.264 decoder [`read_clip`] uses for MP4 files (GIFs and folders ignore it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Decoder {
    /// openh264 when the stream suits it, else ffmpeg when installed, else a clear error.
    #[default]
    Auto,
    /// The bundled openh264 only: a decode error is returned, never routed to ffmpeg.
    OpenH264,
    /// An `ffmpeg` subprocess only.
    Ffmpeg,
}

/// Options of [`read_clip`].
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    pub decoder: Decoder,
    /// Stop after this many frames (all when `None`).
    pub max_frames: Option<usize>,
}

/// How a clip was read: which decoder, how many frames, and anything worth telling the user
/// (fallbacks taken, an assumed frame rate, …).
#[derive(Clone, Debug, Default)]
pub struct DecodeReport {
    pub decoder: String,
    pub frames: usize,
    pub notes: Vec<String>,
}

/// What kind of input a path is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Mp4,
    Gif,
    Folder,
}

/// Reads a clip: `.mp4`/`.m4v`/`.mov` (H.264), `.gif` (all frames, composited to RGB), or a folder
/// of `.png`/`.jpg`/`.jpeg` frames in natural name order (`f2` before `f10`). Files with another
/// extension are recognised by their first bytes. Errors name the file and, where known, the frame.
pub fn read_clip(path: &Path, opts: &ReadOptions) -> Result<(Clip, DecodeReport), VideoError> {
    let (frames, fps, report) = match kind_of(path)? {
        Kind::Mp4 => mp4_in::read_mp4(path, opts)?,
        Kind::Gif => gif_io::read_gif(path, opts.max_frames)?,
        Kind::Folder => folder::read_folder(path, opts.max_frames)?,
    };
    let clip = Clip { frames, fps, source: path.display().to_string() };
    Ok((clip, report))
}

/// Decides how to read `path`: folders are image sequences, files go by extension, then by their
/// magic bytes (`GIF8`, or an MP4 `ftyp` box).
fn kind_of(path: &Path) -> Result<Kind, VideoError> {
    let meta = std::fs::metadata(path).map_err(|e| VideoError::io(path, e))?;
    if meta.is_dir() {
        return Ok(Kind::Folder);
    }
    match extension(path).as_str() {
        "mp4" | "m4v" | "mov" => return Ok(Kind::Mp4),
        "gif" => return Ok(Kind::Gif),
        _ => {}
    }
    let head = read_head(path, 12)?;
    if head.starts_with(b"GIF8") {
        Ok(Kind::Gif)
    } else if head.len() >= 8 && &head[4..8] == b"ftyp" {
        Ok(Kind::Mp4)
    } else {
        Err(VideoError::Unsupported {
            path: path.to_path_buf(),
            message: "not a clip: expected an .mp4/.m4v/.mov (H.264) file, an animated .gif, or a folder of \
                      .png/.jpg frames"
                .into(),
        })
    }
}

/// The first `n` bytes of a file (fewer if it is shorter).
fn read_head(path: &Path, n: usize) -> Result<Vec<u8>, VideoError> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(|e| VideoError::io(path, e))?;
    let mut head = Vec::with_capacity(n);
    file.take(n as u64).read_to_end(&mut head).map_err(|e| VideoError::io(path, e))?;
    Ok(head)
}

/// Lower-case extension of a path ("" when none).
fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Writes a clip as `.gif` or `.mp4` (chosen by the extension), atomically: a failed write leaves
/// no partial file. MP4 is H.264 Baseline; H.264 4:2:0 needs even sizes, so an odd width or height
/// is cropped by one pixel column/row (see [`mp4_out::write_mp4`]). GIF uses the render crate's
/// encoder (one global 255-colour palette, changed rectangles only).
pub fn write_clip(path: &Path, clip: &Clip) -> Result<(), VideoError> {
    check_writable(path, clip)?;
    match extension(path).as_str() {
        "gif" => gif_io::write_gif(path, clip),
        "mp4" | "m4v" | "mov" => mp4_out::write_mp4(path, clip),
        other => Err(VideoError::Encode {
            path: path.to_path_buf(),
            message: format!("cannot write '.{other}': use .mp4 or .gif"),
        }),
    }
}

/// A clip can be written when it has frames, one size, a non-zero size and a usable frame rate.
fn check_writable(path: &Path, clip: &Clip) -> Result<(), VideoError> {
    let fail = |message: String| Err(VideoError::Encode { path: path.to_path_buf(), message });
    if clip.frames.is_empty() {
        return fail("the clip has no frames".into());
    }
    let (w, h) = clip.frames[0].dimensions();
    if w == 0 || h == 0 {
        return fail(format!("frames are {w}x{h}; need at least 1x1"));
    }
    if let Some(i) = clip.frames.iter().position(|f| f.dimensions() != (w, h)) {
        let (fw, fh) = clip.frames[i].dimensions();
        return fail(format!("frame {i} is {fw}x{fh} but frame 0 is {w}x{h}; all frames must have one size"));
    }
    if !(clip.fps.is_finite() && clip.fps > 0.0) {
        return fail(format!("frame rate {} must be a positive number", clip.fps));
    }
    Ok(())
}

/// A decode error for `path`, naming the frame when there is one.
fn decode_err(path: &Path, frame: Option<usize>, message: impl Into<String>) -> VideoError {
    VideoError::Decode { path: path.to_path_buf(), frame, message: message.into() }
}
