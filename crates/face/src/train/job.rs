//! [`TrainJob`]: `inbetween face train` as a job. One network per constraint kind (§3.3) on the
//! procedural clips or on the real captures' training split ([`crate::data::split`]), each resumable
//! from its own checkpoint folder; every network's weights and card appear together at the end, or
//! none.

use std::path::{Path, PathBuf};

use inbetween_core::cancel::Cancel;
use inbetween_io::{OutputSet, Progress};
use serde::Serialize;

use super::{save_face_weights, train_face_cancellable, FaceTrainConfig, TrainError};
use crate::corpus;
use crate::data::FaceError;
use crate::edit::ConstraintKind;
use crate::infer::plan::captures_dir;
use crate::weights;

/// The clips the networks train on.
#[derive(Debug, Clone, PartialEq)]
pub enum TrainData {
    /// `clips` procedural clips of [`TrainJob::PROCEDURAL_CLIP_S`] each (exact viseme labels; the
    /// committed weights are trained on them).
    Procedural { clips: usize },
    /// The training split of the Live Link captures under `captures` (default: the shared data's
    /// `face/neurosync`). They have no phoneme labels, so the viseme network is skipped.
    Real { captures: Option<PathBuf> },
}

/// Train face networks and write each as `<out>/<kind>.bpk` with its card.
#[derive(Debug, Clone)]
pub struct TrainJob {
    /// The networks to train, in order.
    pub kinds: Vec<ConstraintKind>,
    pub data: TrainData,
    /// Output folder (`<kind>.bpk` + `<kind>.json` per network).
    pub out: PathBuf,
    /// Allow `out` to be the committed weights folder.
    pub overwrite_committed: bool,
    /// Checkpoint folder (one subfolder per network); training resumes from it.
    pub checkpoints: PathBuf,
    pub epochs: usize,
    pub steps_per_epoch: usize,
    pub batch: usize,
    /// Frames per training window at 25 fps.
    pub window: usize,
    /// Hidden units per direction (paper: 128).
    pub d_hidden: usize,
    pub seed: u64,
    /// Seconds per network (the running epoch is finished and saved).
    pub time_limit_s: Option<f64>,
}

impl Default for TrainJob {
    fn default() -> Self {
        let paper = FaceTrainConfig::new(ConstraintKind::None);
        TrainJob {
            kinds: ConstraintKind::ALL.to_vec(),
            data: TrainData::Procedural { clips: Self::PROCEDURAL_CLIPS },
            out: PathBuf::from("out/face"),
            overwrite_committed: false,
            checkpoints: PathBuf::from("out/face-train"),
            epochs: 40,
            steps_per_epoch: 25,
            batch: paper.batch,
            window: paper.window,
            d_hidden: paper.d_hidden,
            seed: paper.seed,
            time_limit_s: None,
        }
    }
}

/// One trained network.
#[derive(Debug, Clone, Serialize)]
pub struct TrainedNetwork {
    pub kind: &'static str,
    pub steps: u64,
    pub seconds: f64,
    pub final_generator_loss: f64,
    pub final_reconstruction_loss: f64,
    pub weights: PathBuf,
}

/// What a training run did.
#[derive(Debug, Clone, Serialize)]
pub struct TrainReport {
    /// Networks not trained, and why.
    pub skipped: Vec<String>,
    pub networks: Vec<TrainedNetwork>,
}

impl std::fmt::Display for TrainReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut lines = self.skipped.to_vec();
        lines.extend(self.networks.iter().map(|n| {
            format!(
                "{}: {} steps in {:.1} min, final generator loss {:.4} (reconstruction {:.4}); weights {}",
                n.kind,
                n.steps,
                n.seconds / 60.0,
                n.final_generator_loss,
                n.final_reconstruction_loss,
                n.weights.display()
            )
        }));
        write!(f, "{}", lines.join("\n"))
    }
}

impl TrainJob {
    /// Seconds of each procedural training clip.
    pub const PROCEDURAL_CLIP_S: f64 = 20.0;
    /// Procedural clips unless told otherwise.
    pub const PROCEDURAL_CLIPS: usize = 64;

