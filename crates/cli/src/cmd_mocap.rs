//! `inbetween mocap …` (owned by the mocap engine work): compress / decompress / preview a clip with
//! the keyframe codec, benchmark the keyframe selectors, train SIDQL, stream keys over TCP.

use anyhow::{bail, Context};
use clap::{Args, Subcommand};
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::{positions_clip, Motion};
use inbetween_io::fsutil::write_atomic;
use inbetween_mocap::bench::{self, Protocol};
use inbetween_mocap::codec::{self, Budget};
use inbetween_mocap::dqn::{DqnConfig, TrainOptions};
use inbetween_mocap::representation::JointFilter;
use inbetween_render::StickOptions;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Subcommand)]
pub enum MocapCommand {
    /// Pick keyframes and write them as a compact .ibk file.
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
}

#[derive(Args)]
pub struct TrainArgs {
    /// Policy file to write (burnpack weights; the shape goes beside it as .json).
    #[arg(short, long, default_value = "out/sidql_cmu.bpk")]
    pub output: PathBuf,
    /// Train on procedural gaits (our own data, safe to commit) instead of the CMU training split.
    #[arg(long)]
    pub procedural: bool,
    /// Data folder: the shared corpus (default), its mocap/cmu folder, or any folder of .bvh files
    /// (searched recursively).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Length unit of the clips (overrides the corpus's known units): cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or cm per unit
    /// (e.g. 2.54). Default: known for the corpus folders, else inferred per clip from its rest pose (the report says which and why).
    #[arg(long)]
    pub unit: Option<LengthUnit>,
    /// Episodes (default: the preset's; `paper` runs 2000).
    #[arg(long)]
    pub episodes: Option<usize>,
    /// Hyper-parameters: `paper` (§5.2: lr 0.01, batch 256, memory 10 000, γ = 0.5, target renewed
    /// every 100 updates, 2000 episodes) or `quick` (the same with batch 64 and 300 episodes).
    #[arg(long, default_value = "paper")]
    pub preset: String,
    /// Learning rate (default: the preset's; `paper` uses 0.01).
    #[arg(long)]
    pub lr: Option<f64>,
    /// Stride of the training windows (overlapping windows give more training data).
    #[arg(long, default_value_t = 10)]
    pub stride: usize,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Stop after the episode during which this many minutes have passed; run the same command
    /// again to resume (training state is checkpointed in `<output>.ckpt/`).
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
    #[arg(long, default_value = "127.0.0.1:7878")]
    pub addr: String,
    #[arg(long, default_value = "1cm")]
    pub max_error: String,
    /// Look-ahead window in frames (bounds the added latency).
    #[arg(long, default_value_t = 15)]
    pub lookahead: usize,
    /// Send as fast as possible instead of at the clip's frame rate.
    #[arg(long)]
    pub fast: bool,
    #[arg(long)]
    pub skip_first: bool,
    #[arg(long, default_value_t = 10)]
    pub retries: usize,
    /// Length unit of the clip: cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or cm per unit
    /// (e.g. 2.54). Default: inferred from the skeleton's rest pose (the report says which and why).
    #[arg(long)]
    pub unit: Option<LengthUnit>,
}

#[derive(Args)]
pub struct RecvArgs {
    #[arg(long, default_value = "127.0.0.1:7878")]
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
    #[arg(long, default_value_t = 30.0)]
    pub timeout_s: f64,
}

#[derive(Args, Clone)]
pub struct BudgetArgs {
    /// Number of keyframes (first and last frame included).
    #[arg(short, long, conflicts_with = "max_error")]
    pub k: Option<usize>,
    /// Largest allowed position error of any joint in any frame, e.g. 1cm, 5mm.
    #[arg(long)]
    pub max_error: Option<String>,
    /// Longest gap between two keys, in seconds (bounds the search; -k widens it as needed).
    #[arg(long, default_value_t = 0.5)]
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
        let m = inbetween_io::load_motion(path).with_context(|| format!("reading {}", path.display()))?;
        let m = if self.skip_first && m.num_frames() > 2 { m.crop(1, m.num_frames())? } else { m };
        Ok(JointFilter::parse(&self.joints).apply(&m))
    }

    fn max_gap(&self, m: &Motion) -> usize {
        ((self.max_gap_s / m.frame_time).round() as usize).max(1)
    }
}

#[derive(Args)]
pub struct CompressArgs {
    /// Input .bvh (or .amc with its .asf beside it).
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub budget: BudgetArgs,
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
    #[arg(long, default_value_t = 60)]
    pub stride: usize,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A SIDQL policy written by `mocap train`. Default: the committed policy (trained on our
    /// procedural gaits), unless --train-episodes is given.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Train SIDQL here first, on the CMU training split with the paper's settings, for this many
    /// episodes (saved as out/sidql_cmu.bpk).
    #[arg(long, default_value_t = 0, conflicts_with = "model")]
    pub train_episodes: usize,
    /// Also report codec compression at these max errors (cm), on the full-rate clips.
    #[arg(long, value_delimiter = ',', default_value = "1,0.1")]
    pub codec_bounds: Vec<f64>,
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
    }
}

