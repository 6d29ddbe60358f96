//! Spectral normalisation (Miyato et al. 2018, "Spectral Normalization for Generative
//! Adversarial Networks", Eq. 8 and Algorithm 1), which burn does not provide.
//!
//! The weight is divided by an estimate of its largest singular value σ(W):
//! ```text
//! v ← Wᵀu / ‖Wᵀu‖,   u ← Wv / ‖Wv‖        (power iteration, Algorithm 1; W seen as [out, in])
//! σ(W) ≈ uᵀ W v,     W_SN = W / σ(W)      (Eq. 8)
//! ```
//! `u` persists between calls as module state (a [`RunningState`], saved with the record), so
//! one iteration per forward is enough once training is under way. As in Algorithm 1, `u` and `v`
//! are treated as constants for the gradient; σ is differentiated through `W`.

use burn::config::Config;
use burn::module::{Module, Param, RunningState};
use burn::nn::{Initializer, Linear, LinearConfig};
use burn::tensor::module::conv1d;
use burn::tensor::ops::ConvOptions;
use burn::tensor::{Device, Distribution, Tensor};

const NORM_EPS: f64 = 1e-12;

fn normalize(x: Tensor<1>) -> Tensor<1> {
    let norm = x.clone().square().sum().sqrt().add_scalar(NORM_EPS);
    x / norm
}

fn random_unit_vector(len: usize, device: &Device) -> Tensor<1> {
    normalize(Tensor::random([len], Distribution::Normal(0.0, 1.0), device))
}

/// `n` power iterations on the detached matrix `m` (`[rows, cols]`) from `u` (`[rows]`).
/// Returns the new `u` and `v` (`[cols]`), both detached.
fn power_iteration(m: Tensor<2>, u: Tensor<1>, n: usize) -> (Tensor<1>, Tensor<1>) {
    let [rows, cols] = m.dims();
    let mut u = u;
    let mut v = Tensor::zeros([cols], &m.device());
    for _ in 0..n.max(1) {
        v = normalize(m.clone().transpose().matmul(u.reshape([rows, 1])).reshape([cols]));
        u = normalize(m.clone().matmul(v.clone().reshape([cols, 1])).reshape([rows]));
    }
    (u, v)
}

/// σ(W) ≈ uᵀ W v as a `[1]` tensor, differentiable through `m`.
fn sigma_estimate(m: Tensor<2>, u: Tensor<1>, v: Tensor<1>) -> Tensor<1> {
    let [rows, cols] = m.dims();
    u.reshape([1, rows]).matmul(m).matmul(v.reshape([cols, 1])).reshape([1])
}

/// Shared state of a spectrally normalised layer: the persistent left singular vector `u`.
#[derive(Module, Debug)]
pub struct SpectralState {
    /// Estimate of the leading left singular vector of the weight seen as `[out, in]`.
    pub u: RunningState<Tensor<1>>,
    /// Power iterations per forward pass (≥ 1).
    pub n_power_iterations: usize,
}

impl SpectralState {
    fn new(rows: usize, n_power_iterations: usize, device: &Device) -> Self {
        Self { u: RunningState::new(random_unit_vector(rows, device)), n_power_iterations: n_power_iterations.max(1) }
    }

    /// Advance the power iteration on `m` (`[out, in]`), store `u`, and return `m / σ` and σ.
    fn normalize_matrix(&self, m: Tensor<2>) -> (Tensor<2>, Tensor<1>) {
        let u0 = self.u.value_sync().to_device(&m.device()).detach();
        let (u, v) = power_iteration(m.clone().detach(), u0, self.n_power_iterations);
        self.u.update(u.clone().detach());
        // burn's RunningState holds an update pending until the next `value_sync`, and records read
        // the committed value: commit now, so a checkpoint holds this `u` and a resumed run is exact.
        let _ = self.u.value_sync();
        let sigma = sigma_estimate(m.clone(), u, v);
        let [rows, cols] = m.dims();
        (m / sigma.clone().reshape([1, 1]).expand([rows, cols]), sigma)
    }
}

/// Configuration of a [`SpectralLinear`].
#[derive(Config, Debug)]
pub struct SpectralLinearConfig {
    /// Input features.
    pub d_input: usize,
    /// Output features.
    pub d_output: usize,
    /// Whether the layer has a bias (not normalised).
    #[config(default = true)]
    pub bias: bool,
    /// Power iterations per forward pass.
    #[config(default = 1)]
    pub n_power_iterations: usize,
}

