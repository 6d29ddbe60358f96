//! The critic (discriminator) `D` of §3.2: four spectrally normalised 1-D convolutions (kernel 3,
//! stride 2, padding 1; 64, 32, 16 and 8 channels; Miyato et al. 2018) each followed by
//! LeakyReLU(0.2), then a dense layer to one score. Its input is `[batch, 58, frames]`: the
//! (recomposed) animation's 52 weights and the six key distances of [`crate::edit::distances`] over
//! time, so the critic judges the whole window and pays attention to lip and eyelid closures.
//!
//! The dense layer reads the flattened `[8, frames/16]` map, so a critic is built for one window
//! length ([`CriticConfig::window`]); it only serves training.
//!
//! # The input gradient by hand
//! WGAN-GP (Gulrajani et al. 2017) penalises `(‖∇ₓD(x̂)‖₂ − 1)²`, whose parameter gradient needs the
//! derivative of a derivative. burn has no double backward, so [`Critic::input_gradient_with`]
//! writes `∇ₓD` as an ordinary expression of the weights: with `a_k = conv_k(h_{k−1})`,
//! `h_k = LeakyReLU(a_k)` and `s = w_d · vec(h_4) + b_d`,
//! ```text
//! ∂s/∂h_4 = w_d (reshaped to [8, T_4]),   ∂s/∂a_k = ∂s/∂h_k ⊙ m_k   (m_k = 1 where a_k > 0, else 0.2),
//! ∂s/∂h_{k−1} = conv_transpose1d(∂s/∂a_k, Ŵ_k)   (stride 2, padding 1, output padding to the input length)
//! ```
//! The masks `m_k` are piecewise constant, so they carry no gradient; the expression is
//! differentiable in the normalised kernels `Ŵ_k` and `w_d`, and the penalty needs one backward.

use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::activation::leaky_relu;
use burn::tensor::module::{conv1d, conv_transpose1d};
use burn::tensor::ops::{ConvOptions, ConvTransposeOptions};
use burn::tensor::{Device, Tensor};
use inbetween_nn::burn;
use inbetween_nn::spectral::{SpectralConv1d, SpectralConv1dConfig};

use crate::data::NUM_ARKIT;
use crate::edit::distances::NUM_DISTANCES;

/// Input channels: 52 weights + 6 distances.
pub const CRITIC_CHANNELS: usize = NUM_ARKIT + NUM_DISTANCES;
/// Output channels of the four convolutions (§3.2).
pub const CONV_CHANNELS: [usize; 4] = [64, 32, 16, 8];
/// Negative slope of the LeakyReLUs.
pub const LEAKY_SLOPE: f64 = 0.2;
const KERNEL: usize = 3;
const STRIDE: usize = 2;
const PADDING: usize = 1;

/// Architecture of a [`Critic`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CriticConfig {
    /// Frames of the windows it judges.
    pub window: usize,
    /// Power iterations per spectral normalisation (1 in training: `u` persists between calls).
    pub n_power_iterations: usize,
}

impl CriticConfig {
    pub fn new(window: usize) -> CriticConfig {
        CriticConfig { window, n_power_iterations: 1 }
    }

    /// Length of the time axis after each convolution.
    pub fn lengths(&self) -> [usize; 4] {
        let mut l = self.window;
        CONV_CHANNELS.map(|_| {
            l = conv_len(l);
            l
        })
    }

    /// Build the critic on `device`.
    pub fn init(&self, device: &Device) -> Critic {
        let mut c_in = CRITIC_CHANNELS;
        let convs = CONV_CHANNELS
            .iter()
            .map(|&c_out| {
                let conv = SpectralConv1dConfig::new(c_in, c_out, KERNEL)
                    .with_stride(STRIDE)
                    .with_padding(PADDING)
                    .with_n_power_iterations(self.n_power_iterations)
                    .init(device);
                c_in = c_out;
                conv
            })
            .collect();
        let flat = CONV_CHANNELS[3] * self.lengths()[3];
        Critic { convs, dense: LinearConfig::new(flat, 1).init(device), window: self.window }
    }
}

/// Output length of a kernel-3, stride-2, padding-1 convolution.
fn conv_len(l: usize) -> usize {
    (l + 2 * PADDING - KERNEL) / STRIDE + 1
}

/// The critic: 4 spectrally normalised conv1d + LeakyReLU, dense to one score.
#[derive(Module, Debug)]
pub struct Critic {
    /// The four convolutions, input side first.
    pub convs: Vec<SpectralConv1d>,
    /// `8 · T_4 → 1`.
    pub dense: Linear,
    /// Frames of the windows it judges.
    pub window: usize,
}

/// The weights of one critic evaluation: the normalised kernels (one power iteration each, taken
/// once per training step and shared by every forward and gradient of that step), biases and the
/// dense layer.
#[derive(Clone, Debug)]
pub struct CriticWeights {
    pub kernels: Vec<Tensor<3>>,
    pub biases: Vec<Option<Tensor<1>>>,
    pub dense_w: Tensor<2>,
    pub dense_b: Option<Tensor<1>>,
}

