//! A small, seeded training loop: Adam, exponential learning-rate decay per epoch, a progress
//! bar, periodic checkpoints and resume from the latest checkpoint.
//!
//! The caller supplies two closures: one that builds the model on a device (called once, right
//! after seeding, inside [`backend::seeded_module`](crate::backend::seeded_module), so the initial weights
//! depend only on [`TrainConfig::seed`]) and one that
//! returns the loss of one optimisation step. The loss closure gets a [`Step`] whose
//! [`Step::seed`] depends only on (seed, epoch, step): draw batches from an RNG seeded with it and
//! a resumed run sees exactly the batches an uninterrupted run would.
//!
//! ```no_run
//! use inbetween_nn::{backend, lstm::FusedLstmConfig, train::{fit, TrainConfig}};
//! use burn::tensor::Tensor;
//! let device = backend::cpu_autodiff();
//! let config = TrainConfig { epochs: 5, ..TrainConfig::default() };
//! let report = fit(&config, &device, |d| FusedLstmConfig::new(1, 8).init(d), |lstm, _step| {
//!     let x = Tensor::<2>::ones([4, 1], &device);
//!     lstm.step(x, None).h.square().mean()
//! })
//! .unwrap();
//! println!("{:?}", report.loss_history);
//! ```

use std::io::IsTerminal;
use std::path::PathBuf;

use burn::grad_clipping::GradientClippingConfig;
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::tensor::{Device, Tensor};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::{Deserialize, Serialize};

use crate::checkpoint::{self, CheckpointMeta};
use crate::NnError;

/// Settings of a training run. Serialised into every checkpoint's sidecar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainConfig {
    /// Total epochs (a resumed run continues until this many are done).
    pub epochs: usize,
    /// Optimisation steps per epoch.
    pub steps_per_epoch: usize,
    /// Learning rate of the first epoch.
    pub lr: f64,
    /// Multiplicative decay per epoch: epoch `e` uses `lr · lr_decay^e` (1.0 = constant).
    pub lr_decay: f64,
    /// Seeds the model initialisation, the device RNG of every epoch and [`Step::seed`].
    pub seed: u64,
    /// Save a checkpoint every this many epochs (0 = only at the end). Needs `checkpoint_dir`.
    pub checkpoint_every: usize,
    /// Folder for checkpoints; if it holds one, training resumes from the latest.
    pub checkpoint_dir: Option<PathBuf>,
    /// Clip the global gradient norm to this value.
    pub grad_clip_norm: Option<f32>,
    /// Show a progress bar on stderr (never drawn when stderr is not a terminal).
    pub progress: bool,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            epochs: 10,
            steps_per_epoch: 1,
            lr: 1e-3,
            lr_decay: 1.0,
            seed: 0,
            checkpoint_every: 0,
            checkpoint_dir: None,
            grad_clip_norm: None,
            progress: true,
        }
    }
}

impl TrainConfig {
    /// Check ranges; errors say which field is wrong.
    pub fn validate(&self) -> Result<(), NnError> {
        if self.steps_per_epoch == 0 {
            return Err(NnError::Config("steps_per_epoch must be at least 1".into()));
        }
        if !(self.lr > 0.0 && self.lr.is_finite()) {
            return Err(NnError::Config(format!(
                "lr must be positive and finite, got {}",
                self.lr
            )));
        }
        if !(self.lr_decay > 0.0 && self.lr_decay <= 1.0) {
            return Err(NnError::Config(format!(
                "lr_decay must be in (0, 1], got {}",
                self.lr_decay
            )));
        }
        if let Some(clip) = self.grad_clip_norm {
            if !(clip > 0.0 && clip.is_finite()) {
                return Err(NnError::Config(format!(
                    "grad_clip_norm must be positive, got {clip}"
                )));
            }
        }
        Ok(())
    }

    /// Learning rate of epoch `epoch` (0-based): `lr · lr_decay^epoch`.
    pub fn lr_at(&self, epoch: usize) -> f64 {
        self.lr * self.lr_decay.powi(epoch as i32)
    }

