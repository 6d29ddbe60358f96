//! Causal, one-frame-at-a-time generation for live use (beyond the paper): character features
//! arrive frame by frame and a camera comes back at once. The network runs every 1/6 s (every 5th
//! frame at 30 fps, [`step_frames`]) with the features of that frame; frames in between extrapolate
//! the last network step linearly, so
//! nothing waits for the future. Keys (placed ahead by the user) can be announced at any time; a
//! live camera cannot go back, so it corrects nothing and reports its misses.

use super::keys::ResolvedKeys;
use super::track::{camera_frame, GeneratedTrack, KeyResidual};
use super::{key_vector, toric_distance, velocity_frames, Cam, FastModel, KeyVec, Rollout, Style};
use crate::dataset::Scene;
use crate::dataset::{step_frames, DOWNSAMPLE, FPS};
use crate::features::{decode_camera, encode_camera, encode_character, CharacterFeatures, CAM_DIM};
use crate::toric::{Lens, Toric};
use crate::CameraError;
use inbetween_nn::runtime::LstmState;

/// The live camera: a [`Rollout`] stepped every [`step_frames`] pushed frames.
pub struct CausalCamera<'a> {
    rollout: Rollout<'a>,
    cap: usize,
    frame: usize,
    /// Frames per network step at the scene's rate, and the steps taken.
    step: f64,
    steps: usize,
    velocity: Cam,
    key: Option<(usize, KeyVec)>,
}

impl<'a> CausalCamera<'a> {
    /// Starts at `start` (frame 0) with an optional velocity (x^c per second) through H.
    pub fn new(
        model: &'a FastModel,
        style: &[f32],
        start: &Toric,
        velocity: Option<[f64; 6]>,
        fps: f64,
    ) -> CausalCamera<'a> {
        let dt = DOWNSAMPLE as f64 / FPS;
        let v = velocity.unwrap_or([0.0; 6]);
        CausalCamera {
            rollout: Rollout::mapped(model, style, &velocity_frames(start, velocity)),
            cap: model.config.tta_max as usize,
            frame: 0,
            step: step_frames(fps),
            steps: 0,
            velocity: std::array::from_fn(|j| (v[j] * dt) as f32),
            key: None,
        }
    }

    /// The next keyframe: its frame, camera and the character features expected there. Replacing a
    /// key restarts the generator through H from the motion so far, as offline generation does at
    /// its keys.
    pub fn set_key(&mut self, frame: usize, camera: &Toric, character: &CharacterFeatures) {
        if self.key.is_some() {
            self.rollout.restart_from_arrival();
        }
        self.key = Some((frame, key_vector(&encode_camera(camera), &encode_character(character))));
    }

    /// Consumes the next frame's character features and returns that frame's camera.
    pub fn push(&mut self, character: &CharacterFeatures) -> Toric {
        self.frame += 1;
        // The frames of the last network step and of the next.
        let at = |n: usize| (n as f64 * self.step).round() as usize;
        let (prev, next_at) = (at(self.steps), at(self.steps + 1));
        let last = self.rollout.prev();
        if self.frame >= next_at {
            self.steps += 1;
            let chr = encode_character(character);
            // Times to arrival in the networks' 30 fps frames.
            let to_model = DOWNSAMPLE as f64 / self.step;
            let (tta_frames, key) = match self.key {
                Some((kf, v)) if kf >= self.frame => {
                    ((((kf - self.frame) as f64 * to_model).round() as usize).min(self.cap), v)
                }
                Some((_, v)) => (0, v),
                // No key yet: aim at holding the current camera, as far away as the tta cap.
                None => (self.cap, key_vector(&last, &chr)),
            };
            let next = self.rollout.step(&chr, &key, tta_frames);
            self.velocity = std::array::from_fn(|j| next[j] - last[j]);
            return decode_camera(&next);
        }
        let u = (self.frame - prev) as f32 / (next_at - prev).max(1) as f32;
        decode_camera(&std::array::from_fn::<f32, CAM_DIM, _>(|j| last[j] + self.velocity[j] * u))
    }

    /// The generator's recurrent state.
    pub fn state(&self) -> &LstmState {
        self.rollout.state()
    }
}

