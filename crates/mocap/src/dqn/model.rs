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
//!
//! The layers add a correction to the candidate's exact one-step gain ([`GAIN_INPUT`], already
//! ÷ E(s), so in the unscaled units): Q = gain + net(row). The immediate reward of an action *is*
//! its one-step gain (Eq. 22), so the network only has to learn what the keys still to come add or
//! take away. The last layer starts at zero: an untrained policy is greedy by exact gain. Without
//! this, a 32-32-16 network fitted to cost-to-go ranked nearby candidates worse than uniform keys
//! (held-out k-fold, issue 14).

use super::env::{GAIN_INPUT, INPUTS, SCALE_INPUT};
use burn::module::Module;
use burn::nn::{Initializer, Linear, LinearConfig};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};
use inbetween_nn::burn;
use inbetween_nn::runtime::Dense;
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
        DqnConfig { inputs_per_frame: INPUTS, hidden: [32, 32, 16] }
    }
}

impl DqnConfig {
    pub fn init(&self, device: &Device) -> QNet {
        QNet {
            feature: LinearConfig::new(self.inputs_per_frame, self.hidden[0]).init(device),
            hidden1: LinearConfig::new(self.hidden[0], self.hidden[1]).init(device),
            hidden2: LinearConfig::new(self.hidden[1], self.hidden[2]).init(device),
            out: LinearConfig::new(self.hidden[2], 1).with_initializer(Initializer::Zeros).init(device),
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
        let scale =
            x.clone().reshape([batch * frames, inputs]).slice([0..batch * frames, SCALE_INPUT..SCALE_INPUT + 1]);
        self.forward_unscaled(x) * scale.reshape([batch, frames])
    }

    /// Q / (E(s)/E(s₀)): what the layers compute before the final scaling. Training fits this to
    /// the target divided by the same factor, so late steps (small rewards) weigh as much as early ones.
    pub fn forward_unscaled(&self, x: Tensor<3>) -> Tensor<2> {
        let [batch, frames, inputs] = x.dims();
        let rows = x.reshape([batch * frames, inputs]);
        let gain = rows.clone().slice([0..batch * frames, GAIN_INPUT..GAIN_INPUT + 1]);
        let h = relu(self.feature.forward(rows));
        let h = relu(self.hidden1.forward(h));
        let h = relu(self.hidden2.forward(h));
        (self.out.forward(h) + gain).reshape([batch, frames])
    }
}

/// The Q-network's layers as plain-Rust dense layers (`inbetween_nn::runtime`), for selection:
/// no tensors, no allocation once the buffers have their size.
#[derive(Clone, Debug)]
pub struct QRuntime {
    layers: [Dense; 4],
}

/// Buffers of [`QRuntime::forward_unscaled`].
#[derive(Clone, Debug, Default)]
pub struct QBuffers {
    a: Vec<f32>,
    b: Vec<f32>,
}

impl QRuntime {
    pub fn new(net: &QNet) -> QRuntime {
        QRuntime {
            layers: [
                Dense::from_linear(&net.feature),
                Dense::from_linear(&net.hidden1),
                Dense::from_linear(&net.hidden2),
                Dense::from_linear(&net.out),
            ],
        }
    }

    /// [`QNet::forward_unscaled`] of `rows` rows of `INPUTS` values, into `out[..rows]`.
    pub fn forward_unscaled(&self, x: &[f32], rows: usize, buf: &mut QBuffers, out: &mut [f32]) {
        let (cur, next) = (&mut buf.a, &mut buf.b);
        let last = self.layers.len() - 1;
        for (i, layer) in self.layers.iter().enumerate() {
            next.resize(rows * layer.n_out, 0.0);
            layer.forward(if i == 0 { x } else { cur.as_slice() }, next, rows);
            if i < last {
                next.iter_mut().for_each(|v| *v = v.max(0.0));
            }
            std::mem::swap(cur, next);
        }
        for (r, o) in out[..rows].iter_mut().enumerate() {
            *o = cur[r] + x[r * INPUTS + GAIN_INPUT];
        }
    }
}
