//! DQN training (§4.2, Algorithm 1) on the shared training loop ([`inbetween_nn::train::fit_with`]).
//!
//! Episodes start from the two end keys and add one key per step up to `max_keys`; one episode is
//! one epoch of the loop and one environment step one step of it. Actions are ε-greedy;
//! transitions go to the replay memory; every `train_every` environment steps one minibatch updates
//! the main network towards `y = r + γ · max_a' Q_target(s', a')` (Eq. 23; 0 after the last step)
//! under the Huber loss, and every `target_every` updates the target network copies the main one.
//! Actions that are already keys are never chosen (their Q-values are masked). The Huber loss
//! compares Q and y both divided by E(s)/E(s₀) (see [`super::model`]), so the small rewards of late
//! steps are learnt as precisely as the large early ones.
//!
//! Every random choice of a step draws from that step's seed, and the replay memory, the episode
//! in progress and the target and acting networks are the objective's checkpointed state, so a
//! run stopped and resumed from `checkpoint_dir` is bit-identical to one that never stopped.

use super::env::{EnvWindow, INPUTS};
use super::model::{DqnConfig, QNet};
use super::policy::{best_action, q_values, PolicyInfo, SidqlPolicy};
use super::replay::{Replay, Transition};
use crate::error::SegmentModel;
use crate::representation::SphericalMotion;
use crate::{MocapError, Result};
use burn::module::Module;
use burn::nn::loss::{HuberLoss, HuberLossConfig, Reduction};
use burn::tensor::{Device, Int, Tensor, TensorData};
use inbetween_nn::burn;
use inbetween_nn::checkpoint::{load_module_bytes, module_bytes};
use inbetween_nn::train::{fit_with, Control, EpochEnd, Objective as TrainObjective, Step, TrainConfig};
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Hyper-parameters. [`TrainOptions::paper`] holds §5.2's values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Write the trained policy here at the end (weights + card).
    pub checkpoint: Option<PathBuf>,
    /// Checkpoint the whole training state every this many episodes (needs `checkpoint_dir`).
    pub checkpoint_every: usize,
    /// Folder for resumable training checkpoints; a run finding one there continues from it.
    #[serde(default)]
    pub checkpoint_dir: Option<PathBuf>,
    /// Stop (resumably) after the episode during which this many seconds have passed.
    #[serde(default)]
    pub time_limit_s: Option<f64>,
    pub progress: bool,
    /// What the policy was trained on, in words; written in the weights card.
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
            checkpoint_dir: None,
            time_limit_s: None,
            progress: true,
            data: String::new(),
        }
    }

    /// A short run for smoke tests and quick looks: 300 episodes at batch 64, the rest as the paper.
    pub fn quick() -> TrainOptions {
        TrainOptions { batch: 64, episodes: 300, ..TrainOptions::paper() }
    }

    /// The shared loop's settings: an epoch per episode, a step per key added.
    fn loop_config(&self) -> TrainConfig {
        TrainConfig {
            epochs: self.episodes,
            steps_per_epoch: self.max_keys - 2,
            lr: self.lr,
            lr_decay: 1.0,
            lr_decay_from: 0,
            seed: self.seed,
            checkpoint_every: self.checkpoint_every,
            checkpoint_dir: self.checkpoint_dir.clone(),
            grad_clip_norm: None,
            time_limit_s: self.time_limit_s,
            progress: self.progress,
        }
    }
}

/// What a run did.
#[derive(Clone, Debug)]
pub struct TrainReport {
    /// Episodes done (fewer than asked when the time limit stopped the run).
    pub episodes: usize,
    pub updates: usize,
    /// Mean Huber loss per block of 50 episodes.
    pub loss_curve: Vec<f64>,
    /// Mean episode return (final ε of the episode) per block of 50 episodes.
    pub return_curve: Vec<f64>,
    /// Seconds of training over every sitting of the run.
    pub seconds: f64,
    /// The checkpoint the run resumed from, if any.
    pub resumed_from: Option<PathBuf>,
}