    /// The fields a resumed run must share with the run that wrote the checkpoint
    /// (everything that changes the trajectory; `epochs` may grow).
    fn resume_key(&self) -> (u64, usize, u64, u64, Option<u32>) {
        (
            self.seed,
            self.steps_per_epoch,
            self.lr.to_bits(),
            self.lr_decay.to_bits(),
            self.grad_clip_norm.map(f32::to_bits),
        )
    }
}

/// Where an optimisation step is in the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    /// 0-based epoch.
    pub epoch: usize,
    /// 0-based step within the epoch.
    pub step: usize,
    /// Seed for this step's data sampling, a function of (run seed, epoch, step) only.
    pub seed: u64,
}

/// SplitMix64 finaliser: decorrelates nearby seeds.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Seed of step `step` of epoch `epoch` in a run seeded with `seed`.
pub fn step_seed(seed: u64, epoch: usize, step: usize) -> u64 {
    mix(mix(mix(seed) ^ epoch as u64) ^ step as u64)
}

/// Outcome of [`fit`].
#[derive(Debug)]
pub struct TrainReport<M> {
    /// The trained model (still on the training device).
    pub model: M,
    /// Mean loss of every epoch from the start of the run (including epochs before a resume).
    pub loss_history: Vec<f64>,
    /// Epoch this invocation started at (0, or the resumed checkpoint's epoch).
    pub start_epoch: usize,
    /// Optimiser steps taken in total.
    pub optimizer_steps: u64,
    /// The checkpoint training resumed from, if any.
    pub resumed_from: Option<PathBuf>,
    /// The last checkpoint written, if any.
    pub last_checkpoint: Option<PathBuf>,
}

fn progress_bar(config: &TrainConfig, start_epoch: usize) -> ProgressBar {
    let total = (config.epochs * config.steps_per_epoch) as u64;
    let target = if config.progress && std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(total), target);
    if let Ok(style) = ProgressStyle::with_template(
        "{bar:30} {pos}/{len} steps, {elapsed} elapsed, eta {eta} {msg}",
    ) {
        bar.set_style(style);
    }
    bar.set_position((start_epoch * config.steps_per_epoch) as u64);
    bar
}

fn new_optimizer(config: &TrainConfig) -> ModuleOptimizer {
    AdamConfig::new()
        .with_grad_clipping(config.grad_clip_norm.map(GradientClippingConfig::Norm))
        .init()
}

