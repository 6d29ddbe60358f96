//! Training RSFNet on one clip with the distance loss (§4.1, §6.1) on the shared loop
//! ([`inbetween_nn::train::fit_with`]): Adam, the paper's batch ("patch size") of 8 triplets,
//! seeded sampling.
//!
//! # Triplets from the clip itself
//! The paper prepares its triplets in a supplementary we do not have; ours come from the clip. Each
//! triplet draws an anchor `a` uniformly, then two other frames `p ≠ n`: with probability
//! `local_fraction` both from the window `a ± local_window` (so the network learns the fine order
//! among temporal neighbours), otherwise uniformly from the whole clip (so it learns which distant
//! frames look alike: the new transitions SDPF is after). Eq. 6 labels them by PSNR on the images the
//! network sees; ties are redrawn. The three images of each triplet go through the one network
//! in one batch (the paper's three weight-sharing R-Encoders).
//!
//! Every draw comes from [`Step::seed`](inbetween_nn::train::Step), the initial weights from
//! [`TrainOptions::seed`]: the same frames, config and options give bit-identical embeddings.
//!
//! # Early stopping (§6.1)
//! The paper stops "with 10 epochs patience" on a validation loss. Ours validates after every
//! epoch of `steps_per_epoch` steps on [`EVAL_TRIPLETS`] held-out triplets (their own seed
//! stream): the share whose PSNR order the latent distances reproduce (the *triplet agreement*).
//! Training stops when that share has not improved for `patience` epochs (or after `steps`), and
//! the network of the best epoch is kept. The agreement reported in [`TrainSummary`] is measured
//! on a second held-out set, not the one that chose the epoch. The learning rate stays constant
//! (the runs are a few epochs long, too short for §6.1's halving).
//!
//! # "w/o L_d" (Table 3)
//! §6.5.2 removes the distance loss and measures plain Euclidean distances between the backbone's
//! latent vectors. The paper's backbone was pretrained; ours is not, so `use_distance_loss: false`
//! means the seeded, *untrained* network (random convolutional features, a known baseline), with
//! no training at all.

use std::time::Instant;

use burn::tensor::{Device, Tensor, TensorData};
use image::RgbImage;
use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use inbetween_nn::backend;
use inbetween_nn::train::{fit_with, Control, EpochEnd, Objective, Step, TrainConfig};
use rand::Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::embed::Embedder;
use super::input::{batch_tensor, frame_planes, psnr, Planes};
use super::loss::{distance_loss, euclidean, triplet_label, Triplet};
use super::model::{RsfConfig, RsfNet};
use crate::VideoError;

/// How RSFNet is trained on a clip.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainOptions {
    /// Optimisation steps (rounded up to whole epochs of `steps_per_epoch`).
    pub steps: usize,
    /// Steps per epoch of the shared loop (the loss history has one mean per epoch).
    pub steps_per_epoch: usize,
    /// Triplets per step (the paper's "patch size" 8).
    pub batch: usize,
    /// Adam's learning rate.
    pub lr: f64,
    /// Seeds the initial weights and every triplet draw.
    pub seed: u64,
    /// Train with the distance loss (Eq. 4–6); `false` is the "w/o L_d" ablation (untrained network).
    pub use_distance_loss: bool,
    /// Half-width of the temporal window local triplets are drawn from.
    pub local_window: usize,
    /// Share of triplets drawn inside the window.
    pub local_fraction: f64,
    /// Stop after the epoch during which this many seconds have passed.
    pub time_limit_s: Option<f64>,
    /// Early stopping: epochs without a better validation agreement before training stops (the
    /// best epoch's network is kept); 0 trains all `steps`.
    #[serde(default)]
    pub patience: usize,
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            steps: 120,
            steps_per_epoch: 10,
            batch: 8,
            lr: 1e-3,
            seed: 0,
            use_distance_loss: true,
            local_window: 6,
            local_fraction: 0.5,
            time_limit_s: None,
            patience: 2,
        }
    }
}

