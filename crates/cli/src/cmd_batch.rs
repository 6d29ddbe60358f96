//! `inbetween batch …`: one engine job over a folder, in shards (see `inbetween_batch`). Parses
//! flags into a `BatchJob` or `SummaryJob` and prints its report.

use anyhow::Context;
use clap::{Args, Subcommand};
use inbetween_batch::{BatchJob, Kind, Options, Shard, SummaryJob};
use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum BatchCommand {
    /// Compress every .bvh/.amc below DIR into OUT/<same path>.ibk (`mocap compress`).
    MocapCompress(RunArgs),
    /// Keyframes of every .bvh/.amc below DIR as OUT/<same path>.keys.json (key frames, tangents, errors).
    MocapKeys(RunArgs),
    /// Analyse every .mp4/.gif below DIR (flows, shots, the clip's RSFNet) into OUT/<same path>.analysis.json
    /// and OUT/<same path>.rsfnet/ (a cache `video resequence --cache-dir` reads).
    VideoAnalyse(RunArgs),
    /// Animate every story (.txt) below DIR into the folder OUT/<same path without .txt>/ (`script run`).
    ScriptRun(RunArgs),
    /// Edit every Live Link Face take (.csv) below DIR with one --mask into OUT/<same path> (`face edit`).
    FaceEdit(RunArgs),
    /// Merge the result lines of every shard in OUT into one report: totals, failures, slowest inputs.
    Summary(SummaryArgs),
    /// The CMU corpus (compress at 1 cm) and the video corpus (analysis) by 1 and 2 shard processes, and
    /// by 1 and 2 Dask workers when --python has inbetween and dask: files per second, speed-up, memory,
    /// a projection to 10,000 and 100,000 files.
    Bench(BenchArgs),
}

#[derive(Args)]
pub struct BenchArgs {
    #[arg(short, long, default_value = "out/batch-bench")]
    pub out: PathBuf,
    /// Data folder (default: ../shared/data or $INBETWEEN_DATA).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// A Python with the inbetween package and dask.distributed, for the Dask rows.
    #[arg(long)]
    pub python: Option<PathBuf>,
}

#[derive(Args)]
pub struct RunArgs {
    /// Folder of inputs (searched recursively; names starting with '.' are left out).
    pub dir: PathBuf,
    /// Output folder: outputs mirror the inputs' paths; one line per input in results-<shard>.jsonl.
    #[arg(short, long)]
    pub out: PathBuf,
    /// This process's shard, i/n with i from 0 (default: the scheduler's, else the whole folder).
    /// Slurm job arrays and Kubernetes Indexed Jobs are read from SLURM_ARRAY_TASK_ID/COUNT and
    /// JOB_COMPLETION_INDEX.
    #[arg(long)]
    pub shard: Option<String>,
    /// The number of shards, with a scheduler index from the environment (required for a
    /// Kubernetes Indexed Job: its completions).
    #[arg(long)]
    pub shards: Option<usize>,
    /// Error bound with its unit (mm, cm or m), e.g. 1cm (mocap-compress, mocap-keys).
    #[arg(long)]
    pub max_error: Option<String>,
    /// Number of keyframes (mocap-compress: version 2; mocap-keys).
    #[arg(short, long)]
    pub k: Option<usize>,
    /// mocap-keys: uniform, greedy, sidql, optimal or error_bounded; face-edit: the fill method.
    #[arg(long)]
    pub method: Option<String>,
    /// face-edit: the spans to regenerate, as `face edit --mask` takes them (e.g. 4s..6.5s).
    #[arg(long)]
    pub mask: Option<String>,
    /// script-run, face-edit: the seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Exit with code 1 when any input failed (default: 0 once the shard ran; failures are in the lines).
    #[arg(long)]
    pub strict: bool,
}

#[derive(Args)]
pub struct SummaryArgs {
    /// A batch's output folder.
    pub out: PathBuf,
    /// How many of the slowest inputs to list.
    #[arg(long, default_value_t = SummaryJob::default().slowest)]
    pub slowest: usize,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(c: BatchCommand) -> anyhow::Result<()> {
    let (kind, a) = match c {
        BatchCommand::MocapCompress(a) => (Kind::MocapCompress, a),
        BatchCommand::MocapKeys(a) => (Kind::MocapKeys, a),
        BatchCommand::VideoAnalyse(a) => (Kind::VideoAnalyse, a),
        BatchCommand::ScriptRun(a) => (Kind::ScriptRun, a),
        BatchCommand::FaceEdit(a) => (Kind::FaceEdit, a),
        BatchCommand::Summary(a) => return summary(a),
        BatchCommand::Bench(a) => return bench(a),
    };
    let shard = match (&a.shard, a.shards) {
        (Some(s), _) => Shard::parse(s).context("--shard")?,
        (None, shards) => match Shard::from_env(shards, &|k| std::env::var(k).ok())? {
            Some(s) => s,
            None if shards.is_some() => anyhow::bail!(
                "--shards without a scheduler index (SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX): give --shard i/n"
            ),
            None => Shard::ALL,
        },
    };
    let max_error_cm =
        a.max_error.as_deref().map(inbetween_mocap::codec::parse_length_cm).transpose().context("--max-error")?;
    let job = BatchJob {
        kind,
        input_dir: a.dir.clone(),
        out_dir: a.out.clone(),
        shard,
        options: Options { max_error_cm, keys: a.k, method: a.method, mask: a.mask, seed: a.seed },
    };
    job.validate().map_err(|e| crate::errors::name_flags(e.into(), BATCH_FLAGS))?;
    let progress = Progress::new(0, kind.name());
    let report = job.run(&Cancel::new(), &progress)?;
    progress.finish();
    println!("{report}");
    if a.strict && report.failed > 0 {
        anyhow::bail!("{} of {} inputs failed (--strict)", report.failed, report.inputs);
    }
    Ok(())
}

/// The job's option fields and the flags that set them.
const BATCH_FLAGS: &[(&str, &str)] =
    &[("max_error_cm", "--max-error"), ("keys", "-k"), ("method", "--method"), ("mask", "--mask"), ("seed", "--seed")];

fn summary(a: SummaryArgs) -> anyhow::Result<()> {
    let s = SummaryJob { out_dir: a.out, slowest: a.slowest }.run()?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        println!("{s}");
    }
    Ok(())
}

fn bench(a: BenchArgs) -> anyhow::Result<()> {
    let data = match a.data {
        Some(d) => d,
        None => inbetween_io::shared_data_dir()
            .map_err(|p| anyhow::anyhow!("no data at {} (give --data or set INBETWEEN_DATA)", p.display()))?,
    };
    let exe = std::env::current_exe().context("finding the inbetween binary")?;
    let report = inbetween_batch::bench::run(&inbetween_batch::bench::BenchOptions::new(exe, data, &a.out, a.python))?;
    for p in report.write(&a.out)? {
        println!("wrote {}", p.display());
    }
    println!("{}", report.to_text());
    Ok(())
}