/// Train a model built by `build` on `device` (which must have autodiff, e.g.
/// [`backend::cpu_autodiff`](crate::backend::cpu_autodiff)), minimising the `[1]`-shaped loss
/// returned by `loss` for every step.
///
/// With a `checkpoint_dir` that already holds checkpoints, the model, optimiser state and loss
/// history are restored from the latest one and training continues at its epoch. Given the same
/// config and a loss closure that samples data only from [`Step::seed`], the result is
/// bit-identical to an uninterrupted run (flex runs every op on one thread in a fixed order).
pub fn fit<M, B, L>(
    config: &TrainConfig,
    device: &Device,
    build: B,
    mut loss: L,
) -> Result<TrainReport<M>, NnError>
where
    M: Module,
    B: FnOnce(&Device) -> M,
    L: FnMut(&M, &Step) -> Tensor<1>,
{
    config.validate()?;
    if !device.is_autodiff() {
        return Err(NnError::Config(
            "fit needs an autodiff device (e.g. backend::cpu_autodiff())".into(),
        ));
    }
    let mut model = crate::backend::seeded_module(device, config.seed, build);
    let mut optim = new_optimizer(config);
    let mut loss_history = Vec::new();
    let mut optimizer_steps = 0u64;
    let mut start_epoch = 0;
    let mut resumed_from = None;

    if let Some(dir) = &config.checkpoint_dir {
        if let Some(files) = checkpoint::latest_checkpoint(dir)? {
            let (m, o, meta) = checkpoint::load_checkpoint(&files, model, optim)?;
            check_resumable(config, &meta, &files.meta)?;
            model = m;
            optim = o;
            loss_history = meta.loss_history;
            optimizer_steps = meta.optimizer_steps;
            start_epoch = meta.epoch;
            resumed_from = Some(files.model);
        }
    }

    let bar = progress_bar(config, start_epoch);
    let mut last_checkpoint = None;
    for epoch in start_epoch..config.epochs {
        // Re-seed per epoch so random ops inside the model (noise, dropout) replay identically
        // after a resume.
        crate::backend::seeded(device, step_seed(config.seed, epoch, usize::MAX), || ());
        let lr = config.lr_at(epoch);
        let mut sum = 0.0;
        for step in 0..config.steps_per_epoch {
            let step = Step {
                epoch,
                step,
                seed: step_seed(config.seed, epoch, step),
            };
            let value = loss(&model, &step);
            let scalar = f64::from(value.clone().into_scalar::<f32>());
            if !scalar.is_finite() {
                bar.abandon();
                return Err(NnError::Config(format!(
                    "loss became {scalar} at epoch {epoch}, step {}: lower lr or clip gradients",
                    step.step
                )));
            }
            sum += scalar;
            let grads = GradientsParams::from_grads(value.backward(), &model);
            model = optim.step(lr, model, grads);
            optimizer_steps += 1;
            bar.inc(1);
        }
        let mean = sum / config.steps_per_epoch as f64;
        loss_history.push(mean);
        bar.set_message(format!("epoch {} loss {mean:.5} lr {lr:.2e}", epoch + 1));

        let done = epoch + 1;
        let periodic = config.checkpoint_every > 0 && done % config.checkpoint_every == 0;
        if let Some(dir) = &config.checkpoint_dir {
            if periodic || done == config.epochs {
                let meta = CheckpointMeta {
                    epoch: done,
                    optimizer_steps,
                    loss_history: loss_history.clone(),
                    loss_history_bits: Vec::new(),
                    lr,
                    config: serde_json::to_value(config).unwrap_or(serde_json::Value::Null),
                };
                let files = checkpoint::save_checkpoint(dir, &model, &optim, &meta)?;
                last_checkpoint = Some(files.model);
            }
        }
    }
    bar.finish_and_clear();
    Ok(TrainReport {
        model,
        loss_history,
        start_epoch,
        optimizer_steps,
        resumed_from,
        last_checkpoint,
    })
}

