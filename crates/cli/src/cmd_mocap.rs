//! `inbetween mocap …` (owned by the mocap engine work): compress / decompress / preview a clip with
//! the keyframe codec, benchmark the keyframe selectors, train SIDQL, stream keys over TCP.

use anyhow::{bail, Context};
use clap::{Args, Subcommand};
use inbetween_core::{positions_clip, KeyframeSet, Motion};
use inbetween_io::fsutil::write_atomic;
use inbetween_mocap::bench::{self, Clip, Method, Protocol};
use inbetween_mocap::codec::{self, Budget};
use inbetween_mocap::dqn::{train::SidqlPolicy, DqnConfig, TrainOptions};
use inbetween_mocap::error::{Objective, SegmentModel, SegmentTable};
use inbetween_mocap::representation::{JointFilter, SphericalMotion};
use inbetween_mocap::rotations::RotationMotion;
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
    /// Data folder for the CMU clips (default: the shared corpus).
    #[arg(long)]
    pub data: Option<PathBuf>,
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
}

#[derive(Args)]
pub struct RecvArgs {
    #[arg(long, default_value = "127.0.0.1:7878")]
    pub addr: String,
    #[arg(short, long)]
    pub output: PathBuf,
    /// Compare against this clip and print the error.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    #[arg(long)]
    pub skip_first: bool,
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
}

impl BudgetArgs {
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
    /// Write the table as CSV.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write a bar chart of the mean angle error (PNG).
    #[arg(long)]
    pub plot: Option<PathBuf>,
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
    let c = codec::compress(&m, a.budget.budget()?, a.budget.max_gap(&m))?;
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
            let c = codec::compress(&m, a.budget.budget()?, a.budget.max_gap(&m))?;
            (codec::decode(&c.bytes)?.reconstruct()?, c.keys.len())
        }
    };
    let e = inbetween_core::position_error(&positions_clip(&m), &positions_clip(&rec));
    let cm = inbetween_core::procedural::CM_PER_CMU_UNIT;
    let opts = StickOptions {
        labels: vec!["original".into(), format!("from {keys} keys")],
        title: Some(format!("{} keys: mean {:.2} cm, max {:.2} cm", keys, e.mean * cm, e.max * cm)),
        ..StickOptions::default()
    };
    inbetween_render::render_motion_gif(&a.output, &[&m, &rec], &opts)?;
    println!("{keys} keys; mean {:.3} cm, max {:.3} cm; wrote {}", e.mean * cm, e.max * cm, a.output.display());
    Ok(())
}

/// The CMU takes of a data folder (see [`inbetween_mocap::corpus`]).
fn cmu_clips(dir: &Path) -> anyhow::Result<Vec<Clip>> {
    Ok(inbetween_mocap::corpus::cmu_corpus(dir)?)
}

/// One line per source: how many takes came from where.
fn describe_sources(clips: &[Clip]) -> String {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for c in clips {
        match counts.iter_mut().find(|(s, _)| *s == c.source) {
            Some((_, n)) => *n += 1,
            None => counts.push((c.source, 1)),
        }
    }
    counts.iter().map(|(s, n)| format!("{n} {s}")).collect::<Vec<_>>().join(", ")
}