impl CriticWeights {
    /// The same weights cut from the autodiff graph.
    pub fn detach(&self) -> CriticWeights {
        CriticWeights {
            kernels: self.kernels.iter().map(|k| k.clone().detach()).collect(),
            biases: self.biases.iter().map(|b| b.clone().map(Tensor::detach)).collect(),
            dense_w: self.dense_w.clone().detach(),
            dense_b: self.dense_b.clone().map(Tensor::detach),
        }
    }
}

fn conv_options() -> ConvOptions<1> {
    ConvOptions::new([STRIDE], [PADDING], [1], 1)
}

impl Critic {
    /// The normalised weights for this step (advances each power iteration once).
    pub fn weights(&self) -> CriticWeights {
        let kernels = self.convs.iter().map(SpectralConv1d::normalized_weight).collect();
        CriticWeights {
            kernels,
            biases: self.convs.iter().map(|c| c.bias.as_ref().map(|b| b.val())).collect(),
            dense_w: self.dense.weight.val(),
            dense_b: self.dense.bias.as_ref().map(|b| b.val()),
        }
    }

    /// Scores `[batch, 1]` of `x` (`[batch, 58, window]`); advances the power iterations.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<2> {
        self.forward_with(&self.weights(), x)
    }

    /// Scores `[batch, 1]` of `x` with given weights.
    pub fn forward_with(&self, w: &CriticWeights, x: Tensor<3>) -> Tensor<2> {
        self.check_input(&x);
        let mut h = x;
        for (k, b) in w.kernels.iter().zip(&w.biases) {
            h = leaky_relu(conv1d(h, k.clone(), b.clone(), conv_options()), LEAKY_SLOPE);
        }
        let [batch, channels, len] = h.dims();
        let flat = h.reshape([batch, channels * len]);
        burn::tensor::module::linear(flat, w.dense_w.clone(), w.dense_b.clone())
    }

    /// `∂D(x)_b/∂x_b` for every sample, `[batch, 58, window]`, by hand (module docs); advances the
    /// power iterations.
    pub fn input_gradient(&self, x: Tensor<3>) -> Tensor<3> {
        self.input_gradient_with(&self.weights(), x)
    }

    /// [`Self::input_gradient`] with given weights: differentiable in them, not in `x`.
    pub fn input_gradient_with(&self, w: &CriticWeights, x: Tensor<3>) -> Tensor<3> {
        self.check_input(&x);
        let [batch, _, _] = x.dims();
        // Forward on values only, to read the LeakyReLU masks and the input length of each layer.
        let mut h = x.detach();
        let mut masks = Vec::with_capacity(w.kernels.len());
        let mut lengths = Vec::with_capacity(w.kernels.len());
        for (k, b) in w.kernels.iter().zip(&w.biases) {
            lengths.push(h.dims()[2]);
            let a = conv1d(h, k.clone().detach(), b.clone().map(Tensor::detach), conv_options());
            let positive = a.clone().greater_elem(0.0).float();
            masks.push(positive.mul_scalar(1.0 - LEAKY_SLOPE).add_scalar(LEAKY_SLOPE));
            h = leaky_relu(a, LEAKY_SLOPE);
        }
        let [_, channels, len] = h.dims();
        let mut g: Tensor<3> = w.dense_w.clone().reshape([1, channels, len]).expand([batch, channels, len]);
        for ((k, mask), l_in) in w.kernels.iter().zip(masks).zip(lengths).rev() {
            g = g * mask;
            let l_out = g.dims()[2];
            // conv_transpose gives (l_out − 1)·stride − 2·padding + kernel + padding_out frames.
            let padding_out = l_in + 2 * PADDING - ((l_out - 1) * STRIDE + KERNEL);
            let options = ConvTransposeOptions::new([STRIDE], [PADDING], [padding_out], [1], 1);
            g = conv_transpose1d(g, k.clone(), None, options);
        }
        g
    }

    /// WGAN-GP's penalty `mean_b (‖∇ₓD(x̂_b)‖₂ − 1)²` at `x_hat` (Gulrajani et al. 2017, Eq. 3),
    /// differentiable in the weights. `eps` keeps the norm's gradient finite at 0.
    pub fn gradient_penalty_with(&self, w: &CriticWeights, x_hat: Tensor<3>) -> Tensor<1> {
        let g = self.input_gradient_with(w, x_hat);
        let [batch, c, t] = g.dims();
        let norm = g.reshape([batch, c * t]).square().sum_dim(1).add_scalar(1e-12).sqrt();
        (norm - 1.0).square().mean()
    }

    fn check_input(&self, x: &Tensor<3>) {
        let [_, c, t] = x.dims();
        assert_eq!(
            (c, t),
            (CRITIC_CHANNELS, self.window),
            "critic input is [batch, {c}, {t}], expected [batch, {CRITIC_CHANNELS}, {}]",
            self.window
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::{Distribution, TensorData};
    use inbetween_nn::backend;

    fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
        t.into_data().convert::<f32>().try_into_vec::<f32>().unwrap()
    }

    fn random_input(batch: usize, window: usize, seed: u64, device: &Device) -> Tensor<3> {
        backend::seeded(device, seed, || {
            Tensor::random([batch, CRITIC_CHANNELS, window], Distribution::Normal(0.0, 1.0), device)
        })
    }

    #[test]
    fn model_critic_scores_windows_of_its_length() {
        let device = backend::cpu();
        let critic = backend::seeded_module(&device, 1, |d| CriticConfig::new(100).init(d));
        assert_eq!(CriticConfig::new(100).lengths(), [50, 25, 13, 7]);
        assert_eq!(CriticConfig::new(16).lengths(), [8, 4, 2, 1]);
        let s = critic.forward(random_input(3, 100, 2, &device));
        assert_eq!(s.dims(), [3, 1]);
        assert!(values(s).iter().all(|v| v.is_finite()));
    }

    /// Hand ∇ₓD equals autodiff's gradient of Σ_b D(x)_b w.r.t. x (samples are independent), for an
    /// even and an odd window (the output padding of the transposed convolutions differs).
    #[test]
    fn model_critic_hand_input_gradient_equals_autodiff() {
        let device = backend::cpu_autodiff();
        for (window, seed) in [(16usize, 3u64), (23, 4)] {
            let critic = backend::seeded_module(&device, seed, |d| CriticConfig::new(window).init(d));
            let w = critic.weights().detach();
            let x = random_input(2, window, seed + 10, &device).detach().require_grad();
            let hand = values(critic.input_gradient_with(&w, x.clone()));
            let grads = critic.forward_with(&w, x.clone()).sum().backward();
            let auto = values(x.grad(&grads).expect("input gradient"));
            assert_eq!(hand.len(), auto.len());
            let worst = hand.iter().zip(&auto).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
            let scale = auto.iter().map(|v| v.abs()).fold(0.0f32, f32::max);
            assert!(scale > 1e-4, "gradient is not trivially zero: {scale}");
            assert!(worst < 1e-5, "window {window}: hand vs autodiff differ by {worst} (scale {scale})");
        }
    }

    /// The penalty's gradient w.r.t. a raw conv kernel entry and a dense weight matches central finite
    /// differences. Many power iterations make σ(W) exact, so the normalisation is a function of W.
    #[test]
    fn model_critic_penalty_parameter_gradient_matches_finite_differences() {
        let device = backend::cpu_autodiff();
        let config = CriticConfig { window: 16, n_power_iterations: 60 };
        let critic = backend::seeded_module(&device, 5, |d| config.init(d));
        let x = random_input(3, 16, 6, &device).detach();
        let penalty = |c: &Critic| c.gradient_penalty_with(&c.weights(), x.clone());
        let grads = penalty(&critic).backward();
        let kernel_grad = values(critic.convs[1].weight.val().grad(&grads).expect("kernel gradient"));
        let dense_grad = values(critic.dense.weight.val().grad(&grads).expect("dense gradient"));

        let plain = backend::cpu();
        let base = critic.valid();
        let perturbed_penalty = |which: usize, index: usize, delta: f32| -> f64 {
            let mut c = base.clone();
            if which == 0 {
                let w = c.convs[1].weight.val();
                let dims = w.dims();
                let mut v = values(w);
                v[index] += delta;
                c.convs[1].weight = burn::module::Param::from_data(TensorData::new(v, dims), &plain);
            } else {
                let w = c.dense.weight.val();
                let dims = w.dims();
                let mut v = values(w);
                v[index] += delta;
                c.dense.weight = burn::module::Param::from_data(TensorData::new(v, dims), &plain);
            }
            let p = c.gradient_penalty_with(&c.weights(), x.clone().to_device(&plain));
            f64::from(p.into_scalar::<f32>())
        };
        // The largest-gradient entry, where f32 differences are meaningful.
        let argmax = |g: &[f32]| (0..g.len()).max_by(|a, b| g[*a].abs().total_cmp(&g[*b].abs())).unwrap();
        // h = 1e-3: large steps cross LeakyReLU kinks (measured: h = 1e-2 gives the wrong sign).
        let h = 1e-3f32;
        for (which, grad) in [(0usize, &kernel_grad), (1, &dense_grad)] {
            let i = argmax(grad);
            let fd = (perturbed_penalty(which, i, h) - perturbed_penalty(which, i, -h)) / (2.0 * f64::from(h));
            let g = f64::from(grad[i]);
            println!(
                "penalty gradient, {} entry {i}: autodiff {g:.6}, finite differences {fd:.6}",
                ["kernel", "dense"][which]
            );
            assert!(g.abs() > 1e-4, "gradient too small to compare: {g}");
            assert!((fd - g).abs() < 0.05 * g.abs(), "autodiff {g} vs finite differences {fd}");
        }
    }
}
