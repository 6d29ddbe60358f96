//! The GAN objective of §3.3 on the shared training loop ([`inbetween_nn::train::fit_with`]).
//!
//! The loop trains the generator; the critic belongs to the objective, with its own Adam (lr 1e-3,
//! the paper's, constant). Every step:
//! 1. draw a batch from the step's seed ([`super::data`]) and run the generator with a dropout mask
//!    drawn from the same seed;
//! 2. update the critic `n_critic` times on hinge + WGAN-GP ([`super::losses::critic_loss`]), the
//!    first time on this batch's (detached) generation, later times on fresh batches;
//! 3. return the generator's loss ([`super::losses::generator_loss`]) against the updated critic.
//!
//! No random number comes from the device's global generator (batches, dropout and ε all derive from
//! the step seed), and the critic's weights, its optimiser state and the loss statistics are the
//! objective's checkpointed state: a run stopped and resumed is bit-identical to one that never
//! stopped.

use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::tensor::{Bytes, Device, Tensor};
use inbetween_core::seed::{derive, rng};
use inbetween_io::Progress;
use inbetween_nn::burn;
use inbetween_nn::checkpoint::{load_module_bytes, module_bytes};
use inbetween_nn::train::{Control, EpochEnd, Objective, Step};
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::path::Path;

use super::data::{sample_batch_from, Batch, ClipPool, SamplerConfig};
use super::losses::{critic_input, critic_loss, generator_loss, recompose, DistanceMap};
use super::FaceTrainConfig;
use crate::model::critic::{Critic, CriticConfig};
use crate::model::generator::{dropout_mask, Generator};

/// Random streams of a step (`derive(step.seed, stream + 16·critic_iteration)`).
const STREAM_BATCH: u64 = 1;
const STREAM_DROPOUT: u64 = 2;
const STREAM_EPSILON: u64 = 3;
/// Stream of the critic's initial weights (from the run seed).
const STREAM_CRITIC_INIT: u64 = 0xC417;

/// Mean losses of one epoch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EpochLosses {
    /// The generator's total loss.
    pub generator: f64,
    /// `L_rec`.
    pub rec: f64,
    /// `L_dist`.
    pub dist: f64,
    /// `L_adv` (−mean critic score of the generated windows).
    pub adv: f64,
    /// The critic's hinge loss (last critic update of each step).
    pub critic_hinge: f64,
    /// The critic's gradient penalty, before λ_gp.
    pub critic_gp: f64,
}

const TERMS: usize = 6;

impl EpochLosses {
    fn from_array(a: [f64; TERMS]) -> EpochLosses {
        EpochLosses { generator: a[0], rec: a[1], dist: a[2], adv: a[3], critic_hinge: a[4], critic_gp: a[5] }
    }
}

/// Statistics that travel with checkpoints, as bit patterns (exact through JSON).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Stats {
    critic_updates: u64,
    sums: [u64; TERMS],
    count: u64,
    epochs: Vec<[u64; TERMS]>,
}

impl Stats {
    fn add(&mut self, terms: [f64; TERMS]) {
        for (s, t) in self.sums.iter_mut().zip(terms) {
            *s = (f64::from_bits(*s) + t).to_bits();
        }
        self.count += 1;
    }

    fn close_epoch(&mut self) -> EpochLosses {
        let n = self.count.max(1) as f64;
        let means = self.sums.map(|s| if self.count == 0 { f64::NAN } else { f64::from_bits(s) / n });
        self.epochs.push(means.map(f64::to_bits));
        (self.sums, self.count) = ([0; TERMS], 0);
        EpochLosses::from_array(means)
    }

    fn history(&self) -> Vec<EpochLosses> {
        self.epochs.iter().map(|e| EpochLosses::from_array(e.map(f64::from_bits))).collect()
    }
}

