//! [`TrainJob`]: `inbetween camera train` as a job. The extractor, generator and mapping are trained
//! end to end on the synthetic dataset ([`crate::train`], §5 of the paper), resumable from a
//! checkpoint folder; the weights and their card appear together at the end, or neither.

use std::path::{Path, PathBuf};

use inbetween_core::cancel::Cancel;
use inbetween_io::{OutputSet, Progress};
use serde::Serialize;

use crate::train::{self, TrainConfig, TrainEvent, TrainSummary};
use crate::{weights, CameraError};

/// Train the camera networks and write the weights with their card.
#[derive(Debug, Clone)]
pub struct TrainJob {
    /// Seed, dataset size, epochs, batch, learning rate and widths ([`TrainConfig::default`] holds
    /// the engine's values).
    pub config: TrainConfig,
    /// Where the weights go (burnpack; the JSON card with the style codes beside it).
    pub out: PathBuf,
    /// Allow `out` inside the committed weights folder (replacing the committed weights on purpose).
    pub overwrite_committed: bool,
    /// Checkpoint folder: saved every epoch, and training resumes from it when it holds one.
    pub checkpoints: PathBuf,
    /// When resuming, restart the learning-rate schedule at `config.lr` instead of where it had
    /// decayed to.
    pub restart_lr: bool,
}

impl Default for TrainJob {
    fn default() -> Self {
        TrainJob {
            config: TrainConfig::default(),
            out: PathBuf::from(Self::DEFAULT_OUT),
            overwrite_committed: false,
            checkpoints: PathBuf::from(Self::DEFAULT_CHECKPOINTS),
            restart_lr: false,
        }
    }
}

/// What a training run did and where its weights went.
#[derive(Debug, Clone, Serialize)]
pub struct TrainReport {
    pub summary: TrainSummary,
    /// The weights file (its card is beside it, `.json`).
    pub weights: PathBuf,
}

impl std::fmt::Display for TrainReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = &self.summary;
        write!(
            f,
            "trained {} epochs ({} iterations) in {:.1} min, final loss {:.4}; weights: {}",
            s.epochs_done,
            s.iterations,
            s.seconds / 60.0,
            s.final_loss,
            self.weights.display()
        )
    }
}

impl TrainJob {
    /// Where the weights go unless told otherwise.
    pub const DEFAULT_OUT: &'static str = "out/camera/camera.bpk";
    /// The checkpoint folder unless told otherwise.
    pub const DEFAULT_CHECKPOINTS: &'static str = "out/camera-train";

    /// Refuses the committed weights folder (unless `overwrite_committed`) before hours of training,
    /// not after.
    pub fn validate(&self) -> Result<(), CameraError> {
        weights::check_output(&self.out, self.overwrite_committed)
    }

    /// Trains (stopping at `config.time_limit_s` with the epoch finished and saved, or with an error
    /// when `cancel` fires), then writes the weights and their card together. The progress bar
    /// counts iterations and prints a line per epoch.
    pub fn run(&self, cancel: &Cancel, progress: &Progress) -> Result<TrainReport, CameraError> {
        self.validate()?;
        let mut cfg = self.config.clone();
        if self.restart_lr {
            cfg.lr_decay_from = train::epochs_done(&self.checkpoints)?;
        }
        progress.set_length((cfg.epochs * cfg.iters_per_epoch) as u64);
        let per_epoch = cfg.iters_per_epoch;
        let mut report = |e: TrainEvent| match e {
            TrainEvent::Iteration { epoch, iter, loss } => {
                progress.set_position((epoch * per_epoch + iter + 1) as u64);
                progress.set_message(format!("loss {loss:.4}"));
            }
            TrainEvent::Epoch { epoch, loss, lr, seconds } => {
                progress.println(format!("epoch {:>3}  loss {loss:.5}  lr {lr:.2e}  {seconds:.0} s", epoch + 1));
            }
        };
        let (model, summary) = train::train_cancellable(&cfg, Some(&self.checkpoints), &mut report, cancel)?;
        progress.finish();
        let mut set = OutputSet::new();
        let staged = set.file(&self.out).map_err(|e| io(&self.out, e))?;
        set.file(&self.out.with_extension("json")).map_err(|e| io(&self.out, e))?;
        weights::save(&model, &summary, &staged, self.overwrite_committed)?;
        set.commit().map_err(|e| io(&self.out, e))?;
        Ok(TrainReport { summary, weights: self.out.clone() })
    }
}

fn io(path: &Path, source: std::io::Error) -> CameraError {
    CameraError::Io { path: path.to_path_buf(), source }
}
