//! The generator for inference in plain Rust ([`inbetween_nn::runtime`]): no tensors, no autodiff,
//! buffers reused between calls. The BiLSTM runs over the whole sequence at once
//! ([`inbetween_nn::runtime::BiLstm`]), then the dense layer over every frame, added to the linear
//! prior of the input and clamped to [0, 1].
//! Tests check it against the burn [`Generator`] (inference, no dropout) to 1e-4.

use std::sync::Mutex;

use inbetween_nn::burn;
use inbetween_nn::runtime::{BiLstm, BiLstmScratch, Dense};
use inbetween_nn::weights::Weights;
use inbetween_nn::NnError;

use crate::data::NUM_ARKIT;
use crate::edit::{ConstraintKind, Frame};

use super::generator::{FaceWeightsConfig, Generator, WEIGHTS_FORMAT, WEIGHTS_KIND};

/// Buffers of one run.
#[derive(Debug, Default)]
struct Scratch {
    lstm: BiLstmScratch,
    out: Vec<f32>,
}

/// A trained generator as plain-Rust layers.
#[derive(Debug)]
pub struct GeneratorRuntime {
    /// The bidirectional LSTM stack.
    pub lstm: BiLstm,
    /// `2·d_hidden → 52`.
    pub output: Dense,
    /// Run the two directions of each layer on two threads ([`BiLstm::forward_parallel`]). Off by
    /// default: on the shared 2-core machine a 100-frame edit measured 5.3–6.4 ms on one thread and
    /// 6.0–7.1 ms on two (the spawn and the contention cost more than they save there).
    pub parallel: bool,
    /// Buffers reused by every [`Self::run`] (locked for the call; runs from several threads take
    /// turns, clone the runtime to run them side by side).
    scratch: Mutex<Scratch>,
}

impl Clone for GeneratorRuntime {
    fn clone(&self) -> Self {
        GeneratorRuntime {
            lstm: self.lstm.clone(),
            output: self.output.clone(),
            parallel: self.parallel,
            scratch: Mutex::default(),
        }
    }
}

impl GeneratorRuntime {
    /// Copies a burn generator's parameters.
    pub fn from_generator(g: &Generator) -> GeneratorRuntime {
        GeneratorRuntime {
            lstm: BiLstm::from_bilstm(&g.lstm),
            output: Dense::from_linear(&g.output),
            parallel: false,
            scratch: Mutex::default(),
        }
    }

    /// Input features per frame ([`super::input::input_dim`] of the network's kind).
    pub fn d_input(&self) -> usize {
        self.lstm.d_input()
    }

    /// The generated animation for `frames` frames of input (`frames × d_input`, laid out by
    /// [`super::input::assemble_into`]); every weight in [0, 1].
    pub fn run(&self, input: &[f32], frames: usize) -> Vec<Frame> {
        let mut guard = self.scratch.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let Scratch { lstm, out } = &mut *guard;
        let hidden = if self.parallel {
            self.lstm.forward_parallel(input, frames, lstm)
        } else {
            self.lstm.forward(input, frames, lstm)
        };
        if out.len() < frames * NUM_ARKIT {
            out.resize(frames * NUM_ARKIT, 0.0);
        }
        self.output.forward(hidden, out, frames);
        let d_input = self.d_input();
        out[..frames * NUM_ARKIT]
            .chunks_exact(NUM_ARKIT)
            .zip(input.chunks_exact(d_input))
            .map(|(row, x)| {
                let mut f = [0.0; NUM_ARKIT];
                for ((o, v), p) in f.iter_mut().zip(row).zip(&x[..NUM_ARKIT]) {
                    *o = (p + v).clamp(0.0, 1.0);
                }
                f
            })
            .collect()
    }
}

/// The generator in `weights` (a face weights card, [`super::generator::WEIGHTS_KIND`]) and the
/// constraint kind it reads. Weights of another model, format or layout are refused, naming the file.
pub fn load_generator(weights: &Weights) -> Result<(GeneratorRuntime, ConstraintKind), NnError> {
    let generator = load_generator_module(weights, &inbetween_nn::backend::cpu())?;
    let kind = weights
        .config::<FaceWeightsConfig>()?
        .generator
        .config()
        .map_err(|message| NnError::Mismatch { path: weights.origin().to_path_buf(), message })?;
    Ok((GeneratorRuntime::from_generator(&generator), kind.kind))
}

