//! The one training loop of inbetween: Adam, exponential learning-rate decay per epoch with warm
//! restarts, gradient clipping, a progress bar, a wall-clock limit, per-step and per-epoch hooks,
//! periodic checkpoints, and resume that is bit-identical to an uninterrupted run.
//!
//! The caller supplies a builder (called once, right after seeding, inside
//! [`backend::seeded_module`](crate::backend::seeded_module), so the initial weights depend only on
//! [`TrainConfig::seed`]) and an [`Objective`]: the loss of one optimisation step, plus optional
//! hooks and state of its own. [`fit`] takes a plain loss closure; [`fit_with`] a whole objective.
//! The objective gets a [`Step`] whose [`Step::seed`] depends only on (seed, epoch, step): draw
//! batches from an RNG seeded with it and a resumed run sees exactly the batches an uninterrupted
//! run would. An objective that keeps state between steps (a replay buffer, a target network, an
//! environment) saves it through [`Objective::state`] / [`Objective::restore`], which travel with
//! every checkpoint.
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

use std::path::PathBuf;
use std::time::Instant;

use burn::grad_clipping::GradientClippingConfig;
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::tensor::{Device, Tensor};
use inbetween_io::Progress;
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
    /// Learning rate of the first epoch (of the first epoch after `lr_decay_from`).
    pub lr: f64,
    /// Multiplicative decay per epoch: epoch `e` uses `lr · lr_decay^(e − lr_decay_from)`
    /// (1.0 = constant).
    pub lr_decay: f64,
    /// Epoch the decay counts from. 0 for a fresh run; a resumed run that sets it to the epoch it
    /// resumes at restarts the schedule at `lr` (a warm restart) instead of where it had decayed to.
    #[serde(default)]
    pub lr_decay_from: usize,
    /// Seeds the model initialisation, the device RNG of every epoch and [`Step::seed`].
    pub seed: u64,
    /// Save a checkpoint every this many epochs (0 = only at the end). Needs `checkpoint_dir`.
    pub checkpoint_every: usize,
    /// Folder for checkpoints; if it holds one, training resumes from the latest.
    pub checkpoint_dir: Option<PathBuf>,
    /// Clip the gradient norm of each parameter tensor to this value (burn's `GradientClipping::Norm`
    /// acts per parameter, not on the norm of all gradients together).
    pub grad_clip_norm: Option<f32>,
    /// Stop after the epoch during which this many seconds of this invocation have passed (that
    /// epoch is finished and checkpointed, so the run can be resumed).
    #[serde(default)]
    pub time_limit_s: Option<f64>,
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
            lr_decay_from: 0,
            seed: 0,
            checkpoint_every: 0,
            checkpoint_dir: None,
            grad_clip_norm: None,
            time_limit_s: None,
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
            return Err(NnError::Config(format!("lr must be positive and finite, got {}", self.lr)));
        }
        if !(self.lr_decay > 0.0 && self.lr_decay <= 1.0) {
            return Err(NnError::Config(format!("lr_decay must be in (0, 1], got {}", self.lr_decay)));
        }
        if let Some(clip) = self.grad_clip_norm {
            if !(clip > 0.0 && clip.is_finite()) {
                return Err(NnError::Config(format!("grad_clip_norm must be positive, got {clip}")));
            }
        }
        if let Some(t) = self.time_limit_s {
            if t.is_nan() || t <= 0.0 {
                return Err(NnError::Config(format!("time_limit_s must be positive, got {t}")));
            }
        }
        Ok(())
    }

    /// Learning rate of epoch `epoch` (0-based): `lr · lr_decay^(epoch − lr_decay_from)`.
    pub fn lr_at(&self, epoch: usize) -> f64 {
        self.lr * self.lr_decay.powi(epoch.saturating_sub(self.lr_decay_from) as i32)
    }

    /// The fields a resumed run must share with the run that wrote the checkpoint: everything
    /// that changes the trajectory except the schedule (see [`check_resumable`]).
    fn resume_key(&self) -> (u64, usize, Option<u32>) {
        (self.seed, self.steps_per_epoch, self.grad_clip_norm.map(f32::to_bits))
    }

    fn schedule_key(&self) -> (u64, u64, usize) {
        (self.lr.to_bits(), self.lr_decay.to_bits(), self.lr_decay_from)
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

/// Seed of step `step` of epoch `epoch` in a run seeded with `seed`.
pub fn step_seed(seed: u64, epoch: usize, step: usize) -> u64 {
    use inbetween_core::seed::{derive, mix};
    mix(derive(seed, epoch as u64) ^ step as u64)
}

/// What [`Objective::after_epoch`] learns about the epoch that just ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochEnd {
    /// 0-based epoch that ended.
    pub epoch: usize,
    /// Mean loss over its steps that had one (NaN when none had).
    pub mean_loss: f64,
    /// Learning rate it used.
    pub lr: f64,
    /// Seconds of training so far, over every invocation of the run.
    pub seconds: f64,
}