    /// Parses a list of kinds: `all`, or names separated by commas.
    pub fn parse_kinds(arg: &str) -> Result<Vec<ConstraintKind>, String> {
        if arg == "all" {
            return Ok(ConstraintKind::ALL.to_vec());
        }
        arg.split(',')
            .map(|k| {
                ConstraintKind::from_name(k.trim())
                    .ok_or_else(|| format!("unknown network kind '{k}' (unguided, keyframes, noisy, visemes or all)"))
            })
            .collect()
    }

    /// Refuses the committed weights folder (unless `overwrite_committed`) before training, not after.
    pub fn validate(&self) -> Result<(), FaceError> {
        for k in &self.kinds {
            weights::check_output(&self.out.join(weights::committed_file(*k)), self.overwrite_committed)?;
        }
        Ok(())
    }

    /// The training settings of the network of `kind`.
    pub fn config(&self, kind: ConstraintKind) -> FaceTrainConfig {
        FaceTrainConfig {
            epochs: self.epochs,
            steps_per_epoch: self.steps_per_epoch,
            batch: self.batch,
            window: self.window,
            d_hidden: self.d_hidden,
            seed: self.seed,
            time_limit_s: self.time_limit_s,
            checkpoint_dir: Some(self.checkpoints.join(kind.name())),
            ..FaceTrainConfig::new(kind)
        }
    }

    /// Trains every network in turn (a progress phase each), then moves all the weights into place.
    pub fn run(&self, cancel: &Cancel, progress: &Progress) -> Result<TrainReport, TrainError> {
        self.validate()?;
        let pool = match &self.data {
            TrainData::Procedural { clips } => corpus::procedural_pool(*clips, Self::PROCEDURAL_CLIP_S, self.seed)?,
            TrainData::Real { captures } => corpus::real_pool(&captures_dir(captures.as_deref())?)?,
        };
        let device = inbetween_nn::backend::cpu_autodiff();
        let io = |path: &Path| {
            let file = path.display().to_string();
            move |source| TrainError::Data(FaceError::Io { file, source })
        };
        let mut set = OutputSet::new();
        let mut report = TrainReport { skipped: Vec::new(), networks: Vec::new() };
        for &kind in &self.kinds {
            if matches!(self.data, TrainData::Real { .. }) && kind == ConstraintKind::Visemes {
                report.skipped.push("visemes: skipped, the real captures have no phoneme labels".into());
                continue;
            }
            let cfg = self.config(kind);
            progress.phase((cfg.epochs * cfg.steps_per_epoch) as u64, &format!("train {}", kind.name()));
            let trained = train_face_cancellable(&cfg, &pool, progress, &device, cancel)?;
            let out = self.out.join(weights::committed_file(kind));
            let staged = set.file(&out).map_err(io(&out))?;
            set.file(&out.with_extension("json")).map_err(io(&out))?;
            save_face_weights(&trained, &staged)?;
            let f = trained.final_losses();
            report.networks.push(TrainedNetwork {
                kind: kind.name(),
                steps: trained.steps,
                seconds: trained.seconds,
                final_generator_loss: f.generator,
                final_reconstruction_loss: f.rec,
                weights: out,
            });
        }
        progress.finish();
        set.commit().map_err(io(&self.out))?;
        Ok(report)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_parse_by_name_or_all_and_unknown_names_are_refused() {
        assert_eq!(TrainJob::parse_kinds("all").unwrap(), ConstraintKind::ALL.to_vec());
        assert_eq!(
            TrainJob::parse_kinds("noisy, keyframes").unwrap(),
            vec![ConstraintKind::Noisy, ConstraintKind::Keyframes]
        );
        let e = TrainJob::parse_kinds("noisy,lips").unwrap_err();
        assert!(e.contains("'lips'") && e.contains("visemes or all"), "{e}");
    }

    #[test]
    fn the_committed_folder_is_refused_before_training() {
        let job = TrainJob { out: weights::committed_dir(), kinds: vec![ConstraintKind::Noisy], ..TrainJob::default() };
        assert!(job.validate().is_err());
        assert!(TrainJob { overwrite_committed: true, ..job }.validate().is_ok());
    }
}
