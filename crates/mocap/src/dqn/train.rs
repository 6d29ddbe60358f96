//! DQN training (§4.2, Algorithm 1) and the trained policy.
//!
//! Episodes start from the two end keys and add one key per step up to `max_keys`. Actions are
//! ε-greedy; transitions go to the replay memory; every `train_every` environment steps one
//! minibatch updates the main network towards `y = r + γ · max_a' Q_target(s', a')` (Eq. 23; 0 after
//! the last step) under the Huber loss, and every `target_every` updates the target network copies
//! the main one. Actions that are already keys are never chosen (their Q-values are masked). The
//! Huber loss compares Q and y both divided by E(s)/E(s₀) (see [`super::model`]), so the small
//! rewards of late steps are learnt as precisely as the large early ones.

use super::env::{EnvWindow, INPUTS};
use super::model::{DqnConfig, QNet};
use super::replay::{Replay, Transition};
use crate::error::SegmentModel;
use crate::representation::SphericalMotion;
use crate::{MocapError, Result};
use burn::module::Module;
use burn::nn::loss::{HuberLossConfig, Reduction};
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Int, Tensor, TensorData};
use inbetween_core::KeyframeSet;
use inbetween_nn::burn;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};

/// Hyper-parameters. [`TrainOptions::paper`] holds §5.2's values.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct TrainOptions {
    pub episodes: usize,
    /// Keys at the end of an episode (the largest K the policy is asked for).
    pub max_keys: usize,
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
    /// Fraction of the episodes over which ε decays linearly.
    pub eps_decay: f64,
    pub seed: u64,
    /// Save the policy here every `checkpoint_every` episodes and at the end.
    pub checkpoint: Option<PathBuf>,
    pub checkpoint_every: usize,
    pub progress: bool,
    /// What the policy was trained on, in words; written beside the weights.
    #[serde(default)]
    pub data: String,
}

impl TrainOptions {
    /// §5.2 / §5.3: learning rate 0.01, γ = 0.5, memory 10 000, batch 256, target renewed every 100
    /// updates. (The paper's "training interval" of 100–200 steps is read as gradient steps
    /// between target renewals; the text does not pin it down further.)
    pub fn paper() -> TrainOptions {
        TrainOptions {
            episodes: 2000,
            max_keys: 15,
            lr: 0.01,
            gamma: 0.5,
            memory: 10_000,
            batch: 256,
            train_every: 1,
            target_every: 100,
            eps_start: 1.0,
            eps_end: 0.05,
            eps_decay: 0.6,
            seed: 0,
            checkpoint: None,
            checkpoint_every: 200,
            progress: true,
            data: String::new(),
        }
    }

    /// A short run for smoke tests and quick looks: 300 episodes at batch 64, the rest as the paper.
    pub fn quick() -> TrainOptions {
        TrainOptions { batch: 64, episodes: 300, ..TrainOptions::paper() }
    }
}

/// What a run did.
#[derive(Clone, Debug)]
pub struct TrainReport {
    pub episodes: usize,
    pub updates: usize,
    /// Mean Huber loss per block of 50 episodes.
    pub loss_curve: Vec<f64>,
    /// Mean episode return (final ε of the episode) per block of 50 episodes.
    pub return_curve: Vec<f64>,
    pub seconds: f64,
}

/// What is written beside a policy's weights: the network shape and how it was trained.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PolicyInfo {
    pub config: DqnConfig,
    /// The training data, in words (clips, split, windows).
    pub trained_on: String,
    pub episodes: usize,
    pub updates: usize,
    pub seconds: f64,
    pub options: Option<TrainOptions>,
}

/// A trained SIDQL policy on the plain (inference) CPU device.
pub struct SidqlPolicy {
    pub info: PolicyInfo,
    net: QNet,
    device: Device,
}

fn model_err(e: impl std::fmt::Display) -> MocapError {
    MocapError::Model(e.to_string())
}