/// Whether training goes on after an epoch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    Continue,
    /// Finish now (the epoch is checkpointed first, so the run can be resumed).
    Stop,
}

/// What a training run optimises, with hooks into the loop.
pub trait Objective<M> {
    /// Advances the objective one step and returns the `[1]`-shaped loss to minimise
    /// (differentiable on an autodiff device), or `None` when this step has nothing to learn yet
    /// (e.g. a DQN filling its replay memory); the optimiser then skips the step.
    fn loss(&mut self, model: &M, step: &Step) -> Option<Tensor<1>>;

    /// Checked before every step: an `Err` ends the run at once with [`NnError::Cancelled`], without
    /// checkpointing the unfinished epoch (a cancel button or a job's time budget; see
    /// `inbetween_core::cancel`). Never stops by default.
    fn check_cancel(&self) -> Result<(), inbetween_core::cancel::Cancelled> {
        Ok(())
    }

    /// Called after every step, once the optimiser applied it, with the step's loss if it had one
    /// (logging, target-network updates, …).
    fn after_step(&mut self, _model: &M, _step: &Step, _loss: Option<f64>) {}

    /// Called after every epoch (validation, early stopping, …).
    fn after_epoch(&mut self, _model: &M, _end: &EpochEnd) -> Control {
        Control::Continue
    }

    /// The objective's own state, saved with every checkpoint (empty: none).
    fn state(&self) -> Result<Vec<u8>, String> {
        Ok(Vec::new())
    }

    /// Restores what [`state`](Self::state) saved, when resuming.
    fn restore(&mut self, _state: &[u8]) -> Result<(), String> {
        Ok(())
    }
}

/// A loss closure as an [`Objective`] without hooks or state.
struct LossFn<F>(F);

impl<M, F: FnMut(&M, &Step) -> Tensor<1>> Objective<M> for LossFn<F> {
    fn loss(&mut self, model: &M, step: &Step) -> Option<Tensor<1>> {
        Some((self.0)(model, step))
    }
}

/// Why [`fit_with`] returned.
#[derive(Debug, Clone, PartialEq)]
pub enum Finish {
    /// All `epochs` are done.
    Completed,
    /// `time_limit_s` ran out after this many epochs.
    TimeLimit { epochs_done: usize },
    /// The objective asked to stop after this many epochs.
    Stopped { epochs_done: usize },
}

/// Outcome of [`fit`].
#[derive(Debug)]
pub struct TrainReport<M> {
    /// The trained model (still on the training device).
    pub model: M,
    /// Mean loss of every epoch from the start of the run (including epochs before a resume);
    /// NaN for an epoch in which the objective returned no loss.
    pub loss_history: Vec<f64>,
    /// Epoch this invocation started at (0, or the resumed checkpoint's epoch).
    pub start_epoch: usize,
    /// Optimiser steps taken in total.
    pub optimizer_steps: u64,
    /// Seconds of training over every invocation of the run, as of the end of the last epoch (the
    /// figure its checkpoint records).
    pub seconds: f64,
    /// Why training ended.
    pub finish: Finish,
    /// The checkpoint training resumed from, if any.
    pub resumed_from: Option<PathBuf>,
    /// The last checkpoint written, if any.
    pub last_checkpoint: Option<PathBuf>,
}

fn new_optimizer(config: &TrainConfig) -> ModuleOptimizer {
    AdamConfig::new().with_grad_clipping(config.grad_clip_norm.map(GradientClippingConfig::Norm)).init()
}

