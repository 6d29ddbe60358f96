//! `inbetween face …`: edit blendshape animation by inpainting, train the networks, benchmark.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};

use inbetween_face::bench;
use inbetween_face::data::{read_clip_limited, write_clip, BlendshapeClip};
use inbetween_face::edit::groups::parse_groups;
use inbetween_face::edit::ConstraintKind;
use inbetween_face::infer::files::{write_variants, EditFiles};
use inbetween_face::infer::plan::{
    keeps_live_link, span_seconds, visemes_groups_note, EditResources, GuideSource, LoadedGuide, MethodChoice,
};
use inbetween_face::infer::{EditJob, EditLimits};
use inbetween_face::procedural;
use inbetween_face::train::{TrainData, TrainJob};
use inbetween_io::report::BenchOptions;
use inbetween_io::Progress;

use crate::errors;
use crate::scale::ScaleArgs;

#[derive(Subcommand)]
pub enum FaceCommand {
    /// Regenerate spans of a blendshape animation, unguided or guided by keys, a noisy take or visemes.
    Edit(EditArgs),
    /// Train one network (or all four) on procedural clips or on the real captures' training split.
    Train(TrainArgs),
    /// Held-out evaluation: gap lengths, constraint types, Table 3 and Table 4 (CSV, Markdown, PNG).
    Bench(BenchArgs),
    /// Write a procedural face capture (Live Link CSV or curve CSV/JSON) and its phoneme timing.
    Synth(SynthArgs),
    /// Scaling bench: `face edit` on the demo's example (10 s clip, 3 s gap) at 1×, 10×, 100×, with
    /// time and peak memory per run.
    Scale(ScaleArgs),
}

#[derive(Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// The best measured method for the guidance given (face bench): retrieval when unguided or
    /// guided by a noisy take, the trained network for keys and visemes (and whenever --weights is given).
    Auto,
    /// The trained network for the guidance given.
    Network,
    /// Linear interpolation through the span's borders and keys.
    Linear,
    /// Cubic Hermite interpolation through the span's borders (values and slopes) and keys.
    Cubic,
    /// Segments of recorded motion (--library, and the clip itself outside the spans) joined at the
    /// borders; the seed draws among the best matches.
    Retrieval,
}

#[derive(Args)]
pub struct EditArgs {
    /// Input animation: Live Link Face CSV, or curve CSV/JSON (time_s + the 52 ARKit names).
    pub input: PathBuf,
    /// Span to regenerate, seconds from the first frame (4.0s..6.5s) or frames at the clip's rate
    /// (240f..390f). Repeat for several spans.
    #[arg(long, required = true)]
    pub mask: Vec<String>,
    /// Keyframes to hit exactly (JSON or CSV; see the face README).
    #[arg(long, group = "guidance")]
    pub keys: Option<PathBuf>,
    /// A noisy take of the same performance (any clip format), aligned on its first frame.
    #[arg(long, group = "guidance")]
    pub guide: Option<PathBuf>,
    /// Phoneme timings: a Montreal Forced Aligner TextGrid, or a CSV/JSON of start,end,phoneme.
    #[arg(long, group = "guidance")]
    pub visemes: Option<PathBuf>,
    /// English text spoken during --text-span (default: the first --mask span).
    #[arg(long, group = "guidance")]
    pub text: Option<String>,
    /// Span the --text is spoken over (same syntax as --mask).
    #[arg(long)]
    pub text_span: Option<String>,
    /// TextGrid tier holding the phonemes (default: "phones").
    #[arg(long)]
    pub tier: Option<String>,
    /// Blendshape groups to regenerate: eyes, brows, jaw, mouth, cheeks, tongue, lower, upper, all;
    /// the guidance acts on all of them. Default: every group, visemes (--text, --visemes) guiding
    /// jaw, mouth, cheeks and tongue and the other groups filled unguided.
    #[arg(long)]
    pub groups: Option<String>,
    #[arg(long, value_enum, default_value = "auto")]
    pub method: MethodArg,
    /// Weights for the network (default: the committed ones for the guidance given).
    #[arg(long)]
    pub weights: Option<PathBuf>,
    /// Clips for --method retrieval to draw from (any clip format; comma-separated or repeated).
    /// Default: 120 s of procedural faces. The clip itself outside the spans is always searched.
    #[arg(long, value_delimiter = ',')]
    pub library: Vec<PathBuf>,
    /// Output file; Live Link CSV when the input is, else curve CSV/JSON by extension.
    #[arg(short, long)]
    pub out: PathBuf,
    /// PNG of the edited curves (default: OUT with .png).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// GIF of the schematic face, original beside edited, over the spans ±1 s.
    #[arg(long)]
    pub gif: Option<PathBuf>,
    /// Seed of the generator's noise (the network's fills are stochastic; the same seed gives the
    /// same fill).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write N fills with seeds SEED, SEED+1, …: OUT's name with -1 … -N before its extension (and
    /// the same for the PNG and GIF), and print how far each lies from the first.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub variants: u32,
    /// Most rows (frames) the input clip or the noisy take may hold.
    #[arg(long, default_value_t = EditLimits::default().max_rows)]
    pub max_rows: usize,
    /// Longest stretch, in seconds, from the first --mask span's start to the last one's end.
    #[arg(long, default_value_t = EditLimits::default().max_mask_s)]
    pub max_mask_seconds: f64,
    /// Stop with an error, writing nothing, after this many seconds.
    #[arg(long)]
    pub time_limit: Option<f64>,
}

