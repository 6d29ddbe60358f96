//! Training one face network (§3.3): the losses ([`losses`]), batches ([`data`]) and the GAN
//! objective ([`objective`]) on the shared training loop, with checkpoints, bit-identical resume,
//! a time limit and progress; [`save_face_weights`] writes the generator with its card. [`TrainJob`]
//! trains a set of networks the way `inbetween face train` does.
//!
//! ```no_run
//! use inbetween_face::edit::ConstraintKind;
//! use inbetween_face::train::{save_face_weights, train_face, ClipPool, FaceTrainConfig};
//! # let clips = Vec::new();
//! let pool = ClipPool::new(clips, "procedural, seed 1");
//! let config = FaceTrainConfig { epochs: 20, ..FaceTrainConfig::new(ConstraintKind::Keyframes) };
//! let report = train_face(&config, &pool, &inbetween_io::Progress::hidden()).unwrap();
//! save_face_weights(&report, std::path::Path::new("face-keyframes.bpk")).unwrap();
//! ```

pub mod data;
pub mod job;
pub mod losses;
pub mod objective;

use std::path::{Path, PathBuf};

use burn::module::Module;
use burn::tensor::Device;
use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use inbetween_nn::burn;
use inbetween_nn::train::{fit_with, Finish, TrainConfig};
use inbetween_nn::weights::{self, WeightsCard};
use inbetween_nn::NnError;
use serde::{Deserialize, Serialize};

use crate::edit::constraints::TrackerNoise;
use crate::edit::mask::MaskSampling;
use crate::edit::ConstraintKind;
use crate::model::generator::{FaceWeightsConfig, Generator, GeneratorConfig, WEIGHTS_FORMAT, WEIGHTS_KIND};

pub use data::{ClipPool, TrainClip};
pub use job::{TrainData, TrainJob, TrainReport};
pub use losses::LossWeights;
pub use objective::EpochLosses;

/// Settings of a face training run (serialised into the weights card).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FaceTrainConfig {
    /// The network: which guidance it reads.
    #[serde(with = "kind_name")]
    pub kind: ConstraintKind,
    /// Frames per training window (100 = 4 s at 25 fps).
    pub window: usize,
    /// Windows per batch.
    pub batch: usize,
    pub epochs: usize,
    pub steps_per_epoch: usize,
    /// Seeds the weights of both networks and every batch.
    pub seed: u64,
    /// The generator's Adam learning rate (paper: 1e-3).
    pub lr: f64,
    /// The generator's learning-rate decay per epoch (1 = constant, the paper's).
    pub lr_decay: f64,
    /// The critic's Adam learning rate (paper: 1e-3), constant.
    pub critic_lr: f64,
    /// λ_dist, λ_adv, λ_gp.
    pub lambdas: LossWeights,
    /// Critic updates per generator update.
    pub n_critic: usize,
    /// Hidden units per direction of the generator (paper: 128).
    pub d_hidden: usize,
    /// Bidirectional layers (paper: 2).
    pub layers: usize,
    /// Generator dropout (paper: 0.3).
    pub dropout: f64,
    /// Clip each generator parameter's gradient to this norm.
    pub grad_clip: Option<f32>,
    /// Stop (resumably) after the epoch during which this many seconds have passed.
    pub time_limit_s: Option<f64>,
    /// Folder for checkpoints; a run finding one there resumes from it.
    pub checkpoint_dir: Option<PathBuf>,
    /// Checkpoint every this many epochs (0: only at the end).
    pub checkpoint_every: usize,
}

impl FaceTrainConfig {
    /// The paper's network and optimiser for `kind` (§3.2, §3.3) with our batch, window and run length.
    pub fn new(kind: ConstraintKind) -> FaceTrainConfig {
        FaceTrainConfig {
            kind,
            window: 100,
            batch: 16,
            epochs: 50,
            steps_per_epoch: 50,
            seed: 1,
            lr: 1e-3,
            lr_decay: 1.0,
            critic_lr: 1e-3,
            lambdas: LossWeights::default(),
            n_critic: 1,
            d_hidden: 128,
            layers: 2,
            dropout: 0.3,
            grad_clip: Some(1.0),
            time_limit_s: None,
            checkpoint_dir: None,
            checkpoint_every: 1,
        }
    }

