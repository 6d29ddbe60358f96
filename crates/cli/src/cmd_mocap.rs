//! `inbetween mocap …` (owned by the mocap engine work): compress / decompress / preview a clip with
//! the keyframe codec, benchmark the keyframe selectors, train SIDQL, stream keys over TCP.

use anyhow::{bail, Context};
use clap::{Args, Subcommand};
use inbetween_core::cancel::Cancel;
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::Motion;
use inbetween_io::fsutil::write_atomic;
use inbetween_io::report::BenchOptions;
use inbetween_io::Progress;
use inbetween_mocap::bench::{self, Protocol};
use inbetween_mocap::codec::job::Version;
use inbetween_mocap::codec::{self, Budget};
use inbetween_mocap::dqn::{TrainJob, TrainOptions, DEFAULT_POLICY_PATH};
use inbetween_mocap::protocol::TrainingData;
use inbetween_mocap::representation::{skip_first_frame, JointFilter};
use inbetween_mocap::select::job::{max_gap_frames, DEFAULT_MAX_GAP_S};
use inbetween_mocap::stream::{RecvJob, RecvOptions, SendOptions, DEFAULT_ADDR};
use inbetween_mocap::{CompressJob, DecompressJob, DecompressReport, PreviewJob, Rebuilt};
use std::path::{Path, PathBuf};
use std::sync::LazyLock;
use std::time::Instant;

#[derive(Subcommand)]
pub enum MocapCommand {
    /// Compress a clip into an .ibk file: every frame within --max-error (version 4, the default; or
    /// --format v3), or keyframes (-k N, or --format v2).
    Compress(CompressArgs),
    /// Rebuild a whole clip from an .ibk file and write it as BVH.
    Decompress(DecompressArgs),
    /// Overlay a clip and its reconstruction from keyframes in one GIF.
    Preview(PreviewArgs),
    /// Benchmark keyframe selection methods (RC, UC, Greedy, SIDQL, Optimal) on the CMU clips.
    Bench(BenchArgs),
    /// Train the SIDQL deep Q-network (CMU 80% split or procedural gaits) and save the policy.
    Train(TrainArgs),
    /// Stream keyframes over TCP: `send` a clip in real time, `recv` and rebuild it.
    #[command(subcommand)]
    Stream(StreamCommand),
    /// `mocap compress` (≤ 1 cm) on the demo's procedural walk at 1×, 10×, 100× its length: time
    /// and peak memory per run.
    Scale(crate::scale::ScaleArgs),
}

#[derive(Args)]
pub struct TrainArgs {
    /// Policy file to write (burnpack weights; the card goes beside it as .json); the pretrained
    /// stage goes beside it as <stem>.pretrain.bpk.
    #[arg(short, long, default_value = DEFAULT_POLICY_PATH)]
    pub output: PathBuf,
    /// Train on procedural gaits (our own data) instead of CMU takes.
    #[arg(long, conflicts_with = "all_takes")]
    pub procedural: bool,
    /// Train on every CMU take of the corpus (how the committed policy was trained; the bench's
    /// k-fold scores this recipe on held-out takes) instead of the bench's training split.
    #[arg(long)]
    pub all_takes: bool,
    /// Data folder: the shared corpus (default), its mocap/cmu folder, or any folder of .bvh files
    /// (searched recursively).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Length unit of the clips (overrides the corpus's known units): cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or cm per unit
    /// (e.g. 2.54). Default: known for the corpus folders, else inferred per clip from its rest pose (the report says which and why).
    #[arg(long)]
    pub unit: Option<LengthUnit>,
    /// Hyper-parameters: `default` (no pretraining: the network starts as greedy by exact gain;
    /// then the paper's DQN as a short, gentle fine-tune; `--pretrain-steps 3000` adds pretraining
    /// on exact cost-to-go), `paper` (§5.2's DQN alone: lr 0.01, batch 256, memory 10 000, γ = 0.5,
    /// target renewed every 100 updates, 2000 episodes) or `quick`.
    #[arg(long, default_value = "default")]
    pub preset: String,
    /// Pretraining steps (0 skips pretraining; default: the preset's).
    #[arg(long)]
    pub pretrain_steps: Option<usize>,
    /// Fine-tuning epochs of max-keys − 2 environment steps (0 skips fine-tuning; default: the preset's).
    #[arg(long)]
    pub episodes: Option<usize>,
    /// Fine-tuning learning rate (default: the preset's).
    #[arg(long)]
    pub lr: Option<f64>,
    /// Discount factor γ of the fine-tuning targets (default: the preset's; `paper` uses 0.5).
    #[arg(long)]
    pub gamma: Option<f64>,
    /// Stride of the training windows (overlapping windows give more training data).
    #[arg(long, default_value_t = TrainJob::default().stride)]
    pub stride: usize,
    #[arg(long, default_value_t = TrainOptions::default().seed)]
    pub seed: u64,
    /// Stop after the epoch during which this many minutes have passed (per stage); run the same
    /// command again to resume (training state is checkpointed in `<output>.ckpt/`).
    #[arg(long)]
    pub time_limit_min: Option<f64>,
}