impl MethodArg {
    fn choice(self) -> MethodChoice {
        match self {
            MethodArg::Auto => MethodChoice::Auto,
            MethodArg::Network => MethodChoice::Network,
            MethodArg::Linear => MethodChoice::Linear,
            MethodArg::Cubic => MethodChoice::Cubic,
            MethodArg::Retrieval => MethodChoice::Retrieval,
        }
    }
}

/// The edit job's limit fields and the flags that set them.
const EDIT_FLAGS: &[(&str, &str)] = &[
    ("max_rows", "--max-rows"),
    ("max_mask_s", "--max-mask-seconds"),
    ("library", "--library"),
    ("method", "--method"),
];

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DataArg {
    /// The procedural generator (exact viseme labels); the committed weights are trained on it.
    Procedural,
    /// The training split of ../shared/data/face (never commit these weights).
    Real,
}

#[derive(Args)]
pub struct TrainArgs {
    /// unguided, keyframes, noisy, visemes, or all.
    #[arg(long, default_value = "all")]
    pub kind: String,
    #[arg(long, value_enum, default_value = "procedural")]
    pub data: DataArg,
    /// Output folder: <kind>.bpk + <kind>.json per network. The committed folder is refused unless
    /// --overwrite-committed.
    #[arg(short, long, default_value_os_t = TRAIN.out.clone())]
    pub out: PathBuf,
    #[arg(long)]
    pub overwrite_committed: bool,
    /// Checkpoint folder (one subfolder per network); training resumes from it.
    #[arg(long, default_value_os_t = TRAIN.checkpoints.clone())]
    pub checkpoints: PathBuf,
    /// Minutes per network (the running epoch is finished and saved).
    #[arg(long)]
    pub minutes: Option<f64>,
    #[arg(long, default_value_t = TRAIN.epochs)]
    pub epochs: usize,
    #[arg(long, default_value_t = TRAIN.steps_per_epoch)]
    pub steps_per_epoch: usize,
    #[arg(long, default_value_t = TRAIN.batch)]
    pub batch: usize,
    /// Frames per training window at 25 fps.
    #[arg(long, default_value_t = TRAIN.window)]
    pub window: usize,
    /// Procedural clips (with --data procedural).
    #[arg(long, default_value_t = TrainJob::PROCEDURAL_CLIPS)]
    pub clips: usize,
    /// Hidden units per direction (paper: 128).
    #[arg(long, default_value_t = TRAIN.d_hidden)]
    pub hidden: usize,
    /// Captures folder (default: ../shared/data/face/neurosync or $INBETWEEN_DATA/face/neurosync).
    #[arg(long)]
    pub captures: Option<PathBuf>,
    #[arg(long, default_value_t = TRAIN.seed)]
    pub seed: u64,
    /// Stop with an error after this many seconds over all networks, writing no weights (checkpoints
    /// of finished epochs stay, so a rerun resumes). Unlike --minutes, which ends each network's
    /// training early and saves it.
    #[arg(long)]
    pub time_limit: Option<f64>,
}

/// The engine's training job, the flags' defaults.
static TRAIN: std::sync::LazyLock<TrainJob> = std::sync::LazyLock::new(TrainJob::default);

#[derive(Args)]
pub struct BenchArgs {
    /// A small run (one held-out file, few edits).
    #[arg(long)]
    pub quick: bool,
    /// A folder of weights trained on procedural clips (`face train`) to bench instead of the
    /// committed ones.
    #[arg(long)]
    pub weights: Option<PathBuf>,
    /// A folder of weights trained on the real captures (`face train --data real`), compared too.
    #[arg(long)]
    pub real_weights: Option<PathBuf>,
    #[arg(long)]
    pub captures: Option<PathBuf>,
    #[arg(short, long, default_value = "out/face-bench")]
    pub out: PathBuf,
}