/// Episodes per point of the loss and return curves.
const CURVE_BLOCK: usize = 50;

/// The episode in progress.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Episode {
    window: usize,
    mask: u64,
    err_bits: u64,
}

/// Everything the objective carries between steps; saved with each checkpoint. Floats are kept
/// as bit patterns so the state round-trips exactly through JSON.
#[derive(Debug, Default, Serialize, Deserialize)]
struct DqnState {
    episode: Option<Episode>,
    env_steps: usize,
    updates: usize,
    loss_sum_bits: u64,
    loss_n: usize,
    ret_sum_bits: u64,
    loss_curve_bits: Vec<u64>,
    return_curve_bits: Vec<u64>,
    replay: Replay,
    target: Vec<u8>,
    acting: Vec<u8>,
}

/// The SIDQL objective: environment, replay memory, target and acting networks.
struct Dqn<'a> {
    env: &'a [EnvWindow],
    config: &'a DqnConfig,
    opts: &'a TrainOptions,
    ad: Device,
    plain: Device,
    huber: HuberLoss,
    scratch: crate::error::Scratch,
    state_buf: Vec<f32>,
    s: DqnState,
    /// The target network (Eq. 23) and the copy that picks ε-greedy actions, on the plain device.
    nets: Option<(QNet, QNet)>,
}

fn f(bits: u64) -> f64 {
    f64::from_bits(bits)
}