/// A whole track through [`CausalCamera`] (what [`super::GenerateJob::run`] calls in causal
/// mode): frame by frame, each key announced once the previous one has passed, no correction.
/// Key residuals report the misses.
pub(super) fn run_causal(
    model: &FastModel,
    style: &Style,
    scene: &Scene,
    lens: &Lens,
    keys: &ResolvedKeys,
) -> Result<GeneratedTrack, CameraError> {
    let k = &keys.keys;
    let (first, last) = (keys.first_frame(), keys.last_frame(scene));
    let feats = |f: usize, pair: (usize, usize)| {
        CharacterFeatures::compute(
            &scene.characters[pair.0].frame(f),
            &scene.characters[pair.1].frame(f),
            keys.main_is_a(pair),
        )
    };
    let mut live = CausalCamera::new(model, &style.code, &k[0].camera, k[0].velocity, scene.fps);
    let mut next = 1;
    let mut announced = 0;
    let mut frames = Vec::with_capacity(last - first + 1);
    let mut residuals = vec![KeyResidual { frame: first, residual: 0.0 }];
    let mut toric = k[0].camera;
    for frame in first..=last {
        let target = k.get(next).unwrap_or(&k[k.len() - 1]);
        if frame > first {
            // Each key is announced once, when the previous one has passed; the live clock counts
            // from the first key.
            if let Some(key) = k.get(next).filter(|_| announced < next) {
                live.set_key(key.frame - first, &key.camera, &feats(key.frame, key.pair));
                announced = next;
            }
            toric = live.push(&feats(frame, target.pair));
        }
        if let Some(key) = k.get(next).filter(|key| key.frame == frame) {
            residuals.push(KeyResidual { frame, residual: toric_distance(&toric.to_array(), &key.camera.to_array()) });
            next += 1;
        }
        frames.push(camera_frame(scene, frame, target.pair, toric, lens)?);
    }
    let max_corrected_residual = residuals.iter().map(|r| r.residual).fold(0.0, f64::max);
    Ok(GeneratedTrack {
        fps: scene.fps,
        style: style.name.clone(),
        style_code: style.code.clone(),
        lens: *lens,
        frames,
        key_residuals: residuals,
        max_corrected_residual,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::Scene;
    use crate::infer::{example_keys, GenerateJob, GenerateOptions, Style};
    use crate::model::MAP_FRAMES;

    fn small() -> FastModel {
        crate::infer::test_model(16, 4)
    }

    #[test]
    fn causal_mode_runs_the_network_every_fifth_frame_without_lookahead() {
        let fast = small();
        let scene = Scene::procedural(6, 60, 30.0);
        let feats = scene.character_features(0, 1, true);
        let keys = example_keys(&scene, &[0, 59]);
        let style = [0.1f32, 0.0, -0.2, 0.3];
        let mut live = CausalCamera::new(&fast, &style, &keys.keys[0].camera.toric().unwrap(), None, 30.0);
        live.set_key(59, &keys.keys[1].camera.toric().unwrap(), &feats[59]);
        let out: Vec<Toric> = (1..60).map(|f| live.push(&feats[f])).collect();
        // The same steps by hand.
        let mut state = fast.map_state(&style, &[encode_camera(&keys.keys[0].camera.toric().unwrap()); MAP_FRAMES]);
        let mut prev = encode_camera(&keys.keys[0].camera.toric().unwrap());
        let key = key_vector(&encode_camera(&keys.keys[1].camera.toric().unwrap()), &encode_character(&feats[59]));
        for f in (5..60).step_by(5) {
            let input = crate::infer::StepIn {
                style: &style,
                prev,
                character: encode_character(&feats[f]),
                key,
                tta_frames: 59 - f,
            };
            prev = fast.step(&[input], &mut state)[0];
            let got = encode_camera(&out[f - 1]);
            assert!((0..6).all(|j| (got[j] - prev[j]).abs() < 1e-6), "frame {f}");
        }
        // In between, the last step's motion is extrapolated.
        let (f0, f5, f7) =
            (encode_camera(&keys.keys[0].camera.toric().unwrap()), encode_camera(&out[4]), encode_camera(&out[6]));
        assert!(
            (0..6).all(|j| (f7[j] - (f5[j] + (f5[j] - f0[j]) * 0.4)).abs() < 1e-6),
            "frame 7 extrapolates frames 0 → 5"
        );
    }

    #[test]
    fn causal_mode_restarts_through_h_from_its_last_steps_when_the_next_key_is_announced() {
        let fast = small();
        let scene = Scene::procedural(6, 60, 30.0);
        let feats = scene.character_features(0, 1, true);
        let keys = example_keys(&scene, &[0, 30, 59]);
        let style = [0.1f32, 0.0, -0.2, 0.3];
        let mut live = CausalCamera::new(&fast, &style, &keys.keys[0].camera.toric().unwrap(), None, 30.0);
        live.set_key(30, &keys.keys[1].camera.toric().unwrap(), &feats[30]);
        let out: Vec<Toric> = (1..=30).map(|f| live.push(&feats[f])).collect();
        let steps: [Cam; MAP_FRAMES] = std::array::from_fn(|i| encode_camera(&out[10 + 5 * i - 1]));
        live.set_key(59, &keys.keys[2].camera.toric().unwrap(), &feats[59]);
        let expected = fast.map_state(&style, &steps);
        let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
        assert!(
            close(&live.state().h, &expected.h) && close(&live.state().c, &expected.c),
            "H re-mapped the last five network steps"
        );
    }

    #[test]
    fn a_causal_track_announces_each_key_once_and_reports_its_misses() {
        let fast = small();
        let scene = Scene::procedural(6, 90, 30.0);
        let keys = example_keys(&scene, &[0, 45, 89]);
        let style = Style { name: "t".into(), code: vec![0.1, 0.0, -0.2, 0.3] };
        let job = GenerateJob {
            options: GenerateOptions { causal: true, ..Default::default() },
            ..GenerateJob::new(&fast, &scene, &keys, &style)
        };
        let track = job.run().unwrap();
        assert_eq!(track.frames.len(), 90);
        assert_eq!(track.key_residuals.iter().map(|r| r.frame).collect::<Vec<_>>(), [0, 45, 89]);
        // The same track by hand: announce key 1 at once, key 2 after key 1 has passed.
        let feats = scene.character_features(0, 1, true);
        let mut live = CausalCamera::new(&fast, &style.code, &keys.keys[0].camera.toric().unwrap(), None, 30.0);
        live.set_key(45, &keys.keys[1].camera.toric().unwrap(), &feats[45]);
        for f in 1..90 {
            if f == 46 {
                live.set_key(89, &keys.keys[2].camera.toric().unwrap(), &feats[89]);
            }
            let t = live.push(&feats[f]);
            assert_eq!(track.frames[f].toric, t.clamped(&job.options.lens, 0.02), "frame {f}");
        }
        assert!(track.max_corrected_residual > 0.0, "a live camera corrects nothing");
    }
}