/// The GAN objective (module docs).
pub(crate) struct GanObjective<'a> {
    cfg: &'a FaceTrainConfig,
    pool: &'a ClipPool,
    usable: Vec<usize>,
    sampler: SamplerConfig,
    device: Device,
    dist: DistanceMap,
    critic: Option<Critic>,
    critic_optim: ModuleOptimizer,
    critic_config: CriticConfig,
    stats: Stats,
    progress: &'a Progress,
    /// Checked before every step (`Objective::check_cancel`).
    pub(crate) cancel: inbetween_core::cancel::Cancel,
}

fn scalar(t: Tensor<1>) -> f64 {
    f64::from(t.into_scalar::<f32>())
}

impl<'a> GanObjective<'a> {
    pub(crate) fn new(
        cfg: &'a FaceTrainConfig,
        pool: &'a ClipPool,
        device: &Device,
        progress: &'a Progress,
    ) -> Result<GanObjective<'a>, String> {
        let usable = pool.usable(cfg.kind, cfg.window)?;
        let critic_config = CriticConfig::new(cfg.window);
        let critic = inbetween_nn::backend::seeded_module(device, derive(cfg.seed, STREAM_CRITIC_INIT), |d| {
            critic_config.init(d)
        });
        Ok(GanObjective {
            cfg,
            pool,
            usable,
            sampler: cfg.sampler(),
            device: device.clone(),
            dist: DistanceMap::new(device),
            critic: Some(critic),
            critic_optim: AdamConfig::new().init(),
            critic_config,
            stats: Stats::default(),
            progress,
            cancel: inbetween_core::cancel::Cancel::new(),
        })
    }

    /// Mean losses of every finished epoch (including those before a resume).
    pub(crate) fn history(&self) -> Vec<EpochLosses> {
        self.stats.history()
    }

    fn batch(&self, seed: u64) -> Batch {
        sample_batch_from(self.pool, &self.usable, &self.sampler, seed).to_device(&self.device)
    }

    /// The generator on `batch` with dropout drawn from `seed`.
    fn generate(&self, generator: &Generator, batch: &Batch, seed: u64) -> Tensor<3> {
        let shape = [self.cfg.batch, self.cfg.window, 2 * generator.d_hidden()];
        let keep = dropout_mask(&mut rng(seed), shape, self.cfg.dropout, &self.device);
        generator.forward_dropped(&batch.inputs, keep)
    }

    /// One critic update on `real` and `fake` critic inputs; returns (hinge, penalty).
    fn critic_update(&mut self, real: Tensor<3>, fake: Tensor<3>, epsilon_seed: u64) -> (f64, f64) {
        let mut r = rng(epsilon_seed);
        let epsilon: Vec<f32> = (0..self.cfg.batch).map(|_| r.random::<f32>()).collect();
        let critic = self.critic.take().expect("the critic is always put back");
        let weights = critic.weights();
        let loss = critic_loss(&critic, &weights, real, fake, &epsilon, &self.cfg.lambdas);
        let (hinge, gp) = (scalar(loss.hinge), scalar(loss.gp));
        let grads = GradientsParams::from_grads(loss.total.backward(), &critic);
        self.critic = Some(self.critic_optim.step(self.cfg.critic_lr, critic, grads));
        self.stats.critic_updates += 1;
        (hinge, gp)
    }
}