fn bench_cmd(a: BenchArgs) -> anyhow::Result<()> {
    let dir = match a.data.clone() {
        Some(d) => d,
        None => match inbetween_io::data::shared_data_dir() {
            Ok(d) => d,
            Err(p) => bail!("no data at {} (give --data DIR)", p.display()),
        },
    };
    let clips = cmu_clips(&dir)?;
    let protocol = Protocol { stride: a.stride, seed: a.seed, ..Protocol::paper() };
    let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
    let (train, test) = bench::split_clips(&names, &protocol);
    let mut all = Vec::new();
    for clip in &clips {
        all.extend(bench::clip_windows(clip, &protocol)?);
    }
    if all.is_empty() {
        bail!("no clip in {} is long enough for one {}-frame window at {} fps", dir.display(), protocol.window, protocol.fps);
    }
    let test_windows: Vec<_> = all.iter().filter(|w| test.contains(&w.clip)).cloned().collect();
    let joints: std::collections::BTreeSet<usize> = all.iter().map(|w| w.rep.num_joints).collect();
    println!(
        "{} takes ({}) from {}: {} windows of {} frames at {} fps, joints per skeleton {:?}",
        clips.len(),
        describe_sources(&clips),
        dir.display(),
        all.len(),
        protocol.window,
        protocol.fps,
        joints,
    );
    println!("test split ({} windows): {test:?}\ntraining split: {train:?}", test_windows.len());
    let ks = [5, 10, 15];
    let policy = if let Some(p) = &a.model {
        let policy = SidqlPolicy::load(p)?;
        println!("SIDQL: {} (trained on: {})", p.display(), policy.info.trained_on);
        policy
    } else if a.train_episodes > 0 {
        let train_windows = training_windows(&clips, &train, &protocol, 10)?;
        let opts = TrainOptions {
            episodes: a.train_episodes,
            seed: a.seed,
            data: format!("CMU training split {train:?}, {} windows at stride 10", train_windows.len()),
            ..TrainOptions::paper()
        };
        println!("SIDQL: training {} episodes on {} windows of the training split…", opts.episodes, train_windows.len());
        let (policy, report) = inbetween_mocap::dqn::train(&train_windows, &DqnConfig::default(), &opts)?;
        println!(
            "SIDQL: trained in {:.0} s, {} updates, loss per 50 episodes {:?}",
            report.seconds,
            report.updates,
            report.loss_curve.iter().map(|l| format!("{l:.4}")).collect::<Vec<_>>()
        );
        let path = PathBuf::from("out/sidql_cmu.bpk");
        std::fs::create_dir_all("out").ok();
        policy.save(&path)?;
        println!("SIDQL: saved {} (weights trained on CMU data: keep out of the repository)", path.display());
        policy
    } else {
        let policy = SidqlPolicy::committed()?;
        println!("SIDQL: the committed policy (trained on: {})", policy.info.trained_on);
        policy
    };
    let policy_fn = move |rep: &SphericalMotion, k: usize| policy.select(rep, k);
    let pf: Option<bench::PolicyFn> = Some(&policy_fn);
    let mut rows = bench::evaluate("all", &all, &Method::ALL, &ks, a.seed, pf)?;
    if test_windows.is_empty() {
        println!("the test split has no windows (too few or too short clips): only the `all` rows are shown");
    } else {
        rows.extend(bench::evaluate("test", &test_windows, &Method::ALL, &ks, a.seed, pf)?);
    }
    println!("{}", bench::to_table(&rows));
    if let Some(p) = &a.csv {
        write_atomic(p, bench::to_csv(&rows).as_bytes()).with_context(|| format!("writing {}", p.display()))?;
        println!("wrote {}", p.display());
    }
    if let Some(p) = &a.plot {
        bench_plot(p, &rows)?;
        println!("wrote {}", p.display());
    }
    reconstruction_throughput(&all)?;
    both_reconstructions(&all)?;
    // The codec measures cm in CMU units: the cgspeed takes (or a plain folder, read as CMU units).
    let cmu_units: Vec<&Clip> = clips.iter().filter(|c| c.source == "cgspeed" || c.source == "bvh").collect();
    for &bound in &a.codec_bounds {
        codec_ratio(&cmu_units, bound)?;
    }
    Ok(())
}

fn bench_plot(path: &Path, rows: &[bench::Row]) -> anyhow::Result<()> {
    let groups: Vec<String> = [5, 10, 15].iter().map(|k| format!("K = {k}")).collect();
    // The test split when there is one, else all windows.
    let split = if rows.iter().any(|r| r.split == "test") { "test" } else { "all" };
    let mut series = Vec::new();
    for m in Method::ALL {
        let vals: Vec<f64> = [5, 10, 15]
            .iter()
            .filter_map(|&k| {
                rows.iter().find(|r| r.split == split && r.method == m && r.k == k).map(|r| r.mean_angle_error)
            })
            .collect();
        if vals.len() == 3 {
            series.push((m.name().to_string(), vals));
        }
    }
    inbetween_render::plot::grouped_bar_chart(
        path,
        &format!("Mean angle error, {} 60-frame windows", if split == "test" { "test-split" } else { "all" }),
        "mean angle error (rad)",
        &groups,
        &series,
    )?;
    Ok(())
}

/// Frames per second of the spherical reconstruction (all frames of all windows, K = 10, uniform).
fn reconstruction_throughput(windows: &[bench::Window]) -> anyhow::Result<()> {
    let t = Instant::now();
    let mut frames = 0usize;
    for _ in 0..5 {
        for w in windows {
            let keys = KeyframeSet::uniform(w.rep.num_frames, 10.min(w.rep.num_frames))?;
            let rec = inbetween_mocap::reconstruct_spherical(&w.rep, &keys);
            frames += rec.positions.len() / w.rep.num_joints;
        }
    }
    let secs = t.elapsed().as_secs_f64();
    let joints: std::collections::BTreeSet<usize> = windows.iter().map(|w| w.rep.num_joints).collect();
    println!(
        "reconstruction throughput (spherical, K = 10, skeletons of {joints:?} joints): {:.0} frames/s",
        frames as f64 / secs
    );
    Ok(())
}

