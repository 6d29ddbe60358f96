//! SIDQL's training hyper-parameters: shared by training ([`super::train`]), which uses them, and
//! the runtime policy ([`super::policy`]), whose weights card records them; neither module imports
//! the other for them.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Hyper-parameters of both stages. [`TrainOptions::default`] is what the committed policy used.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainOptions {
    /// K of each episode is drawn uniformly from `min_keys..=max_keys`.
    pub min_keys: usize,
    pub max_keys: usize,
    /// Pretraining: gradient steps (0 skips the stage), episodes advanced together (states per
    /// step), learning rate (Adam).
    pub pretrain_steps: usize,
    pub pretrain_batch: usize,
    pub pretrain_lr: f64,
    /// Fine-tuning: epochs of `max_keys − 2` environment steps each (0 skips the stage).
    pub episodes: usize,
    pub lr: f64,
    /// Discount factor γ (Eq. 23).
    pub gamma: f64,
    /// Replay memory size.
    pub memory: usize,
    pub batch: usize,
    /// Environment steps per gradient step.
    pub train_every: usize,
    /// Gradient steps between target-network renewals.
    pub target_every: usize,
    pub eps_start: f64,
    pub eps_end: f64,
    /// Fraction of the fine-tuning epochs over which ε decays linearly.
    pub eps_decay: f64,
    pub seed: u64,
    /// Write the trained policy here at the end (weights + card); the pretrained one beside it as
    /// `<stem>.pretrain.bpk`.
    pub checkpoint: Option<PathBuf>,
    /// Checkpoint each stage's whole state every this many epochs (needs `checkpoint_dir`).
    pub checkpoint_every: usize,
    /// Folder for resumable checkpoints (`pretrain/`, `finetune/`); a run finding them continues.
    #[serde(default)]
    pub checkpoint_dir: Option<PathBuf>,
    /// Each stage stops (resumably) after the epoch during which this many seconds have passed.
    #[serde(default)]
    pub time_limit_s: Option<f64>,
    pub progress: bool,
    /// What the policy was trained on, in words; written in the weights card.
    #[serde(default)]
    pub data: String,
}

impl Default for TrainOptions {
    /// K in 3..=16; no pretraining (the network starts as greedy by exact gain, see
    /// [`super::model`]; pretraining on cost-to-go made every held-out k-fold worse, at learning
    /// rates 0.002 to 0.0001, so it is opt-in: 3000 steps of 32 states at lr 0.002 when asked);
    /// 150 fine-tuning epochs with §5.2's memory (10 000), target renewal (100 updates) and batch
    /// (here 64), lr 0.000003 (0.0001 lost to uniform keys held out; 0.00001 and 400 epochs
    /// drifted further below the greedy start), γ = 1.
    fn default() -> TrainOptions {
        TrainOptions {
            min_keys: 3,
            max_keys: 16,
            pretrain_steps: 0,
            pretrain_batch: 32,
            pretrain_lr: 0.002,
            episodes: 150,
            lr: 3e-6,
            gamma: 1.0,
            memory: 10_000,
            batch: 64,
            train_every: 1,
            target_every: 100,
            eps_start: 0.2,
            eps_end: 0.02,
            eps_decay: 0.6,
            seed: 0,
            checkpoint: None,
            checkpoint_every: 100,
            checkpoint_dir: None,
            time_limit_s: None,
            progress: true,
            data: String::new(),
        }
    }
}

impl TrainOptions {
    /// The paper's DQN alone (§5.2 / §5.3: lr 0.01, γ = 0.5, memory 10 000, batch 256, target
    /// renewed every 100 updates, 2000 episodes, ε from 1), without pretraining.
    pub fn paper() -> TrainOptions {
        TrainOptions {
            pretrain_steps: 0,
            episodes: 2000,
            lr: 0.01,
            gamma: 0.5,
            batch: 256,
            eps_start: 1.0,
            eps_end: 0.05,
            ..TrainOptions::default()
        }
    }

    /// A short run for smoke tests and quick looks.
    pub fn quick() -> TrainOptions {
        TrainOptions { pretrain_steps: 600, episodes: 40, ..TrainOptions::default() }
    }

    /// A preset by name: `default`, `paper` or `quick` (None for any other name).
    pub fn preset(name: &str) -> Option<TrainOptions> {
        match name {
            "default" => Some(TrainOptions::default()),
            "quick" => Some(TrainOptions::quick()),
            "paper" => Some(TrainOptions::paper()),
            _ => None,
        }
    }

    /// The preset `name` ([`TrainOptions::preset`]) with the values given in place of its own
    /// (what `mocap train` runs); an unknown name is an error naming the presets.
    pub fn preset_with(
        name: &str,
        pretrain_steps: Option<usize>,
        episodes: Option<usize>,
        lr: Option<f64>,
        gamma: Option<f64>,
    ) -> crate::Result<TrainOptions> {
        let base = TrainOptions::preset(name).ok_or_else(|| {
            crate::MocapError::Invalid(format!("unknown preset '{name}'; expected default, paper or quick"))
        })?;
        Ok(TrainOptions {
            pretrain_steps: pretrain_steps.unwrap_or(base.pretrain_steps),
            episodes: episodes.unwrap_or(base.episodes),
            lr: lr.unwrap_or(base.lr),
            gamma: gamma.unwrap_or(base.gamma),
            ..base
        })
    }
}

/// Where `mocap train` and a bench that trains write the policy by default.
pub const DEFAULT_POLICY_PATH: &str = "out/sidql_cmu.bpk";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_preset_takes_the_values_given_and_an_unknown_one_is_named() {
        let p = TrainOptions::preset_with("paper", None, Some(5), None, Some(0.9)).unwrap();
        assert_eq!((p.episodes, p.gamma, p.lr, p.batch), (5, 0.9, 0.01, 256));
        assert_eq!(TrainOptions::preset_with("quick", None, None, None, None).unwrap(), TrainOptions::quick());
        let e = TrainOptions::preset_with("fast", None, None, None, None).unwrap_err().to_string();
        assert!(e.contains("unknown preset 'fast'; expected default, paper or quick"), "{e}");
    }
}
