//! The three networks of §4 and Appendix A.1, trained together end to end (§4.4):
//! the gating LSTM [`extractor`] (reference clip → style code z ∈ R⁴), the autoregressive
//! [`generator`] (Eq. 3) and the hidden-state [`mapping`] H (Eq. 6).
//!
//! Sizes follow Appendix A.1: extractor LSTM(14 → 256) + FC(256 → 4); generator FC+ReLU(160 → 256),
//! FC+ReLU(256 → 256), LSTM(256 → 256), FC+ReLU(256 → 256), FC(256 → 6); mapping FC+ReLU(34 → 256),
//! FC(256 → 2·256). Our inputs: x^v is encoded in 8 values (`features::CHAR_ENC`, sin/cos of the
//! angles), x^c has the 6 values of Eq. 2, so the extractor sees 8 + 6 = 14 values per step and the
//! generator z (4) + x^c_{i−1} (6) + x^v_i (8) + K (6 + 8) + z_tta (128) = 160, as in the paper.
//! The generator predicts the change of x^c from the previous step (a residual): the same
//! function as Eq. 3, easier to learn in a short CPU training.

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
}

impl Default for ModelConfig {
    fn default() -> Self {
        ModelConfig { hidden: 256, style_dim: 4, tta_dim: 128, tta_max: 200.0 }
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