impl TrainOptions {
    /// Checks ranges; the error names the field.
    pub fn validate(&self) -> Result<(), VideoError> {
        let bad = |m: String| Err(VideoError::Invalid(format!("RSFNet training: {m}")));
        if self.batch == 0 || self.steps_per_epoch == 0 {
            return bad(format!(
                "batch ({}) and steps_per_epoch ({}) must be at least 1",
                self.batch, self.steps_per_epoch
            ));
        }
        if !(self.lr > 0.0 && self.lr.is_finite()) {
            return bad(format!("lr must be positive, got {}", self.lr));
        }
        if !(0.0..=1.0).contains(&self.local_fraction) {
            return bad(format!("local_fraction must be in [0, 1], got {}", self.local_fraction));
        }
        if self.local_window == 0 {
            return bad("local_window must be at least 1".into());
        }
        Ok(())
    }

    /// Epochs of the shared loop: `ceil(steps / steps_per_epoch)`.
    pub fn epochs(&self) -> usize {
        self.steps.div_ceil(self.steps_per_epoch)
    }
}

/// What a training run did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainSummary {
    /// Whether the network was trained (false for the "w/o L_d" ablation).
    pub trained: bool,
    /// Optimiser steps taken.
    pub steps: usize,
    /// Wall-clock seconds of training (building the network and the loop).
    pub seconds: f64,
    /// Mean distance loss of each epoch.
    pub loss_history: Vec<f64>,
    /// Share of [`EVAL_TRIPLETS`] held-out-seed triplets whose PSNR order (Eq. 6) the latent
    /// distances reproduce, with the initial weights…
    pub agreement_before: f64,
    /// …and with the final ones (the best epoch's, with early stopping).
    pub agreement_after: f64,
    /// Validation agreement after each epoch (the early-stopping signal; its own held-out set).
    #[serde(default)]
    pub val_agreement: Vec<f64>,
    /// The epoch whose network was kept (0-based; the last one without early stopping).
    #[serde(default)]
    pub best_epoch: usize,
}

/// Triplets drawn (from their own seed stream) to measure [`TrainSummary::agreement_after`].
pub const EVAL_TRIPLETS: usize = 512;
/// Seed stream of the evaluation triplets.
const EVAL_STREAM: u64 = 0xE7A1;
/// Seed stream of the validation triplets of early stopping.
const VAL_STREAM: u64 = 0x7A11;
/// Draws per triplet before giving up on a clip whose frames all tie.
const MAX_DRAWS: usize = 32;

/// Draws labelled triplets from a clip (see the module docs).
#[derive(Debug, Clone)]
pub struct TripletSampler<'a> {
    planes: &'a [Planes],
    window: usize,
    local_fraction: f64,
}

