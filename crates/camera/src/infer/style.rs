//! Style codes z (§4.1): per-behaviour codes averaged over seeded synthetic sequences (computed
//! once at training time and stored in the weights card, see [`crate::weights`]), and codes
//! extracted from a user's reference clip.

use super::FastModel;
use crate::dataset::{Behaviour, Dataset, BEHAVIOURS, DOWNSAMPLE};
use crate::features::{encode_camera, encode_character, CharacterFeatures};
use crate::model::STYLE_STEPS;
use crate::toric::Toric;
use crate::CameraError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A style code with the name it is reported under.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Style {
    pub name: String,
    pub code: Vec<f32>,
}

/// A style code named after the behaviour it was averaged from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NamedStyle {
    pub behaviour: Behaviour,
    pub main_is_a: bool,
    pub code: Vec<f32>,
}

/// Seed and scene count of the synthetic sequences the stored behaviour codes average over.
pub const BEHAVIOUR_STYLE_SEED: u64 = 777;
pub const BEHAVIOUR_STYLE_SCENES: usize = 2;

impl FastModel {
    /// Style codes of the dataset's behaviours: the mean z over seeded sequences (main = A or B).
    pub fn behaviour_styles(&self, seed: u64, scenes: usize) -> Vec<NamedStyle> {
        let data = Dataset::generate(seed, scenes, crate::dataset::SCENE_FRAMES);
        let mut out = Vec::new();
        for b in BEHAVIOURS {
            for main_is_a in [true, false] {
                let codes: Vec<Vec<f32>> = data
                    .sequences
                    .iter()
                    .filter(|s| s.behaviour == b && s.main_is_a == main_is_a)
                    .map(|s| {
                        let (c, x) = s.encoded(DOWNSAMPLE);
                        self.extract_style(&c[..STYLE_STEPS], &x[..STYLE_STEPS])
                    })
                    .collect();
                let mut mean = vec![0.0; self.config.style_dim];
                for z in &codes {
                    for (m, v) in mean.iter_mut().zip(z) {
                        *m += v / codes.len() as f32;
                    }
                }
                out.push(NamedStyle { behaviour: b, main_is_a, code: mean });
            }
        }
        out
    }
}

/// The code of `behaviour` with the main character on the left, from `styles`.
pub fn behaviour_code(styles: &[NamedStyle], behaviour: Behaviour) -> Option<Style> {
    styles
        .iter()
        .find(|s| s.behaviour == behaviour && s.main_is_a)
        .map(|s| Style { name: behaviour.name().into(), code: s.code.clone() })
}

/// A reference clip for style extraction: Eq. 1 and Eq. 2 features per frame (30 fps). A dataset
/// [`crate::dataset::Sequence`] file is one.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReferenceClip {
    pub characters: Vec<CharacterFeatures>,
    pub camera: Vec<Toric>,
}

impl ReferenceClip {
    /// Style code of the clip; needs at least 50 frames (300 recommended, §4.5).
    pub fn style(&self, model: &FastModel, origin: &Path) -> Result<Vec<f32>, CameraError> {
        let n = self.characters.len().min(self.camera.len());
        if n < DOWNSAMPLE * 10 {
            return Err(CameraError::invalid(
                origin,
                format!("reference clip has {n} frames; at least {} are needed (300 recommended)", DOWNSAMPLE * 10),
            ));
        }
        let chars: Vec<_> = (0..n).step_by(DOWNSAMPLE).map(|i| encode_character(&self.characters[i])).collect();
        let cams: Vec<_> = (0..n).step_by(DOWNSAMPLE).map(|i| encode_camera(&self.camera[i])).collect();
        Ok(model.extract_style(&chars, &cams))
    }
}