#[derive(Args)]
pub struct SynthArgs {
    #[arg(short, long)]
    pub out: PathBuf,
    #[arg(long, default_value_t = procedural::ProceduralConfig::default().duration_s)]
    pub seconds: f64,
    /// Write Live Link Face CSV (else curve CSV/JSON by extension).
    #[arg(long)]
    pub live_link: bool,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(c: FaceCommand) -> anyhow::Result<()> {
    match c {
        FaceCommand::Edit(a) => run_edit(a).map_err(|e| errors::name_flags(e, EDIT_FLAGS)),
        FaceCommand::Train(a) => run_train(a).map_err(|e| errors::name_flags(e, &[])),
        FaceCommand::Bench(a) => run_bench(a),
        FaceCommand::Synth(a) => run_synth(a),
        FaceCommand::Scale(a) => run_scale(a),
    }
}

fn guide_of(a: &EditArgs, clip: &BlendshapeClip, spans: &[(f64, f64)]) -> anyhow::Result<LoadedGuide> {
    let source = match (&a.keys, &a.guide, &a.visemes, &a.text) {
        (Some(k), ..) => GuideSource::KeysFile(k),
        (_, Some(g), ..) => GuideSource::TakeFile(g),
        (_, _, Some(v), _) => GuideSource::VisemesFile(v, a.tier.as_deref()),
        (_, _, _, Some(text)) => {
            GuideSource::Text(text, a.text_span.as_ref().map_or(Ok(spans[0]), |t| span_seconds(t, clip))?)
        }
        _ => GuideSource::None,
    };
    let loaded = source.load(a.max_rows)?;
    if let Some(note) = loaded.guessed_note() {
        eprintln!("note: {note}");
    }
    Ok(loaded)
}

fn run_edit(a: EditArgs) -> anyhow::Result<()> {
    let cancel = errors::time_limit(a.time_limit)?;
    let limits = EditLimits { max_rows: a.max_rows, max_mask_s: a.max_mask_seconds };
    let clip = read_clip_limited(&a.input, limits.max_rows)?;
    let spans = a.mask.iter().map(|m| span_seconds(m, &clip)).collect::<Result<Vec<_>, _>>()?;
    let channels = a.groups.as_deref().map(parse_groups).transpose().map_err(anyhow::Error::msg)?;
    let LoadedGuide { guide, file: guide_file, .. } = guide_of(&a, &clip, &spans)?;
    // Said once the edit is written (an error stays the only line of a failed run).
    let groups_note = (guide.kind() == ConstraintKind::Visemes)
        .then(|| format!("note: {}", visemes_groups_note(a.groups.as_deref(), "--groups", "--groups")));
    let mut res = EditResources::load_network(a.method.choice(), guide.kind(), a.weights.as_deref())?;
    res.check_library_given(!a.library.is_empty())?;
    res.load_library(&a.library, channels.is_some(), limits.max_rows)?;
    let method = res.method(a.variants as usize)?;
    let library = res.library.as_ref();
    let mut job =
        EditJob { clip: &clip, spans, channels, guide, method, seed: a.seed, limits, cancel, guide_file, library };
    let files = EditFiles {
        live_link: keeps_live_link(&a.input, &a.out),
        input: a.input,
        out: a.out,
        png: a.png,
        gif: a.gif,
        variants: a.variants,
    };
    let written = write_variants(&mut job, &files)?;
    written.lines.iter().chain(&groups_note).chain(&written.spreads_line()).for_each(|l| println!("{l}"));
    Ok(())
}

fn run_train(a: TrainArgs) -> anyhow::Result<()> {
    let job = TrainJob {
        kinds: TrainJob::parse_kinds(&a.kind).map_err(anyhow::Error::msg)?,
        data: match a.data {
            DataArg::Procedural => TrainData::Procedural { clips: a.clips },
            DataArg::Real => TrainData::Real { captures: a.captures },
        },
        out: a.out,
        overwrite_committed: a.overwrite_committed,
        checkpoints: a.checkpoints,
        epochs: a.epochs,
        steps_per_epoch: a.steps_per_epoch,
        batch: a.batch,
        window: a.window,
        d_hidden: a.hidden,
        seed: a.seed,
        time_limit_s: a.minutes.map(|m| m * 60.0),
    };
    job.validate()?;
    let cancel = errors::time_limit(a.time_limit)?;
    println!("{}", job.run(&cancel, &Progress::new(0, "train"))?);
    Ok(())
}

fn run_bench(a: BenchArgs) -> anyhow::Result<()> {
    let engine = bench::FaceBench { weights: a.weights, real_weights: a.real_weights };
    let opts = BenchOptions { out: Some(a.out), data: a.captures, quick: a.quick, ..BenchOptions::new(engine) };
    crate::bench::run("face bench", opts, bench::run)?.print_summary();
    Ok(())
}

fn run_synth(a: SynthArgs) -> anyhow::Result<()> {
    let p = procedural::generate(&procedural::ProceduralConfig { duration_s: a.seconds, ..Default::default() }, a.seed);
    println!("{}", p.write(&a.out, a.live_link)?);
    Ok(())
}

fn run_scale(a: ScaleArgs) -> anyhow::Result<()> {
    crate::scale::run(&a, "face", "face edit (unguided network) at multiples of the demo's example", |k, exe, work| {
        let ex = inbetween_face::demo::scaled_example(k);
        let (clip, (start, end)) = (&ex.clip, ex.span_s);
        let input = work.join(format!("clip-{k}.csv"));
        write_clip(&input, clip, false)?;
        let mut command = std::process::Command::new(exe);
        command.args(["face".as_ref(), "edit".as_ref(), input.as_os_str(), "--mask".as_ref()]);
        command.arg(format!("{start}s..{end}s")).arg("-o").arg(work.join(format!("edit-{k}.csv")));
        let input = format!("{} s clip ({} rows), {:.1} s gap", ex.seconds, clip.num_frames(), end - start);
        Ok(crate::scale::Measured { input, command })
    })
}