fn sidecar(path: &Path) -> PathBuf {
    path.with_extension("json")
}

impl SidqlPolicy {
    /// Writes the weights (`path`, burnpack) and [`PolicyInfo`] (`path` with `.json`).
    pub fn save(&self, path: &Path) -> Result<()> {
        inbetween_nn::checkpoint::save_module(&self.net, path).map_err(model_err)?;
        let json = serde_json::to_vec_pretty(&self.info).map_err(model_err)?;
        inbetween_io::write_atomic(&sidecar(path), &json)
            .map_err(|source| MocapError::Io { path: sidecar(path).display().to_string(), source })
    }

    /// Loads a policy saved by [`SidqlPolicy::save`].
    pub fn load(path: &Path) -> Result<SidqlPolicy> {
        let side = sidecar(path);
        let text =
            std::fs::read(&side).map_err(|source| MocapError::Io { path: side.display().to_string(), source })?;
        let info: PolicyInfo = serde_json::from_slice(&text).map_err(|e| {
            MocapError::Model(format!("{}: {e} (a policy written by an older version? retrain it)", side.display()))
        })?;
        let weights =
            std::fs::read(path).map_err(|source| MocapError::Io { path: path.display().to_string(), source })?;
        Self::from_info(info, weights, path)
    }

    /// The committed policy (`crates/mocap/weights/sidql.bpk`, trained by `inbetween mocap train
    /// --procedural` on our own gaits), compiled into the binary so the bench and the tools run from
    /// any folder.
    pub fn committed() -> Result<SidqlPolicy> {
        const WEIGHTS: &[u8] = include_bytes!("../../weights/sidql.bpk");
        const INFO: &[u8] = include_bytes!("../../weights/sidql.json");
        let origin = Path::new(env!("CARGO_MANIFEST_DIR")).join("weights/sidql.bpk");
        Self::from_bytes(WEIGHTS, INFO, &origin)
    }

    /// A policy from weights and [`PolicyInfo`] JSON already in memory; `origin` names them in errors.
    pub fn from_bytes(weights: &[u8], info_json: &[u8], origin: &Path) -> Result<SidqlPolicy> {
        let info: PolicyInfo = serde_json::from_slice(info_json)
            .map_err(|e| MocapError::Model(format!("{}: {e}", sidecar(origin).display())))?;
        Self::from_info(info, weights.to_vec(), origin)
    }

    fn from_info(info: PolicyInfo, weights: Vec<u8>, origin: &Path) -> Result<SidqlPolicy> {
        if info.config.inputs_per_frame != INPUTS {
            return Err(MocapError::Model(format!(
                "{}: the policy reads {} inputs per frame, this version builds {INPUTS}; retrain it",
                origin.display(),
                info.config.inputs_per_frame
            )));
        }
        let device = inbetween_nn::backend::cpu();
        let net = inbetween_nn::checkpoint::load_module_bytes(info.config.init(&device), weights, origin)
            .map_err(model_err)?;
        Ok(SidqlPolicy { info, net, device })
    }

    /// Chooses `k` keys for a window: starting from the end keys, repeatedly the frame with the
    /// highest Q-value among the non-keys.
    pub fn select(&self, rep: &SphericalMotion, k: usize) -> Result<KeyframeSet> {
        crate::select::check_k(rep.num_frames, k)?;
        if k <= 2 {
            return Ok(KeyframeSet::new(vec![0, rep.num_frames - 1], rep.num_frames)?);
        }
        let w = EnvWindow::new(rep.clone())?;
        let mut mask = w.initial_mask();
        let mut scratch = rep.scratch();
        let mut state = Vec::with_capacity(w.frames() * INPUTS);
        while (mask.count_ones() as usize) < k {
            state.clear();
            w.state(mask, &mut scratch, &mut state);
            let q = q_values(&self.net, &state, 1, w.frames(), &self.device);
            mask |= 1 << best_action(&q, mask, w.frames());
        }
        Ok(KeyframeSet::new((0..w.frames()).filter(|&f| mask >> f & 1 == 1).collect(), w.frames())?)
    }
}