/// Linear layer whose weight is divided by its spectral norm at every forward pass.
#[derive(Module, Debug)]
pub struct SpectralLinear {
    /// The raw (unnormalised) layer; its weight is `[d_input, d_output]`.
    pub linear: Linear,
    /// Power-iteration state.
    pub spectral: SpectralState,
}

impl SpectralLinearConfig {
    /// Build the layer on `device`.
    pub fn init(&self, device: &Device) -> SpectralLinear {
        SpectralLinear {
            linear: LinearConfig::new(self.d_input, self.d_output).with_bias(self.bias).init(device),
            spectral: SpectralState::new(self.d_output, self.n_power_iterations, device),
        }
    }
}

impl SpectralLinear {
    /// The normalised weight `W / σ(W)` (`[d_input, d_output]`); advances the power iteration.
    pub fn normalized_weight(&self) -> Tensor<2> {
        // burn stores W as [in, out]; the power iteration works on [out, in].
        let (m, _) = self.spectral.normalize_matrix(self.linear.weight.val().transpose());
        m.transpose()
    }

    /// Current estimate of σ(W) of the raw weight; advances the power iteration.
    pub fn sigma(&self) -> f32 {
        let (_, sigma) = self.spectral.normalize_matrix(self.linear.weight.val().transpose());
        sigma.into_scalar()
    }

    /// `x · W/σ(W) + b` for `x` of shape `[..., d_input]`.
    pub fn forward<const D: usize>(&self, x: Tensor<D>) -> Tensor<D> {
        let weight = self.normalized_weight();
        let bias = self.linear.bias.as_ref().map(Param::val);
        burn::tensor::module::linear(x, weight, bias)
    }
}

/// Configuration of a [`SpectralConv1d`].
#[derive(Config, Debug)]
pub struct SpectralConv1dConfig {
    /// Input channels.
    pub channels_in: usize,
    /// Output channels.
    pub channels_out: usize,
    /// Kernel width.
    pub kernel_size: usize,
    /// Stride.
    #[config(default = 1)]
    pub stride: usize,
    /// Symmetric zero padding on both ends of the time axis.
    #[config(default = 0)]
    pub padding: usize,
    /// Dilation.
    #[config(default = 1)]
    pub dilation: usize,
    /// Whether the layer has a bias (not normalised).
    #[config(default = true)]
    pub bias: bool,
    /// Power iterations per forward pass.
    #[config(default = 1)]
    pub n_power_iterations: usize,
}

/// 1-D convolution whose kernel, reshaped to `[out, in·k]` (Miyato et al. Sec. 2.1), is divided
/// by its spectral norm at every forward pass.
#[derive(Module, Debug)]
pub struct SpectralConv1d {
    /// Kernel `[channels_out, channels_in, kernel_size]`.
    pub weight: Param<Tensor<3>>,
    /// Bias `[channels_out]`.
    pub bias: Option<Param<Tensor<1>>>,
    /// Power-iteration state.
    pub spectral: SpectralState,
    /// Stride.
    pub stride: usize,
    /// Symmetric padding.
    pub padding: usize,
    /// Dilation.
    pub dilation: usize,
}

impl SpectralConv1dConfig {
    /// Build the layer on `device` (uniform ±1/√(in·k) initialisation, like burn's Conv1d).
    pub fn init(&self, device: &Device) -> SpectralConv1d {
        let fan_in = self.channels_in * self.kernel_size;
        let init = Initializer::KaimingUniform { gain: 1.0 / 3f64.sqrt(), fan_out_only: false };
        let shape = [self.channels_out, self.channels_in, self.kernel_size];
        let weight = init.init_with(shape, Some(fan_in), None, device);
        let bias = self.bias.then(|| init.init_with([self.channels_out], Some(fan_in), None, device));
        SpectralConv1d {
            weight,
            bias,
            spectral: SpectralState::new(self.channels_out, self.n_power_iterations, device),
            stride: self.stride,
            padding: self.padding,
            dilation: self.dilation,
        }
    }
}

impl SpectralConv1d {
    /// The normalised kernel `W / σ(W)`; advances the power iteration.
    pub fn normalized_weight(&self) -> Tensor<3> {
        let w = self.weight.val();
        let [out, inp, k] = w.dims();
        let (m, _) = self.spectral.normalize_matrix(w.reshape([out, inp * k]));
        m.reshape([out, inp, k])
    }

    /// `[batch, channels_in, length]` → `[batch, channels_out, length_out]`.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let options = ConvOptions::new([self.stride], [self.padding], [self.dilation], 1);
        conv1d(x, self.normalized_weight(), self.bias.as_ref().map(Param::val), options)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend;

