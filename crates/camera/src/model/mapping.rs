//! Hidden-state mapping H (§4.3, Eq. 6): five camera frames and a style code → the generator LSTM's
//! starting state (h, c). Resetting the state with H at any step gives velocity and direction
//! control there; H sees no history.

use super::{ModelConfig, MAP_FRAMES};
use crate::features::CAM_DIM;
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::activation::leaky_relu;
use burn::tensor::{Device, Tensor};
use inbetween_nn::lstm::LstmState;

#[derive(Module, Debug)]
pub struct Mapping {
    pub fc1: Linear,
    pub fc2: Linear,
    pub hidden: usize,
    /// Negative slope of the ReLU (0: plain ReLU).
    pub slope: f64,
}

impl Mapping {
    pub fn new(c: &ModelConfig, device: &Device) -> Mapping {
        Mapping {
            fc1: LinearConfig::new(c.mapping_input(), c.hidden).init(device),
            fc2: LinearConfig::new(c.hidden, 2 * c.hidden).init(device),
            hidden: c.hidden,
            slope: c.leaky_slope as f64,
        }
    }

    /// `z` is `[batch, 4]`, `frames` is `[batch, 5·6]` (x^c_0 … x^c_4 concatenated).
    pub fn forward(&self, z: Tensor<2>, frames: Tensor<2>) -> LstmState {
        debug_assert_eq!(frames.dims()[1], MAP_FRAMES * CAM_DIM);
        let y = self.fc2.forward(leaky_relu(self.fc1.forward(Tensor::cat(vec![z, frames], 1)), self.slope));
        LstmState { h: y.clone().narrow(1, 0, self.hidden), c: y.narrow(1, self.hidden, self.hidden) }
    }
}