fn compress(a: CompressArgs) -> anyhow::Result<()> {
    let m = a.budget.load(&a.input)?;
    let t = Instant::now();
    let c = codec::compress_in(&m, a.budget.unit(&m), a.budget.budget()?, a.budget.max_gap(&m))?;
    let secs = t.elapsed().as_secs_f64();
    write_atomic(&a.output, &c.bytes).with_context(|| format!("writing {}", a.output.display()))?;
    for l in compress_report(&m, &c) {
        println!("{l}");
    }
    println!("wrote {} in {secs:.2} s", a.output.display());
    Ok(())
}

fn compress_report(m: &Motion, c: &codec::Compressed) -> Vec<String> {
    let raw = codec::raw_bytes(m);
    vec![
        c.unit.to_string(),
        format!(
            "{} frames, {} joints, {} keys; {} bytes ({} bytes per key) vs {} raw f32 bytes: ratio {:.1}x",
            m.num_frames(),
            m.skeleton.len(),
            c.keys.len(),
            c.bytes.len(),
            codec::bytes_per_key(&m.skeleton),
            raw,
            raw as f64 / c.bytes.len() as f64
        ),
        format!(
            "error: mean {:.3} cm, max {:.3} cm (decoded file); mean local rotation error {:.3} deg",
            c.decoded_mean_cm,
            c.decoded_max_cm,
            c.planned.mean_angle.to_degrees()
        ),
    ]
}

fn decompress(a: DecompressArgs) -> anyhow::Result<()> {
    let bytes = std::fs::read(&a.input).with_context(|| format!("reading {}", a.input.display()))?;
    let d = codec::decode(&bytes).with_context(|| format!("decoding {}", a.input.display()))?;
    let m = d.reconstruct()?;
    inbetween_io::write_bvh(&a.output, &m)?;
    println!("{} (the file keeps the source's unit)", LengthUnit::infer(&d.skeleton));
    println!(
        "{} keys → {} frames at {:.1} fps; wrote {}",
        d.key_frames.len(),
        m.num_frames(),
        m.fps(),
        a.output.display()
    );
    Ok(())
}

fn preview(a: PreviewArgs) -> anyhow::Result<()> {
    let m = a.budget.load(&a.input)?;
    let unit = a.budget.unit(&m);
    println!("{unit}");
    let (rec, keys) = match &a.ibk {
        Some(p) => {
            let d = codec::decode(&std::fs::read(p).with_context(|| format!("reading {}", p.display()))?)
                .with_context(|| format!("decoding {}", p.display()))?;
            if d.skeleton != m.skeleton || d.num_frames != m.num_frames() {
                bail!(
                    "{} does not match {} (skeleton or frame count differ; use the same --joints/--skip-first)",
                    p.display(),
                    a.input.display()
                );
            }
            (d.reconstruct()?, d.key_frames.len())
        }
        None => {
            let c = codec::compress_in(&m, unit.clone(), a.budget.budget()?, a.budget.max_gap(&m))?;
            (codec::decode(&c.bytes)?.reconstruct()?, c.keys.len())
        }
    };
    let e = inbetween_core::position_error(&positions_clip(&m), &positions_clip(&rec));
    let cm = unit.cm_per_unit();
    let opts = StickOptions {
        labels: vec!["original".into(), format!("from {keys} keys")],
        title: Some(format!("{} keys: mean {:.2} cm, max {:.2} cm", keys, e.mean * cm, e.max * cm)),
        ..StickOptions::default()
    };
    inbetween_render::render_motion_gif(&a.output, &[&m, &rec], &opts)?;
    println!("{keys} keys; mean {:.3} cm, max {:.3} cm; wrote {}", e.mean * cm, e.max * cm, a.output.display());
    Ok(())
}

impl BenchArgs {
    /// The library's bench configuration for these arguments.
    fn config(&self) -> bench::BenchConfig {
        let policy = match (&self.model, self.train_episodes) {
            (Some(p), _) => bench::PolicyChoice::File(p.clone()),
            (None, 0) => bench::PolicyChoice::Committed,
            (None, episodes) => bench::PolicyChoice::Train { episodes, output: PathBuf::from("out/sidql_cmu.bpk") },
        };
        bench::BenchConfig {
            data: self.data.clone(),
            unit: self.unit,
            protocol: Protocol { stride: self.stride, seed: self.seed, ..Protocol::paper() },
            policy,
            codec_bounds_cm: self.codec_bounds.clone(),
            output_dir: self.output.clone(),
            csv: self.csv.clone(),
            plot: self.plot.clone(),
            ..bench::BenchConfig::default()
        }
    }
}

fn bench_cmd(a: BenchArgs) -> anyhow::Result<()> {
    let progress = inbetween_io::Progress::new(0, "mocap bench");
    let out = bench::run(&a.config(), &progress);
    progress.finish();
    let out = out?;
    print!("{}", out.report.to_text());
    for p in &out.written {
        println!("wrote {}", p.display());
    }
    Ok(())
}