    /// Largest singular value of a small row-major `rows × cols` matrix, from the eigenvalues of
    /// MᵀM by cyclic Jacobi rotations in f64 (independent of the power iteration under test).
    fn largest_singular_value(m: &[f64], rows: usize, cols: usize) -> f64 {
        let mut a = vec![0.0; cols * cols];
        for i in 0..cols {
            for j in 0..cols {
                a[i * cols + j] = (0..rows).map(|r| m[r * cols + i] * m[r * cols + j]).sum();
            }
        }
        for _sweep in 0..100 {
            let off: f64 = (0..cols)
                .flat_map(|i| (0..cols).filter(move |&j| j != i).map(move |j| (i, j)))
                .map(|(i, j)| a[i * cols + j].powi(2))
                .sum();
            if off < 1e-24 {
                break;
            }
            for p in 0..cols {
                for q in p + 1..cols {
                    let apq = a[p * cols + q];
                    if apq.abs() < 1e-300 {
                        continue;
                    }
                    let theta = (a[q * cols + q] - a[p * cols + p]) / (2.0 * apq);
                    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                    let t = if theta == 0.0 { 1.0 } else { t };
                    let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
                    for k in 0..cols {
                        let (akp, akq) = (a[k * cols + p], a[k * cols + q]);
                        a[k * cols + p] = c * akp - s * akq;
                        a[k * cols + q] = s * akp + c * akq;
                    }
                    for k in 0..cols {
                        let (apk, aqk) = (a[p * cols + k], a[q * cols + k]);
                        a[p * cols + k] = c * apk - s * aqk;
                        a[q * cols + k] = s * apk + c * aqk;
                    }
                }
            }
        }
        (0..cols).map(|i| a[i * cols + i]).fold(0.0, f64::max).sqrt()
    }

    fn to_f64(t: Tensor<2>) -> Vec<f64> {
        t.into_data().try_to_vec::<f32>().unwrap().into_iter().map(f64::from).collect()
    }

    #[test]
    fn jacobi_reference_is_right_on_a_known_matrix() {
        // diag(3, 1) rotated: singular values 3 and 1.
        let (c, s) = (0.6, 0.8);
        let m = [3.0 * c, -s, 3.0 * s, c];
        assert!((largest_singular_value(&m, 2, 2) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn spectral_linear_brings_largest_singular_value_to_one() {
        let device = backend::cpu();
        let layer = backend::seeded_module(&device, 11, |d| SpectralLinearConfig::new(6, 4).init(d));
        let raw = to_f64(layer.linear.weight.val());
        let sigma_ref = largest_singular_value(&raw, 6, 4);
        // The persistent u converges over successive forward passes.
        for _ in 0..30 {
            let _ = layer.forward(Tensor::<2>::ones([2, 6], &device));
        }
        let sigma = layer.sigma() as f64;
        assert!((sigma - sigma_ref).abs() < 1e-4 * sigma_ref, "σ {sigma} vs reference {sigma_ref}");
        let normalized = to_f64(layer.normalized_weight());
        let top = largest_singular_value(&normalized, 6, 4);
        assert!((top - 1.0).abs() < 1e-4, "largest singular value after normalisation: {top}");
        assert!(sigma_ref > 0.3, "raw weight should not already be normalised: {sigma_ref}");
    }

    #[test]
    fn spectral_conv1d_normalises_the_reshaped_kernel() {
        let device = backend::cpu();
        let conv = backend::seeded_module(&device, 12, |d| {
            SpectralConv1dConfig::new(3, 5, 3).with_padding(1).with_n_power_iterations(20).init(d)
        });
        let x =
            backend::seeded(&device, 14, || Tensor::<3>::random([2, 3, 9], Distribution::Normal(0.0, 1.0), &device));
        let y = conv.forward(x);
        assert_eq!(y.dims(), [2, 5, 9]);
        let normalized = to_f64(conv.normalized_weight().reshape([5, 9]));
        let top = largest_singular_value(&normalized, 5, 9);
        assert!((top - 1.0).abs() < 1e-3, "largest singular value after normalisation: {top}");
    }

    #[test]
    fn gradient_flows_to_the_raw_weight() {
        let device = backend::cpu_autodiff();
        let layer = backend::seeded_module(&device, 13, |d| SpectralLinearConfig::new(3, 2).init(d));
        let loss = layer.forward(Tensor::<2>::ones([4, 3], &device)).square().sum();
        let grads = loss.backward();
        let g = layer.linear.weight.val().grad(&grads).expect("weight gradient");
        let g = g.abs().sum().into_scalar::<f32>();
        assert!(g.is_finite() && g > 0.0, "gradient magnitude {g}");
    }
}
