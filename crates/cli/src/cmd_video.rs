//! `inbetween video …`: new frame orders from one clip (RSFNet metric + SDPF path finding).

use std::path::PathBuf;
use std::sync::LazyLock;

use clap::{Args, Subcommand, ValueEnum};
use inbetween_io::report::BenchOptions;
use inbetween_io::Progress;
use inbetween_video::frames::{write_clip, Decoder, ProceduralKind, ReadOptions, SynthJob};
use inbetween_video::job::{AnalyseJob, ResequenceJob, ResequenceSource, VideoInput};
use inbetween_video::pipeline::{MetricChoice, ResequenceConfig, VideoLimits};
use inbetween_video::sdpf::SdpfParams;

use crate::errors::name_flags;

#[derive(Subcommand)]
pub enum VideoCommand {
    /// A new frame order from a start frame: MP4/GIF/PNG-folder in, MP4 or GIF out, plus a contact sheet.
    Resequence(ResequenceArgs),
    /// Write a procedural test clip (no files needed).
    Synth(SynthArgs),
    /// What the bundled H.264 decoder does with an MP4, sample by sample.
    Probe(ProbeArgs),
    /// M_D / Δo per clip, the ablations of Table 3 and seconds per stage (procedural and real clips).
    Bench(BenchArgs),
    /// `video resequence` on the demo's procedural clip at 1×, 10×, 100× its frames (a scale over
    /// the frame limit is refused, and the table says so): time and peak memory per run.
    Scale(crate::scale::ScaleArgs),
}

#[derive(Args)]
pub struct BenchArgs {
    /// One short procedural clip and a tiny network (seconds).
    #[arg(long)]
    pub quick: bool,
    /// Folder of the real clips (default: ../shared/data/video or $INBETWEEN_DATA/video).
    #[arg(long)]
    pub clips: Option<PathBuf>,
    /// Start frames per clip (from frame 0, evenly spread; default 4, or 2 with --quick).
    #[arg(long)]
    pub starts: Option<usize>,
    #[arg(short, long, default_value = "out/video-bench")]
    pub out: PathBuf,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum DecoderArg {
    Auto,
    Openh264,
    Ffmpeg,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum MetricArg {
    /// RSFNet trained on the clip (the paper).
    Rsfnet,
    /// Euclidean distance of downscaled pixels (ablation).
    Pixels,
}

#[derive(Args)]
pub struct ResequenceArgs {
    /// Input clip: .mp4, .gif, or a folder of PNG/JPEG frames.
    pub input: PathBuf,
    /// Output clip (.mp4 or .gif). With --count N > 1, files are numbered (new-1.mp4, …).
    #[arg(short, long)]
    pub out: PathBuf,
    /// Start frame (0-based source index).
    #[arg(long, default_value_t = ResequenceJob::default().start)]
    pub start: usize,
    /// Target length in frames, at least 1 (default: the source's frame count; with --stop-early,
    /// until no candidate is left).
    #[arg(long)]
    pub length: Option<usize>,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Distinct sequences to write (at least 1).
    #[arg(long, default_value_t = ResequenceJob::default().count)]
    pub count: usize,
    /// The paper's early stop: end where no candidate is left, instead of cutting to the shot that
    /// best matches or looping back.
    #[arg(long)]
    pub stop_early: bool,
    /// Round 2's walk (ablation): where no candidate is left, a cut or one loop back to the closest
    /// frame of the path, instead of matched transitions, and no step cap.
    #[arg(long)]
    pub no_transitions: bool,
    /// Let steps that play the motion backwards through in shots judged undirected (water, fire,
    /// flicker); shots judged directed keep them out. --explain says how each shot was judged.
    #[arg(long)]
    pub allow_reverse: bool,
    /// Drop the reverse distillation C_r (ablation: steps back to the previous frames allowed).
    #[arg(long)]
    pub no_cr: bool,
    /// Give up after this many seconds (decoding excepted), writing nothing.
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// Refuse clips of more frames than this (checked while decoding).
    #[arg(long, default_value_t = VideoLimits::default().max_frames)]
    pub limit_frames: usize,
    /// Refuse frames larger than this, WIDTHxHEIGHT (compared as a pixel count).
    #[arg(long, default_value = RESOLUTION.as_str(), value_parser = VideoLimits::parse_pixels)]
    pub limit_resolution: u64,
    /// Refuse target lengths above this many frames.
    #[arg(long, default_value_t = VideoLimits::default().max_length)]
    pub limit_length: usize,
    /// Refuse --count above this.
    #[arg(long, default_value_t = VideoLimits::default().max_count)]
    pub limit_count: usize,
    /// End on a frame that can transition back to the start (a loop).
    #[arg(long = "loop")]
    pub loop_close: bool,
    /// Allow jumps across detected scene cuts.
    #[arg(long)]
    pub allow_cuts: bool,
    /// Print each transition's candidates, what removed them and the softmax choice.
    #[arg(long)]
    pub explain: bool,
    /// Cross-fade the written clip over N frames at each jump inside a shot whose difference is
    /// above the shot's own step between frames (Schödl et al. 2000); 0: none. M_D is then measured
    /// on the written frames.
    #[arg(long, default_value_t = ResequenceJob::default().blend, value_name = "N")]
    pub blend: usize,
    /// Contact sheet PNG (default: next to the output, <out>.sheet.png).
    #[arg(long)]
    pub sheet: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "rsfnet")]
    pub metric: MetricArg,
    /// Drop the directional distillation C_d (ablation).
    #[arg(long)]
    pub no_cd: bool,
    /// Drop the coherent distillation C_t (ablation).
    #[arg(long)]
    pub no_ct: bool,
    /// Choose the next frame by Eq. 20 exactly as printed (motion only, τ = 1 in latent units)
    /// instead of the default that also weighs content.
    #[arg(long)]
    pub paper_choice: bool,
    /// Most RSFNet training steps (batch 8; early stopping usually ends sooner).
    #[arg(long)]
    pub steps: Option<usize>,
    /// Cache of trained networks per clip (default ~/.cache/inbetween/video).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "auto")]
    pub decoder: DecoderArg,
    /// Read at most this many frames.
    #[arg(long)]
    pub max_frames: Option<usize>,
}

