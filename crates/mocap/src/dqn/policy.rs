//! A trained SIDQL policy (§4.1): inference only, no training code. Weights are saved and loaded
//! through the shared [`inbetween_nn::weights`] format (`sidql.bpk` + its `sidql.json` card, kind
//! [`POLICY_KIND`]).

use super::env::{EnvWindow, StateScratch, INPUTS};
use super::model::{DqnConfig, QBuffers, QNet, QRuntime};
use super::options::TrainOptions;
use crate::representation::SphericalMotion;
use crate::select::refine_keys;
use crate::{MocapError, Result};
use burn::tensor::{Device, Tensor, TensorData};
use inbetween_core::KeyframeSet;
use inbetween_nn::burn;
use inbetween_nn::weights::{self, Weights, WeightsCard};
use std::path::Path;

/// Kind and architecture version written in a policy's weights card.
pub const POLICY_KIND: &str = "mocap-sidql";
/// 2: rows carry the one-step gain and the budget left; 3: the network outputs a correction to
/// that gain (older policies are refused by name).
pub const POLICY_FORMAT: u32 = 3;

/// What a policy's card says: the network shape and how it was trained.
#[derive(Clone, Debug, PartialEq)]
pub struct PolicyInfo {
    pub config: DqnConfig,
    /// The training data, in words (clips, split, windows).
    pub trained_on: String,
    pub episodes: usize,
    pub updates: usize,
    pub seconds: f64,
    pub options: Option<TrainOptions>,
}

impl PolicyInfo {
    fn to_card(&self) -> Result<WeightsCard> {
        let json = |v: serde_json::Result<serde_json::Value>| v.map_err(|e| MocapError::Model(e.to_string()));
        let mut card =
            WeightsCard::new(POLICY_KIND, POLICY_FORMAT, json(serde_json::to_value(&self.config))?, &self.trained_on);
        card.training = json(serde_json::to_value(&self.options))?;
        card.metrics.insert("episodes".into(), self.episodes as f64);
        card.metrics.insert("updates".into(), self.updates as f64);
        card.metrics.insert("seconds".into(), self.seconds);
        Ok(card)
    }

    fn from_weights(w: &Weights) -> Result<PolicyInfo> {
        w.expect_kind(POLICY_KIND, POLICY_FORMAT)?;
        let card = w.card();
        let metric = |k: &str| card.metrics.get(k).copied().unwrap_or(0.0);
        Ok(PolicyInfo {
            config: w.config()?,
            trained_on: card.data.clone(),
            episodes: metric("episodes") as usize,
            updates: metric("updates") as usize,
            seconds: metric("seconds"),
            options: serde_json::from_value(card.training.clone()).ok(),
        })
    }
}

/// A trained SIDQL policy on the plain (inference) CPU device.
pub struct SidqlPolicy {
    pub info: PolicyInfo,
    net: QNet,
    runtime: QRuntime,
    device: Device,
}

impl SidqlPolicy {
    /// A policy from a trained network (moved to the inference device).
    pub fn new(info: PolicyInfo, net: QNet) -> SidqlPolicy {
        SidqlPolicy { info, runtime: QRuntime::new(&net), net, device: inbetween_nn::backend::cpu() }
    }

    /// Writes the weights (`path`, burnpack) and their card (`path` with `.json`).
    pub fn save(&self, path: &Path) -> Result<()> {
        Ok(weights::save(&self.net, &self.info.to_card()?, path)?)
    }

    /// Loads a policy saved by [`SidqlPolicy::save`].
    pub fn load(path: &Path) -> Result<SidqlPolicy> {
        Self::from_weights(&Weights::from_path(path)?)
    }

    /// The committed policy (`crates/mocap/weights/sidql.bpk`, trained by `inbetween mocap train`
    /// on every CMU take of the corpus; its card says how), compiled into the binary so the bench
    /// and the tools run from any folder.
    pub fn committed() -> Result<SidqlPolicy> {
        let w = Weights::embedded(
            "crates/mocap/weights/sidql.bpk",
            include_bytes!("../../weights/sidql.bpk"),
            include_str!("../../weights/sidql.json"),
        )?;
        Self::from_weights(&w)
    }