#[derive(Subcommand)]
pub enum StreamCommand {
    /// Read a clip as if captured live, choose keys online and send them.
    Send(SendArgs),
    /// Accept a stream, rebuild the frames and write them as BVH.
    Recv(RecvArgs),
}

#[derive(Args)]
pub struct SendArgs {
    pub input: PathBuf,
    #[arg(long, default_value = DEFAULT_ADDR)]
    pub addr: String,
    #[arg(long, default_value = STREAM_MAX_ERROR.as_str())]
    pub max_error: String,
    /// Look-ahead window in frames (bounds the added latency).
    #[arg(long, default_value_t = SendOptions::default().lookahead)]
    pub lookahead: usize,
    /// Send as fast as possible instead of at the clip's frame rate.
    #[arg(long)]
    pub fast: bool,
    #[arg(long)]
    pub skip_first: bool,
    #[arg(long, default_value_t = SendOptions::default().retries)]
    pub retries: usize,
    /// Length unit of the clip: cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or cm per unit
    /// (e.g. 2.54). Default: inferred from the skeleton's rest pose (the report says which and why).
    #[arg(long)]
    pub unit: Option<LengthUnit>,
}

/// The engine's defaults, written as the flags take them: the stream's error bound, the bench's
/// bounds in cm (comma-separated).
static STREAM_MAX_ERROR: LazyLock<String> = LazyLock::new(|| format!("{}cm", SendOptions::default().max_cm));
static CODEC_BOUNDS: LazyLock<String> = LazyLock::new(|| list(&bench::BenchConfig::default().codec_bounds_cm));
static ACL_BOUNDS: LazyLock<String> = LazyLock::new(|| list(&bench::acl::AclConfig::default().bounds_cm));
static RACE_BOUNDS: LazyLock<String> = LazyLock::new(|| list(&bench::acl::AclConfig::default().race_bounds));

fn list(values: &[f64]) -> String {
    values.iter().map(f64::to_string).collect::<Vec<_>>().join(",")
}

#[derive(Args)]
pub struct RecvArgs {
    #[arg(long, default_value = DEFAULT_ADDR)]
    pub addr: String,
    #[arg(short, long)]
    pub output: PathBuf,
    /// Compare against this clip and print the error (from the frame the stream starts at).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    #[arg(long)]
    pub skip_first: bool,
    /// Length unit of the reference clip, for errors in cm: cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or cm per unit
    /// (e.g. 2.54). Default: inferred from the skeleton's rest pose (the report says which and why).
    #[arg(long)]
    pub unit: Option<LengthUnit>,

    /// Seconds to wait for a (re)connection.
    #[arg(long, default_value_t = RecvOptions::default().accept_timeout.as_secs_f64())]
    pub timeout_s: f64,
}

#[derive(Args, Clone)]
pub struct BudgetArgs {
    /// Number of keyframes (first and last frame included).
    #[arg(short, long, conflicts_with = "max_error")]
    pub k: Option<usize>,
    /// Error bound with its unit (mm, cm or m), e.g. 1cm, 5mm. Version 3 and 4 files bound the
    /// virtual-vertex error: three points 3 cm from each joint along its local axes (ACL's metric;
    /// a joint itself may move a little more); version 2 (-k or --format v2) bounds each joint's
    /// position error.
    #[arg(long)]
    pub max_error: Option<String>,
    /// Longest gap between two keys, in seconds (bounds the search; -k widens it as needed).
    #[arg(long, default_value_t = DEFAULT_MAX_GAP_S)]
    pub max_gap_s: f64,
    /// Joints to keep: `all`, `paper` (drop fingers, thumbs, toes) or comma-separated name parts to drop.
    #[arg(long, default_value = "all")]
    pub joints: String,
    /// Drop the first frame (the T-pose of CMU cgspeed files).
    #[arg(long)]
    pub skip_first: bool,
    /// Length unit of the clip: cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or cm per unit
    /// (e.g. 2.54). Default: inferred from the skeleton's rest pose (the report says which and why).
    #[arg(long)]
    pub unit: Option<LengthUnit>,
}