impl Objective<Generator> for GanObjective<'_> {
    fn loss(&mut self, generator: &Generator, step: &Step) -> Option<Tensor<1>> {
        let stream = |s: u64, i: usize| derive(step.seed, s + 16 * i as u64);
        let batch = self.batch(stream(STREAM_BATCH, 0));
        let generated = self.generate(generator, &batch, stream(STREAM_DROPOUT, 0));
        let (mut hinge, mut gp) = (f64::NAN, f64::NAN);
        for i in 0..self.cfg.n_critic.max(1) {
            let (target, fake_anim, mask) = if i == 0 {
                (batch.target.clone(), generated.clone().detach(), batch.mask.clone())
            } else {
                let extra = self.batch(stream(STREAM_BATCH, i));
                let g = self.generate(generator, &extra, stream(STREAM_DROPOUT, i)).detach();
                (extra.target, g, extra.mask)
            };
            let real = critic_input(target.clone(), &self.dist);
            let fake = critic_input(recompose(target, fake_anim, mask), &self.dist).detach();
            (hinge, gp) = self.critic_update(real, fake, stream(STREAM_EPSILON, i));
        }
        let critic = self.critic.as_ref().expect("the critic is always put back");
        let weights = critic.weights();
        let loss = generator_loss(critic, &weights, generated, batch.target, batch.mask, &self.dist, &self.cfg.lambdas);
        let terms = [scalar(loss.total.clone()), scalar(loss.rec), scalar(loss.dist), scalar(loss.adv), hinge, gp];
        self.stats.add(terms);
        Some(loss.total)
    }

    fn check_cancel(&self) -> Result<(), inbetween_core::cancel::Cancelled> {
        self.cancel.check()
    }

    fn after_step(&mut self, _: &Generator, step: &Step, loss: Option<f64>) {
        let done = step.epoch * self.cfg.steps_per_epoch + step.step + 1;
        self.progress.set_position(done as u64);
        if let Some(l) = loss {
            self.progress.set_message(format!("epoch {} loss {l:.4}", step.epoch + 1));
        }
    }

    fn after_epoch(&mut self, _: &Generator, end: &EpochEnd) -> Control {
        let e = self.stats.close_epoch();
        self.progress.set_message(format!(
            "epoch {}: G {:.4} (rec {:.4} dist {:.4} adv {:.3}) D hinge {:.3} gp {:.3}",
            end.epoch + 1,
            e.generator,
            e.rec,
            e.dist,
            e.adv,
            e.critic_hinge,
            e.critic_gp
        ));
        Control::Continue
    }

    fn state(&self) -> Result<Vec<u8>, String> {
        let origin = Path::new("face-critic");
        let critic = self.critic.as_ref().ok_or("no critic")?;
        let critic = module_bytes(critic, origin).map_err(|e| e.to_string())?;
        let optim = self.critic_optim.into_bytes().map_err(|e| format!("critic optimiser: {e}"))?;
        let stats = serde_json::to_vec(&self.stats).map_err(|e| e.to_string())?;
        let mut out = Vec::with_capacity(critic.len() + optim.len() + stats.len() + 32);
        out.extend_from_slice(STATE_MAGIC);
        for part in [&critic[..], &optim[..], &stats[..]] {
            out.extend_from_slice(&(part.len() as u64).to_le_bytes());
            out.extend_from_slice(part);
        }
        Ok(out)
    }

    fn restore(&mut self, state: &[u8]) -> Result<(), String> {
        let rest = state.strip_prefix(STATE_MAGIC).ok_or("not a face GAN training state")?;
        let (critic, rest) = take_part(rest)?;
        let (optim, rest) = take_part(rest)?;
        let (stats, rest) = take_part(rest)?;
        if !rest.is_empty() {
            return Err(format!("{} trailing bytes after the training state", rest.len()));
        }
        let fresh = self.critic_config.init(&self.device);
        let critic = load_module_bytes(fresh, critic.to_vec(), Path::new("face-critic")).map_err(|e| e.to_string())?;
        // The optimiser state is keyed by parameter ids, which the critic record restored.
        let optim = AdamConfig::new()
            .init()
            .from_bytes(Bytes::from_bytes_vec(optim.to_vec()))
            .map_err(|e| format!("critic optimiser: {e}"))?;
        self.stats = serde_json::from_slice(stats).map_err(|e| format!("training statistics: {e}"))?;
        self.critic = Some(critic);
        self.critic_optim = optim;
        Ok(())
    }
}

const STATE_MAGIC: &[u8] = b"inbetween-face-gan-1\n";