    fn from_weights(w: &Weights) -> Result<SidqlPolicy> {
        let info = PolicyInfo::from_weights(w)?;
        if info.config.inputs_per_frame != INPUTS {
            return Err(MocapError::Model(format!(
                "{}: the policy reads {} inputs per frame, this version builds {INPUTS}; retrain it",
                w.origin().display(),
                info.config.inputs_per_frame
            )));
        }
        let device = inbetween_nn::backend::cpu();
        let net = w.load_into(info.config.init(&device))?;
        Ok(SidqlPolicy { info, runtime: QRuntime::new(&net), net, device })
    }

    /// The network's layers for plain-Rust inference.
    pub fn runtime(&self) -> &QRuntime {
        &self.runtime
    }

    /// Q-values `[batch × frames]` of states laid out `[batch, frames, INPUTS]`.
    pub fn q_values(&self, states: &[f32], batch: usize, frames: usize) -> Vec<f32> {
        q_values(&self.net, states, batch, frames, &self.device)
    }

    /// Chooses `k` keys for a window: the network's keys ([`Finish::NetworkAlone`]), checked
    /// against uniform keys and refined ([`Finish::CheckedAndRefined`]).
    pub fn select(&self, rep: &SphericalMotion, k: usize) -> Result<KeyframeSet> {
        self.select_with(rep, k, Finish::CheckedAndRefined)
    }

    /// Chooses `k` keys: starting from the end keys, repeatedly the frame with the highest Q-value
    /// among the non-keys, the budget left in the state; then `finish`.
    pub fn select_with(&self, rep: &SphericalMotion, k: usize, finish: Finish) -> Result<KeyframeSet> {
        crate::select::check_k(rep.num_frames, k)?;
        if k <= 2 {
            return Ok(KeyframeSet::new(vec![0, rep.num_frames - 1], rep.num_frames)?);
        }
        let w = EnvWindow::lazy(rep)?;
        let mut s = w.scratch();
        let mut mask = rollout(&self.runtime, &w, k, &mut s, &mut Rollout::default());
        if finish != Finish::NetworkAlone {
            // Checked exactly against uniform keys (K − 1 segment costs): never worse than UC.
            let uniform = KeyframeSet::uniform(w.frames(), k)?;
            let uniform_mask = uniform.frames().iter().fold(0u64, |m, &f| m | 1 << f);
            if w.error(uniform_mask, &mut s) < w.error(mask, &mut s) {
                mask = uniform_mask;
            }
        }
        let mut keys: Vec<usize> = (0..w.frames()).filter(|&f| mask >> f & 1 == 1).collect();
        if finish == Finish::CheckedAndRefined {
            refine_keys(&mut keys, |a, b| w.cost(a, b, &mut s));
        }
        Ok(KeyframeSet::new(keys, w.frames())?)
    }

    /// The network's own keys ([`Finish::NetworkAlone`]).
    pub fn select_unchecked(&self, rep: &SphericalMotion, k: usize) -> Result<KeyframeSet> {
        self.select_with(rep, k, Finish::NetworkAlone)
    }
}

/// What [`SidqlPolicy::select_with`] does with the network's keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Finish {
    /// The keys as the network chose them (the paper's policy).
    NetworkAlone,
    /// Replaced by uniform keys when those cost less (exactly, K − 1 segment costs).
    CheckedAgainstUc,
    /// Checked, then each key moved to the best frame between its neighbours until none moves
    /// ([`crate::select::refine`]): never worse than either. The default.
    CheckedAndRefined,
}

/// Buffers of [`rollout`].
#[derive(Clone, Debug, Default)]
pub struct Rollout {
    state: Vec<f32>,
    rows: Vec<f32>,
    index: Vec<usize>,
    q: Vec<f32>,
    buffers: QBuffers,
}

