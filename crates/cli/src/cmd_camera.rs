//! `inbetween camera …` (owned by the camera engine work).

use anyhow::Context;
use clap::{Args, Subcommand};
use inbetween_camera::bench;
use inbetween_camera::dataset::Scene;
use inbetween_camera::generate_files::{write_tracks, TrackFiles};
use inbetween_camera::infer::{GenerateLimits, GenerateOptions, Keys};
use inbetween_camera::train::TrainConfig;
use inbetween_camera::weights::{self, CameraWeights};
use inbetween_camera::TrainJob;
use inbetween_io::report::BenchOptions;
use std::path::{Path, PathBuf};

use crate::errors;
use crate::scale::ScaleArgs;

#[derive(Subcommand)]
pub enum CameraCommand {
    /// Generate a camera track through keyframes in a style (toric track + world poses as JSON).
    Generate(GenerateArgs),
    /// Write a procedural two-character scene, example keyframes and a reference clip per behaviour.
    Scene(SceneArgs),
    /// Train extractor, generator and mapping end to end on the synthetic dataset (resumable).
    Train(TrainArgs),
    /// Benchmark: Table 1, Table 2 (SD/TD/KD), §6.3 spline comparison, style PCA, frames/s.
    Bench(BenchArgs),
    /// Scaling bench: `camera generate` on the demo's example (300 frames, 3 keys) at 1×, 10×,
    /// 100×, with time and peak memory per run.
    Scale(ScaleArgs),
}

#[derive(Args)]
pub struct BenchArgs {
    /// Reduced run (under a minute on 2 cores).
    #[arg(long)]
    pub quick: bool,
    /// Folder for CSV tables, PNG charts and the JSON report.
    #[arg(short, long, default_value = "out/camera-bench")]
    pub out: PathBuf,
    /// Weights (default: the committed weights).
    #[arg(long)]
    pub weights: Option<PathBuf>,
}

#[derive(Args)]
pub struct GenerateArgs {
    /// Scene JSON (characters' root and shoulder positions per frame).
    #[arg(long, required_unless_present = "characters", conflicts_with = "characters")]
    pub scene: Option<PathBuf>,
    /// Two mocap takes (BVH, or ASF+AMC as .amc with its .asf beside it) as the scene's characters:
    /// roots from their hips, shoulders from their upper-arm joints (found by name on the common rigs,
    /// else by the skeleton's shape), metres, Y up.
    #[arg(long, num_args = 2, value_names = ["A", "B"])]
    pub characters: Vec<PathBuf>,
    /// With --characters: a roles file naming the joints whose role neither names nor shape settle
    /// (JSON, role → joint name, e.g. {"left_upper_arm": "lShldrBend"}); applies to both takes.
    #[arg(long, requires = "characters")]
    pub roles: Option<PathBuf>,
    /// Keyframes JSON: {"keys": [{"frame", "camera": {"pa", "pb", "theta", "phi"}, "targets"?, "velocity"?}], "main"?}.
    #[arg(long)]
    pub keys: PathBuf,
    /// A behaviour's style code: direct, relative, side or orbit.
    #[arg(long, conflicts_with_all = ["reference", "all_styles"])]
    pub style: Option<String>,
    /// Extract the style from a reference clip: JSON with per-frame "characters" features and "camera" toric, or a glTF / GLB camera animation over this scene's characters.
    #[arg(long, conflicts_with = "all_styles")]
    pub reference: Option<PathBuf>,
    /// One track per style (the paper's UI flow): writes OUT with the style name inserted.
    #[arg(long)]
    pub all_styles: bool,
    /// Output JSON (per-frame toric coordinates, targets, camera position and rotation).
    #[arg(short, long)]
    pub out: PathBuf,
    /// Also write the camera animation as glTF 2.0 (default: OUT with .gltf).
    #[arg(long)]
    pub gltf: Option<PathBuf>,
    /// Also write a top-down preview GIF with a picture-in-picture camera view.
    #[arg(long)]
    pub gif: Option<PathBuf>,
    /// Causal live mode: one frame at a time, no look-ahead, no correction (beyond the paper).
    #[arg(long)]
    pub causal: bool,
    /// Keep the network's own keyframe misses instead of correcting them away.
    #[arg(long)]
    pub no_exact_keys: bool,
    /// Weights (default: the committed weights).
    #[arg(long)]
    pub weights: Option<PathBuf>,
    /// Most frames the scene may hold.
    #[arg(long, default_value_t = GenerateLimits::default().max_frames)]
    pub max_frames: usize,
    /// Most keyframes the keys file may hold.
    #[arg(long, default_value_t = GenerateLimits::default().max_keys)]
    pub max_keys: usize,
    /// Stop with an error, writing nothing, after this many seconds.
    #[arg(long)]
    pub time_limit: Option<f64>,
}