/// The paper's spherical reconstruction vs our rotation (quaternion Hermite) one, same optimal keys.
fn both_reconstructions(windows: &[bench::Window]) -> anyhow::Result<()> {
    for k in [5, 10, 15] {
        let (mut sph, mut rot, mut rot_deg, mut sph_max, mut rot_max) = (0.0, 0.0, 0.0, 0.0f64, 0.0f64);
        for w in windows {
            let keys = inbetween_mocap::select::optimal(&SegmentTable::full(&w.rep), k, Objective::Angle)?;
            let es = w.rep.error(&keys);
            let mut rm = RotationMotion::from_motion(&w.motion)?;
            rm.cm_per_unit = w.rep.cm_per_unit;
            let er = rm.error(&keys);
            sph += es.mean_cm;
            rot += er.mean_cm;
            rot_deg += er.mean_angle.to_degrees();
            sph_max = sph_max.max(es.max_cm);
            rot_max = rot_max.max(er.max_cm);
        }
        let n = windows.len().max(1) as f64;
        println!(
            "K={k:<2} optimal keys, all windows: spherical (paper) mean {:.3} cm / max {:.2} cm; rotation (BVH) mean {:.3} cm / max {:.2} cm, local rotation error {:.2} deg",
            sph / n,
            sph_max,
            rot / n,
            rot_max,
            rot_deg / n
        );
    }
    Ok(())
}