/// The burn [`Generator`] in `weights`, on `device`.
pub fn load_generator_module(weights: &Weights, device: &burn::tensor::Device) -> Result<Generator, NnError> {
    weights.expect_kind(WEIGHTS_KIND, WEIGHTS_FORMAT)?;
    let card: FaceWeightsConfig = weights.config()?;
    let config = card
        .generator
        .config()
        .map_err(|message| NnError::Mismatch { path: weights.origin().to_path_buf(), message })?;
    weights.load_into(config.init(device))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::{Constraint, Mask, Segment};
    use crate::model::generator::GeneratorConfig;
    use crate::model::input::{assemble, noise};
    use burn::tensor::{Tensor, TensorData};
    use inbetween_core::seed::rng;
    use inbetween_nn::backend;

    fn clip_input(kind_frames: usize) -> (Vec<f32>, usize) {
        let anim: Vec<Frame> =
            (0..kind_frames).map(|f| std::array::from_fn(|c| 0.5 + 0.4 * ((f * 3 + c) as f32 * 0.1).sin())).collect();
        let mask = Mask::from_segments(kind_frames, &[Segment { start: 5, end: 17 }], &[true; NUM_ARKIT]);
        let keys = Constraint::Keyframes(vec![(8, anim[8]), (12, anim[12])]);
        (assemble(&anim, &mask, &keys, &noise(&mut rng(2), kind_frames)), kind_frames)
    }

    fn burn_forward(g: &Generator, input: &[f32], frames: usize) -> Vec<f32> {
        let d = g.d_input();
        let device = backend::cpu();
        let steps: Vec<Tensor<2>> = (0..frames)
            .map(|t| Tensor::from_data(TensorData::new(input[t * d..(t + 1) * d].to_vec(), [1, d]), &device))
            .collect();
        g.forward(&steps).into_data().try_to_vec::<f32>().unwrap()
    }

    #[test]
    fn model_runtime_equals_the_burn_generator() {
        let device = backend::cpu();
        let config = GeneratorConfig { kind: ConstraintKind::Keyframes, d_hidden: 16, layers: 2, dropout: 0.3 };
        let g = backend::seeded_module(&device, 8, |d| config.init(d));
        let rt = GeneratorRuntime::from_generator(&g);
        assert_eq!(rt.d_input(), config.d_input());
        let (input, frames) = clip_input(24);
        let expected = burn_forward(&g, &input, frames);
        let got: Vec<f32> = rt.run(&input, frames).into_iter().flatten().collect();
        let two_threads = GeneratorRuntime { parallel: true, ..rt.clone() };
        assert_eq!(two_threads.run(&input, frames).concat(), got, "threads do not change the bits");
        let worst = got.iter().zip(&expected).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert_eq!(got.len(), expected.len());
        assert!(worst < 1e-4, "runtime vs burn: {worst}");
        // A second, shorter run reuses the buffers and still agrees.
        let short: Vec<f32> = rt.run(&input[..10 * rt.d_input()], 10).into_iter().flatten().collect();
        let expected_short = burn_forward(&g, &input[..10 * rt.d_input()], 10);
        assert!(short.iter().zip(&expected_short).all(|(a, b)| (a - b).abs() < 1e-4));
    }

    #[test]
    fn model_runtime_loads_face_weights_and_refuses_others() {
        let device = backend::cpu();
        let config = GeneratorConfig { kind: ConstraintKind::Noisy, d_hidden: 8, layers: 2, dropout: 0.3 };
        let g = backend::seeded_module(&device, 9, |d| config.init(d));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.bpk");
        let card_config = FaceWeightsConfig { generator: config.to_card(), window: 100 };
        let card = inbetween_nn::weights::WeightsCard::new(
            WEIGHTS_KIND,
            WEIGHTS_FORMAT,
            serde_json::to_value(&card_config).unwrap(),
            "test",
        );
        inbetween_nn::weights::save(&g, &card, &path).unwrap();
        let w = Weights::from_path(&path).unwrap();
        let (rt, kind) = load_generator(&w).unwrap();
        assert_eq!(kind, ConstraintKind::Noisy);
        let d = rt.d_input();
        let input: Vec<f32> = (0..6 * d).map(|i| (i as f32 * 0.3).cos()).collect();
        let a: Vec<f32> = rt.run(&input, 6).into_iter().flatten().collect();
        let b = burn_forward(&g, &input, 6);
        assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-4));

        let other = inbetween_nn::weights::WeightsCard::new("camera", 1, serde_json::json!({}), "test");
        inbetween_nn::weights::save(&g, &other, &path).unwrap();
        let err = load_generator(&Weights::from_path(&path).unwrap()).unwrap_err().to_string();
        assert!(err.contains("g.bpk") && err.contains("expected face"), "{err}");
        let wrong = FaceWeightsConfig { generator: GeneratorConfig { d_hidden: 16, ..config }.to_card(), window: 100 };
        let card = inbetween_nn::weights::WeightsCard::new(
            WEIGHTS_KIND,
            WEIGHTS_FORMAT,
            serde_json::to_value(&wrong).unwrap(),
            "t",
        );
        inbetween_nn::weights::save(&g, &card, &path).unwrap();
        assert!(load_generator(&Weights::from_path(&path).unwrap()).unwrap_err().to_string().contains("g.bpk"));
    }
}
