//! The video part of `inbetween demo`: a procedural clip (pendulum, a ball in linear motion, a scene
//! cut) resequenced from one of its frames, written as a GIF with its contact sheet.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;

use crate::frames::{procedural_clip, write_clip, ProceduralKind};
use crate::job::{AnalyseJob, ResequenceJob};
use crate::metric::TrainOptions;
use crate::pipeline::{reorder, ResequenceConfig};
use crate::preview::{write_contact_sheet, SheetOptions};
use crate::sdpf::SdpfParams;
use crate::VideoError;

/// What the demo wrote and measured.
#[derive(Debug)]
pub struct VideoDemo {
    pub files: Vec<PathBuf>,
    /// The new order (source frame indices).
    pub order: Vec<usize>,
    /// M_D (Eq. 21) of the new order and of the source.
    pub md: (f64, f64),
    /// Δ_o (Eq. 23) of the new order.
    pub delta_o: f64,
}

/// Frames of the demo clip and its start frame.
pub const FRAMES: usize = 48;
pub const START: usize = 6;
/// The demo clip's frame size, pixels.
pub const WIDTH: u32 = 192;
pub const HEIGHT: u32 = 108;

/// The demo's procedural clip (seed 1) at `k`× its frames: what `video scale` resequences.
pub fn scaled_clip(k: usize) -> crate::frames::Clip {
    procedural_clip(ProceduralKind::Mixed, FRAMES * k, WIDTH, HEIGHT, 1)
}

impl std::fmt::Display for VideoDemo {
    /// The demo's line: the new order's length, M_D beside the source's, Δo and the files.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let files: Vec<String> = self.files.iter().map(|f| f.display().to_string()).collect();
        write!(
            f,
            "video: procedural clip resequenced from frame {START}: {} frames, M_D {:.4} (source {:.4}), Δo {:.3} -> {}",
            self.order.len(),
            self.md.0,
            self.md.1,
            self.delta_o,
            files.join(", ")
        )
    }
}

/// Run the demo into `dir` (`video-demo-source.gif`, `video-demo.gif`, `video-demo.sheet.png`).
pub fn run(dir: &Path, seed: u64, progress: &Progress) -> Result<VideoDemo, VideoError> {
    let clip = procedural_clip(ProceduralKind::Mixed, FRAMES, WIDTH, HEIGHT, seed);
    // A short training run keeps the demo quick; `inbetween video resequence` trains longer.
    let cfg = ResequenceConfig {
        train: TrainOptions { steps: 40, seed, ..TrainOptions::default() },
        cache_dir: dir.join("video-cache"),
        ..ResequenceConfig::default()
    };
    let cancel = Cancel::default();
    let analysed = AnalyseJob { config: cfg, ..AnalyseJob::for_clip(clip) }.run(&cancel, progress)?;
    let job = ResequenceJob {
        start: START,
        params: SdpfParams { seed, ..SdpfParams::default() },
        ..ResequenceJob::on(Arc::new(analysed))
    };
    let report = job.run(&cancel, progress)?;
    let clip = &report.analysis.clip;
    let sequence = &report.sequences[0];
    let order = sequence.order.clone();
    std::fs::create_dir_all(dir).map_err(|e| VideoError::io(dir, e))?;
    let source_gif = dir.join("video-demo-source.gif");
    write_clip(&source_gif, clip)?;
    let gif = dir.join("video-demo.gif");
    write_clip(&gif, &reorder(clip, &order))?;
    let sheet = dir.join("video-demo.sheet.png");
    let title = format!("procedural clip resequenced from frame {START} (seed {seed}): {} frames", order.len());
    let opts = SheetOptions {
        title,
        columns: 8,
        thumb_width: 120,
        cuts: sequence.path.cut_positions(),
        loops: sequence.path.loop_positions(),
        ..SheetOptions::default()
    };
    write_contact_sheet(&sheet, &clip.frames, &order, &opts)?;
    let md = (sequence.md, report.analysis.source_md);
    let delta_o = sequence.delta_o;
    Ok(VideoDemo { files: vec![source_gif, gif, sheet], order, md, delta_o })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scaled_clip_is_the_demo_clip_k_times_as_long() {
        let c = scaled_clip(3);
        assert_eq!((c.len(), c.width(), c.height()), (3 * FRAMES, WIDTH, HEIGHT));
    }
}
