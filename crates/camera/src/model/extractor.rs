//! The camera behaviour extractor (§4.1): a gating LSTM over a reference clip's cinematic features
//! (x^v, x^c per step, zero initial state); its last output goes through one FC layer to the style
//! code z ∈ R⁴, left unconstrained (no softmax, no KL) as in the paper.

use super::ModelConfig;
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::{Device, Tensor};
use inbetween_nn::lstm::{FusedLstm, FusedLstmConfig};

#[derive(Module, Debug)]
pub struct Extractor {
    pub lstm: FusedLstm,
    pub out: Linear,
}

impl Extractor {
    pub fn new(c: &ModelConfig, device: &Device) -> Extractor {
        Extractor {
            lstm: FusedLstmConfig::new(c.extractor_input(), c.hidden).init(device),
            out: LinearConfig::new(c.hidden, c.style_dim).init(device),
        }
    }

    /// `steps[t]` is `[batch, 14]` (encoded x^v then x^c); returns z as `[batch, 4]`.
    pub fn forward(&self, steps: &[Tensor<2>]) -> Tensor<2> {
        let (_, state) = self.lstm.forward_seq(steps, None);
        self.out.forward(state.h)
    }
}