/// Codec size at an error bound over the full-rate, full-skeleton cgspeed clips (T-pose frame
/// dropped; the codec measures cm in CMU units).
fn codec_ratio(clips: &[&Clip], bound_cm: f64) -> anyhow::Result<()> {
    let (mut raw, mut packed, mut keys, mut frames, mut max_cm) = (0usize, 0usize, 0usize, 0usize, 0.0f64);
    let t = Instant::now();
    for clip in clips {
        let m = clip.motion.crop(1, clip.motion.num_frames())?;
        let gap = ((0.5 / m.frame_time).round() as usize).max(1);
        let c = codec::compress(&m, Budget::MaxErrorCm(bound_cm), gap)?;
        raw += codec::raw_bytes(&m);
        packed += c.bytes.len();
        keys += c.keys.len();
        frames += m.num_frames();
        max_cm = max_cm.max(c.decoded_max_cm);
    }
    println!(
        "codec at max error {bound_cm} cm: {keys} keys for {frames} frames, {packed} bytes vs {raw} raw f32 bytes = ratio {:.1}x (decoded max error {max_cm:.3} cm, {:.1} s)",
        raw as f64 / packed as f64,
        t.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The mocap part of `inbetween demo`: writes its outputs under `out` and returns lines to print.
pub fn demo(out: &Path) -> anyhow::Result<Vec<String>> {
    let t = Instant::now();
    let mut p = inbetween_core::procedural::GaitParams::walk();
    p.frames = 60;
    let walk = inbetween_core::procedural::gait(&p);
    let paper = JointFilter::paper().apply(&walk);
    let rep = SphericalMotion::from_motion(&paper)?;
    let table = SegmentTable::full(&rep);
    let mut lines = vec!["mocap: procedural walk, 60 frames at 30 fps, 23 joints (paper representation)".to_string()];
    let sidql = SidqlPolicy::committed()?;
    for k in [5, 10] {
        let opt = inbetween_mocap::select::optimal(&table, k, Objective::Angle)?;
        let uc = inbetween_mocap::select::uniform(60, k)?;
        let sq = sidql.select(&rep, k)?;
        let (eo, eu, es) = (rep.error(&opt), rep.error(&uc), rep.error(&sq));
        lines.push(format!(
            "  K={k:<2} optimal keys {:?}: angle err {:.4}, mean {:.2} cm, max {:.2} cm | uniform: {:.4}, {:.2} cm, {:.2} cm | SIDQL (committed policy): {:.4}, {:.2} cm, {:.2} cm",
            opt.frames(),
            eo.mean_angle,
            eo.mean_cm,
            eo.max_cm,
            eu.mean_angle,
            eu.mean_cm,
            eu.max_cm,
            es.mean_angle,
            es.mean_cm,
            es.max_cm
        ));
    }
    let c = codec::compress(&walk, Budget::MaxErrorCm(1.0), 15)?;
    lines.extend(compress_report(&walk, &c).into_iter().map(|l| format!("  codec (31 joints, ≤ 1 cm): {l}")));
    let ibk = out.join("mocap_walk.ibk");
    write_atomic(&ibk, &c.bytes)?;
    let rec = codec::decode(&c.bytes)?.reconstruct()?;
    let bvh = out.join("mocap_walk_reconstructed.bvh");
    inbetween_io::write_bvh(&bvh, &rec)?;
    let gif = out.join("mocap_overlay.gif");
    let opts = StickOptions {
        labels: vec!["original".into(), format!("from {} keys", c.keys.len())],
        title: Some(format!("mocap codec: {} keys, max {:.2} cm", c.keys.len(), c.decoded_max_cm)),
        max_frames: 60,
        ..StickOptions::default()
    };
    inbetween_render::render_motion_gif(&gif, &[&walk, &rec], &opts)?;
    // The rotation model is the one the codec uses; say how it compares to the spherical one.
    let rm = RotationMotion::from_motion(&paper)?;
    let k10 = inbetween_mocap::select::optimal(&table, 10, Objective::Angle)?;
    lines.push(format!(
        "  K=10 on 23 joints: rotation reconstruction mean {:.2} cm vs spherical {:.2} cm",
        rm.error(&k10).mean_cm,
        rep.error(&k10).mean_cm
    ));
    lines.push(format!(
        "  wrote {}, {}, {} ({:.1} s)",
        ibk.display(),
        bvh.display(),
        gif.display(),
        t.elapsed().as_secs_f64()
    ));
    Ok(lines)
}

/// Windows of the named clips with the given stride (overlapping windows for training).
fn training_windows(
    clips: &[Clip],
    names: &[String],
    protocol: &Protocol,
    stride: usize,
) -> anyhow::Result<Vec<SphericalMotion>> {
    let p = Protocol { stride, ..protocol.clone() };
    let mut out = Vec::new();
    for clip in clips.iter().filter(|c| names.contains(&c.name)) {
        out.extend(bench::clip_windows(clip, &p)?.into_iter().map(|w| w.rep));
    }
    Ok(out)
}

/// Procedural gaits (our own data) as clips in CMU units.
fn procedural_clips(seed: u64, count: usize) -> Vec<Clip> {
    inbetween_core::procedural::gait_library(seed, count, 241, 30.0)
        .into_iter()
        .enumerate()
        .map(|(i, m)| Clip {
            name: format!("gait{i}"),
            source: "procedural",
            motion: m,
            cm_per_unit: inbetween_core::procedural::CM_PER_CMU_UNIT,
        })
        .collect()
}

fn train_cmd(a: TrainArgs) -> anyhow::Result<()> {
    let protocol = Protocol { seed: a.seed, ..Protocol::paper() };
    let (windows, data) = if a.procedural {
        let clips = procedural_clips(a.seed, 24);
        let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
        let p = Protocol { skip_first_frame: false, ..protocol.clone() };
        let windows = training_windows(&clips, &names, &p, a.stride)?;
        let data = format!(
            "{} procedural gaits (seed {}), {} windows of 60 frames at stride {}",
            clips.len(),
            a.seed,
            windows.len(),
            a.stride
        );
        (windows, data)
    } else {
        let dir = match a.data.clone() {
            Some(d) => d,
            None => inbetween_io::data::shared_data_dir()
                .map_err(|p| anyhow::anyhow!("no data at {} (give --data DIR or --procedural)", p.display()))?,
        };
        let clips = cmu_clips(&dir)?;
        let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
        let (train, test) = bench::split_clips(&names, &protocol);
        let windows = training_windows(&clips, &train, &protocol, a.stride)?;
        let data = format!(
            "CMU training split (seed {}) {train:?}, {} windows of 60 frames at stride {}; test split {test:?} held out",
            a.seed,
            windows.len(),
            a.stride
        );
        (windows, data)
    };
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
    let opts = TrainOptions {
        episodes: a.episodes.unwrap_or(base.episodes),
        lr: a.lr.unwrap_or(base.lr),
        seed: a.seed,
        checkpoint: Some(a.output.clone()),
        data,
        ..base
    };
    let (_, report) = inbetween_mocap::dqn::train(&windows, &DqnConfig::default(), &opts)?;
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
    };
    let r = inbetween_mocap::stream::send(&a.addr, &m, &opts)?;
    let secs = m.duration().max(1e-9);
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
        "received {} keys ({} bytes, {} sessions, {}), emitted {} frames; wrote {}",
        got.keys,
        got.bytes,
        got.sessions,
        if got.complete { "complete" } else { "incomplete" },
        got.motion.num_frames(),
        a.output.display()
    );
    if let Some(r) = &a.reference {
        let m = inbetween_io::load_motion(r)?;
        let m = if a.skip_first && m.num_frames() > 2 { m.crop(1, m.num_frames())? } else { m };
        let n = m.num_frames().min(got.motion.num_frames());
        let e =
            inbetween_core::position_error(&positions_clip(&m.crop(0, n)?), &positions_clip(&got.motion.crop(0, n)?));
        let cm = inbetween_core::procedural::CM_PER_CMU_UNIT;
        println!("error vs {}: mean {:.3} cm, max {:.3} cm over {n} frames", r.display(), e.mean * cm, e.max * cm);
    }
    Ok(())
}