    /// The generator this run trains.
    pub fn generator(&self) -> GeneratorConfig {
        GeneratorConfig { kind: self.kind, d_hidden: self.d_hidden, layers: self.layers, dropout: self.dropout }
    }

    /// How batches are drawn (default masks and tracker noise).
    pub fn sampler(&self) -> data::SamplerConfig {
        data::SamplerConfig {
            kind: self.kind,
            window: self.window,
            batch: self.batch,
            mask: MaskSampling::default(),
            tracker: TrackerNoise::default(),
        }
    }

    /// Ranges the shared loop does not check itself.
    pub fn validate(&self) -> Result<(), String> {
        if self.window < 2 || self.batch == 0 || self.d_hidden == 0 || self.layers == 0 {
            return Err(format!(
                "window ({}) must be at least 2, batch ({}), d_hidden ({}) and layers ({}) at least 1",
                self.window, self.batch, self.d_hidden, self.layers
            ));
        }
        if !(0.0..1.0).contains(&self.dropout) {
            return Err(format!("dropout must be in [0, 1), got {}", self.dropout));
        }
        if !(self.critic_lr > 0.0 && self.critic_lr.is_finite()) {
            return Err(format!("critic_lr must be positive, got {}", self.critic_lr));
        }
        let l = &self.lambdas;
        if ![l.dist, l.adv, l.gp].iter().all(|v| v.is_finite() && *v >= 0.0) {
            return Err(format!("λ values must be finite and non-negative, got {l:?}"));
        }
        Ok(())
    }

    fn loop_config(&self) -> TrainConfig {
        TrainConfig {
            epochs: self.epochs,
            steps_per_epoch: self.steps_per_epoch,
            lr: self.lr,
            lr_decay: self.lr_decay,
            lr_decay_from: 0,
            seed: self.seed,
            checkpoint_every: self.checkpoint_every,
            checkpoint_dir: self.checkpoint_dir.clone(),
            grad_clip_norm: self.grad_clip,
            time_limit_s: self.time_limit_s,
            progress: false,
        }
    }
}

/// [`ConstraintKind`] as its name in JSON.
mod kind_name {
    use crate::edit::ConstraintKind;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(kind: &ConstraintKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(kind.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<ConstraintKind, D::Error> {
        let name = String::deserialize(d)?;
        ConstraintKind::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown constraint kind \"{name}\"")))
    }
}