/// The engine's frame size limit, written as --limit-resolution takes it.
static RESOLUTION: LazyLock<String> = LazyLock::new(|| {
    let (width, height) = VideoLimits::DEFAULT_RESOLUTION;
    format!("{width}x{height}")
});

#[derive(Clone, Copy, ValueEnum)]
pub enum KindArg {
    Pendulum,
    Walker,
    Slider,
    /// A block moving right at constant speed over the whole clip.
    Drift,
    Mixed,
}

#[derive(Args)]
pub struct SynthArgs {
    /// Output clip (.gif or .mp4).
    #[arg(short, long)]
    pub out: PathBuf,
    #[arg(long, value_enum, default_value = "mixed")]
    pub kind: KindArg,
    #[arg(long, default_value_t = SynthJob::default().frames)]
    pub frames: usize,
    #[arg(long, default_value_t = SynthJob::default().width)]
    pub width: u32,
    #[arg(long, default_value_t = SynthJob::default().height)]
    pub height: u32,
    #[arg(long, default_value_t = SynthJob::default().seed)]
    pub seed: u64,
}

#[derive(Args)]
pub struct ProbeArgs {
    pub input: PathBuf,
}

pub fn run(c: VideoCommand) -> anyhow::Result<()> {
    match c {
        VideoCommand::Resequence(a) => run_resequence(a),
        VideoCommand::Synth(a) => run_synth(a),
        VideoCommand::Probe(a) => run_probe(a),
        VideoCommand::Bench(a) => run_bench(a),
        VideoCommand::Scale(a) => run_scale(a),
    }
}

/// The fields the engine names (its limits, the read options) and the flags that set them.
const VIDEO_FLAGS: &[(&str, &str)] = &[
    ("max_frames", "--limit-frames"),
    ("max_pixels", "--limit-resolution"),
    ("max_length", "--limit-length"),
    ("max_count", "--limit-count"),
    ("read.max_frames", "--max-frames"),
];

fn kind(k: KindArg) -> ProceduralKind {
    match k {
        KindArg::Pendulum => ProceduralKind::Pendulum,
        KindArg::Walker => ProceduralKind::Walker,
        KindArg::Slider => ProceduralKind::Slider,
        KindArg::Drift => ProceduralKind::Drift,
        KindArg::Mixed => ProceduralKind::Mixed,
    }
}

