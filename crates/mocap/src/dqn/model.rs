//! The Q-network of §5.2: "a fully connected network to extract the features of the keyframes" and
//! two hidden layers as the decision-making module, one Q-value per frame (action = make that frame a
//! keyframe).
//!
//! The layers read each frame's row of the state (see [`super::env`]) with the same weights, so the
//! value of a candidate depends on what the candidate looks like, not on where it sits in the window.
//! Our first network took the whole window as one 5640-wide vector; with ~100 training windows it
//! learnt the windows, not the task, and lost to uniform keys on held-out clips.
//!
//! Rewards (Eq. 22) are shares of E(s₀), so they shrink as keys are added, while the state's errors
//! are relative to the current E(s). The network therefore outputs Q / (E(s)/E(s₀)) and the last
//! step multiplies by E(s)/E(s₀), read from the state ([`SCALE_INPUT`]): the layers learn one
//! scale-free task instead of a family of ever smaller ones. The targets are the paper's.

use super::env::{INPUTS, SCALE_INPUT};
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};
use inbetween_nn::burn;
use serde::{Deserialize, Serialize};

/// Shape of the network; stored beside the weights so a checkpoint says what it fits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DqnConfig {
    /// Inputs per frame row ([`INPUTS`]); checked on load.
    pub inputs_per_frame: usize,
    /// Feature layer, then the two hidden layers.
    pub hidden: [usize; 3],
}

impl Default for DqnConfig {
    fn default() -> Self {
        DqnConfig { inputs_per_frame: INPUTS, hidden: [64, 64, 32] }
    }
}

impl DqnConfig {
    pub fn init(&self, device: &Device) -> QNet {
        QNet {
            feature: LinearConfig::new(self.inputs_per_frame, self.hidden[0]).init(device),
            hidden1: LinearConfig::new(self.hidden[0], self.hidden[1]).init(device),
            hidden2: LinearConfig::new(self.hidden[1], self.hidden[2]).init(device),
            out: LinearConfig::new(self.hidden[2], 1).init(device),
        }
    }
}

#[derive(Module, Debug)]
pub struct QNet {
    feature: Linear,
    hidden1: Linear,
    hidden2: Linear,
    out: Linear,
}

impl QNet {
    /// Q-values `[batch, frames]` of states `[batch, frames, inputs]`.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<2> {
        let [batch, frames, inputs] = x.dims();
        let scale = x.clone().reshape([batch * frames, inputs]).slice([0..batch * frames, SCALE_INPUT..SCALE_INPUT + 1]);
        self.forward_unscaled(x) * scale.reshape([batch, frames])
    }

    /// Q / (E(s)/E(s₀)): what the layers compute before the final scaling. Training fits this to
    /// the target divided by the same factor, so late steps (small rewards) weigh as much as early ones.
    pub fn forward_unscaled(&self, x: Tensor<3>) -> Tensor<2> {
        let [batch, frames, inputs] = x.dims();
        let rows = x.reshape([batch * frames, inputs]);
        let h = relu(self.feature.forward(rows));
        let h = relu(self.hidden1.forward(h));
        let h = relu(self.hidden2.forward(h));
        self.out.forward(h).reshape([batch, frames])
    }
}
