//! The autoregressive camera motion generator (§4.2, Eq. 3):
//! x^c_i = f(z, x^c_{i−1}, x^v_i, K, z_tta, h_{i−1}) with an encoder of two FC+ReLU layers, a 256-unit
//! LSTM and a decoder FC+ReLU, FC. K is the next keyframe's camera and character features and
//! z_tta the time-to-arrival embedding (Eq. 4–5, tta capped at 200 frames). The ReLUs are leaky
//! when `ModelConfig::leaky_slope` > 0, and the output is a residual on the previous pose, or on
//! one step of the straight line to the key (`ModelConfig::arrival_base`).

use super::ModelConfig;
use burn::module::Module;
use burn::module::Param;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::activation::leaky_relu;
use burn::tensor::{Device, Tensor, TensorData};
use inbetween_nn::lstm::{FusedLstm, FusedLstmConfig, LstmState};

#[derive(Module, Debug)]
pub struct Generator {
    pub enc1: Linear,
    pub enc2: Linear,
    pub lstm: FusedLstm,
    pub dec1: Linear,
    pub dec2: Linear,
    /// Negative slope of the ReLUs (0: plain ReLU).
    pub slope: f64,
}

/// Everything but the recurrent state that one generator step reads, each `[batch, ·]`.
pub struct StepInput {
    pub style: Tensor<2>,
    pub prev_camera: Tensor<2>,
    pub character: Tensor<2>,
    /// Next keyframe: x^c_K (6) then encoded x^v_K (8).
    pub key: Tensor<2>,
    pub tta: Tensor<2>,
    /// `[batch, 1]`: [`ModelConfig::arrival_weight`] of this step's tta (zeros: plain residual).
    pub arrival: Tensor<2>,
}

impl Generator {
    pub fn new(c: &ModelConfig, device: &Device) -> Generator {
        let h = c.hidden;
        Generator {
            enc1: LinearConfig::new(c.generator_input(), h).init(device),
            enc2: LinearConfig::new(h, h).init(device),
            lstm: FusedLstmConfig::new(h, h).init(device),
            dec1: LinearConfig::new(h, h).init(device),
            dec2: small_output(LinearConfig::new(h, crate::features::CAM_DIM).init(device), device),
            slope: c.leaky_slope as f64,
        }
    }

    /// One step: returns x̂^c_i (`[batch, 6]`) and the new LSTM state.
    pub fn step(&self, x: StepInput, state: Option<LstmState>) -> (Tensor<2>, LstmState) {
        let prev = x.prev_camera.clone();
        let toward = (x.key.clone().narrow(1, 0, crate::features::CAM_DIM) - prev.clone()) * x.arrival;
        let input = Tensor::cat(vec![x.style, x.prev_camera, x.character, x.key, x.tta], 1);
        let act = |t: Tensor<2>| leaky_relu(t, self.slope);
        let e = act(self.enc2.forward(act(self.enc1.forward(input))));
        let state = self.lstm.step(e, state);
        let delta = self.dec2.forward(act(self.dec1.forward(state.h.clone())));
        (prev + toward + delta, state)
    }
}

/// The output layer starts 10× smaller than burn's default, so the untrained generator stays near
/// its base (the previous pose, or the straight line to the key) instead of drifting by ±0.1 a step.
fn small_output(mut l: Linear, device: &Device) -> Linear {
    // Rebuilt from plain data so the parameters stay leaves under autodiff.
    let w = l.weight.val();
    let dims = w.dims();
    let values: Vec<f32> = w.into_data().try_to_vec::<f32>().unwrap_or_default().into_iter().map(|v| v * 0.1).collect();
    l.weight = Param::from_data(TensorData::new(values, dims), device);
    if let Some(b) = l.bias.take() {
        l.bias = Some(Param::from_data(TensorData::new(vec![0.0f32; b.dims()[0]], [b.dims()[0]]), device));
    }
    l
}