fn run_synth(a: SynthArgs) -> anyhow::Result<()> {
    let job = SynthJob { kind: kind(a.kind), frames: a.frames, width: a.width, height: a.height, seed: a.seed };
    println!("{}", job.write(&a.out)?);
    Ok(())
}

fn run_probe(a: ProbeArgs) -> anyhow::Result<()> {
    println!("{}: {}", a.input.display(), inbetween_video::frames::probe_openh264(&a.input)?);
    Ok(())
}

fn run_resequence(a: ResequenceArgs) -> anyhow::Result<()> {
    let limits = VideoLimits {
        max_frames: a.limit_frames,
        max_pixels: a.limit_resolution,
        max_length: a.limit_length,
        max_count: a.limit_count,
    };
    let cancel = crate::errors::time_limit(a.time_limit)?;
    let decoder = match a.decoder {
        DecoderArg::Auto => Decoder::Auto,
        DecoderArg::Openh264 => Decoder::OpenH264,
        DecoderArg::Ffmpeg => Decoder::Ffmpeg,
    };
    let mut config = ResequenceConfig {
        metric: match a.metric {
            MetricArg::Rsfnet => MetricChoice::RsfNet,
            MetricArg::Pixels => MetricChoice::Pixels,
        },
        limits,
        ..ResequenceConfig::default()
    };
    if let Some(s) = a.steps {
        config.train.steps = s;
    }
    if let Some(d) = &a.cache_dir {
        config.cache_dir = d.clone();
    }
    let params = SdpfParams {
        use_cd: !a.no_cd,
        use_ct: !a.no_ct,
        use_cr: !a.no_cr,
        allow_reverse: a.allow_reverse,
        stop_early: a.stop_early,
        length: a.length,
        loop_close: a.loop_close,
        allow_cuts: a.allow_cuts,
        seed: a.seed,
        transitions: !a.no_transitions,
        ..SdpfParams::default()
    };
    let steps = config.train.steps as u64;
    let job = ResequenceJob {
        source: ResequenceSource::Analyse(Box::new(AnalyseJob {
            input: VideoInput::File(a.input.clone()),
            read: ReadOptions { decoder, max_frames: a.max_frames },
            config,
        })),
        start: a.start,
        params: if a.paper_choice { params.paper_choice() } else { params },
        count: a.count,
        out: Some(a.out.clone()),
        sheet: a.sheet.clone(),
        blend: a.blend,
        explain: a.explain,
    };
    job.validate().map_err(|e| name_flags(e.into(), VIDEO_FLAGS))?;
    let progress = Progress::new(steps, "RSFNet");
    let report = job.run(&cancel, &progress).map_err(|e| name_flags(e.into(), VIDEO_FLAGS))?;
    progress.finish();
    print!("{}", crate::errors::with_flags(&report.to_string()));
    Ok(())
}

fn run_bench(a: BenchArgs) -> anyhow::Result<()> {
    use inbetween_video::bench::{real_clips, run, VideoBench};
    if !a.quick {
        println!("{}", real_clips(a.clips.as_deref()).1);
    }
    let engine = VideoBench { starts: a.starts };
    let opts = BenchOptions { out: Some(a.out), data: a.clips, quick: a.quick, ..BenchOptions::new(engine) };
    crate::bench::run("video bench", opts, run)?.print_summary();
    Ok(())
}

fn run_scale(a: crate::scale::ScaleArgs) -> anyhow::Result<()> {
    use inbetween_video::demo::{scaled_clip, HEIGHT, START, WIDTH};
    // The demo's clip k times as long (not timed); a scale over the frame limit is refused and the
    // table says so.
    crate::scale::run(&a, "video", "video resequence at multiples of the demo's procedural clip", |k, exe, work| {
        let (clip, path) = (scaled_clip(k), work.join(format!("clip-{k}.gif")));
        write_clip(&path, &clip)?;
        let mut command = std::process::Command::new(exe);
        command.args(["video".as_ref(), "resequence".as_ref(), path.as_os_str(), "--start".as_ref()]);
        command.arg(START.to_string()).arg("-o").arg(work.join(format!("new-{k}.gif")));
        Ok(crate::scale::Measured { input: format!("{} frames of {WIDTH}×{HEIGHT} px", clip.len()), command })
    })
}
