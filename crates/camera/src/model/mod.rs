//! The three networks of §4 and Appendix A.1, trained together end to end (§4.4):
//! the gating LSTM [`extractor`] (reference clip → style code z ∈ R⁴), the autoregressive
//! [`generator`] (Eq. 3) and the hidden-state [`mapping`] H (Eq. 6).
//!
//! Sizes follow Appendix A.1: extractor LSTM(14 → 256) + FC(256 → 4); generator FC+ReLU(160 → 256),
//! FC+ReLU(256 → 256), LSTM(256 → 256), FC+ReLU(256 → 256), FC(256 → 6); mapping FC+ReLU(34 → 256),
//! FC(256 → 2·256), each ReLU leaky with slope `leaky_slope` (0.01 by default, 0 = ReLU). Our inputs: x^v is encoded in 8 values (`features::CHAR_ENC`, sin/cos of the
//! angles), x^c has the 6 values of Eq. 2, so the extractor sees 8 + 6 = 14 values per step and the
//! generator z (4) + x^c_{i−1} (6) + x^v_i (8) + K (6 + 8) + z_tta (128) = 160, as in the paper.
//! The generator predicts the change of x^c from the previous step (a residual): the same
//! function as Eq. 3, easier to learn in a short CPU training. With `arrival_base` (default) the
//! residual is taken from the straight Toric line to the next key instead (one step of it, a fixed
//! function of x^c_{i−1}, K and tta, all inputs of Eq. 3), so an untrained correction gives plain
//! Toric interpolation and the network only learns how the style departs from a line.

pub mod extractor;
pub mod generator;
pub mod mapping;

use crate::features::{CAM_DIM, CHAR_ENC};
use burn::module::Module;
use burn::tensor::Device;
use serde::{Deserialize, Serialize};

pub use extractor::Extractor;
pub use generator::Generator;
pub use mapping::Mapping;

/// Steps of camera history the mapping H reads (Eq. 6).
pub const MAP_FRAMES: usize = 5;
/// Reference-clip length the extractor reads, in (downsampled) steps: 300 frames / 5.
pub const STYLE_STEPS: usize = 60;

/// Sizes of the networks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModelConfig {
    pub hidden: usize,
    pub style_dim: usize,
    pub tta_dim: usize,
    /// tta cap in frames (§4.2: 200).
    pub tta_max: f32,
    /// The generator's residual starts from the straight Toric line to the next key: x^c_i =
    /// x^c_{i−1} + w·(x^c_K − x^c_{i−1}) + Δ with w = 5 / (min(tta, tta_max) + 5) (see
    /// [`ModelConfig::arrival_weight`]); without it x^c_i = x^c_{i−1} + Δ. Weights saved before this
    /// option existed read as `false`.
    #[serde(default)]
    pub arrival_base: bool,
    /// Negative slope of the encoder / decoder / H activations: 0 is the paper's ReLU; a leaky
    /// ReLU keeps a gradient through units that a short small-batch training would otherwise
    /// switch off for good (see the README). Older summaries read as 0.
    #[serde(default)]
    pub leaky_slope: f32,
}

impl Default for ModelConfig {
    fn default() -> Self {
        ModelConfig { hidden: 256, style_dim: 4, tta_dim: 128, tta_max: 200.0, arrival_base: true, leaky_slope: 0.01 }
    }
}

impl ModelConfig {
    pub fn extractor_input(&self) -> usize {
        CHAR_ENC + CAM_DIM
    }

    pub fn generator_input(&self) -> usize {
        self.style_dim + CAM_DIM + CHAR_ENC + (CAM_DIM + CHAR_ENC) + self.tta_dim
    }

    pub fn mapping_input(&self) -> usize {
        self.style_dim + MAP_FRAMES * CAM_DIM
    }

    pub fn tta(&self) -> inbetween_nn::tta::TtaEmbedding {
        inbetween_nn::tta::TtaEmbedding::new(self.tta_dim, self.tta_max)
    }

    /// Share of the remaining way to the key that the straight line covers in this step:
    /// `tta_frames` frames are left after it, so 1 at the key and 5 / (tta + 5) before (tta capped
    /// like its embedding); 0 when [`ModelConfig::arrival_base`] is off.
    pub fn arrival_weight(&self, tta_frames: f32) -> f32 {
        if !self.arrival_base {
            return 0.0;
        }
        let step = crate::dataset::DOWNSAMPLE as f32;
        step / (tta_frames.clamp(0.0, self.tta_max) + step)
    }

    pub fn init(&self, device: &Device) -> CameraModel {
        CameraModel {
            extractor: Extractor::new(self, device),
            generator: Generator::new(self, device),
            mapping: Mapping::new(self, device),
        }
    }
}

/// All three networks, trained jointly.
#[derive(Module, Debug)]
pub struct CameraModel {
    pub extractor: Extractor,
    pub generator: Generator,
    pub mapping: Mapping,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrival_weight_reaches_one_at_the_key_and_is_off_for_old_configs() {
        let c = ModelConfig::default();
        assert_eq!(c.arrival_weight(0.0), 1.0);
        assert!((c.arrival_weight(5.0) - 0.5).abs() < 1e-6);
        assert!((c.arrival_weight(195.0) - 5.0 / 200.0).abs() < 1e-6);
        assert_eq!(c.arrival_weight(400.0), c.arrival_weight(200.0), "capped like the tta embedding");
        // Summaries written before the option existed load with the plain residual.
        let old: ModelConfig =
            serde_json::from_str(r#"{"hidden":256,"style_dim":4,"tta_dim":128,"tta_max":200.0}"#).unwrap();
        assert!(!old.arrival_base);
        assert_eq!(old.arrival_weight(0.0), 0.0);
    }
}