impl BudgetArgs {
    /// The clip's unit: `--unit`, else inferred from its skeleton.
    fn unit(&self, m: &Motion) -> UnitChoice {
        UnitChoice::resolve(self.unit, &m.skeleton)
    }

    fn budget(&self) -> anyhow::Result<Budget> {
        match (self.k, &self.max_error) {
            (Some(k), None) => Ok(Budget::Keys(k)),
            (None, Some(e)) => Ok(Budget::MaxErrorCm(codec::parse_length_cm(e)?)),
            _ => bail!("give either -k N or --max-error LENGTH (e.g. --max-error 1cm)"),
        }
    }

    fn load(&self, path: &Path) -> anyhow::Result<Motion> {
        let m = load(path, self.skip_first)?;
        Ok(JointFilter::parse(&self.joints).apply(&m))
    }

    /// The compression these flags ask for (the version the budget picks, the default segments).
    fn job(&self, m: &Motion) -> anyhow::Result<CompressJob> {
        let (max_gap, unit) = (max_gap_frames(self.max_gap_s, m.frame_time), self.unit(m));
        Ok(CompressJob { max_gap, unit, ..CompressJob::for_motion(m, self.budget()?) })
    }
}

/// A clip from a file, without its first frame when asked (`--skip-first`).
fn load(path: &Path, skip_first: bool) -> anyhow::Result<Motion> {
    let m = inbetween_io::load_motion(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(if skip_first { skip_first_frame(m)? } else { m })
}

#[derive(Args)]
pub struct CompressArgs {
    /// Input .bvh (or .amc with its .asf beside it).
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub budget: BudgetArgs,
    /// File format: `v4` (every frame, fixed-width values per segment: the runtime layout, a pose
    /// samples in well under a microsecond), `v3` (every frame, entropy coded: smaller files,
    /// slower to sample) or `v2` (keyframes). v3 and v4 bound the virtual vertices 3 cm from each
    /// joint; v2 bounds each joint's position. Default: v4 with --max-error, v2 with -k.
    #[arg(long)]
    pub format: Option<String>,
    /// Frames per segment of a v3 or v4 file (a pose decodes from its segment alone). Default: 32
    /// for v3, 16 for v4.
    #[arg(long)]
    pub segment: Option<usize>,
}

#[derive(Args)]
pub struct DecompressArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Args)]
pub struct PreviewArgs {
    /// The original clip.
    pub input: PathBuf,
    /// GIF to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Reconstruct from this .ibk file instead of choosing keys here.
    #[arg(long)]
    pub ibk: Option<PathBuf>,
    #[command(flatten)]
    pub budget: BudgetArgs,
}

#[derive(Args)]
pub struct BenchArgs {
    /// Data folder (default: the shared corpus); every CMU take under <DIR>/mocap/cmu (cgspeed BVH,
    /// ASF/AMC, iClone BVH; one entry per take), or each .bvh in DIR itself.
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Write the whole report into this folder: report.txt and report.md (every table), one CSV
    /// per table (mocap_bench.csv holds every row) and table3.png.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write every row as CSV (the columns of mocap_bench.csv).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Also write the bar chart of the mean angle error (PNG).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Length unit of the clips (overrides the corpus's known units): cm, m, mm, in, cmu (CMU mocap
    /// units, 5.6444 cm) or cm per unit. Default: known for the corpus folders, else inferred per
    /// clip from its rest pose (the report says which and why).
    #[arg(long)]
    pub unit: Option<LengthUnit>,
    /// Window stride in frames (60 = non-overlapping windows, as in the paper).
    #[arg(long, default_value_t = Protocol::paper().stride)]
    pub stride: usize,
    #[arg(long, default_value_t = Protocol::paper().seed)]
    pub seed: u64,
    /// A SIDQL policy written by `mocap train`. Default: the committed policy (trained on every
    /// CMU take of the corpus), unless --train-episodes is given.
    #[arg(long)]
    pub model: Option<PathBuf>,
    #[arg(long, default_value_t = 0, conflicts_with = "model", help = format!(
        "Train SIDQL here first, on the CMU training split (pretraining, then this many fine-tuning epochs; saved as {DEFAULT_POLICY_PATH})"
    ))]
    pub train_episodes: usize,
    /// Also report codec compression at these max errors (cm), on the full-rate clips.
    #[arg(long, value_delimiter = ',', default_value = CODEC_BOUNDS.as_str())]
    pub codec_bounds: Vec<f64>,
    /// Error bounds (cm) of the codec table on ACL's protocol (24 fps, 40-byte raw, virtual
    /// vertices 3 cm away) and its rate–error curve; written as acl_codec.* beside the report.
    #[arg(long, value_delimiter = ',', default_value = ACL_BOUNDS.as_str())]
    pub acl_bounds: Vec<f64>,
    /// Run only the codec table on ACL's protocol (skip the keyframe-selection bench).
    #[arg(long)]
    pub codec_only: bool,
    /// Bounds (cm) of the race against the real ACL (built from ../shared/peers/acl-race when it and
    /// g++ exist; otherwise `skipped: ACL not built` and our rows only).
    #[arg(long, value_delimiter = ',', default_value = RACE_BOUNDS.as_str())]
    pub race_bounds: Vec<f64>,
    /// Frames per segment of the codec files on ACL's protocol.
    #[arg(long, default_value_t = inbetween_mocap::codec::v3::DEFAULT_SEGMENT_LEN)]
    pub acl_segment: usize,
    /// Take-level k-fold of SIDQL: a policy trained per fold on the other takes, every window
    /// scored once held out (0 skips it; a few CPU minutes at 5).
    #[arg(long, default_value_t = bench::run::KFoldConfig::default().folds)]
    pub folds: usize,
}