impl<'a> Dqn<'a> {
    fn new(env: &'a [EnvWindow], config: &'a DqnConfig, opts: &'a TrainOptions) -> Dqn<'a> {
        // Windows may come from different skeletons; the widest one's buffers serve them all.
        let scratch = env.iter().max_by_key(|w| w.rep.num_joints).map(|w| w.rep.scratch()).unwrap_or_default();
        Dqn {
            env,
            config,
            opts,
            ad: inbetween_nn::backend::cpu_autodiff(),
            plain: inbetween_nn::backend::cpu(),
            huber: HuberLossConfig::new(1.0).init(),
            scratch,
            state_buf: Vec::new(),
            s: DqnState { replay: Replay::new(opts.memory), ..DqnState::default() },
            nets: None,
        }
    }

    fn epsilon(&self, episode: usize) -> f64 {
        let span = (self.opts.episodes as f64 * self.opts.eps_decay).max(1.0);
        let t = (episode as f64 / span).min(1.0);
        self.opts.eps_start + (self.opts.eps_end - self.opts.eps_start) * t
    }

    /// One ε-greedy environment step; the transition goes to the replay memory.
    fn act(&mut self, step: &Step, rng: &mut impl Rng) {
        let steps_per_episode = self.opts.max_keys - 2;
        let ep = match self.s.episode {
            Some(ep) if step.step > 0 => ep,
            _ => {
                let window = rng.random_range(0..self.env.len());
                Episode { window, mask: self.env[window].initial_mask(), err_bits: self.env[window].e0.to_bits() }
            }
        };
        let w = &self.env[ep.window];
        let frames = w.frames();
        let action = if rng.random::<f64>() < self.epsilon(step.epoch) {
            let free: Vec<usize> = (0..frames).filter(|&f| ep.mask >> f & 1 == 0).collect();
            free[rng.random_range(0..free.len())]
        } else {
            self.state_buf.clear();
            w.state(ep.mask, &mut self.scratch, &mut self.state_buf);
            let acting = &self.nets.as_ref().expect("networks set before acting").1;
            best_action(&q_values(acting, &self.state_buf, 1, frames, &self.plain), ep.mask, frames)
        };
        let next = ep.mask | 1 << action;
        let mut errs = vec![0.0; frames];
        let next_err = w.frame_errors(next, &mut self.scratch, &mut errs);
        let reward = w.reward(f(ep.err_bits), next_err);
        self.s.ret_sum_bits = (f(self.s.ret_sum_bits) + reward as f64).to_bits();
        self.s.replay.push(Transition {
            window: ep.window,
            mask: ep.mask,
            action,
            reward,
            next_mask: next,
            done: step.step + 1 == steps_per_episode,
        });
        self.s.episode = Some(Episode { window: ep.window, mask: next, err_bits: next_err.to_bits() });
        self.s.env_steps += 1;
    }

    /// The Huber loss of one minibatch (Eq. 23 targets) on the main network.
    fn minibatch_loss(&mut self, main: &QNet, batch: &[Transition]) -> Tensor<1> {
        let frames = self.env[batch[0].window].frames();
        let b = batch.len();
        let input = frames * INPUTS;
        let (mut states, mut nexts) = (Vec::with_capacity(b * input), Vec::with_capacity(b * input));
        let mut scales = Vec::with_capacity(b);
        for t in batch {
            let w = &self.env[t.window];
            scales.push((w.state(t.mask, &mut self.scratch, &mut states) / w.e0.max(1e-12)).max(1e-6) as f32);
            w.state(t.next_mask, &mut self.scratch, &mut nexts);
        }
        let target = &self.nets.as_ref().expect("networks set before learning").0;
        let q_next = q_values(target, &nexts, b, frames, &self.plain);
        let gamma = self.opts.gamma as f32;
        let y: Vec<f32> = batch
            .iter()
            .enumerate()
            .map(|(i, t)| {
                if t.done {
                    return t.reward;
                }
                let row = &q_next[i * frames..(i + 1) * frames];
                t.reward + gamma * row[best_action(row, t.next_mask, frames)]
            })
            .zip(&scales)
            .map(|(y, scale)| y / scale)
            .collect();
        let x = Tensor::<3>::from_data(TensorData::new(states, [b, frames, INPUTS]), &self.ad);
        let actions = Tensor::<2, Int>::from_data(
            TensorData::new(batch.iter().map(|t| t.action as i64).collect::<Vec<_>>(), [b, 1]),
            &self.ad,
        );
        // Both sides divided by E(s)/E(s₀) (see `QNet::forward_unscaled`).
        let q = main.forward_unscaled(x).gather(1, actions);
        let y = Tensor::<2>::from_data(TensorData::new(y, [b, 1]), &self.ad);
        self.huber.forward(q, y, Reduction::Mean).reshape([1])
    }

    fn curves(&self) -> (Vec<f64>, Vec<f64>) {
        (self.s.loss_curve_bits.iter().map(|&b| f(b)).collect(), self.s.return_curve_bits.iter().map(|&b| f(b)).collect())
    }
}

impl TrainObjective<QNet> for Dqn<'_> {
    fn loss(&mut self, main: &QNet, step: &Step) -> Option<Tensor<1>> {
        if self.nets.is_none() {
            self.nets = Some((main.valid(), main.valid()));
        }
        let mut rng = inbetween_core::seed::rng(step.seed);
        self.act(step, &mut rng);
        let ready = self.s.replay.len() >= self.opts.batch && self.s.env_steps.is_multiple_of(self.opts.train_every.max(1));
        if !ready {
            return None;
        }
        let batch = self.s.replay.sample(self.opts.batch, &mut rng);
        Some(self.minibatch_loss(main, &batch))
    }

    fn after_step(&mut self, main: &QNet, _step: &Step, loss: Option<f64>) {
        let Some(loss) = loss else { return };
        self.s.loss_sum_bits = (f(self.s.loss_sum_bits) + loss).to_bits();
        self.s.loss_n += 1;
        self.s.updates += 1;
        let nets = self.nets.as_mut().expect("networks set before learning");
        if self.s.updates.is_multiple_of(self.opts.target_every.max(1)) {
            nets.0 = main.valid();
        }
        if self.s.updates.is_multiple_of(10) {
            nets.1 = main.valid();
        }
    }