fn take_part(bytes: &[u8]) -> Result<(&[u8], &[u8]), String> {
    let (len, rest) = bytes.split_first_chunk::<8>().ok_or("truncated training state")?;
    let len = usize::try_from(u64::from_le_bytes(*len)).map_err(|_| "corrupt training state")?;
    if rest.len() < len {
        return Err(format!("truncated training state: a part of {len} bytes, {} left", rest.len()));
    }
    Ok(rest.split_at(len))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn train_state_parts_are_length_prefixed_and_truncation_is_caught() {
        let mut bytes = Vec::new();
        for part in [&b"abc"[..], &b""[..]] {
            bytes.extend_from_slice(&(part.len() as u64).to_le_bytes());
            bytes.extend_from_slice(part);
        }
        let (a, rest) = take_part(&bytes).unwrap();
        let (b, rest) = take_part(rest).unwrap();
        assert_eq!((a, b, rest.len()), (&b"abc"[..], &b""[..], 0));
        assert!(take_part(&bytes[..5]).unwrap_err().contains("truncated"));
        assert!(take_part(&bytes[..10]).unwrap_err().contains("3 bytes"));
    }

    #[test]
    fn train_stats_means_are_per_epoch() {
        let mut s = Stats::default();
        s.add([1.0; TERMS]);
        s.add([3.0; TERMS]);
        assert_eq!(s.close_epoch().rec, 2.0);
        assert!(s.close_epoch().rec.is_nan(), "an epoch without steps");
        assert_eq!(s.history().len(), 2);
    }
    /// The critic, its power-iteration vectors and its optimiser come back exactly: the next step of
    /// a restored objective equals that of the original, bit for bit.
    #[test]
    fn train_objective_state_restores_the_critic_exactly() {
        use crate::edit::ConstraintKind;
        use crate::train::{ClipPool, FaceTrainConfig, TrainClip};
        let frames = (0..40).map(|f| std::array::from_fn(|c| 0.5 + 0.4 * ((f + c) as f32 * 0.2).sin())).collect();
        let pool = ClipPool::new(vec![TrainClip { frames, visemes: None }], "sines");
        let cfg = FaceTrainConfig { window: 16, batch: 4, d_hidden: 8, ..FaceTrainConfig::new(ConstraintKind::None) };
        let device = inbetween_nn::backend::cpu_autodiff();
        let progress = Progress::hidden();
        let g = inbetween_nn::backend::seeded_module(&device, 1, |d| cfg.generator().init(d));
        let mut a = GanObjective::new(&cfg, &pool, &device, &progress).unwrap();
        for s in 0..3 {
            let _ = a.loss(&g, &Step { epoch: 0, step: s, seed: 100 + s as u64 });
        }
        a.stats.close_epoch();
        let mut b = GanObjective::new(&cfg, &pool, &device, &progress).unwrap();
        b.restore(&a.state().unwrap()).unwrap();
        let u = |o: &GanObjective| {
            o.critic.as_ref().unwrap().convs[2].spectral.u.value_sync().into_data().try_to_vec::<f32>().unwrap()
        };
        let w = |o: &GanObjective| {
            o.critic.as_ref().unwrap().convs[0].weight.val().into_data().try_to_vec::<f32>().unwrap()
        };
        assert_eq!(w(&a), w(&b));
        assert_eq!(u(&a), u(&b));
        assert_eq!(a.history(), b.history());
        assert_eq!(b.stats.critic_updates, 3);
        let step = Step { epoch: 1, step: 0, seed: 7 };
        let la = a.loss(&g, &step).unwrap().into_scalar::<f32>();
        let lb = b.loss(&g, &step).unwrap().into_scalar::<f32>();
        assert_eq!(la.to_bits(), lb.to_bits());
        assert_eq!(w(&a), w(&b), "the optimiser's moments came back too");
        assert!(b.restore(b"garbage").unwrap_err().contains("not a face GAN"));
    }
}