pub fn run(c: MocapCommand) -> anyhow::Result<()> {
    match c {
        MocapCommand::Compress(a) => compress(a),
        MocapCommand::Decompress(a) => decompress(a),
        MocapCommand::Preview(a) => preview(a),
        MocapCommand::Bench(a) => bench_cmd(a),
        MocapCommand::Train(a) => train_cmd(a),
        MocapCommand::Stream(StreamCommand::Send(a)) => stream_send(a),
        MocapCommand::Stream(StreamCommand::Recv(a)) => stream_recv(a),
        MocapCommand::Scale(a) => run_scale(a),
    }
}

fn compress(a: CompressArgs) -> anyhow::Result<()> {
    let m = a.budget.load(&a.input)?;
    let job = a.budget.job(&m)?;
    let job =
        CompressJob { version: a.format.as_deref().map(Version::parse).transpose()?, segment_len: a.segment, ..job };
    job.validate()?;
    let t = Instant::now();
    let report = job.run(&m).with_context(|| format!("compressing {}", a.input.display()))?;
    let secs = t.elapsed().as_secs_f64();
    write_atomic(&a.output, report.bytes()).with_context(|| format!("writing {}", a.output.display()))?;
    println!("{}", crate::errors::with_flags(&report.to_string()));
    println!("wrote {} in {secs:.2} s", a.output.display());
    Ok(())
}

/// An `.ibk` file decoded by the engine's `DecompressJob`.
fn decompress_file(path: &Path) -> anyhow::Result<DecompressReport> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    DecompressJob
        .run(&bytes, &Cancel::new(), &Progress::hidden())
        .with_context(|| format!("decoding {}", path.display()))
}

fn decompress(a: DecompressArgs) -> anyhow::Result<()> {
    let r = decompress_file(&a.input)?;
    inbetween_io::write_bvh(&a.output, &r.motion).with_context(|| format!("writing {}", a.output.display()))?;
    println!("{r}; wrote {}", a.output.display());
    Ok(())
}

fn preview(a: PreviewArgs) -> anyhow::Result<()> {
    let m = a.budget.load(&a.input)?;
    let unit = a.budget.unit(&m);
    println!("{unit}");
    let rebuilt = match &a.ibk {
        Some(p) => Rebuilt::File(p, Box::new(decompress_file(p)?)),
        None => Rebuilt::Keys(a.budget.job(&m)?),
    };
    println!("{}", PreviewJob { original: &m, name: &a.input, unit, rebuilt, out: &a.output }.run()?);
    Ok(())
}

impl BenchArgs {
    /// The library's bench configuration for these arguments.
    fn config(&self) -> bench::BenchConfig {
        let policy = match (&self.model, self.train_episodes) {
            (Some(p), _) => bench::PolicyChoice::File(p.clone()),
            (None, 0) => bench::PolicyChoice::Committed,
            (None, episodes) => bench::PolicyChoice::train(episodes),
        };
        bench::BenchConfig {
            unit: self.unit,
            protocol: Protocol { stride: self.stride, ..Protocol::paper() },
            policy,
            codec_bounds_cm: self.codec_bounds.clone(),
            chart: self.plot.is_some(),
            kfold: (self.folds > 0).then(|| bench::run::KFoldConfig { folds: self.folds, ..Default::default() }),
            ..bench::BenchConfig::default()
        }
    }