/// Train a model built by `build` on `device` (which must have autodiff, e.g.
/// [`backend::cpu_autodiff`](crate::backend::cpu_autodiff)), minimising the loss `loss` returns
/// for every step. See [`fit_with`].
pub fn fit<M, B, L>(config: &TrainConfig, device: &Device, build: B, loss: L) -> Result<TrainReport<M>, NnError>
where
    M: Module,
    B: FnOnce(&Device) -> M,
    L: FnMut(&M, &Step) -> Tensor<1>,
{
    fit_with(config, device, build, &mut LossFn(loss))
}

/// Train a model built by `build` on `device` against `objective`.
///
/// With a `checkpoint_dir` that already holds checkpoints, the model, optimiser state, loss
/// history and the objective's state are restored from the latest one and training continues at
/// its epoch. Given the same config and an objective that samples data only from [`Step::seed`]
/// (or keeps the rest in its state), the result is bit-identical to an uninterrupted run.
///
/// The tensor kernels run on rayon's pool: every core by default (`RAYON_NUM_THREADS=1`, or a
/// caller's `ThreadPool::install`, for fewer); flex gives bit-identical results on any number of
/// threads (tested), so two single-threaded runs side by side are a fair use of two cores.
pub fn fit_with<M, B, O>(
    config: &TrainConfig,
    device: &Device,
    build: B,
    objective: &mut O,
) -> Result<TrainReport<M>, NnError>
where
    M: Module,
    B: FnOnce(&Device) -> M,
    O: Objective<M>,
{
    config.validate()?;
    if !device.is_autodiff() {
        return Err(NnError::Config("fit needs an autodiff device (e.g. backend::cpu_autodiff())".into()));
    }
    run(config, device, build, objective)
}

/// Where a run stands: restored from a checkpoint or fresh.
struct RunState<M> {
    model: M,
    optim: ModuleOptimizer,
    loss_history: Vec<f64>,
    optimizer_steps: u64,
    start_epoch: usize,
    seconds_before: f64,
    resumed_from: Option<PathBuf>,
}

fn start<M, B, O>(config: &TrainConfig, device: &Device, build: B, objective: &mut O) -> Result<RunState<M>, NnError>
where
    M: Module,
    B: FnOnce(&Device) -> M,
    O: Objective<M>,
{
    let model = crate::backend::seeded_module(device, config.seed, build);
    let optim = new_optimizer(config);
    let fresh = RunState {
        model,
        optim,
        loss_history: Vec::new(),
        optimizer_steps: 0,
        start_epoch: 0,
        seconds_before: 0.0,
        resumed_from: None,
    };
    let Some(dir) = &config.checkpoint_dir else { return Ok(fresh) };
    let Some(files) = checkpoint::latest_checkpoint(dir)? else { return Ok(fresh) };
    let (model, optim, meta) = checkpoint::load_checkpoint(&files, fresh.model, fresh.optim)?;
    check_resumable(config, &meta, &files.meta)?;
    if files.state.exists() {
        let bytes = std::fs::read(&files.state).map_err(|source| NnError::Io { path: files.state.clone(), source })?;
        objective.restore(&bytes).map_err(|message| NnError::Record {
            path: files.state.clone(),
            message: format!("objective state: {message}"),
        })?;
    }
    Ok(RunState {
        model,
        optim,
        loss_history: meta.loss_history,
        optimizer_steps: meta.optimizer_steps,
        start_epoch: meta.epoch,
        seconds_before: meta.seconds,
        resumed_from: Some(files.model),
    })
}