impl<'a> TripletSampler<'a> {
    pub fn new(planes: &'a [Planes], opts: &TrainOptions) -> TripletSampler<'a> {
        TripletSampler { planes, window: opts.local_window, local_fraction: opts.local_fraction }
    }

    /// A frame other than `a`: inside `a ± window` when `local`, anywhere otherwise.
    fn other(&self, rng: &mut impl Rng, a: usize, local: bool) -> usize {
        let n = self.planes.len();
        let (lo, hi) = if local { (a.saturating_sub(self.window), (a + self.window).min(n - 1)) } else { (0, n - 1) };
        // Draw from [lo, hi] without a: one fewer slot, shifted past a.
        let k = rng.random_range(lo..hi);
        if k >= a {
            k + 1
        } else {
            k
        }
    }

    /// One triplet and its label, or `None` when `MAX_DRAWS` draws all tied.
    pub fn draw(&self, rng: &mut impl Rng) -> Option<(Triplet, f32)> {
        let n = self.planes.len();
        for _ in 0..MAX_DRAWS {
            let a = rng.random_range(0..n);
            let local = rng.random_bool(self.local_fraction);
            let (p, q) = (self.other(rng, a, local), self.other(rng, a, local));
            if p == q {
                continue;
            }
            let label = triplet_label(psnr(&self.planes[a], &self.planes[p]), psnr(&self.planes[a], &self.planes[q]));
            if let Some(z) = label {
                return Some(((a, p, q), z));
            }
        }
        None
    }

    /// Up to `count` triplets (fewer only for a clip whose frames all tie).
    pub fn draw_many(&self, rng: &mut impl Rng, count: usize) -> Vec<(Triplet, f32)> {
        (0..count).filter_map(|_| self.draw(rng)).collect()
    }
}

/// Share of labelled triplets whose order the embeddings reproduce (`z = 1` ⇔ `‖r_a − r_p‖ <
/// ‖r_a − r_n‖`); 0 for none.
pub fn agreement(embeddings: &[Vec<f32>], triplets: &[(Triplet, f32)]) -> f64 {
    let right = triplets
        .iter()
        .filter(|((a, p, n), z)| {
            let closer_p = euclidean(&embeddings[*a], &embeddings[*p]) < euclidean(&embeddings[*a], &embeddings[*n]);
            closer_p == (*z == 1.0)
        })
        .count();
    right as f64 / triplets.len().max(1) as f64
}

/// Distance loss on triplets drawn from each step's seed, reporting to a [`Progress`], with
/// early stopping on the validation agreement.
struct TripletObjective<'a> {
    sampler: TripletSampler<'a>,
    batch: usize,
    side: usize,
    device: Device,
    progress: &'a Progress,
    cfg: &'a RsfConfig,
    val: Vec<(Triplet, f32)>,
    patience: usize,
    val_history: Vec<f64>,
    /// Best validation agreement so far, its epoch and network.
    best: Option<(f64, usize, Embedder)>,
    /// Once cancelled, the remaining steps are skipped and the epoch ends the loop.
    cancel: &'a Cancel,
}

impl TripletObjective<'_> {
    fn batch_loss(&self, model: &RsfNet, triplets: &[(Triplet, f32)]) -> Tensor<1> {
        let b = triplets.len();
        let order: Vec<usize> =
            [0, 1, 2].iter().flat_map(|&k| triplets.iter().map(move |((a, p, n), _)| [*a, *p, *n][k])).collect();
        let x = batch_tensor(self.sampler.planes, &order, self.side, &self.device);
        let r = model.forward(x);
        let z: Vec<f32> = triplets.iter().map(|(_, z)| *z).collect();
        let z = Tensor::from_data(TensorData::new(z, [b]), &self.device);
        distance_loss(r.clone().narrow(0, 0, b), r.clone().narrow(0, b, b), r.narrow(0, 2 * b, b), z)
    }
}

impl Objective<RsfNet> for TripletObjective<'_> {
    fn loss(&mut self, model: &RsfNet, step: &Step) -> Option<Tensor<1>> {
        if self.cancel.is_cancelled() {
            return None;
        }
        let mut rng = inbetween_core::seed::rng(step.seed);
        let triplets = self.sampler.draw_many(&mut rng, self.batch);
        (!triplets.is_empty()).then(|| self.batch_loss(model, &triplets))
    }

    fn after_step(&mut self, _: &RsfNet, _: &Step, loss: Option<f64>) {
        self.progress.inc(1);
        if let Some(l) = loss {
            self.progress.set_message(format!("loss {l:.4}"));
        }
    }

    fn after_epoch(&mut self, model: &RsfNet, end: &EpochEnd) -> Control {
        if self.cancel.is_cancelled() {
            return Control::Stop;
        }
        let embedder = Embedder::new(model.clone(), self.cfg.clone());
        let a = agreement(&embedder.embed_planes(self.sampler.planes), &self.val);
        self.val_history.push(a);
        if self.best.as_ref().is_none_or(|(b, _, _)| a > *b) {
            self.best = Some((a, end.epoch, embedder));
        }
        let best_epoch = self.best.as_ref().map_or(end.epoch, |(_, e, _)| *e);
        if self.patience > 0 && end.epoch >= best_epoch + self.patience {
            Control::Stop
        } else {
            Control::Continue
        }
    }
}

/// The images RSFNet sees for each frame (resized in parallel).
pub fn clip_planes(frames: &[RgbImage], side: u32) -> Vec<Planes> {
    frames.par_iter().map(|f| frame_planes(f, side as usize)).collect()
}