    fn after_epoch(&mut self, _main: &QNet, end: &EpochEnd) -> Control {
        let done = end.epoch + 1;
        if done.is_multiple_of(CURVE_BLOCK) || done == self.opts.episodes {
            let loss = if self.s.loss_n > 0 { f(self.s.loss_sum_bits) / self.s.loss_n as f64 } else { f64::NAN };
            self.s.loss_curve_bits.push(loss.to_bits());
            self.s.return_curve_bits.push((f(self.s.ret_sum_bits) / CURVE_BLOCK as f64).to_bits());
            (self.s.loss_sum_bits, self.s.loss_n, self.s.ret_sum_bits) = (0, 0, 0);
        }
        Control::Continue
    }

    fn state(&self) -> std::result::Result<Vec<u8>, String> {
        let origin = Path::new("dqn-state");
        let (target, acting) = match &self.nets {
            Some((t, a)) => (module_bytes(t, origin).map_err(|e| e.to_string())?, module_bytes(a, origin).map_err(|e| e.to_string())?),
            None => (Vec::new(), Vec::new()),
        };
        let state = DqnState { target, acting, replay: self.s.replay.clone(), ..self.s.clone_counters() };
        serde_json::to_vec(&state).map_err(|e| e.to_string())
    }

    fn restore(&mut self, bytes: &[u8]) -> std::result::Result<(), String> {
        let mut state: DqnState = serde_json::from_slice(bytes).map_err(|e| e.to_string())?;
        if !state.target.is_empty() {
            let origin = Path::new("dqn-state");
            let load = |b: &[u8]| load_module_bytes(self.config.init(&self.plain), b.to_vec(), origin).map_err(|e| e.to_string());
            self.nets = Some((load(&state.target)?, load(&state.acting)?));
        }
        (state.target, state.acting) = (Vec::new(), Vec::new());
        self.s = state;
        Ok(())
    }
}

impl DqnState {
    /// Everything but the replay memory and the networks.
    fn clone_counters(&self) -> DqnState {
        DqnState {
            episode: self.episode,
            env_steps: self.env_steps,
            updates: self.updates,
            loss_sum_bits: self.loss_sum_bits,
            loss_n: self.loss_n,
            ret_sum_bits: self.ret_sum_bits,
            loss_curve_bits: self.loss_curve_bits.clone(),
            return_curve_bits: self.return_curve_bits.clone(),
            ..DqnState::default()
        }
    }
}

fn check_inputs(windows: &[SphericalMotion], config: &DqnConfig, opts: &TrainOptions) -> Result<()> {
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
    Ok(())
}

