//! `inbetween convert`: a motion file (BVH, or ASF/AMC) cropped and resampled, written as BVH.

use std::fmt;
use std::path::{Path, PathBuf};

use inbetween_core::Motion;

use crate::IoError;

/// Loads `file`: by extension ([`crate::load_motion`]), or as an `.amc` with the skeleton `asf`.
pub fn load_motion_with(file: &Path, asf: Option<&Path>) -> Result<Motion, IoError> {
    match asf {
        Some(asf) => crate::read_asf_amc(asf, file),
        None => crate::load_motion(file),
    }
}

/// What to convert and how.
#[derive(Clone, Debug, Default)]
pub struct ConvertJob {
    pub input: PathBuf,
    /// The `.amc` input's skeleton when it is not beside it.
    pub asf: Option<PathBuf>,
    /// The BVH file to write (atomically).
    pub output: PathBuf,
    /// First input frame kept (0-based; None: 0) and the frame to stop before (None: the end).
    pub start: Option<usize>,
    pub end: Option<usize>,
    /// Frame rate to resample to, after cropping (None: the input's).
    pub fps: Option<f64>,
}

/// What [`ConvertJob::run`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvertReport {
    pub output: PathBuf,
    pub joints: usize,
    pub channels: usize,
    pub frames: usize,
    pub fps: f64,
    pub seconds: f64,
    /// Frames of the input before cropping and resampling.
    pub input_frames: usize,
}

impl ConvertJob {
    /// Reads, crops, resamples and writes; errors name the file or the step that failed.
    pub fn run(&self) -> Result<ConvertReport, IoError> {
        let mut m = load_motion_with(&self.input, self.asf.as_deref())?;
        let n = m.num_frames();
        if self.start.is_some() || self.end.is_some() {
            let (start, end) = (self.start.unwrap_or(0), self.end.unwrap_or(n));
            let what = format!("cropping {}", self.input.display());
            m = m.crop(start, end).map_err(|source| IoError::Motion { what, source })?;
        }
        if let Some(fps) = self.fps {
            let what = format!("resampling to {fps} fps");
            m = m.resample(fps).map_err(|source| IoError::Motion { what, source })?;
        }
        crate::write_bvh(&self.output, &m)?;
        Ok(ConvertReport {
            output: self.output.clone(),
            joints: m.skeleton.len(),
            channels: m.num_channels(),
            frames: m.num_frames(),
            fps: m.fps(),
            seconds: m.duration(),
            input_frames: n,
        })
    }
}

impl fmt::Display for ConvertReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "wrote {}: {} joints, {} channels, {} frames at {:.3} fps ({:.3} s) from {} input frames",
            self.output.display(),
            self.joints,
            self.channels,
            self.frames,
            self.fps,
            self.seconds,
            self.input_frames
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    /// A 60-frame walk at 30 fps, frames 10..40 at 15 fps: 15 frames (0.933 s from first to last), read back as written;
    /// an empty crop names the input and writes nothing.
    #[test]
    fn crops_then_resamples_and_says_what_it_wrote() {
        let dir = std::env::temp_dir().join(format!("inbetween-convert-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("walk.bvh");
        let walk = gait(&GaitParams { frames: 60, ..GaitParams::walk() });
        crate::write_bvh(&input, &walk).unwrap();
        let output = dir.join("out.bvh");
        let job = ConvertJob {
            input: input.clone(),
            output: output.clone(),
            start: Some(10),
            end: Some(40),
            fps: Some(15.0),
            ..Default::default()
        };
        let r = job.run().unwrap();
        assert_eq!((r.frames, r.input_frames, r.joints), (15, 60, walk.skeleton.len()));
        let back = crate::read_bvh(&output).unwrap();
        assert_eq!((back.num_frames(), back.num_channels()), (15, r.channels));
        assert_eq!(
            r.to_string(),
            format!(
                "wrote {}: {} joints, {} channels, 15 frames at 15.000 fps (0.933 s) from 60 input frames",
                output.display(),
                r.joints,
                r.channels
            )
        );
        let empty = ConvertJob { output: dir.join("none.bvh"), start: Some(30), end: Some(30), ..job };
        let e = empty.run().unwrap_err();
        assert!(e.to_string() == format!("cropping {}", input.display()), "{e}");
        assert!(!dir.join("none.bvh").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