/// Trains RSFNet on the frames of one clip (see the module docs) and returns it ready for
/// inference, with a summary. Needs at least 3 frames.
pub fn train_rsfnet(
    frames: &[RgbImage],
    cfg: &RsfConfig,
    opts: &TrainOptions,
    progress: &Progress,
) -> Result<(Embedder, TrainSummary), VideoError> {
    let planes = clip_planes(frames, cfg.input_side);
    train_on_planes(&planes, cfg, opts, progress)
}

/// [`train_rsfnet`] on frames already resized by [`clip_planes`].
pub fn train_on_planes(
    planes: &[Planes],
    cfg: &RsfConfig,
    opts: &TrainOptions,
    progress: &Progress,
) -> Result<(Embedder, TrainSummary), VideoError> {
    train_on_planes_with(planes, cfg, opts, progress, &Cancel::new())
}

/// [`train_on_planes`] that stops with [`VideoError::Cancelled`] once `cancel` is cancelled
/// (checked before every training step and after every epoch).
pub fn train_on_planes_with(
    planes: &[Planes],
    cfg: &RsfConfig,
    opts: &TrainOptions,
    progress: &Progress,
    cancel: &Cancel,
) -> Result<(Embedder, TrainSummary), VideoError> {
    cfg.validate()?;
    opts.validate()?;
    cancel.check()?;
    if planes.len() < 3 {
        return Err(VideoError::Invalid(format!("RSFNet training needs at least 3 frames, got {}", planes.len())));
    }
    let sampler = TripletSampler::new(planes, opts);
    let eval = sampler
        .draw_many(&mut inbetween_core::seed::rng(inbetween_core::seed::derive(opts.seed, EVAL_STREAM)), EVAL_TRIPLETS);
    let initial = Embedder::new(backend::seeded_module(&backend::cpu(), opts.seed, |d| cfg.init(d)), cfg.clone());
    let agreement_before = agreement(&initial.embed_planes(planes), &eval);
    // A clip whose frames all tie (a still shot) has no triplet to learn from: nothing to train.
    if !opts.use_distance_loss || opts.steps == 0 || eval.is_empty() {
        let summary = TrainSummary {
            trained: false,
            steps: 0,
            seconds: 0.0,
            loss_history: Vec::new(),
            agreement_before,
            agreement_after: agreement_before,
            val_agreement: Vec::new(),
            best_epoch: 0,
        };
        return Ok((initial, summary));
    }
    let started = Instant::now();
    let device = backend::cpu_autodiff();
    let loop_config = TrainConfig {
        epochs: opts.epochs(),
        steps_per_epoch: opts.steps_per_epoch,
        lr: opts.lr,
        seed: opts.seed,
        time_limit_s: opts.time_limit_s,
        progress: false,
        ..TrainConfig::default()
    };
    progress.phase((loop_config.epochs * loop_config.steps_per_epoch) as u64, "RSFNet");
    let val = sampler
        .draw_many(&mut inbetween_core::seed::rng(inbetween_core::seed::derive(opts.seed, VAL_STREAM)), EVAL_TRIPLETS);
    let mut objective = TripletObjective {
        sampler,
        batch: opts.batch,
        side: cfg.input_side as usize,
        device: device.clone(),
        progress,
        cfg,
        val,
        patience: opts.patience,
        val_history: Vec::new(),
        best: None,
        cancel,
    };
    let run = fit_with(&loop_config, &device, |d| cfg.init(d), &mut objective)?;
    cancel.check()?;
    let last_epoch = run.loss_history.len().saturating_sub(1);
    let (best_epoch, embedder) = match objective.best.take() {
        Some((_, epoch, e)) => (epoch, e),
        None => (last_epoch, Embedder::new(run.model, cfg.clone())),
    };
    let agreement_after = agreement(&embedder.embed_planes(planes), &eval);
    let summary = TrainSummary {
        trained: true,
        steps: run.optimizer_steps as usize,
        seconds: started.elapsed().as_secs_f64(),
        loss_history: run.loss_history,
        agreement_before,
        agreement_after,
        val_agreement: objective.val_history,
        best_epoch,
    };
    Ok((embedder, summary))
}
