//! `preview` (owned by the render work): a motion file as an animated GIF or a PNG of one frame,
//! optionally with a second file overlaid in another colour.

use clap::Args;
use inbetween_render::preview::{PreviewJob, PROGRESS_AFTER};
use inbetween_render::stick::StickOptions;
use std::path::PathBuf;

#[derive(Args)]
pub struct PreviewArgs {
    /// Motion file: .bvh, or .amc with its .asf beside it.
    pub file: PathBuf,
    /// Output file: .gif for the animation, .png for one frame (see --frame).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Frame to draw into a .png output (0-based).
    #[arg(long)]
    pub frame: Option<usize>,
    /// GIF frame rate; frames are skipped to keep real-time playback (default: the file's rate).
    #[arg(long)]
    pub fps: Option<f64>,
    #[arg(long, default_value_t = StickOptions::default().width)]
    pub width: u32,
    #[arg(long, default_value_t = StickOptions::default().height)]
    pub height: u32,
    /// A second motion file overlaid in another colour (e.g. a reconstruction of FILE).
    #[arg(long)]
    pub compare: Option<PathBuf>,
    /// Most frames in a GIF (longer clips are stepped through).
    #[arg(long, default_value_t = StickOptions::default().max_frames)]
    pub max_frames: usize,
    /// Title drawn in the top-left corner (default: the file name).
    #[arg(long)]
    pub title: Option<String>,
    /// Leave out the ground grid and shadows.
    #[arg(long)]
    pub no_grid: bool,
}

pub fn run(a: PreviewArgs) -> anyhow::Result<()> {
    let job = PreviewJob {
        file: a.file,
        output: a.output,
        frame: a.frame,
        compare: a.compare,
        title: a.title,
        stick: StickOptions {
            width: a.width,
            height: a.height,
            fps: a.fps,
            max_frames: a.max_frames,
            grid: !a.no_grid,
            ..StickOptions::default()
        },
    };
    println!("{}", job.run(&inbetween_io::Progress::after(PROGRESS_AFTER, 0, "encoding"))?);
    Ok(())
}