    /// The codec table on ACL's protocol (`bench::acl`), written beside the bench report.
    fn acl(&self) -> bench::acl::AclConfig {
        bench::acl::AclConfig {
            unit: self.unit,
            bounds_cm: self.acl_bounds.clone(),
            segment_len: self.acl_segment,
            race_bounds: self.race_bounds.clone(),
            ..Default::default()
        }
    }

    fn options<E>(&self, engine: E) -> BenchOptions<E> {
        BenchOptions {
            out: self.output.clone(),
            data: self.data.clone(),
            seed: Some(self.seed),
            ..BenchOptions::new(engine)
        }
    }
}

fn bench_cmd(a: BenchArgs) -> anyhow::Result<()> {
    if !a.codec_only {
        let mut done = crate::bench::run("mocap bench", a.options(a.config()), bench::run)?;
        if let Some(p) = &a.csv {
            let rows = done.report.find_table(bench::report::ROWS_TABLE).map(|t| t.to_csv()).unwrap_or_default();
            write_atomic(p, rows.as_bytes()).with_context(|| format!("writing {}", p.display()))?;
            done.files.push(p.clone());
        }
        if let Some(p) = &a.plot {
            let png = done.report.file_bytes(bench::report::CHART_FILE).unwrap_or_default();
            write_atomic(p, png).with_context(|| format!("writing {}", p.display()))?;
            done.files.push(p.clone());
        }
        done.print_files();
    }
    crate::bench::run("codec (ACL protocol)", a.options(a.acl()), bench::acl::run)?.print_files();
    Ok(())
}

fn train_cmd(a: TrainArgs) -> anyhow::Result<()> {
    let base = TrainOptions::preset_with(&a.preset, a.pretrain_steps, a.episodes, a.lr, a.gamma)?;
    let job = TrainJob {
        data: match (a.procedural, a.all_takes) {
            (true, _) => TrainingData::Procedural,
            (false, true) => TrainingData::CmuAll,
            (false, false) => TrainingData::CmuSplit,
        },
        data_dir: a.data,
        unit: a.unit,
        stride: a.stride,
        options: TrainOptions { seed: a.seed, time_limit_s: a.time_limit_min.map(|m| m * 60.0), ..base },
        output: a.output,
    };
    println!("{}", job.run(&Cancel::new(), &Progress::hidden())?);
    Ok(())
}

fn stream_send(a: SendArgs) -> anyhow::Result<()> {
    let m = load(&a.input, a.skip_first)?;
    let opts = SendOptions {
        max_cm: codec::parse_length_cm(&a.max_error)?,
        lookahead: a.lookahead,
        realtime: !a.fast,
        retries: a.retries,
        unit: a.unit,
    };
    let r = inbetween_mocap::stream::send(&a.addr, &m, &opts)?;
    println!("{}", crate::errors::with_flags(&r.unit.to_string()));
    println!("{r}");
    Ok(())
}

fn stream_recv(a: RecvArgs) -> anyhow::Result<()> {
    let options = RecvOptions { accept_timeout: std::time::Duration::from_secs_f64(a.timeout_s), ..Default::default() };
    let reference = a.reference.map(|r| load(&r, a.skip_first).map(|m| (r, m))).transpose()?;
    let job = RecvJob { addr: a.addr, output: a.output, options, reference, unit: a.unit };
    let report = job.run()?;
    for w in &report.received.warnings {
        eprintln!("warning: {w}");
    }
    if report.output.is_some() {
        println!("{report}");
    }
    Ok(report.check()?)
}

fn run_scale(a: crate::scale::ScaleArgs) -> anyhow::Result<()> {
    // The demo's procedural walk, k times as long, written as BVH.
    crate::scale::run(&a, "mocap", "mocap compress (≤ 1 cm) at multiples of the demo's walk", |k, exe, work| {
        let walk = inbetween_mocap::demo::scaled_walk(k);
        let input = work.join(format!("walk-{k}.bvh"));
        inbetween_io::write_bvh(&input, &walk)?;
        let mut command = std::process::Command::new(exe);
        command.args(["mocap".as_ref(), "compress".as_ref(), input.as_os_str()]);
        command.args(["--max-error", "1cm", "-o"]).arg(work.join(format!("walk-{k}.ibk")));
        let input = format!("{} frames × {} joints at {:.0} fps", walk.num_frames(), walk.skeleton.len(), walk.fps());
        Ok(crate::scale::Measured { input, command })
    })
}
