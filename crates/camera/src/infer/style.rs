//! Style codes z (§4.1): per-behaviour codes averaged over seeded synthetic sequences (computed
//! once at training time and stored in the weights card, see [`crate::weights`]), and codes
//! extracted from a user's reference clip.

use super::FastModel;
use crate::dataset::Scene;
use crate::dataset::{step_frames, Behaviour, Dataset, BEHAVIOURS, DOWNSAMPLE, FPS};
use crate::features::{encode_camera, encode_character, CharacterFeatures};
use crate::model::STYLE_STEPS;
use crate::toric::{from_pose, CameraPose, Lens, Toric};
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

/// A reference clip for style extraction: Eq. 1 and Eq. 2 features per frame at `fps` (30 when a
/// file does not say). A dataset [`crate::dataset::Sequence`] file is one.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReferenceClip {
    pub characters: Vec<CharacterFeatures>,
    pub camera: Vec<Toric>,
    /// Frames per second; the style is read every network step (1/6 s, [`step_frames`]).
    #[serde(default = "training_fps")]
    pub fps: f64,
}

fn training_fps() -> f64 {
    FPS
}

impl ReferenceClip {
    /// Style code of the clip, read every network step; needs at least 10 steps (50 frames at
    /// 30 fps; 60 steps recommended, §4.5).
    pub fn style(&self, model: &FastModel, origin: &Path) -> Result<Vec<f32>, CameraError> {
        let n = self.characters.len().min(self.camera.len());
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(CameraError::invalid(
                origin,
                format!("reference clip at {} fps: expected a positive rate", self.fps),
            ));
        }
        let step = step_frames(self.fps);
        let frames = |steps: f64| (steps * step).round() as usize;
        if n < frames(10.0) {
            return Err(CameraError::invalid(
                origin,
                format!(
                    "reference clip has {n} frames; at least {} are needed ({} recommended)",
                    frames(10.0),
                    frames(60.0)
                ),
            ));
        }
        // The frame of every step inside the clip (every 5th at 30 fps).
        let at: Vec<usize> = (0..).map(|s| (s as f64 * step).round() as usize).take_while(|&i| i < n).collect();
        let chars: Vec<_> = at.iter().map(|&i| encode_character(&self.characters[i])).collect();
        let cams: Vec<_> = at.iter().map(|&i| encode_camera(&self.camera[i])).collect();
        Ok(model.extract_style(&chars, &cams))
    }

    /// A reference clip from a camera's world poses over `scene`, one per frame from frame 0 (at
    /// most the scene's frames): each pose turned into Toric coordinates (Eq. 2) against the
    /// scene's first two characters ([`from_pose`]), their Eq. 1 features from the scene. The
    /// error names the first frame whose pose cannot frame both.
    pub fn from_poses(scene: &Scene, poses: &[CameraPose], lens: &Lens) -> Result<ReferenceClip, String> {
        if scene.characters.len() < 2 || poses.len() > scene.num_frames() {
            return Err(format!(
                "{} camera poses for a scene of {} frames and {} characters: expected at most one pose per frame \
                 and two characters",
                poses.len(),
                scene.num_frames(),
                scene.characters.len()
            ));
        }
        let (a, b) = (&scene.characters[0], &scene.characters[1]);
        let camera = poses
            .iter()
            .enumerate()
            .map(|(f, pose)| {
                from_pose(pose, a.frame(f).target(), b.frame(f).target(), lens).map_err(|e| {
                    format!("frame {f} ({:.2} s): the camera cannot frame both characters: {e}", f as f64 / scene.fps)
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut characters = scene.character_features(0, 1, true);
        characters.truncate(camera.len());
        Ok(ReferenceClip { characters, camera, fps: scene.fps })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::{example_keys, GenerateJob};
    use glam::DVec3;

    #[test]
    fn a_reference_from_camera_poses_reads_back_their_toric_track_and_names_a_bad_frame() {
        let scene = Scene::procedural(3, 120, 30.0);
        let model = crate::infer::test_model(16, 4);
        let style = Style { name: "test".into(), code: vec![0.0; 4] };
        let track = GenerateJob::new(&model, &scene, &example_keys(&scene, &[0, 119]), &style).run().unwrap();
        let poses: Vec<CameraPose> = track.frames.iter().map(|f| f.pose).collect();
        let clip = ReferenceClip::from_poses(&scene, &poses, &track.lens).unwrap();
        assert_eq!((clip.camera.len(), clip.characters.len()), (120, 120));
        for (got, f) in clip.camera.iter().zip(&track.frames) {
            let (g, w) = (got.to_array(), f.toric.to_array());
            assert!((0..6).all(|i| (g[i] - w[i]).abs() < 1e-9), "frame {}: {g:?} vs {w:?}", f.frame);
        }
        assert_eq!(clip.style(&model, Path::new("ref")).unwrap().len(), 4);
        // A pose turned away from both characters at frame 3.
        let mut away = poses.clone();
        let p = away[3].position;
        let (a, b) = (scene.characters[0].frame(3).target(), scene.characters[1].frame(3).target());
        away[3] = CameraPose::look_at(p, p + (p - (a + b) * 0.5) + DVec3::new(0.0, 0.01, 0.0));
        let e = ReferenceClip::from_poses(&scene, &away, &track.lens).unwrap_err();
        assert!(e.starts_with("frame 3 (0.10 s): the camera cannot frame both characters"), "{e}");
        let e = ReferenceClip::from_poses(&scene, &[poses[0]; 121], &track.lens).unwrap_err();
        assert!(e.contains("121 camera poses for a scene of 120 frames"), "{e}");
    }
}