/// Why training failed.
#[derive(Debug, thiserror::Error)]
pub enum TrainError {
    /// The configuration or the clips cannot train this network.
    #[error("face training: {0}")]
    Setup(String),
    /// The training loop, a checkpoint or a weights file failed.
    #[error(transparent)]
    Nn(#[from] NnError),
    /// The clips could not be read, or the output refused ([`TrainJob`]).
    #[error(transparent)]
    Data(#[from] crate::data::FaceError),
}

/// What a run did.
#[derive(Debug)]
pub struct FaceTrainReport {
    /// The trained generator, on the CPU inference device.
    pub generator: Generator,
    pub config: FaceTrainConfig,
    /// Where the clips came from ([`ClipPool::description`]).
    pub data: String,
    /// The generator's mean loss per epoch (from the start of the run).
    pub loss_history: Vec<f64>,
    /// Every loss term per epoch.
    pub epoch_losses: Vec<EpochLosses>,
    /// Generator updates in total.
    pub steps: u64,
    /// Seconds of training over every invocation of the run.
    pub seconds: f64,
    /// Why training ended.
    pub finish: Finish,
    /// The checkpoint this invocation resumed from.
    pub resumed_from: Option<PathBuf>,
}

impl FaceTrainReport {
    /// The last epoch's losses (NaN everywhere before any epoch).
    pub fn final_losses(&self) -> EpochLosses {
        self.epoch_losses.last().copied().unwrap_or(EpochLosses {
            generator: f64::NAN,
            rec: f64::NAN,
            dist: f64::NAN,
            adv: f64::NAN,
            critic_hinge: f64::NAN,
            critic_gp: f64::NAN,
        })
    }
}

/// Train (or resume from `config.checkpoint_dir`) one face network on the CPU, reporting to
/// `progress` (one unit per step).
pub fn train_face(
    config: &FaceTrainConfig,
    pool: &ClipPool,
    progress: &Progress,
) -> Result<FaceTrainReport, TrainError> {
    train_face_on(config, pool, progress, &inbetween_nn::backend::cpu_autodiff())
}

/// [`train_face`] on a given autodiff `device`.
pub fn train_face_on(
    config: &FaceTrainConfig,
    pool: &ClipPool,
    progress: &Progress,
    device: &Device,
) -> Result<FaceTrainReport, TrainError> {
    train_face_cancellable(config, pool, progress, device, &Cancel::new())
}

/// [`train_face_on`] that stops before the next step once `cancel` is cancelled (or its time limit
/// passes), returning [`NnError::Cancelled`] inside [`TrainError::Nn`]. Nothing of the unfinished
/// epoch is checkpointed, so a later run resumes from the last whole epoch.
pub fn train_face_cancellable(
    config: &FaceTrainConfig,
    pool: &ClipPool,
    progress: &Progress,
    device: &Device,
    cancel: &Cancel,
) -> Result<FaceTrainReport, TrainError> {
    config.validate().map_err(TrainError::Setup)?;
    progress.set_length((config.epochs * config.steps_per_epoch) as u64);
    let mut objective = objective::GanObjective::new(config, pool, device, progress).map_err(TrainError::Setup)?;
    objective.cancel = cancel.clone();
    let generator = config.generator();
    let run = fit_with(&config.loop_config(), device, |d| generator.init(d), &mut objective)?;
    Ok(FaceTrainReport {
        generator: run.model.valid(),
        config: config.clone(),
        data: pool.description.clone(),
        loss_history: run.loss_history,
        epoch_losses: objective.history(),
        steps: run.optimizer_steps,
        seconds: run.seconds,
        finish: run.finish,
        resumed_from: run.resumed_from,
    })
}

/// The weights card of a trained generator: kind "face", the generator configuration and window,
/// the training settings, and provenance (data, steps, seconds, final losses).
pub fn face_card(report: &FaceTrainReport) -> WeightsCard {
    let config = FaceWeightsConfig { generator: report.config.generator().to_card(), window: report.config.window };
    let mut card = WeightsCard::new(
        WEIGHTS_KIND,
        WEIGHTS_FORMAT,
        serde_json::to_value(&config).unwrap_or(serde_json::Value::Null),
        &report.data,
    );
    card.training = serde_json::to_value(&report.config).unwrap_or(serde_json::Value::Null);
    let f = report.final_losses();
    for (name, value) in [
        ("steps", report.steps as f64),
        ("epochs", report.loss_history.len() as f64),
        ("seconds", report.seconds),
        ("final_generator_loss", f.generator),
        ("final_rec", f.rec),
        ("final_dist", f.dist),
        ("final_adv", f.adv),
        ("final_critic_hinge", f.critic_hinge),
        ("final_critic_gp", f.critic_gp),
    ] {
        if value.is_finite() {
            card.metrics.insert(name.into(), value);
        }
    }
    card
}

/// Writes the trained generator to `path` (`x.bpk`) and its card (`x.json`), atomically.
pub fn save_face_weights(report: &FaceTrainReport, path: &Path) -> Result<(), NnError> {
    weights::save(&report.generator, &face_card(report), path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::NUM_ARKIT;
    use crate::edit::Frame;
    use crate::visemes::{Viseme, NUM_VISEMES};

    /// Smooth pseudo-animations with blinks and jaw motion, and viseme labels.
    fn toy_pool(clips: usize, frames: usize) -> ClipPool {
        let clip = |k: usize| {
            let frames: Vec<Frame> = (0..frames)
                .map(|f| {
                    let t = f as f32 / 25.0 + k as f32;
                    let mut x = [0.0; NUM_ARKIT];
                    for (c, v) in x.iter_mut().enumerate() {
                        *v = 0.5 + 0.4 * (t * (0.5 + c as f32 * 0.07) + c as f32).sin();
                    }
                    x
                })
                .collect();
            let visemes = (0..frames.len()).map(|f| Viseme::ALL[(f / 5 + k) % NUM_VISEMES]).collect();
            TrainClip { frames, visemes: Some(visemes) }
        };
        ClipPool::new((0..clips).map(clip).collect(), "toy sines")
    }

    fn tiny(kind: ConstraintKind, epochs: usize, dir: Option<&Path>) -> FaceTrainConfig {
        FaceTrainConfig {
            window: 16,
            batch: 4,
            epochs,
            steps_per_epoch: 2,
            d_hidden: 8,
            seed: 5,
            checkpoint_dir: dir.map(Path::to_path_buf),
            ..FaceTrainConfig::new(kind)
        }
    }

    fn param_bits(g: &Generator) -> Vec<u32> {
        let mut out = Vec::new();
        for layer in &g.lstm.layers {
            for cell in [&layer.forward, &layer.backward] {
                out.extend(
                    cell.gates.weight.val().into_data().try_to_vec::<f32>().unwrap().iter().map(|v| v.to_bits()),
                );
            }
        }
        out.extend(g.output.weight.val().into_data().try_to_vec::<f32>().unwrap().iter().map(|v| v.to_bits()));
        out
    }

    #[test]
    fn train_resumed_gan_run_is_bit_identical_to_an_uninterrupted_one() {
        let pool = toy_pool(3, 40);
        let hidden = Progress::hidden();
        let (straight_dir, split_dir) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let kind = ConstraintKind::Keyframes;
        let straight = train_face(&tiny(kind, 3, Some(straight_dir.path())), &pool, &hidden).unwrap();
        let first = train_face(&tiny(kind, 1, Some(split_dir.path())), &pool, &hidden).unwrap();
        assert_eq!(first.loss_history.len(), 1);
        let resumed = train_face(&tiny(kind, 3, Some(split_dir.path())), &pool, &hidden).unwrap();
        assert!(resumed.resumed_from.is_some());
        assert_eq!(resumed.steps, 6);
        assert_eq!(hidden.position(), 6);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&resumed.loss_history), bits(&straight.loss_history));
        assert_eq!(resumed.epoch_losses, straight.epoch_losses);
        assert_eq!(param_bits(&resumed.generator), param_bits(&straight.generator));
        // Every term was measured; the critic learnt something (its hinge is not the initial 2).
        let f = straight.final_losses();
        for v in [f.rec, f.dist, f.adv, f.critic_hinge, f.critic_gp] {
            assert!(v.is_finite(), "{f:?}");
        }
        // Another seed trains another network.
        let other = train_face(&FaceTrainConfig { seed: 6, ..tiny(kind, 1, None) }, &pool, &hidden).unwrap();
        assert_ne!(param_bits(&other.generator), param_bits(&first.generator));
    }

    #[test]
    fn train_cancelled_run_stops_before_a_step_and_checkpoints_nothing_new() {
        let pool = toy_pool(2, 40);
        let hidden = Progress::hidden();
        let dir = tempfile::tempdir().unwrap();
        let kind = ConstraintKind::None;
        train_face(&tiny(kind, 1, Some(dir.path())), &pool, &hidden).unwrap();
        let listing = |d: &Path| {
            let mut v: Vec<_> = std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name()).collect();
            v.sort();
            v
        };
        let before = listing(dir.path());
        let cancel = Cancel::new();
        cancel.cancel();
        let device = inbetween_nn::backend::cpu_autodiff();
        let counted = Progress::hidden();
        let e =
            train_face_cancellable(&tiny(kind, 3, Some(dir.path())), &pool, &counted, &device, &cancel).unwrap_err();
        assert!(matches!(e, TrainError::Nn(NnError::Cancelled(inbetween_core::cancel::Cancelled::Requested))), "{e}");
        assert_eq!(e.to_string(), "training stopped: cancelled");
        assert_eq!(counted.position(), 0, "no step reported");
        assert_eq!(listing(dir.path()), before, "no checkpoint of the unfinished epoch");
        let limited = Cancel::with_time_limit(std::time::Duration::ZERO);
        let e = train_face_cancellable(&tiny(kind, 3, None), &pool, &counted, &device, &limited).unwrap_err();
        assert_eq!(e.to_string(), "training stopped: time limit of 0 s reached");
    }

