//! `preview` (owned by the render work): a motion file as an animated GIF or a PNG of one frame,
//! optionally with a second file overlaid in another colour.

use anyhow::{bail, Context};
use clap::Args;
use inbetween_render::stick::{self, StickOptions};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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

/// How long GIF encoding may run before a progress bar appears.
const PROGRESS_AFTER: Duration = Duration::from_secs(1);

fn file_label(p: &Path) -> String {
    p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| p.display().to_string())
}

pub fn run(a: PreviewArgs) -> anyhow::Result<()> {
    let ext = a.output.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    let is_gif = match ext.as_deref() {
        Some("gif") => true,
        Some("png") => false,
        _ => bail!("{}: output must end in .gif (animation) or .png (one frame)", a.output.display()),
    };
    if is_gif && a.frame.is_some() {
        bail!("--frame selects the frame of a .png output; {} is a GIF of every frame", a.output.display());
    }
    let started = Instant::now();
    let main = inbetween_io::load_motion(&a.file).with_context(|| format!("loading {}", a.file.display()))?;
    let other = match &a.compare {
        Some(p) => Some(inbetween_io::load_motion(p).with_context(|| format!("loading {}", p.display()))?),
        None => None,
    };
    let mut motions = vec![&main];
    let mut labels = vec![file_label(&a.file)];
    if let (Some(m), Some(p)) = (&other, &a.compare) {
        motions.push(m);
        labels.push(file_label(p));
    }
    let opts = StickOptions {
        width: a.width,
        height: a.height,
        fps: a.fps,
        max_frames: a.max_frames,
        grid: !a.no_grid,
        title: Some(a.title.clone().unwrap_or_else(|| file_label(&a.file)))
            .filter(|_| other.is_none() || a.title.is_some()),
        // With a comparison, the legend names both files; alone, the title does.
        labels: if other.is_some() { labels } else { Vec::new() },
        ..StickOptions::default()
    };
    if is_gif {
        let frames = write_gif(&a.output, &motions, &opts)?;
        let size = std::fs::metadata(&a.output).map(|m| m.len()).unwrap_or(0);
        println!(
            "wrote {}: {} frames of {} ({} source frames at {:.1} fps), {}×{}, {:.1} KiB, in {:.2} s",
            a.output.display(),
            frames,
            a.file.display(),
            main.num_frames(),
            main.fps(),
            a.width,
            a.height,
            size as f64 / 1024.0,
            started.elapsed().as_secs_f64()
        );
    } else {
        let frame = a.frame.unwrap_or(0);
        stick::render_motion_png(&a.output, &motions, frame, &opts)
            .with_context(|| format!("rendering frame {frame} of {}", a.file.display()))?;
        println!(
            "wrote {}: frame {frame} of {} ({} frames), {}×{}",
            a.output.display(),
            a.file.display(),
            main.num_frames(),
            a.width,
            a.height
        );
    }
    Ok(())
}

/// Renders the GIF, showing a progress bar over the encoding once it has taken over a second.
/// Returns the number of GIF frames.
fn write_gif(path: &Path, motions: &[&inbetween_core::Motion], opts: &StickOptions) -> anyhow::Result<usize> {
    let bar = inbetween_io::Progress::after(PROGRESS_AFTER, 0, "encoding");
    let mut total = 0;
    stick::render_motion_gif_with_progress(path, motions, opts, &mut |done, all| {
        total = all;
        bar.set_length(all as u64);
        bar.set_position(done as u64);
    })
    .with_context(|| format!("writing {}", path.display()))?;
    bar.finish();
    Ok(total)
}
