//! The Q-network: a fully connected feature layer over the state (motion features, keyframe mask,
//! per-frame current error) and two hidden layers, one Q-value per frame (action = make that frame
//! a keyframe), as in §5.2.

use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};
use inbetween_nn::burn;
use serde::{Deserialize, Serialize};

/// Shape of the network; stored beside the weights so a checkpoint says what it fits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DqnConfig {
    /// Frames per window (actions).
    pub frames: usize,
    /// Motion features per frame (4 per joint: root velocity/height, then θ, φ, θ̇, φ̇ per bone).
    pub features_per_frame: usize,
    pub hidden: [usize; 3],
}

impl DqnConfig {
    /// The paper's protocol: 60 frames × 23 joints × 4 features, layers 512 → 256 (plus a 512-wide
    /// feature layer).
    pub fn paper() -> DqnConfig {
        DqnConfig { frames: 60, features_per_frame: 23 * 4, hidden: [512, 256, 128] }
    }

    /// Input width: motion features, then the mask and the per-frame error, one each per frame.
    pub fn input_size(&self) -> usize {
        self.frames * (self.features_per_frame + 2)
    }

    pub fn init(&self, device: &Device) -> QNet {
        QNet {
            feature: LinearConfig::new(self.input_size(), self.hidden[0]).init(device),
            hidden1: LinearConfig::new(self.hidden[0], self.hidden[1]).init(device),
            hidden2: LinearConfig::new(self.hidden[1], self.hidden[2]).init(device),
            out: LinearConfig::new(self.hidden[2], self.frames).init(device),
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
    /// Q-values `[batch, frames]` of states `[batch, input]`.
    pub fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        let h = relu(self.feature.forward(x));
        let h = relu(self.hidden1.forward(h));
        let h = relu(self.hidden2.forward(h));
        self.out.forward(h)
    }
}
