//! Inference: the trained networks in plain Rust, style codes, and keyframed generation with the
//! beyond-the-paper extras (exact keyframes by residual correction, a causal live mode).
//!
//! | module | what |
//! |---|---|
//! | [`networks`] | [`FastModel`]: extractor (§4.1), H (Eq. 6), generator step (Eq. 3) on `nn::runtime` layers |
//! | [`rollout`] | [`Rollout`]: one trajectory stepped every 5th frame, restarts through H; shared by generation, the causal mode, the bench and the examples |
//! | [`keys`] | the keyframes file ([`Keys`]) and its validation against a scene |
//! | [`style`] | per-behaviour style codes ([`NamedStyle`]) and reference clips ([`ReferenceClip`]) |
//! | [`track`] | what both modes return: [`GeneratedTrack`], its frames and key misses |
//! | [`generate`] | [`GenerateJob`]: validate, run the network (offline, or the causal mode), Catmull-Rom fill, key correction, world poses |
//! | [`causal`] | [`CausalCamera`]: one frame at a time, no look-ahead (uses [`track`], not [`generate`]) |
//!
//! The curve math (Catmull-Rom fill, key correction) is `inbetween_core::curve`.

pub mod causal;
pub mod generate;
pub mod keys;
pub mod networks;
pub mod reference_gltf;
pub mod rollout;
pub mod style;
pub mod track;

use crate::features::{CAM_DIM, CHAR_ENC};
use crate::model::MAP_FRAMES;
use crate::toric::Toric;

pub use causal::CausalCamera;
pub use generate::{generate_causal, GenerateJob, GenerateLimits, GenerateOptions};
pub use keys::{example_keys, KeyCamera, KeyPose, Keyframe, Keys, ResolvedKey};
pub use networks::{FastModel, Scratch, StepIn};
pub use reference_gltf::reference_from_gltf;
pub use rollout::Rollout;
pub use style::{NamedStyle, ReferenceClip, Style};
pub use track::{CameraFrame, GeneratedTrack, KeyResidual};

/// x^c as the networks see it (Eq. 2 order, f32).
pub type Cam = [f32; CAM_DIM];
/// Encoded x^v.
pub type Chr = [f32; CHAR_ENC];
/// The generator's key input K: the key's x^c, then the encoded x^v at the key.
pub type KeyVec = [f32; CAM_DIM + CHAR_ENC];

/// K from a key's camera and the character features there (Eq. 3).
pub fn key_vector(camera: &Cam, character: &Chr) -> KeyVec {
    let mut v = [0.0; CAM_DIM + CHAR_ENC];
    v[..CAM_DIM].copy_from_slice(camera);
    v[CAM_DIM..].copy_from_slice(character);
    v
}

/// H's input for a camera at `camera` moving at `velocity` (x^c per second; none = still): the
/// [`MAP_FRAMES`] network steps (1/6 s apart, [`crate::dataset::step_frames`]) that end on `camera`.
pub fn velocity_frames(camera: &Toric, velocity: Option<[f64; 6]>) -> [Cam; MAP_FRAMES] {
    let v = velocity.unwrap_or([0.0; 6]);
    let dt = crate::dataset::DOWNSAMPLE as f64 / crate::dataset::FPS;
    std::array::from_fn(|i| {
        let back = (MAP_FRAMES - 1 - i) as f64 * dt;
        std::array::from_fn(|j| (camera.to_array()[j] - v[j] * back) as f32)
    })
}

/// ‖a − b‖₂ over the six Toric values: the error and key-miss measure of the paper's tables.
pub fn toric_distance(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    (0..6).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// [`toric_distance`] of network values.
pub fn cam_distance(a: &Cam, b: &Cam) -> f64 {
    a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>().sqrt()
}

/// A small randomly initialised model for tests: `hidden` units, weights drawn under `seed`.
#[cfg(test)]
pub(crate) fn test_model(hidden: usize, seed: u64) -> FastModel {
    let device = inbetween_nn::backend::cpu();
    let cfg = crate::model::ModelConfig { hidden, tta_dim: 8, ..crate::model::ModelConfig::default() };
    FastModel::from_burn(&inbetween_nn::backend::seeded_module(&device, seed, |d| cfg.init(d)), cfg)
}