fn run<M, B, O>(config: &TrainConfig, device: &Device, build: B, objective: &mut O) -> Result<TrainReport<M>, NnError>
where
    M: Module,
    B: FnOnce(&Device) -> M,
    O: Objective<M>,
{
    let RunState {
        mut model,
        mut optim,
        mut loss_history,
        mut optimizer_steps,
        start_epoch,
        seconds_before,
        resumed_from,
    } = start(config, device, build, objective)?;
    let total = (config.epochs * config.steps_per_epoch) as u64;
    let bar = if config.progress { Progress::new(total, "training") } else { Progress::hidden() };
    bar.set_position((start_epoch * config.steps_per_epoch) as u64);
    let started = Instant::now();
    let mut last_checkpoint = None;
    let mut finish = Finish::Completed;
    // Training time as of the last finished epoch: what checkpoints record and the report returns.
    let mut seconds = seconds_before;
    for epoch in start_epoch..config.epochs {
        // Re-seed per epoch so random ops inside the model (noise, dropout) replay identically
        // after a resume.
        crate::backend::seeded(device, step_seed(config.seed, epoch, usize::MAX), || ());
        let lr = config.lr_at(epoch);
        let (mut sum, mut losses) = (0.0, 0usize);
        for step in 0..config.steps_per_epoch {
            if let Err(stop) = objective.check_cancel() {
                bar.abandon();
                return Err(stop.into());
            }
            let step = Step { epoch, step, seed: step_seed(config.seed, epoch, step) };
            let mut scalar = None;
            if let Some(value) = objective.loss(&model, &step) {
                let v = f64::from(value.clone().into_scalar::<f32>());
                if !v.is_finite() {
                    bar.abandon();
                    return Err(NnError::NonFiniteLoss { epoch, step: step.step, loss: v });
                }
                let grads = GradientsParams::from_grads(value.backward(), &model);
                model = optim.step(lr, model, grads);
                optimizer_steps += 1;
                (sum, losses) = (sum + v, losses + 1);
                scalar = Some(v);
            }
            objective.after_step(&model, &step, scalar);
            bar.inc(1);
        }
        // NaN marks an epoch without a single optimiser step.
        let mean = if losses > 0 { sum / losses as f64 } else { f64::NAN };
        loss_history.push(mean);
        bar.set_message(format!("epoch {} loss {mean:.5} lr {lr:.2e}", epoch + 1));
        seconds = seconds_before + started.elapsed().as_secs_f64();
        let end = EpochEnd { epoch, mean_loss: mean, lr, seconds };
        let done = epoch + 1;
        if objective.after_epoch(&model, &end) == Control::Stop {
            finish = Finish::Stopped { epochs_done: done };
        } else if config.time_limit_s.is_some_and(|t| started.elapsed().as_secs_f64() >= t) && done < config.epochs {
            finish = Finish::TimeLimit { epochs_done: done };
        }
        let periodic = config.checkpoint_every > 0 && done % config.checkpoint_every == 0;
        let last = done == config.epochs || finish != Finish::Completed;
        if let (Some(dir), true) = (&config.checkpoint_dir, periodic || last) {
            let meta = CheckpointMeta {
                epoch: done,
                optimizer_steps,
                loss_history: loss_history.clone(),
                loss_history_bits: Vec::new(),
                lr,
                seconds,
                config: serde_json::to_value(config).unwrap_or(serde_json::Value::Null),
            };
            let state = objective.state().map_err(|message| NnError::Record {
                path: dir.clone(),
                message: format!("objective state: {message}"),
            })?;
            let files = checkpoint::save_checkpoint(dir, &model, &optim, &state, &meta)?;
            last_checkpoint = Some(files.model);
        }
        if finish != Finish::Completed {
            break;
        }
    }
    bar.finish();
    Ok(TrainReport {
        model,
        loss_history,
        start_epoch,
        optimizer_steps,
        seconds,
        finish,
        resumed_from,
        last_checkpoint,
    })
}