fn q_values(net: &QNet, states: &[f32], batch: usize, frames: usize, device: &Device) -> Vec<f32> {
    let x = Tensor::<3>::from_data(TensorData::new(states.to_vec(), [batch, frames, INPUTS]), device);
    net.forward(x).into_data().try_to_vec::<f32>().expect("f32 Q-values")
}

/// The non-key frame with the highest Q-value.
fn best_action(q: &[f32], mask: u64, frames: usize) -> usize {
    (0..frames).filter(|&f| mask >> f & 1 == 0).max_by(|&a, &b| q[a].total_cmp(&q[b])).expect("a non-key frame remains")
}

/// Trains a policy on `windows` (all of one length, ≤ 64 frames; any skeleton).
pub fn train(
    windows: &[SphericalMotion],
    config: &DqnConfig,
    opts: &TrainOptions,
) -> Result<(SidqlPolicy, TrainReport)> {
    let Some(first) = windows.first() else {
        return Err(MocapError::Model("no training windows".into()));
    };
    let frames = first.num_frames;
    if let Some(w) = windows.iter().find(|w| w.num_frames != frames) {
        return Err(MocapError::Model(format!(
            "training windows must share one length: {frames} and {} frames",
            w.num_frames
        )));
    }
    if opts.max_keys < 3 || opts.max_keys > frames {
        return Err(MocapError::Model(format!("max_keys {} must lie in 3..={frames}", opts.max_keys)));
    }
    if config.inputs_per_frame != INPUTS {
        return Err(MocapError::Model(format!("the state has {INPUTS} inputs per frame, not {}", config.inputs_per_frame)));
    }
    let env: Vec<EnvWindow> = windows.iter().map(|r| EnvWindow::new(r.clone())).collect::<Result<_>>()?;
    let t0 = std::time::Instant::now();
    let ad = inbetween_nn::backend::cpu_autodiff();
    let plain = inbetween_nn::backend::cpu();
    let mut main = inbetween_nn::backend::seeded_module(&ad, opts.seed, |d| config.init(d));
    let mut target = main.valid();
    let mut acting = main.valid();
    let mut optim = AdamConfig::new().init();
    let huber = HuberLossConfig::new(1.0).init();
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    let mut replay = Replay::new(opts.memory);
    let input = frames * INPUTS;
    let steps_per_episode = opts.max_keys - 2;
    let bar = progress_bar(opts);
    // Windows may come from different skeletons; the widest one's buffers serve them all.
    let mut scratch = env.iter().max_by_key(|w| w.rep.num_joints).map(|w| w.rep.scratch()).unwrap_or_default();
    let (mut env_steps, mut updates) = (0usize, 0usize);
    let (mut loss_sum, mut loss_n, mut ret_sum) = (0.0, 0usize, 0.0);
    let mut report = TrainReport {
        episodes: opts.episodes,
        updates: 0,
        loss_curve: Vec::new(),
        return_curve: Vec::new(),
        seconds: 0.0,
    };
    let mut state = Vec::with_capacity(input);
    for episode in 0..opts.episodes {
        let eps = epsilon(opts, episode);
        let wi = rng.random_range(0..env.len());
        let w = &env[wi];
        let mut mask = w.initial_mask();
        let mut err = w.e0;
        for t in 0..steps_per_episode {
            let action = if rng.random::<f64>() < eps {
                let free: Vec<usize> = (0..w.frames()).filter(|&f| mask >> f & 1 == 0).collect();
                free[rng.random_range(0..free.len())]
            } else {
                state.clear();
                w.state(mask, &mut scratch, &mut state);
                best_action(&q_values(&acting, &state, 1, frames, &plain), mask, frames)
            };
            let next = mask | 1 << action;
            let mut errs = vec![0.0; w.frames()];
            let next_err = w.frame_errors(next, &mut scratch, &mut errs);
            let reward = w.reward(err, next_err);
            ret_sum += reward as f64;
            replay.push(Transition {
                window: wi,
                mask,
                action,
                reward,
                next_mask: next,
                done: t + 1 == steps_per_episode,
            });
            mask = next;
            err = next_err;
            env_steps += 1;
            if replay.len() >= opts.batch && env_steps % opts.train_every.max(1) == 0 {
                let batch = replay.sample(opts.batch, &mut rng);
                let (m, loss) =
                    update(main, &target, &mut optim, &huber, &env, &batch, opts, &ad, &plain, &mut scratch);
                main = m;
                loss_sum += loss;
                loss_n += 1;
                updates += 1;
                if updates % opts.target_every.max(1) == 0 {
                    target = main.valid();
                }
                if updates % 10 == 0 {
                    acting = main.valid();
                }
            }
        }
        if (episode + 1) % 50 == 0 || episode + 1 == opts.episodes {
            report.loss_curve.push(if loss_n > 0 { loss_sum / loss_n as f64 } else { f64::NAN });
            report.return_curve.push(ret_sum / 50.0);
            bar.set_message(format!(
                "loss {:.5} return {:.3} ε {eps:.2}",
                report.loss_curve.last().unwrap(),
                ret_sum / 50.0
            ));
            (loss_sum, loss_n, ret_sum) = (0.0, 0, 0.0);
        }
        if let Some(path) = &opts.checkpoint {
            if (episode + 1) % opts.checkpoint_every.max(1) == 0 {
                let info = policy_info(config, opts, episode + 1, updates, t0.elapsed().as_secs_f64());
                SidqlPolicy { info, net: main.valid(), device: plain.clone() }.save(path)?;
            }
        }
        bar.inc(1);
    }
    bar.finish();
    report.updates = updates;
    report.seconds = t0.elapsed().as_secs_f64();
    let info = policy_info(config, opts, opts.episodes, updates, report.seconds);
    let policy = SidqlPolicy { info, net: main.valid(), device: plain };
    if let Some(path) = &opts.checkpoint {
        policy.save(path)?;
    }
    Ok((policy, report))
}