/// A checkpoint written with a different seed, lr, decay, steps per epoch or clipping would not
/// continue the same run: refuse rather than silently mixing trajectories.
fn check_resumable(
    config: &TrainConfig,
    meta: &CheckpointMeta,
    path: &std::path::Path,
) -> Result<(), NnError> {
    let saved: TrainConfig =
        serde_json::from_value(meta.config.clone()).map_err(|e| NnError::Metadata {
            path: path.to_path_buf(),
            line: 0,
            column: 0,
            message: format!("field \"config\" is not a TrainConfig: {e}"),
        })?;
    if saved.resume_key() != config.resume_key() {
        return Err(NnError::Config(format!(
            "{}: checkpoint was written with seed {}, lr {}, lr_decay {}, steps_per_epoch {}, grad_clip_norm {:?}; \
             this run has seed {}, lr {}, lr_decay {}, steps_per_epoch {}, grad_clip_norm {:?} \
             (use another checkpoint_dir to start afresh)",
            path.display(),
            saved.seed, saved.lr, saved.lr_decay, saved.steps_per_epoch, saved.grad_clip_norm,
            config.seed, config.lr, config.lr_decay, config.steps_per_epoch, config.grad_clip_norm,
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend;
    use crate::lstm::{FusedLstm, FusedLstmConfig};
    use burn::nn::{Linear, LinearConfig};
    use burn::tensor::TensorData;

    /// Tiny next-sample predictor: LSTM(1 → 16) + linear head.
    #[derive(Module, Debug)]
    struct SinePredictor {
        lstm: FusedLstm,
        head: Linear,
    }

    fn build(device: &Device) -> SinePredictor {
        SinePredictor {
            lstm: FusedLstmConfig::new(1, 16).init(device),
            head: LinearConfig::new(16, 1).init(device),
        }
    }

    const BATCH: usize = 16;
    const STEPS: usize = 24;

    /// A batch of sine waves with phase and frequency drawn from `seed`:
    /// inputs x_0..x_{T-1}, targets x_1..x_T.
    fn sine_batch(seed: u64, device: &Device) -> (Vec<Tensor<2>>, Tensor<2>) {
        let mut state = seed;
        let mut uniform = || {
            state = mix(state);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let waves: Vec<(f64, f64)> = (0..BATCH)
            .map(|_| (uniform() * std::f64::consts::TAU, 0.25 + 0.3 * uniform()))
            .collect();
        let sample = |b: usize, t: usize| {
            let (phase, omega) = waves[b];
            (phase + omega * t as f64).sin() as f32
        };
        let inputs = (0..STEPS)
            .map(|t| {
                let column: Vec<f32> = (0..BATCH).map(|b| sample(b, t)).collect();
                Tensor::from_data(TensorData::new(column, [BATCH, 1]), device)
            })
            .collect();
        let targets: Vec<f32> = (0..BATCH)
            .flat_map(|b| (1..=STEPS).map(move |t| (b, t)))
            .map(|(b, t)| sample(b, t))
            .collect();
        (
            inputs,
            Tensor::from_data(TensorData::new(targets, [BATCH, STEPS]), device),
        )
    }

    fn predict(model: &SinePredictor, inputs: &[Tensor<2>]) -> Tensor<2> {
        let (hs, _) = model.lstm.forward_seq(inputs, None);
        Tensor::cat(hs.into_iter().map(|h| model.head.forward(h)).collect(), 1)
    }

    fn sine_loss(device: &Device) -> impl FnMut(&SinePredictor, &Step) -> Tensor<1> + '_ {
        move |model, step| {
            let (inputs, targets) = sine_batch(step.seed, device);
            (predict(model, &inputs) - targets).square().mean()
        }
    }

    fn config(epochs: usize) -> TrainConfig {
        TrainConfig {
            epochs,
            steps_per_epoch: 5,
            lr: 0.02,
            lr_decay: 0.95,
            seed: 42,
            progress: false,
            ..TrainConfig::default()
        }
    }

    fn weights(model: &SinePredictor) -> Vec<f32> {
        let mut all = model
            .lstm
            .gates
            .weight
            .val()
            .into_data()
            .try_to_vec::<f32>()
            .unwrap();
        all.extend(
            model
                .head
                .weight
                .val()
                .into_data()
                .try_to_vec::<f32>()
                .unwrap(),
        );
        all
    }

    #[test]
    fn tiny_lstm_learns_a_sine_wave() {
        let device = backend::cpu_autodiff();
        let report = fit(&config(30), &device, build, sine_loss(&device)).unwrap();
        let first = report.loss_history[0];
        let last = *report.loss_history.last().unwrap();
        println!(
            "sine smoke: first-epoch loss {first:.5}, last-epoch loss {last:.5}, ratio {:.4}",
            last / first
        );
        assert_eq!(report.loss_history.len(), 30);
        assert_eq!(report.optimizer_steps, 150);
        assert!(
            last < 0.2 * first,
            "loss did not fall enough: {first} -> {last}"
        );
    }

    #[test]
    fn same_seed_gives_identical_runs() {
        let device = backend::cpu_autodiff();
        let a = fit(&config(2), &device, build, sine_loss(&device)).unwrap();
        let b = fit(&config(2), &device, build, sine_loss(&device)).unwrap();
        assert_eq!(a.loss_history, b.loss_history);
        assert_eq!(weights(&a.model), weights(&b.model));
        let other = TrainConfig {
            seed: 43,
            ..config(2)
        };
        let c = fit(&other, &device, build, sine_loss(&device)).unwrap();
        assert_ne!(weights(&a.model), weights(&c.model));
    }

    #[test]
    fn resume_matches_an_uninterrupted_run() {
        let device = backend::cpu_autodiff();
        let straight_dir = tempfile::tempdir().unwrap();
        let split_dir = tempfile::tempdir().unwrap();
        let with_dir = |epochs, dir: &std::path::Path| TrainConfig {
            checkpoint_every: 2,
            checkpoint_dir: Some(dir.to_path_buf()),
            ..config(epochs)
        };
        let straight = fit(
            &with_dir(4, straight_dir.path()),
            &device,
            build,
            sine_loss(&device),
        )
        .unwrap();
        // Interrupted after 2 epochs, then restarted with the full epoch count.
        let first = fit(
            &with_dir(2, split_dir.path()),
            &device,
            build,
            sine_loss(&device),
        )
        .unwrap();
        assert_eq!(first.loss_history.len(), 2);
        let resumed = fit(
            &with_dir(4, split_dir.path()),
            &device,
            build,
            sine_loss(&device),
        )
        .unwrap();
        assert_eq!(resumed.start_epoch, 2);
        assert!(resumed.resumed_from.is_some());
        assert_eq!(resumed.optimizer_steps, straight.optimizer_steps);
        assert_eq!(resumed.loss_history, straight.loss_history);
        assert_eq!(weights(&resumed.model), weights(&straight.model));

        // A checkpoint from another seed is refused with a message naming both.
        let mismatched = TrainConfig {
            seed: 7,
            ..with_dir(6, split_dir.path())
        };
        let err = fit(&mismatched, &device, build, sine_loss(&device))
            .unwrap_err()
            .to_string();
        assert!(err.contains("seed 42") && err.contains("seed 7"), "{err}");
    }

    #[test]
    fn checkpointed_model_gives_identical_outputs() {
        let device = backend::cpu_autodiff();
        let report = fit(&config(1), &device, build, sine_loss(&device)).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sine.bpk");
        checkpoint::save_module(&report.model, &path).unwrap();
        // A differently seeded fresh model, then loaded: must reproduce the trained outputs.
        let fresh = backend::seeded_module(&device, 999, build);
        let loaded = checkpoint::load_module(fresh, &path).unwrap();
        let (inputs, _) = sine_batch(5, &device);
        let expected = predict(&report.model, &inputs)
            .into_data()
            .try_to_vec::<f32>()
            .unwrap();
        let got = predict(&loaded, &inputs)
            .into_data()
            .try_to_vec::<f32>()
            .unwrap();
        assert_eq!(expected, got);
    }

    #[test]
    fn bad_config_and_files_give_clear_errors() {
        let device = backend::cpu_autodiff();
        let bad = TrainConfig {
            lr_decay: 1.5,
            ..config(1)
        };
        let err = fit(&bad, &device, build, sine_loss(&device))
            .unwrap_err()
            .to_string();
        assert!(err.contains("lr_decay"), "{err}");
        let plain = backend::cpu();
        let err = fit(&config(1), &plain, build, sine_loss(&plain))
            .unwrap_err()
            .to_string();
        assert!(err.contains("autodiff"), "{err}");

        let dir = tempfile::tempdir().unwrap();
        let garbage = dir.path().join("garbage.bpk");
        std::fs::write(&garbage, b"not a burnpack").unwrap();
        let err = checkpoint::load_module(build(&device), &garbage)
            .unwrap_err()
            .to_string();
        assert!(err.contains("garbage.bpk"), "{err}");
        let meta = dir.path().join("epoch-000001.json");
        std::fs::write(&meta, "{\n  \"epoch\": 1,\n  oops\n}").unwrap();
        let err = CheckpointMeta::load(&meta).unwrap_err().to_string();
        assert!(
            err.contains("epoch-000001.json") && err.contains("line 3"),
            "{err}"
        );
        let missing = dir.path().join("missing.bpk");
        let err = checkpoint::load_module(build(&device), &missing)
            .unwrap_err()
            .to_string();
        assert!(err.contains("missing.bpk"), "{err}");
    }
}