    #[test]
    fn train_a_few_steps_lower_the_generator_loss_for_every_kind() {
        let pool = toy_pool(2, 40);
        for kind in ConstraintKind::ALL {
            let config = FaceTrainConfig { lr: 5e-3, steps_per_epoch: 6, epochs: 2, ..tiny(kind, 2, None) };
            let report = train_face(&config, &pool, &Progress::hidden()).unwrap();
            let (a, b) = (report.epoch_losses[0].rec, report.epoch_losses[1].rec);
            assert!(b < a, "{kind:?}: L_rec {a} → {b}");
        }
    }

    #[test]
    fn train_saved_weights_carry_a_face_card() {
        let pool = toy_pool(2, 40);
        let report = train_face(&tiny(ConstraintKind::Visemes, 1, None), &pool, &Progress::hidden()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("face.bpk");
        save_face_weights(&report, &path).unwrap();
        let w = inbetween_nn::weights::Weights::from_path(&path).unwrap();
        w.expect_kind(WEIGHTS_KIND, WEIGHTS_FORMAT).unwrap();
        let config: FaceWeightsConfig = w.config().unwrap();
        assert_eq!(config.window, 16);
        assert_eq!(config.generator.config().unwrap(), report.config.generator());
        assert_eq!(w.card().data, "toy sines");
        assert_eq!(w.card().metrics["steps"], 2.0);
        let training: FaceTrainConfig = serde_json::from_value(w.card().training.clone()).unwrap();
        assert_eq!(training, report.config);
    }

    #[test]
    fn train_refuses_unusable_setups() {
        let pool = toy_pool(1, 10);
        let err = train_face(&tiny(ConstraintKind::None, 1, None), &pool, &Progress::hidden()).unwrap_err();
        assert!(err.to_string().contains("16-frame window"), "{err}");
        let bad = FaceTrainConfig { dropout: 1.0, ..tiny(ConstraintKind::None, 1, None) };
        assert!(train_face(&bad, &toy_pool(1, 40), &Progress::hidden()).unwrap_err().to_string().contains("dropout"));
    }

    /// Steps per second of the default configuration (batch 16, window 100, 2 × 128 units) on toy
    /// clips; 30 steps, about 25 s on the 2-core machine (1.26–1.30 steps/s measured).
    #[test]
    #[ignore = "measurement, run by hand"]
    fn train_speed_of_the_default_config() {
        let pool = toy_pool(8, 400);
        let kind = ConstraintKind::Keyframes;
        let config = FaceTrainConfig { epochs: 1, steps_per_epoch: 30, ..FaceTrainConfig::new(kind) };
        let t = std::time::Instant::now();
        let report = train_face(&config, &pool, &Progress::hidden()).unwrap();
        let secs = t.elapsed().as_secs_f64();
        assert_eq!(report.steps, 30);
        println!("{kind:?}: {} steps in {secs:.1} s = {:.3} steps/s", report.steps, report.steps as f64 / secs);
    }
}