/// A checkpoint written with a different seed, steps per epoch or clipping would not continue the
/// same run: refuse rather than silently mixing trajectories. The schedule (lr, decay) may change
/// only as a warm restart, i.e. with `lr_decay_from` at or after the checkpoint's epoch.
fn check_resumable(config: &TrainConfig, meta: &CheckpointMeta, path: &std::path::Path) -> Result<(), NnError> {
    let saved: TrainConfig = serde_json::from_value(meta.config.clone()).map_err(|e| NnError::Metadata {
        path: path.to_path_buf(),
        line: 0,
        column: 0,
        message: format!("field \"config\" is not a TrainConfig: {e}"),
    })?;
    if saved.resume_key() != config.resume_key() {
        return Err(NnError::Config(format!(
            "{}: checkpoint was written with seed {}, steps_per_epoch {}, grad_clip_norm {:?}; \
             this run has seed {}, steps_per_epoch {}, grad_clip_norm {:?} \
             (use another checkpoint_dir to start afresh)",
            path.display(),
            saved.seed,
            saved.steps_per_epoch,
            saved.grad_clip_norm,
            config.seed,
            config.steps_per_epoch,
            config.grad_clip_norm,
        )));
    }
    if saved.schedule_key() != config.schedule_key() && config.lr_decay_from < meta.epoch {
        return Err(NnError::Config(format!(
            "{}: checkpoint at epoch {} was written with lr {}, lr_decay {}, lr_decay_from {}; this run has lr {}, \
             lr_decay {}, lr_decay_from {}: a new schedule must start at or after the resumed epoch \
             (set lr_decay_from to {} for a warm restart)",
            path.display(),
            meta.epoch,
            saved.lr,
            saved.lr_decay,
            saved.lr_decay_from,
            config.lr,
            config.lr_decay,
            config.lr_decay_from,
            meta.epoch,
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
        SinePredictor { lstm: FusedLstmConfig::new(1, 16).init(device), head: LinearConfig::new(16, 1).init(device) }
    }

    const BATCH: usize = 16;
    const STEPS: usize = 24;

    /// A batch of sine waves with phase and frequency drawn from `seed`:
    /// inputs x_0..x_{T-1}, targets x_1..x_T.
    fn sine_batch(seed: u64, device: &Device) -> (Vec<Tensor<2>>, Tensor<2>) {
        let mut state = seed;
        let mut uniform = || {
            state = inbetween_core::seed::mix(state);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let waves: Vec<(f64, f64)> =
            (0..BATCH).map(|_| (uniform() * std::f64::consts::TAU, 0.25 + 0.3 * uniform())).collect();
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
        let targets: Vec<f32> =
            (0..BATCH).flat_map(|b| (1..=STEPS).map(move |t| (b, t))).map(|(b, t)| sample(b, t)).collect();
        (inputs, Tensor::from_data(TensorData::new(targets, [BATCH, STEPS]), device))
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
        let mut all = model.lstm.gates.weight.val().into_data().try_to_vec::<f32>().unwrap();
        all.extend(model.head.weight.val().into_data().try_to_vec::<f32>().unwrap());
        all
    }

    #[test]
    fn tiny_lstm_learns_a_sine_wave() {
        let device = backend::cpu_autodiff();
        let report = fit(&config(30), &device, build, sine_loss(&device)).unwrap();
        let first = report.loss_history[0];
        let last = *report.loss_history.last().unwrap();
        println!("sine smoke: first-epoch loss {first:.5}, last-epoch loss {last:.5}, ratio {:.4}", last / first);
        assert_eq!(report.loss_history.len(), 30);
        assert_eq!(report.optimizer_steps, 150);
        assert!(last < 0.2 * first, "loss did not fall enough: {first} -> {last}");
    }

    #[test]
    fn same_seed_gives_identical_runs() {
        let device = backend::cpu_autodiff();
        let a = fit(&config(2), &device, build, sine_loss(&device)).unwrap();
        let b = fit(&config(2), &device, build, sine_loss(&device)).unwrap();
        assert_eq!(a.loss_history, b.loss_history);
        assert_eq!(weights(&a.model), weights(&b.model));
        let other = TrainConfig { seed: 43, ..config(2) };
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
        let straight = fit(&with_dir(4, straight_dir.path()), &device, build, sine_loss(&device)).unwrap();
        // Interrupted after 2 epochs, then restarted with the full epoch count.
        let first = fit(&with_dir(2, split_dir.path()), &device, build, sine_loss(&device)).unwrap();
        assert_eq!(first.loss_history.len(), 2);
        let resumed = fit(&with_dir(4, split_dir.path()), &device, build, sine_loss(&device)).unwrap();
        assert_eq!(resumed.start_epoch, 2);
        assert!(resumed.resumed_from.is_some());
        assert_eq!(resumed.optimizer_steps, straight.optimizer_steps);
        assert_eq!(resumed.loss_history, straight.loss_history);
        assert_eq!(weights(&resumed.model), weights(&straight.model));

        // A checkpoint from another seed is refused with a message naming both.
        let mismatched = TrainConfig { seed: 7, ..with_dir(6, split_dir.path()) };
        let err = fit(&mismatched, &device, build, sine_loss(&device)).unwrap_err().to_string();
        assert!(err.contains("seed 42") && err.contains("seed 7"), "{err}");
    }

    /// An objective with state of its own (a running count that feeds the loss, like a replay
    /// buffer feeds a DQN) and hooks that record what the loop reports.
    struct Counting<'a> {
        device: &'a Device,
        seen: u64,
        steps: Vec<(usize, usize)>,
        epochs: Vec<EpochEnd>,
        stop_after: Option<usize>,
    }

    impl<'a> Counting<'a> {
        fn new(device: &'a Device) -> Self {
            Counting { device, seen: 0, steps: Vec::new(), epochs: Vec::new(), stop_after: None }
        }
    }

    impl Objective<SinePredictor> for Counting<'_> {
        fn loss(&mut self, model: &SinePredictor, step: &Step) -> Option<Tensor<1>> {
            // Nothing to learn on the first step of an epoch (like a DQN warming up).
            if step.step == 0 {
                return None;
            }
            // The batch depends on the objective's state, not only on the step seed.
            let (inputs, targets) = sine_batch(step.seed ^ self.seen, self.device);
            Some((predict(model, &inputs) - targets).square().mean())
        }
        fn after_step(&mut self, _: &SinePredictor, step: &Step, loss: Option<f64>) {
            assert_eq!(loss.is_none(), step.step == 0);
            self.seen += 1 + loss.map_or(0, |l| (l * 1e6) as u64 % 7);
            self.steps.push((step.epoch, step.step));
        }
        fn after_epoch(&mut self, _: &SinePredictor, end: &EpochEnd) -> Control {
            self.epochs.push(*end);
            if self.stop_after == Some(end.epoch + 1) {
                Control::Stop
            } else {
                Control::Continue
            }
        }
        fn state(&self) -> Result<Vec<u8>, String> {
            Ok(self.seen.to_le_bytes().to_vec())
        }
        fn restore(&mut self, state: &[u8]) -> Result<(), String> {
            self.seen = u64::from_le_bytes(state.try_into().map_err(|_| format!("{} bytes, expected 8", state.len()))?);
            Ok(())
        }
    }

    #[test]
    fn hooks_see_every_step_and_objective_state_resumes_bit_identically() {
        let device = backend::cpu_autodiff();
        let (straight_dir, split_dir) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let with_dir =
            |epochs, dir: &std::path::Path| TrainConfig { checkpoint_dir: Some(dir.to_path_buf()), ..config(epochs) };
        let mut whole = Counting::new(&device);
        let straight = fit_with(&with_dir(4, straight_dir.path()), &device, build, &mut whole).unwrap();
        assert_eq!(whole.steps.len(), 20);
        assert_eq!(whole.steps[7], (1, 2));
        assert_eq!(straight.optimizer_steps, 16, "steps without a loss are skipped");
        assert_eq!(whole.epochs.iter().map(|e| e.epoch).collect::<Vec<_>>(), [0, 1, 2, 3]);
        assert_eq!(whole.epochs[3].mean_loss, straight.loss_history[3]);

        // Stopped by the objective after 2 epochs, then resumed by a fresh objective.
        let mut first = Counting::new(&device);
        first.stop_after = Some(2);
        let stopped = fit_with(&with_dir(4, split_dir.path()), &device, build, &mut first).unwrap();
        assert_eq!(stopped.finish, Finish::Stopped { epochs_done: 2 });
        let mut second = Counting::new(&device);
        let resumed = fit_with(&with_dir(4, split_dir.path()), &device, build, &mut second).unwrap();
        assert_eq!(resumed.start_epoch, 2);
        assert_eq!(second.seen, whole.seen, "objective state was not restored");
        assert_eq!(resumed.loss_history, straight.loss_history);
        assert_eq!(weights(&resumed.model), weights(&straight.model));
    }

    #[test]
    fn a_time_limit_stops_after_a_checkpointed_epoch_that_resumes() {
        let device = backend::cpu_autodiff();
        let dir = tempfile::tempdir().unwrap();
        let limited =
            TrainConfig { time_limit_s: Some(1e-9), checkpoint_dir: Some(dir.path().to_path_buf()), ..config(3) };
        let report = fit(&limited, &device, build, sine_loss(&device)).unwrap();
        assert_eq!(report.finish, Finish::TimeLimit { epochs_done: 1 });
        assert!(report.last_checkpoint.is_some());
        let rest = TrainConfig { time_limit_s: None, ..limited.clone() };
        let resumed = fit(&rest, &device, build, sine_loss(&device)).unwrap();
        let straight = fit(&config(3), &device, build, sine_loss(&device)).unwrap();
        assert_eq!(resumed.finish, Finish::Completed);
        assert_eq!(resumed.loss_history, straight.loss_history);
        let saved = CheckpointMeta::load(&checkpoint::CheckpointFiles::in_dir(dir.path(), 1).meta).unwrap();
        assert_eq!(saved.seconds.to_bits(), report.seconds.to_bits(), "the report and its checkpoint disagree");
        assert!(resumed.seconds > report.seconds, "the second sitting's time was not added");
    }

    #[test]
    fn a_warm_restart_resumes_with_a_new_schedule_only_from_the_resumed_epoch() {
        let restarted = TrainConfig { lr: 5e-4, lr_decay: 0.97, lr_decay_from: 95, ..TrainConfig::default() };
        assert!((restarted.lr_at(95) - 5e-4).abs() < 1e-15);
        assert!((restarted.lr_at(96) - 5e-4 * 0.97).abs() < 1e-15);
        assert!((restarted.lr_at(10) - 5e-4).abs() < 1e-15);

        let device = backend::cpu_autodiff();
        let dir = tempfile::tempdir().unwrap();
        let with_dir = |c: TrainConfig| TrainConfig { checkpoint_dir: Some(dir.path().to_path_buf()), ..c };
        fit(&with_dir(config(2)), &device, build, sine_loss(&device)).unwrap();
        // A new lr that claims to count from epoch 0 would rewrite history: refused.
        let err = fit(&with_dir(TrainConfig { lr: 0.01, ..config(3) }), &device, build, sine_loss(&device))
            .unwrap_err()
            .to_string();
        assert!(err.contains("lr_decay_from") && err.contains("epoch 2"), "{err}");
        let warm = with_dir(TrainConfig { lr: 0.01, lr_decay_from: 2, ..config(3) });
        let report = fit(&warm, &device, build, sine_loss(&device)).unwrap();
        assert_eq!(report.start_epoch, 2);
        assert_eq!(report.loss_history.len(), 3);
    }

    #[test]
    fn thread_count_does_not_change_the_result() {
        let run_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let device = backend::cpu_autodiff();
                let r = fit(&config(2), &device, build, sine_loss(&device)).unwrap();
                (r.loss_history, weights(&r.model))
            })
        };
        assert_eq!(run_on(1), run_on(2));
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
        let expected = predict(&report.model, &inputs).into_data().try_to_vec::<f32>().unwrap();
        let got = predict(&loaded, &inputs).into_data().try_to_vec::<f32>().unwrap();
        assert_eq!(expected, got);
    }

    #[test]
    fn bad_config_and_files_give_clear_errors() {
        let device = backend::cpu_autodiff();
        let bad = TrainConfig { lr_decay: 1.5, ..config(1) };
        let err = fit(&bad, &device, build, sine_loss(&device)).unwrap_err().to_string();
        assert!(err.contains("lr_decay"), "{err}");
        let plain = backend::cpu();
        let err = fit(&config(1), &plain, build, sine_loss(&plain)).unwrap_err().to_string();
        assert!(err.contains("autodiff"), "{err}");

        let dir = tempfile::tempdir().unwrap();
        let garbage = dir.path().join("garbage.bpk");
        std::fs::write(&garbage, b"not a burnpack").unwrap();
        let err = checkpoint::load_module(build(&device), &garbage).unwrap_err().to_string();
        assert!(err.contains("garbage.bpk"), "{err}");
        let meta = dir.path().join("epoch-000001.json");
        std::fs::write(&meta, "{\n  \"epoch\": 1,\n  oops\n}").unwrap();
        let err = CheckpointMeta::load(&meta).unwrap_err().to_string();
        assert!(err.contains("epoch-000001.json") && err.contains("line 3"), "{err}");
        let missing = dir.path().join("missing.bpk");
        let err = checkpoint::load_module(build(&device), &missing).unwrap_err().to_string();
        assert!(err.contains("missing.bpk"), "{err}");
    }

    #[test]
    fn a_nan_loss_is_named_with_its_epoch_and_step_not_as_a_configuration_error() {
        let device = backend::cpu_autodiff();
        let mut loss = sine_loss(&device);
        let diverging = move |model: &SinePredictor, step: &Step| {
            let l = loss(model, step);
            if step.epoch == 1 && step.step == 3 {
                l.mul_scalar(f32::NAN)
            } else {
                l
            }
        };
        let err = fit(&config(2), &device, build, diverging).unwrap_err();
        match &err {
            NnError::NonFiniteLoss { epoch: 1, step: 3, loss } => assert!(loss.is_nan()),
            other => panic!("expected NonFiniteLoss at epoch 1, step 3, got {other:?}"),
        }
        assert!(err.to_string().contains("loss became NaN at epoch 1, step 3"), "{err}");
    }
}
