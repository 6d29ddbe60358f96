//! [`PreviewJob`]: `inbetween preview` as a job. A motion file drawn as stick figures: an animated GIF
//! of every frame, or a PNG of one frame, optionally with a second file overlaid in another colour.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use inbetween_io::Progress;
use serde::Serialize;

use crate::stick::{render_motion_gif_with_progress, render_motion_png, StickOptions};
use crate::RenderError;

/// Draw a motion file (and, overlaid, a second one) into a GIF or a PNG.
#[derive(Clone, Debug)]
pub struct PreviewJob {
    /// Motion file: `.bvh`, or `.amc` with its `.asf` beside it.
    pub file: PathBuf,
    /// `.gif` for the animation, `.png` for one frame.
    pub output: PathBuf,
    /// Frame of a `.png` output (0-based; default 0). Refused for a GIF.
    pub frame: Option<usize>,
    /// A second motion file overlaid in another colour (e.g. a reconstruction of `file`).
    pub compare: Option<PathBuf>,
    /// Title in the top-left corner (default: the file name; none when comparing, the legend names
    /// both files).
    pub title: Option<String>,
    /// Size, rate, frame limit and grid ([`StickOptions::default`]).
    pub stick: StickOptions,
}

impl Default for PreviewJob {
    fn default() -> Self {
        PreviewJob {
            file: PathBuf::new(),
            output: PathBuf::new(),
            frame: None,
            compare: None,
            title: None,
            stick: StickOptions::default(),
        }
    }
}

/// What a preview wrote.
#[derive(Clone, Debug, Serialize)]
pub struct PreviewReport {
    pub output: PathBuf,
    pub file: PathBuf,
    /// GIF frames written, or the one frame drawn into the PNG.
    pub frames: usize,
    pub frame: Option<usize>,
    pub source_frames: usize,
    pub source_fps: f64,
    pub width: u32,
    pub height: u32,
    pub bytes: u64,
    pub seconds: f64,
}

impl std::fmt::Display for PreviewReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.frame {
            None => write!(
                f,
                "wrote {}: {} frames of {} ({} source frames at {:.1} fps), {}×{}, {:.1} KiB, in {:.2} s",
                self.output.display(),
                self.frames,
                self.file.display(),
                self.source_frames,
                self.source_fps,
                self.width,
                self.height,
                self.bytes as f64 / 1024.0,
                self.seconds
            ),
            Some(frame) => write!(
                f,
                "wrote {}: frame {frame} of {} ({} frames), {}×{}",
                self.output.display(),
                self.file.display(),
                self.source_frames,
                self.width,
                self.height
            ),
        }
    }
}

/// How long GIF encoding may run before a progress bar appears.
pub const PROGRESS_AFTER: Duration = Duration::from_secs(1);

fn file_label(p: &Path) -> String {
    p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| p.display().to_string())
}

impl PreviewJob {
    /// Whether the output is a GIF: it must end in `.gif` or `.png`, and `frame` goes with a PNG only.
    pub fn validate(&self) -> Result<bool, RenderError> {
        let ext = self.output.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
        let is_gif = match ext.as_deref() {
            Some("gif") => true,
            Some("png") => false,
            _ => {
                return Err(RenderError::Request(format!(
                    "{}: output must end in .gif (animation) or .png (one frame)",
                    self.output.display()
                )))
            }
        };
        if is_gif && self.frame.is_some() {
            return Err(RenderError::Request(format!(
                "`frame` selects the frame of a .png output; {} is a GIF of every frame",
                self.output.display()
            )));
        }
        Ok(is_gif)
    }

    /// Reads the files and writes the preview; a GIF's encoding shows `progress` (set up by the
    /// caller, e.g. [`Progress::after`] with [`PROGRESS_AFTER`]).
    pub fn run(&self, progress: &Progress) -> Result<PreviewReport, RenderError> {
        let is_gif = self.validate()?;
        let started = Instant::now();
        let load = |p: &Path| {
            inbetween_io::load_motion(p).map_err(|source| RenderError::Load { path: p.to_path_buf(), source })
        };
        let main = load(&self.file)?;
        let other = self.compare.as_deref().map(load).transpose()?;
        let mut motions = vec![&main];
        let mut labels = vec![file_label(&self.file)];
        if let (Some(m), Some(p)) = (&other, &self.compare) {
            motions.push(m);
            labels.push(file_label(p));
        }
        let opts = StickOptions {
            title: Some(self.title.clone().unwrap_or_else(|| file_label(&self.file)))
                .filter(|_| other.is_none() || self.title.is_some()),
            // With a comparison, the legend names both files; alone, the title does.
            labels: if other.is_some() { labels } else { Vec::new() },
            ..self.stick.clone()
        };
        let (frames, frame) = if is_gif {
            let mut total = 0;
            render_motion_gif_with_progress(&self.output, &motions, &opts, &mut |done, all| {
                total = all;
                progress.set_length(all as u64);
                progress.set_position(done as u64);
            })
            .map_err(|e| RenderError::Writing { path: self.output.clone(), source: Box::new(e) })?;
            progress.finish();
            (total, None)
        } else {
            let frame = self.frame.unwrap_or(0);
            render_motion_png(&self.output, &motions, frame, &opts).map_err(|e| RenderError::Frame {
                frame,
                file: self.file.clone(),
                source: Box::new(e),
            })?;
            (1, Some(frame))
        };
        Ok(PreviewReport {
            output: self.output.clone(),
            file: self.file.clone(),
            frames,
            frame,
            source_frames: main.num_frames(),
            source_fps: main.fps(),
            width: opts.width,
            height: opts.height,
            bytes: std::fs::metadata(&self.output).map(|m| m.len()).unwrap_or(0),
            seconds: started.elapsed().as_secs_f64(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn refuses_other_outputs_and_a_frame_of_a_gif_then_draws_a_png() {
        let dir = tempfile::tempdir().unwrap();
        let bvh = dir.path().join("walk.bvh");
        inbetween_io::write_bvh(&bvh, &gait(&GaitParams { frames: 12, ..GaitParams::walk() })).unwrap();
        let job = |out: &str, frame| PreviewJob {
            file: bvh.clone(),
            output: dir.path().join(out),
            frame,
            ..Default::default()
        };
        assert!(job("a.jpg", None).validate().unwrap_err().to_string().contains("must end in .gif"));
        assert!(job("a.gif", Some(3)).validate().unwrap_err().to_string().starts_with("`frame` selects"));
        let r = job("a.png", Some(3)).run(&Progress::hidden()).unwrap();
        assert_eq!((r.frame, r.source_frames, r.width), (Some(3), 12, 480));
        assert!(r.bytes > 0 && r.to_string().starts_with("wrote "), "{r}");
        let missing = PreviewJob { file: dir.path().join("none.bvh"), ..job("b.png", None) };
        assert!(missing.run(&Progress::hidden()).unwrap_err().to_string().starts_with("loading "));
    }
}