/// The generate job's limit fields and the flags that set them.
const GENERATE_FLAGS: &[(&str, &str)] = &[("max_frames", "--max-frames"), ("max_keys", "--max-keys")];

#[derive(Args)]
pub struct SceneArgs {
    /// Output folder: scene.json, keys.json, reference-<behaviour>.json.
    #[arg(short, long)]
    pub out: PathBuf,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long, default_value_t = inbetween_camera::demo::EXAMPLE_SCENE_FRAMES)]
    pub frames: usize,
    /// Most frames a scene may hold (the generate job's limit).
    #[arg(long, default_value_t = GenerateLimits::default().max_frames)]
    pub max_frames: usize,
}

#[derive(Args)]
pub struct TrainArgs {
    /// Where the trained weights go (burnpack; its JSON card, with the style codes, is written
    /// beside it). The committed weights folder is refused unless --overwrite-committed.
    #[arg(short, long, default_value = TrainJob::DEFAULT_OUT)]
    pub out: PathBuf,
    /// Allow OUT inside crates/camera/weights/ (replacing the committed weights on purpose).
    #[arg(long)]
    pub overwrite_committed: bool,
    /// Checkpoint folder: saved every epoch, and training resumes from it when it holds one.
    #[arg(long, default_value = TrainJob::DEFAULT_CHECKPOINTS)]
    pub checkpoints: PathBuf,
    /// Epochs (the paper: 200).
    #[arg(long, default_value_t = TRAIN.epochs)]
    pub epochs: usize,
    /// Optimiser steps per epoch (the learning rate decays ×0.97 per epoch).
    #[arg(long, default_value_t = TRAIN.iters_per_epoch)]
    pub iters_per_epoch: usize,
    /// Batch size (the paper: 1024).
    #[arg(long, default_value_t = TRAIN.batch)]
    pub batch: usize,
    /// Procedural scenes in the training set (8 filmed sequences each).
    #[arg(long, default_value_t = TRAIN.scenes)]
    pub scenes: usize,
    /// Stop after this many minutes (the running epoch is finished and saved).
    #[arg(long)]
    pub minutes: Option<f64>,
    /// Initial learning rate (decays ×0.97 per epoch).
    #[arg(long, default_value_t = TRAIN.lr)]
    pub lr: f64,
    /// When resuming, restart the learning-rate schedule at --lr instead of where it had decayed to.
    #[arg(long)]
    pub restart_lr: bool,
    #[arg(long, default_value_t = TRAIN.seed)]
    pub seed: u64,
    /// LSTM / FC width (the paper: 256).
    #[arg(long, default_value_t = TRAIN.model.hidden)]
    pub hidden: usize,
    /// Stop with an error after this many seconds, writing no weights (checkpoints of finished
    /// epochs stay, so a rerun resumes). Unlike --minutes, which ends training early and saves it.
    #[arg(long)]
    pub time_limit: Option<f64>,
}

/// The engine's training settings, the flags' defaults.
static TRAIN: std::sync::LazyLock<TrainConfig> = std::sync::LazyLock::new(TrainConfig::default);

pub fn run(c: CameraCommand) -> anyhow::Result<()> {
    match c {
        CameraCommand::Generate(a) => run_generate(a).map_err(|e| errors::name_flags(e, GENERATE_FLAGS)),
        CameraCommand::Scene(a) => run_scene(a).map_err(|e| errors::name_flags(e, &[("max_frames", "--max-frames")])),
        CameraCommand::Train(a) => run_train(a).map_err(|e| errors::name_flags(e, &[])),
        CameraCommand::Bench(a) => run_bench(a),
        CameraCommand::Scale(a) => run_scale(a),
    }
}

