//! The generator `G` of §3.2: a stack of bidirectional LSTM layers (2 × 128 units in the paper),
//! dropout 0.3 (§3.3) and a dense output layer to the 52 ARKit weights.
//!
//! Dropout is applied by the caller's mask ([`Generator::forward_dropped`], [`dropout_mask`]) drawn
//! from a seeded generator, not from the device's global random generator: a training step is then
//! a function of its seed alone, whatever else runs in the process.
//!
//! The dense layer outputs a correction of the linear prior that the input carries in its first 52
//! features ([`super::input`]: a difference on purpose), and starts at zero, so an untrained
//! generator gives the linear baseline. [`Generator::forward`] clamps `prior + correction` to
//! [0, 1] (the "weights stay in [0, 1]"); training uses the unclamped sum
//! ([`Generator::forward_dropped`]) so that no gradient is cut. The sequence is a `Vec` of per-step
//! `[batch, input_dim]` tensors ([`inbetween_nn::lstm`]: slicing one big tensor per step makes
//! backward quadratic in the length); the dense layer then runs once over the stacked
//! `[batch, frames, 2·d_hidden]` outputs.

use burn::module::Module;
use burn::nn::{Initializer, Linear, LinearConfig};
use burn::tensor::{Device, Tensor, TensorData};
use inbetween_nn::burn;
use inbetween_nn::lstm::{stack_time, BiLstm, BiLstmConfig};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::data::NUM_ARKIT;
use crate::edit::ConstraintKind;

use super::input::input_dim;

/// Architecture of a [`Generator`]: which constraint it reads (fixes the input width,
/// [`input_dim`]), hidden units per direction, stacked layers and dropout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneratorConfig {
    /// The guidance this network is trained for (one network per kind, §3.1).
    pub kind: ConstraintKind,
    /// Hidden units per direction (paper: 128).
    pub d_hidden: usize,
    /// Stacked bidirectional layers (paper: 2).
    pub layers: usize,
    /// Dropout before the dense layer while training (paper: 0.3).
    pub dropout: f64,
}

impl GeneratorConfig {
    /// The paper's network for `kind`: 2 bidirectional layers of 128 units, dropout 0.3.
    pub fn paper(kind: ConstraintKind) -> GeneratorConfig {
        GeneratorConfig { kind, d_hidden: 128, layers: 2, dropout: 0.3 }
    }

    /// Input features per frame.
    pub fn d_input(&self) -> usize {
        input_dim(self.kind)
    }

    /// Build the generator on `device` (an autodiff device to train it). Wrap the call in
    /// [`inbetween_nn::backend::seeded_module`] for seeded weights.
    pub fn init(&self, device: &Device) -> Generator {
        let lstm = BiLstmConfig::new(self.d_input(), self.d_hidden).with_num_layers(self.layers.max(1)).init(device);
        let output = LinearConfig::new(2 * self.d_hidden, NUM_ARKIT).with_initializer(Initializer::Zeros).init(device);
        Generator { lstm, output }
    }

    /// The configuration as saved in a weights card.
    pub fn to_card(&self) -> GeneratorCard {
        GeneratorCard {
            kind: self.kind.name().to_string(),
            d_input: self.d_input(),
            d_hidden: self.d_hidden,
            layers: self.layers,
            dropout: self.dropout,
            d_output: NUM_ARKIT,
        }
    }
}

/// [`GeneratorConfig`] as JSON in a weights card (the kind by name, the input width to check the
/// input layout has not changed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GeneratorCard {
    /// [`ConstraintKind::name`].
    pub kind: String,
    /// Input features per frame the weights were trained with.
    pub d_input: usize,
    pub d_hidden: usize,
    pub layers: usize,
    pub dropout: f64,
    /// Output features per frame (52).
    pub d_output: usize,
}

impl GeneratorCard {
    /// Back to a [`GeneratorConfig`], refusing an unknown kind or a layout this build does not have.
    pub fn config(&self) -> Result<GeneratorConfig, String> {
        let kind = ConstraintKind::from_name(&self.kind)
            .ok_or_else(|| format!("unknown constraint kind \"{}\"", self.kind))?;
        let config = GeneratorConfig { kind, d_hidden: self.d_hidden, layers: self.layers, dropout: self.dropout };
        if config.d_input() != self.d_input || self.d_output != NUM_ARKIT {
            return Err(format!(
                "the weights take {} inputs and give {} outputs per frame; this build's {} network takes {} and gives {}",
                self.d_input,
                self.d_output,
                self.kind,
                config.d_input(),
                NUM_ARKIT
            ));
        }
        if self.d_hidden == 0 || self.layers == 0 {
            return Err(format!("d_hidden {} and layers {} must be positive", self.d_hidden, self.layers));
        }
        Ok(config)
    }
}

/// `kind` of the weights card of a face generator ([`inbetween_nn::weights`]).
pub const WEIGHTS_KIND: &str = "face";
/// Architecture version of face generator weights; bump it when the parameter layout changes.
pub const WEIGHTS_FORMAT: u32 = 2;

/// The `config` of a face weights card: the generator and the window length it was trained on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FaceWeightsConfig {
    #[serde(flatten)]
    pub generator: GeneratorCard,
    /// Frames per training window.
    pub window: usize,
}

/// BiLSTM stack + (training) dropout + dense layer adding to the linear prior (§3.2).
#[derive(Module, Debug)]
pub struct Generator {
    /// The bidirectional LSTM layers.
    pub lstm: BiLstm,
    /// `2·d_hidden → 52`: the correction of the prior.
    pub output: Linear,
}