/// The mask of `k` keys `net` chooses greedily on window `w` (only non-key rows are evaluated).
pub fn rollout(net: &QRuntime, w: &EnvWindow, k: usize, s: &mut StateScratch, r: &mut Rollout) -> u64 {
    let n = w.frames();
    let mut mask = w.initial_mask();
    while (mask.count_ones() as usize) < k {
        let budget = k - mask.count_ones() as usize;
        r.state.clear();
        w.state(mask, budget, s, &mut r.state);
        r.rows.clear();
        r.index.clear();
        for f in (0..n).filter(|&f| mask >> f & 1 == 0) {
            r.rows.extend_from_slice(&r.state[f * INPUTS..(f + 1) * INPUTS]);
            r.index.push(f);
        }
        r.q.resize(r.index.len(), 0.0);
        net.forward_unscaled(&r.rows, r.index.len(), &mut r.buffers, &mut r.q);
        // Every row shares the scale E(s)/E(s₀): the unscaled values rank the actions alike.
        let best = (0..r.index.len()).fold(0, |b, i| if r.q[i] > r.q[b] { i } else { b });
        mask |= 1 << r.index[best];
    }
    mask
}

/// Q-values `[batch × frames]` of states laid out `[batch, frames, INPUTS]`.
pub(crate) fn q_values(net: &QNet, states: &[f32], batch: usize, frames: usize, device: &Device) -> Vec<f32> {
    let x = Tensor::<3>::from_data(TensorData::new(states.to_vec(), [batch, frames, INPUTS]), device);
    net.forward(x).into_data().try_to_vec::<f32>().expect("f32 Q-values")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::SegmentModel;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn committed_policy_serves_any_skeleton_and_window_length() {
        let policy = SidqlPolicy::committed().unwrap();
        assert!(policy.info.trained_on.contains("CMU"), "{}", policy.info.trained_on);
        let m = gait(&GaitParams { frames: 40, fps: 30.0, ..GaitParams::walk() });
        // All 31 joints (the policy was trained on 22–23) and 40 frames (trained on 60).
        let rep = SphericalMotion::from_motion(&m).unwrap();
        let keys = policy.select(&rep, 6).unwrap();
        assert_eq!(keys.len(), 6);
        let two = KeyframeSet::new(vec![], 40).unwrap();
        assert!(rep.error(&keys).mean_angle < 0.5 * rep.error(&two).mean_angle);
    }

    /// Each finishing step only lowers the exact error: network alone ≥ checked (and uniform keys
    /// ≥ checked) ≥ checked and refined, at every K, on gaits the policy never saw.
    #[test]
    fn checking_and_refining_never_raise_the_error() {
        let policy = SidqlPolicy::committed().unwrap();
        let mut refined_better = 0;
        for (i, params) in [GaitParams::walk(), GaitParams::run()].into_iter().enumerate() {
            let m = gait(&GaitParams { frames: 60, fps: 30.0, turn_rate: 0.4, ..params.jittered(i as u64, 0.3) });
            let rep = SphericalMotion::from_motion(&m).unwrap();
            for k in [3, 5, 10, 15] {
                let err = |finish: Finish| rep.error(&policy.select_with(&rep, k, finish).unwrap()).mean_angle;
                let (alone, checked, refined) =
                    (err(Finish::NetworkAlone), err(Finish::CheckedAgainstUc), err(Finish::CheckedAndRefined));
                let uniform = rep.error(&KeyframeSet::uniform(60, k).unwrap()).mean_angle;
                let tol = 1e-12;
                assert!(checked <= alone + tol && checked <= uniform + tol, "K={k}: {checked} vs {alone}, {uniform}");
                assert!(refined <= checked + tol, "K={k}: refined {refined} vs checked {checked}");
                assert_eq!(
                    policy.select(&rep, k).unwrap(),
                    policy.select_with(&rep, k, Finish::CheckedAndRefined).unwrap()
                );
                refined_better += usize::from(refined < checked - tol);
            }
        }
        assert!(refined_better > 0, "refinement moved no key on 8 windows");
    }

    #[test]
    fn a_file_of_another_model_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("other.bpk");
        let net = DqnConfig::default().init(&inbetween_nn::backend::cpu());
        let card = WeightsCard::new("camera", 1, serde_json::to_value(DqnConfig::default()).unwrap(), "x");
        weights::save(&net, &card, &path).unwrap();
        let err = SidqlPolicy::load(&path).err().unwrap().to_string();
        assert!(err.contains("other.bpk") && err.contains("expected mocap-sidql"), "{err}");
        let err = SidqlPolicy::load(&dir.path().join("missing.bpk")).err().unwrap().to_string();
        assert!(err.contains("missing.bpk"), "{err}");
    }
}