fn policy_info(config: &DqnConfig, opts: &TrainOptions, episodes: usize, updates: usize, seconds: f64) -> PolicyInfo {
    PolicyInfo {
        config: config.clone(),
        trained_on: opts.data.clone(),
        episodes,
        updates,
        seconds,
        options: Some(TrainOptions { checkpoint: None, data: String::new(), ..opts.clone() }),
    }
}

fn epsilon(opts: &TrainOptions, episode: usize) -> f64 {
    let span = (opts.episodes as f64 * opts.eps_decay).max(1.0);
    let t = (episode as f64 / span).min(1.0);
    opts.eps_start + (opts.eps_end - opts.eps_start) * t
}

fn progress_bar(opts: &TrainOptions) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !opts.progress || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(opts.episodes as u64);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("SIDQL {bar:30} {pos}/{len} episodes, {elapsed} < {eta} {msg}")
    {
        bar.set_style(style);
    }
    bar
}

/// One minibatch step on the main network (Eq. 23 targets, Huber loss). Returns the loss.
#[allow(clippy::too_many_arguments)]
fn update(
    main: QNet,
    target: &QNet,
    optim: &mut burn::optim::ModuleOptimizer,
    huber: &burn::nn::loss::HuberLoss,
    env: &[EnvWindow],
    batch: &[Transition],
    opts: &TrainOptions,
    ad: &Device,
    plain: &Device,
    scratch: &mut crate::error::Scratch,
) -> (QNet, f64) {
    let frames = env[batch[0].window].frames();
    let input = frames * INPUTS;
    let b = batch.len();
    let (mut states, mut nexts) = (Vec::with_capacity(b * input), Vec::with_capacity(b * input));
    let mut scales = Vec::with_capacity(b);
    for t in batch {
        let w = &env[t.window];
        scales.push((w.state(t.mask, scratch, &mut states) / w.e0.max(1e-12)).max(1e-6) as f32);
        w.state(t.next_mask, scratch, &mut nexts);
    }
    let q_next = q_values(target, &nexts, b, frames, plain);
    let y: Vec<f32> = batch
        .iter()
        .enumerate()
        .map(|(i, t)| {
            if t.done {
                return t.reward;
            }
            let row = &q_next[i * frames..(i + 1) * frames];
            t.reward + opts.gamma as f32 * row[best_action(row, t.next_mask, frames)]
        })
        .zip(&scales)
        .map(|(y, scale)| y / scale)
        .collect();
    let x = Tensor::<3>::from_data(TensorData::new(states, [b, frames, INPUTS]), ad);
    let actions = Tensor::<2, Int>::from_data(
        TensorData::new(batch.iter().map(|t| t.action as i64).collect::<Vec<_>>(), [b, 1]),
        ad,
    );
    // Both sides divided by E(s)/E(s₀) (see `QNet::forward_unscaled`).
    let q = main.forward_unscaled(x).gather(1, actions);
    let y = Tensor::<2>::from_data(TensorData::new(y, [b, 1]), ad);
    let loss = huber.forward(q, y, Reduction::Mean);
    let value = f64::from(loss.clone().into_scalar::<f32>());
    let grads = GradientsParams::from_grads(loss.backward(), &main);
    (optim.step(opts.lr, main, grads), value)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::representation::JointFilter;
    use inbetween_core::procedural::gait_library;

    #[test]
    fn a_short_run_trains_selects_and_round_trips_through_a_checkpoint() {
        // Tiny windows and network so the test stays fast: 12 frames, 23 joints.
        let reps: Vec<SphericalMotion> = gait_library(3, 4, 12, 30.0)
            .iter()
            .map(|m| SphericalMotion::from_motion(&JointFilter::paper().apply(m)).unwrap())
            .collect();
        let config = DqnConfig { hidden: [32, 32, 16], ..DqnConfig::default() };
        let opts =
            TrainOptions { episodes: 150, max_keys: 5, batch: 16, progress: false, ..TrainOptions::paper() };
        let (policy, report) = train(&reps, &config, &opts).unwrap();
        assert!(report.updates > 100);
        assert!(report.loss_curve.iter().all(|l| l.is_finite()));
        let keys = policy.select(&reps[0], 4).unwrap();
        assert_eq!(keys.len(), 4);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sidql.bpk");
        policy.save(&path).unwrap();
        let loaded = SidqlPolicy::load(&path).unwrap();
        assert_eq!(loaded.select(&reps[0], 4).unwrap(), keys);
        assert!(SidqlPolicy::load(&dir.path().join("missing.bpk")).is_err());
        assert!(SidqlPolicy::from_bytes(b"not burnpack", b"{}", &path).is_err());
        // Its keys lower the error below the two-key start state.
        assert!(reps[0].error(&keys).mean_angle < reps[0].error(&KeyframeSet::new(vec![], 12).unwrap()).mean_angle);
    }

    #[test]
    fn committed_policy_serves_any_skeleton_and_window_length() {
        let policy = SidqlPolicy::committed().unwrap();
        assert!(policy.info.trained_on.contains("procedural"), "{}", policy.info.trained_on);
        let m = inbetween_core::procedural::gait(&inbetween_core::procedural::GaitParams {
            frames: 40,
            fps: 30.0,
            ..inbetween_core::procedural::GaitParams::walk()
        });
        // All 31 joints (the policy was trained on 23) and 40 frames (trained on 60).
        let rep = SphericalMotion::from_motion(&m).unwrap();
        let keys = policy.select(&rep, 6).unwrap();
        assert_eq!(keys.len(), 6);
        let two = KeyframeSet::new(vec![], 40).unwrap();
        assert!(rep.error(&keys).mean_angle < 0.5 * rep.error(&two).mean_angle);
    }
}