/// An inverted-dropout mask `[batch, frames, 2·d_hidden]` for [`Generator::forward_dropped`]: each
/// entry 0 with probability `p`, else `1/(1 − p)`, drawn from `rng`.
pub fn dropout_mask(rng: &mut impl Rng, shape: [usize; 3], p: f64, device: &Device) -> Tensor<3> {
    let keep = (1.0 / (1.0 - p)) as f32;
    let n = shape.iter().product();
    let v: Vec<f32> = (0..n).map(|_| if rng.random::<f64>() < p { 0.0 } else { keep }).collect();
    Tensor::from_data(TensorData::new(v, shape), device)
}

impl Generator {
    /// Input features per frame.
    pub fn d_input(&self) -> usize {
        self.lstm.layers[0].forward.d_input
    }

    /// Hidden units per direction.
    pub fn d_hidden(&self) -> usize {
        self.lstm.layers[0].forward.d_hidden
    }

    /// The generated animation `[batch, frames, 52]` in [0, 1] from per-frame inputs
    /// (`frames` tensors of `[batch, input_dim]`, laid out by [`super::input`]).
    pub fn forward(&self, steps: &[Tensor<2>]) -> Tensor<3> {
        let hidden = stack_time(&self.lstm.forward_seq(steps));
        (prior(steps) + self.output.forward(hidden)).clamp(0.0, 1.0)
    }

    /// The training forward pass: dropout (the recurrent outputs are multiplied by `keep`, a
    /// [`dropout_mask`] of shape `[batch, frames, 2·d_hidden]`, before the dense layer) and no clamp.
    pub fn forward_dropped(&self, steps: &[Tensor<2>], keep: Tensor<3>) -> Tensor<3> {
        let hidden = stack_time(&self.lstm.forward_seq(steps));
        prior(steps) + self.output.forward(hidden * keep)
    }
}

/// The linear prior `[batch, frames, 52]`: the first 52 input features of every step.
fn prior(steps: &[Tensor<2>]) -> Tensor<3> {
    let p: Vec<Tensor<2>> = steps
        .iter()
        .map(|s| {
            let [batch, _] = s.dims();
            s.clone().slice([0..batch, 0..NUM_ARKIT])
        })
        .collect();
    stack_time(&p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_nn::backend;

    fn steps(frames: usize, batch: usize, d: usize, device: &Device) -> Vec<Tensor<2>> {
        (0..frames)
            .map(|t| {
                let v: Vec<f32> = (0..batch * d).map(|i| ((i * 7 + t * 3) as f32 * 0.37).sin()).collect();
                Tensor::from_data(burn::tensor::TensorData::new(v, [batch, d]), device)
            })
            .collect()
    }

    #[test]
    fn model_generator_starts_at_the_prior_and_stays_in_the_unit_interval() {
        let device = backend::cpu();
        let config = GeneratorConfig { kind: ConstraintKind::Keyframes, d_hidden: 8, layers: 2, dropout: 0.3 };
        let g = backend::seeded_module(&device, 1, |d| config.init(d));
        assert_eq!(g.d_input(), input_dim(ConstraintKind::Keyframes));
        assert_eq!(g.d_hidden(), 8);
        let x = steps(6, 3, g.d_input(), &device);
        let y = g.forward(&x);
        assert_eq!(y.dims(), [3, 6, NUM_ARKIT]);
        let v = y.into_data().try_to_vec::<f32>().unwrap();
        let p: Vec<f32> = prior(&x).clamp(0.0, 1.0).into_data().try_to_vec::<f32>().unwrap();
        assert_eq!(v, p, "an untrained generator gives the prior");
        // A trained (non-zero) output layer: still in [0, 1]; the training pass is unclamped.
        let g = Generator { output: LinearConfig::new(16, NUM_ARKIT).init(&device), ..g };
        let v = g.forward(&x).into_data().try_to_vec::<f32>().unwrap();
        assert!(v.iter().all(|x| (0.0..=1.0).contains(x)));
        assert_ne!(v, p);
        // An all-ones mask is no dropout; a real one changes the output.
        let ones = Tensor::<3>::ones([3, 6, 16], &device);
        let same = g.forward_dropped(&x, ones).clamp(0.0, 1.0).into_data().try_to_vec::<f32>().unwrap();
        assert_eq!(v, same);
        let mask = dropout_mask(&mut inbetween_core::seed::rng(4), [3, 6, 16], 0.3, &device);
        let m = mask.clone().into_data().try_to_vec::<f32>().unwrap();
        let dropped = m.iter().filter(|x| **x == 0.0).count();
        assert!(dropped > 60 && dropped < 200, "{dropped} of 288 dropped");
        assert!(m.iter().all(|x| *x == 0.0 || (*x - 1.0 / 0.7).abs() < 1e-6));
        let other = g.forward_dropped(&x, mask).clamp(0.0, 1.0).into_data().try_to_vec::<f32>().unwrap();
        assert_ne!(v, other);
    }

    #[test]
    fn model_generator_card_round_trips_and_refuses_other_layouts() {
        let config = GeneratorConfig::paper(ConstraintKind::Visemes);
        let card = config.to_card();
        assert_eq!(card.config().unwrap(), config);
        let json = serde_json::to_value(&card).unwrap();
        assert_eq!(json["kind"], "visemes");
        let bad = GeneratorCard { d_input: card.d_input + 1, ..card.clone() };
        assert!(bad.config().unwrap_err().contains("inputs"));
        let unknown = GeneratorCard { kind: "telepathy".into(), ..card };
        assert!(unknown.config().unwrap_err().contains("telepathy"));
    }
}
