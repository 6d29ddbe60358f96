//! The synthetic dataset: procedural scenes filmed by the four behaviours, with left/right main
//! character and per-scene parameter variation (§4.5). Seeded, fast (pure geometry) and serialisable.

pub mod behaviours;
pub mod from_motion;
pub mod scene;

pub use behaviours::{film, Behaviour, BehaviourParams, BEHAVIOURS};
pub use from_motion::{
    scene_from_files, scene_from_motions, scene_from_motions_in_units, scene_from_motions_with, SceneNotes,
};
pub use scene::Scene;

use crate::features::{encode_camera, encode_character, CharacterFeatures, CAM_DIM, CHAR_ENC};
use crate::toric::{Lens, Toric};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// Frames per scene in the paper's synthetic set (1500 at 30 fps).
pub const SCENE_FRAMES: usize = 1500;
pub const FPS: f64 = 30.0;
/// The networks see every 5th frame (§4.5).
pub const DOWNSAMPLE: usize = 5;

/// Frames per network step in a scene at `fps`: the networks were trained on every 5th frame at
/// 30 fps ([`DOWNSAMPLE`], [`FPS`]: a step is 1/6 s), so a scene at another rate steps every
/// `5 · fps / 30` frames (20 at 120 fps, 4 at 24 fps; rounded to the nearest frame where that is not
/// whole) and its motion keeps the speed the networks learned.
pub fn step_frames(fps: f64) -> f64 {
    DOWNSAMPLE as f64 * fps / FPS
}

/// One filmed sequence: character features and the camera track, frame by frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sequence {
    pub scene_seed: u64,
    pub behaviour: Behaviour,
    pub main_is_a: bool,
    /// Which scene character is A (screen-left).
    pub a_index: usize,
    pub params: BehaviourParams,
    pub characters: Vec<CharacterFeatures>,
    pub camera: Vec<Toric>,
}

impl Sequence {
    pub fn len(&self) -> usize {
        self.camera.len()
    }

    pub fn is_empty(&self) -> bool {
        self.camera.is_empty()
    }

    /// Network-ready arrays at every `step`-th frame: (character encodings, camera features).
    pub fn encoded(&self, step: usize) -> (Vec<[f32; CHAR_ENC]>, Vec<[f32; CAM_DIM]>) {
        let idx = (0..self.len()).step_by(step);
        (
            idx.clone().map(|i| encode_character(&self.characters[i])).collect(),
            idx.map(|i| encode_camera(&self.camera[i])).collect(),
        )
    }
}

/// A set of filmed sequences.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dataset {
    pub seed: u64,
    pub lens: Lens,
    pub sequences: Vec<Sequence>,
}

impl Dataset {
    /// `scenes` procedural scenes of `frames` frames, each filmed by every behaviour with A or B as
    /// the main character (8 sequences per scene), each with freshly drawn parameters.
    pub fn generate(seed: u64, scenes: usize, frames: usize) -> Dataset {
        let lens = Lens::default();
        let mut sequences = Vec::with_capacity(scenes * 8);
        for i in 0..scenes {
            let scene_seed = seed.wrapping_mul(1_000_003).wrapping_add(i as u64);
            let scene = Scene::procedural(scene_seed, frames, FPS);
            let mut rng = inbetween_core::seed::rng(scene_seed ^ 0x5eed);
            for behaviour in BEHAVIOURS {
                for main_is_a in [true, false] {
                    sequences.push(film_sequence(&scene, scene_seed, behaviour, main_is_a, &mut rng, &lens));
                }
            }
        }
        Dataset { seed, lens, sequences }
    }

    pub fn save(&self, path: &std::path::Path) -> Result<(), crate::CameraError> {
        crate::write_json(path, self)
    }

    pub fn load(path: &std::path::Path) -> Result<Dataset, crate::CameraError> {
        crate::read_json(path)
    }
}

/// Films one sequence of `scene` with random A/B assignment and parameters.
pub fn film_sequence(
    scene: &Scene,
    scene_seed: u64,
    behaviour: Behaviour,
    main_is_a: bool,
    rng: &mut impl Rng,
    lens: &Lens,
) -> Sequence {
    let a_index = rng.random_range(0..2usize);
    let params = BehaviourParams::sample(rng);
    let camera = film(scene, a_index, 1 - a_index, main_is_a, behaviour, &params, lens);
    let characters = scene.character_features(a_index, 1 - a_index, main_is_a);
    Sequence { scene_seed, behaviour, main_is_a, a_index, params, characters, camera }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dataset_is_seeded_balanced_and_serialisable() {
        let d = Dataset::generate(4, 2, 200);
        assert_eq!(d.sequences.len(), 16);
        for b in BEHAVIOURS {
            assert_eq!(d.sequences.iter().filter(|s| s.behaviour == b).count(), 4);
        }
        assert_eq!(d.sequences.iter().filter(|s| s.main_is_a).count(), 8);
        assert_eq!(d, Dataset::generate(4, 2, 200));
        let (c, x) = d.sequences[0].encoded(DOWNSAMPLE);
        assert_eq!((c.len(), x.len()), (40, 40));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("d.json");
        d.save(&p).unwrap();
        let back = Dataset::load(&p).unwrap();
        assert_eq!(back.sequences.len(), 16);
        let (a, b) = (&back.sequences[5].camera[100], &d.sequences[5].camera[100]);
        assert!((a.theta - b.theta).abs() < 1e-12 && back.sequences[5].behaviour == d.sequences[5].behaviour);
    }
}
