//! [`TrainJob`]: `inbetween mocap train` as a job. SIDQL's training windows ([`crate::protocol`]),
//! both stages of [`super::train()`] with resumable checkpoints beside the policy file, and a report
//! of what each stage did.

use std::fmt;
use std::path::PathBuf;

use inbetween_core::cancel::Cancel;
use inbetween_core::units::LengthUnit;
use inbetween_io::Progress;
use serde::Serialize;

use super::{DqnConfig, TrainOptions, TrainReport, DEFAULT_POLICY_PATH};
use crate::protocol::{training_set, TrainingData};
use crate::{MocapError, Result};

/// Train the SIDQL policy and write it (weights + card; the pretrained stage beside it).
#[derive(Clone, Debug)]
pub struct TrainJob {
    /// Which windows: the CMU training split (default), every CMU take, or procedural gaits.
    pub data: TrainingData,
    /// The corpus folder (default: the shared data).
    pub data_dir: Option<PathBuf>,
    /// Length unit of the clips (default: the corpus's known units, else inferred per clip).
    pub unit: Option<LengthUnit>,
    /// Stride of the training windows, frames.
    pub stride: usize,
    /// Both stages' hyper-parameters ([`TrainOptions::default`]: the committed policy's). The
    /// checkpoints, the output and the data description are set by [`TrainJob::run`].
    pub options: TrainOptions,
    /// The policy file (burnpack; its card beside it as `.json`).
    pub output: PathBuf,
}

impl Default for TrainJob {
    fn default() -> Self {
        TrainJob {
            data: TrainingData::CmuSplit,
            data_dir: None,
            unit: None,
            stride: 10,
            options: TrainOptions::default(),
            output: PathBuf::from(DEFAULT_POLICY_PATH),
        }
    }
}

/// What a training run did and wrote.
#[derive(Clone, Debug, Serialize)]
pub struct TrainJobReport {
    /// The windows trained on, in words (also in the policy's card).
    pub data: String,
    pub train: TrainReport,
    pub output: PathBuf,
    /// The resumable state of both stages.
    pub checkpoint_dir: PathBuf,
    /// The pretrained stage's policy, when fine-tuning ran after it.
    pub pretrained: Option<PathBuf>,
}

impl TrainJob {
    /// Checks the window stride before loading any data.
    pub fn validate(&self) -> Result<()> {
        if self.stride == 0 {
            return Err(MocapError::Invalid("stride must be at least 1 frame".into()));
        }
        Ok(())
    }

    /// Loads the windows, trains both stages (each resumes from `<output>.ckpt/` and stops, resumably,
    /// at `options.time_limit_s`) and writes the policy. `cancel` is checked before training starts.
    pub fn run(&self, cancel: &Cancel, _progress: &Progress) -> Result<TrainJobReport> {
        self.validate()?;
        let (windows, data) =
            training_set(self.data, self.data_dir.as_deref(), self.unit, self.options.seed, self.stride)?;
        if let Some(dir) = self.output.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|source| MocapError::Io { path: dir.display().to_string(), source })?;
        }
        cancel.check()?;
        let checkpoint_dir = self.output.with_extension("ckpt");
        let opts = TrainOptions {
            checkpoint: Some(self.output.clone()),
            checkpoint_dir: Some(checkpoint_dir.clone()),
            data: data.clone(),
            ..self.options.clone()
        };
        let trained = super::train(&windows, &DqnConfig::default(), &opts)?;
        let pretrained = trained.finetuned.is_some().then(|| super::train::pretrain_path(&self.output));
        Ok(TrainJobReport { data, train: trained.report, output: self.output.clone(), checkpoint_dir, pretrained })
    }
}

impl fmt::Display for TrainJobReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = &self.train;
        writeln!(f, "training on {}", self.data)?;
        if let Some(from) = &r.resumed_from {
            writeln!(f, "resumed from {}", from.display())?;
        }
        if r.stopped_early {
            writeln!(
                f,
                "stopped at the time limit; run the same command again to resume from {}",
                self.checkpoint_dir.display()
            )?;
        }
        let list = |v: &[f64], digits: usize| v.iter().map(|l| format!("{l:.digits$}")).collect::<Vec<_>>();
        writeln!(
            f,
            "pretraining: {} steps in {:.0} s; loss per {} steps {:?}",
            r.pretrain_steps,
            r.pretrain_seconds,
            r.pretrain_block,
            list(&r.pretrain_loss, 4)
        )?;
        writeln!(
            f,
            "fine-tuning: {} epochs, {} updates in {:.0} s; loss per {} epochs {:?}; return per episode {:?}",
            r.episodes,
            r.updates,
            r.finetune_seconds,
            r.curve_block,
            list(&r.loss_curve, 4),
            list(&r.return_curve, 3)
        )?;
        write!(f, "wrote {}", self.output.display())?;
        if let Some(p) = &self.pretrained {
            write!(f, "\nwrote {} (pretrained stage)", p.display())?;
        }
        Ok(())
    }
}