fn load_weights(path: Option<&Path>) -> anyhow::Result<CameraWeights> {
    match path {
        Some(path) => weights::load(path).with_context(|| format!("loading camera weights {}", path.display())),
        None => weights::committed().context("loading the committed camera weights"),
    }
}

fn run_generate(a: GenerateArgs) -> anyhow::Result<()> {
    let cancel = errors::time_limit(a.time_limit)?;
    let limits = GenerateLimits { max_frames: a.max_frames, max_keys: a.max_keys };
    let w = load_weights(a.weights.as_deref())?;
    let (scene, scene_name) = match &a.scene {
        Some(p) => (Scene::load(p)?, p.display().to_string()),
        None => {
            let roles = crate::cmd_io::read_roles(a.roles.as_deref())?;
            let (scene, notes, name) = inbetween_camera::dataset::scene_from_files(&a.characters, &roles)?;
            for line in notes.lines {
                println!("  {line}");
            }
            (scene, name)
        }
    };
    limits.check_scene(scene_name, &scene)?;
    let keys = Keys::load(&a.keys)?;
    let options = GenerateOptions {
        exact_keys: !a.no_exact_keys,
        causal: a.causal,
        limits,
        cancel: Some(&cancel),
        ..GenerateOptions::default()
    };
    let styles = w.requested_styles(a.all_styles, a.reference.as_deref(), a.style.as_deref(), &scene)?;
    let files = TrackFiles { out: a.out, gltf: a.gltf, gif: a.gif, per_style: a.all_styles };
    for line in write_tracks(&w.model, &scene, &keys, &a.keys, styles, options, &files)? {
        println!("{line}");
    }
    Ok(())
}

fn run_scene(a: SceneArgs) -> anyhow::Result<()> {
    let limits = GenerateLimits { max_frames: a.max_frames, ..GenerateLimits::default() };
    let files = inbetween_camera::demo::write_example_scene(&a.out, a.seed, a.frames, &limits)?;
    println!("wrote {} to {}", files.join(", "), a.out.display());
    Ok(())
}

fn run_bench(a: BenchArgs) -> anyhow::Result<()> {
    let engine = bench::CameraBench { weights: a.weights };
    let opts = BenchOptions { out: Some(a.out), quick: a.quick, ..BenchOptions::new(engine) };
    crate::bench::run("camera bench", opts, bench::run)?.print_summary();
    Ok(())
}

fn run_train(a: TrainArgs) -> anyhow::Result<()> {
    let mut config = TrainConfig {
        seed: a.seed,
        scenes: a.scenes,
        epochs: a.epochs,
        iters_per_epoch: a.iters_per_epoch,
        batch: a.batch,
        time_limit_s: a.minutes.map(|m| m * 60.0),
        lr: a.lr,
        ..TrainConfig::default()
    };
    config.model.hidden = a.hidden;
    let job = TrainJob {
        config,
        out: a.out,
        overwrite_committed: a.overwrite_committed,
        checkpoints: a.checkpoints,
        restart_lr: a.restart_lr,
    };
    let cancel = errors::time_limit(a.time_limit)?;
    job.validate()?;
    println!("{}", job.run(&cancel, &inbetween_io::Progress::new(0, "training"))?);
    Ok(())
}

fn run_scale(a: ScaleArgs) -> anyhow::Result<()> {
    crate::scale::run(
        &a,
        "camera",
        "camera generate (orbit style) at multiples of the demo's example",
        |k, exe, work| {
            let (scene, keys) = inbetween_camera::demo::scaled_example(k);
            let (scene_path, keys_path) = (work.join(format!("scene-{k}.json")), work.join(format!("keys-{k}.json")));
            scene.save(&scene_path)?;
            inbetween_camera::write_json(&keys_path, &keys)?;
            let mut command = std::process::Command::new(exe);
            command.args(["camera", "generate", "--style", "orbit", "--scene"]).arg(&scene_path);
            command.arg("--keys").arg(&keys_path).arg("-o").arg(work.join(format!("cam-{k}.json")));
            let input = format!("{} frames at 30 fps, {} keys", scene.num_frames(), keys.keys.len());
            Ok(crate::scale::Measured { input, command })
        },
    )
}