fn train_cmd(a: TrainArgs) -> anyhow::Result<()> {
    let (windows, data) = bench::run::training_set(a.procedural, a.data.as_deref(), a.unit, a.seed, a.stride)?;
    let base = match a.preset.as_str() {
        "quick" => TrainOptions::quick(),
        "paper" => TrainOptions::paper(),
        other => bail!("unknown preset '{other}'; expected paper or quick"),
    };
    if let Some(dir) = a.output.parent() {
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir)?;
        }
    }
    println!("training on {data}");
    let checkpoint_dir = a.output.with_extension("ckpt");
    let opts = TrainOptions {
        episodes: a.episodes.unwrap_or(base.episodes),
        lr: a.lr.unwrap_or(base.lr),
        seed: a.seed,
        checkpoint: Some(a.output.clone()),
        checkpoint_dir: Some(checkpoint_dir.clone()),
        time_limit_s: a.time_limit_min.map(|m| m * 60.0),
        data,
        ..base
    };
    let (_, report) = inbetween_mocap::dqn::train(&windows, &DqnConfig::default(), &opts)?;
    if let Some(from) = &report.resumed_from {
        println!("resumed from {}", from.display());
    }
    if report.episodes < opts.episodes {
        println!(
            "stopped at the time limit after {} of {} episodes; run the same command again to resume from {}",
            report.episodes,
            opts.episodes,
            checkpoint_dir.display()
        );
    }
    println!(
        "trained {} episodes, {} updates in {:.0} s; loss per 50 episodes {:?}; return per episode {:?}",
        report.episodes,
        report.updates,
        report.seconds,
        report.loss_curve.iter().map(|l| format!("{l:.4}")).collect::<Vec<_>>(),
        report.return_curve.iter().map(|r| format!("{r:.3}")).collect::<Vec<_>>()
    );
    println!("wrote {}", a.output.display());
    Ok(())
}

fn stream_send(a: SendArgs) -> anyhow::Result<()> {
    let m = inbetween_io::load_motion(&a.input).with_context(|| format!("reading {}", a.input.display()))?;
    let m = if a.skip_first && m.num_frames() > 2 { m.crop(1, m.num_frames())? } else { m };
    let opts = inbetween_mocap::stream::SendOptions {
        max_cm: codec::parse_length_cm(&a.max_error)?,
        lookahead: a.lookahead,
        realtime: !a.fast,
        retries: a.retries,
        unit: a.unit,
    };
    let r = inbetween_mocap::stream::send(&a.addr, &m, &opts)?;
    let secs = m.duration().max(1e-9);
    println!("{}", r.unit);
    println!(
        "sent {} keys for {} frames in {:.2} s: {} bytes ({:.0} B/s) vs {} raw bytes ({:.0} B/s), {:.1}x less; added latency mean {:.0} ms, max {:.0} ms; {} reconnects",
        r.keys,
        r.frames,
        r.seconds,
        r.bytes_sent,
        r.bytes_sent as f64 / secs,
        r.raw_bytes,
        r.raw_bytes as f64 / secs,
        r.raw_bytes as f64 / r.bytes_sent as f64,
        r.mean_latency_ms,
        r.max_latency_ms,
        r.reconnects
    );
    Ok(())
}

fn stream_recv(a: RecvArgs) -> anyhow::Result<()> {
    let listener = std::net::TcpListener::bind(&a.addr).with_context(|| format!("listening on {}", a.addr))?;
    let opts = inbetween_mocap::stream::RecvOptions {
        max_sessions: 8,
        accept_timeout: std::time::Duration::from_secs_f64(a.timeout_s),
    };
    let got = inbetween_mocap::stream::recv(&listener, &opts)?;
    for w in &got.warnings {
        eprintln!("warning: {w}");
    }
    inbetween_io::write_bvh(&a.output, &got.motion)?;
    println!(
        "received {} keys ({} bytes, {} sessions, {}), emitted {} frames (frames {}..{} of the sender's {}-frame clip); wrote {}",
        got.keys,
        got.bytes,
        got.sessions,
        if got.complete { "complete" } else { "incomplete" },
        got.motion.num_frames(),
        got.start_frame,
        got.start_frame + got.motion.num_frames(),
        got.clip_frames,
        a.output.display()
    );
    if got.start_frame > 0 {
        println!("joined mid-stream: the output's frame 0 is frame {} of the sender's clip", got.start_frame);
    }
    if let Some(r) = &a.reference {
        let m = inbetween_io::load_motion(r).with_context(|| format!("reading {}", r.display()))?;
        let m = if a.skip_first && m.num_frames() > 2 { m.crop(1, m.num_frames())? } else { m };
        let unit = UnitChoice::resolve(a.unit, &m.skeleton);
        let e = inbetween_mocap::stream::compare(&got, &m, unit.cm_per_unit())
            .with_context(|| format!("comparing with {}", r.display()))?;
        println!("{unit}");
        println!(
            "error vs {} frames {}..{}: mean {:.3} cm, max {:.3} cm over {} frames",
            r.display(),
            e.start_frame,
            e.start_frame + e.frames,
            e.mean_cm,
            e.max_cm,
            e.frames
        );
    }
    Ok(())
}