/// Trains a policy on `windows` (all of one length, ≤ 64 frames; any skeleton), resuming from
/// `opts.checkpoint_dir` when it holds a checkpoint, and writes it to `opts.checkpoint` if set.
pub fn train(windows: &[SphericalMotion], config: &DqnConfig, opts: &TrainOptions) -> Result<(SidqlPolicy, TrainReport)> {
    check_inputs(windows, config, opts)?;
    let env: Vec<EnvWindow> = windows.iter().map(|r| EnvWindow::new(r.clone())).collect::<Result<_>>()?;
    let mut dqn = Dqn::new(&env, config, opts);
    let ad = dqn.ad.clone();
    let run = fit_with(&opts.loop_config(), &ad, |d| config.init(d), &mut dqn)?;
    let (loss_curve, return_curve) = dqn.curves();
    let episodes = run.loss_history.len();
    let report = TrainReport { episodes, updates: dqn.s.updates, loss_curve, return_curve, seconds: run.seconds, resumed_from: run.resumed_from };
    let info = PolicyInfo {
        config: config.clone(),
        trained_on: opts.data.clone(),
        episodes,
        updates: report.updates,
        seconds: report.seconds,
        options: Some(TrainOptions { checkpoint: None, checkpoint_dir: None, data: String::new(), ..opts.clone() }),
    };
    let policy = SidqlPolicy::new(info, run.model.valid());
    if let Some(path) = &opts.checkpoint {
        policy.save(path)?;
    }
    Ok((policy, report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::representation::JointFilter;
    use inbetween_core::procedural::gait_library;
    use inbetween_core::KeyframeSet;

    /// Tiny windows so the tests stay fast: 12 frames, 23 joints.
    fn windows() -> Vec<SphericalMotion> {
        gait_library(3, 4, 12, 30.0).iter().map(|m| SphericalMotion::from_motion(&JointFilter::paper().apply(m)).unwrap()).collect()
    }

    fn small() -> DqnConfig {
        DqnConfig { hidden: [32, 32, 16], ..DqnConfig::default() }
    }

    #[test]
    fn a_short_run_trains_selects_and_round_trips_through_its_weights_file() {
        let reps = windows();
        let opts = TrainOptions { episodes: 150, max_keys: 5, batch: 16, progress: false, ..TrainOptions::paper() };
        let (policy, report) = train(&reps, &small(), &opts).unwrap();
        assert_eq!(report.episodes, 150);
        assert!(report.updates > 100, "{} updates", report.updates);
        assert_eq!(report.loss_curve.len(), 3);
        assert!(report.loss_curve.iter().all(|l| l.is_finite()), "{:?}", report.loss_curve);
        let keys = policy.select(&reps[0], 4).unwrap();
        assert_eq!(keys.len(), 4);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sidql.bpk");
        policy.save(&path).unwrap();
        let loaded = SidqlPolicy::load(&path).unwrap();
        assert_eq!(loaded.select(&reps[0], 4).unwrap(), keys);
        assert_eq!(loaded.info, policy.info);
        // Its keys beat uniform keys on the windows it trained on, at the K it was trained for
        // (max_keys = 5).
        let mean = |f: &dyn Fn(&SphericalMotion) -> KeyframeSet| reps.iter().map(|r| r.error(&f(r)).mean_angle).sum::<f64>() / reps.len() as f64;
        let sidql = mean(&|r| policy.select(r, 5).unwrap());
        let uniform = mean(&|r| crate::select::uniform(r.num_frames, 5).unwrap());
        assert!(sidql < uniform, "SIDQL {sidql:.5} vs uniform {uniform:.5} at K=5");
    }

    #[test]
    fn a_stopped_run_resumes_bit_identically() {
        let reps = windows();
        let base = TrainOptions { episodes: 40, max_keys: 5, batch: 8, memory: 64, target_every: 7, checkpoint_every: 15, progress: false, ..TrainOptions::paper() };
        let straight_dir = tempfile::tempdir().unwrap();
        let split_dir = tempfile::tempdir().unwrap();
        let straight_opts = TrainOptions { checkpoint_dir: Some(straight_dir.path().into()), ..base.clone() };
        let (straight, straight_report) = train(&reps, &small(), &straight_opts).unwrap();
        // The same run stopped by a time limit after each of its first five episodes (updates start
        // in the third), resumed every time, then run to the end.
        for sitting in 1..=5 {
            let short = TrainOptions { time_limit_s: Some(1e-9), checkpoint_dir: Some(split_dir.path().into()), ..base.clone() };
            let (_, r) = train(&reps, &small(), &short).unwrap();
            assert_eq!(r.episodes, sitting);
        }
        let rest = TrainOptions { checkpoint_dir: Some(split_dir.path().into()), ..base.clone() };
        let (resumed, report) = train(&reps, &small(), &rest).unwrap();
        assert!(report.resumed_from.is_some());
        assert_eq!(report.updates, straight_report.updates);
        assert_eq!(report.loss_curve.iter().map(|l| l.to_bits()).collect::<Vec<_>>(), straight_report.loss_curve.iter().map(|l| l.to_bits()).collect::<Vec<_>>());
        // Same weights: bit-identical Q-values on states of every window (the files differ only
        // in burn's random parameter ids).
        let frames = reps[0].num_frames;
        let mut states = Vec::new();
        for r in &reps {
            let w = EnvWindow::new(r.clone()).unwrap();
            w.state(w.initial_mask() | 0b1000, &mut r.scratch(), &mut states);
        }
        let bits = |p: &SidqlPolicy| p.q_values(&states, reps.len(), frames).iter().map(|q| q.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&resumed), bits(&straight), "weights differ after resume");
    }
}
