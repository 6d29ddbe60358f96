//! The camera a scene gets does not depend on its frame rate: the networks were trained at 30 fps
//! on every 5th frame, and a scene at 120 fps (CMU takes, Blender scenes) steps them every 20
//! frames (`dataset::step_frames`), so the same motion filmed at 120 fps gets the same camera as at
//! 30 fps, offline, live (causal) and for a reference clip's style. Side by side in the same run:
//! the 120 fps scene labelled 30 fps, which steps the networks every 5 frames as every rate did
//! before (four times as often per second: the camera's motion runs four times too fast).

use inbetween_camera::dataset::scene::CharacterPoints;
use inbetween_camera::dataset::{film, Behaviour, BehaviourParams, Scene};
use inbetween_camera::infer::{example_keys, GenerateJob, GenerateOptions, Keys, ReferenceClip};
use inbetween_camera::toric::{to_pose, CameraPose, Lens, Toric};
use inbetween_camera::weights;
use rand::SeedableRng;
use std::path::Path;

/// `scene` at `k` times its rate (linear between its frames).
fn upsampled(scene: &Scene, k: usize) -> Scene {
    let up = |v: &Vec<glam::DVec3>| -> Vec<glam::DVec3> {
        (0..=(v.len() - 1) * k)
            .map(|f| {
                let (i, u) = (f / k, (f % k) as f64 / k as f64);
                if u == 0.0 {
                    v[i]
                } else {
                    v[i].lerp(v[i + 1], u)
                }
            })
            .collect()
    };
    Scene {
        fps: scene.fps * k as f64,
        characters: scene
            .characters
            .iter()
            .map(|c| CharacterPoints {
                name: c.name.clone(),
                root: up(&c.root),
                shoulder_l: up(&c.shoulder_l),
                shoulder_r: up(&c.shoulder_r),
            })
            .collect(),
    }
}

/// Mean Toric distance between the 30 fps track and the 120 fps track at the same times.
fn apart(a: &[Toric], b: &[Toric], k: usize) -> f64 {
    let d: Vec<f64> = a
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let (x, y) = (x.to_array(), b[i * k].to_array());
            (0..6).map(|j| (x[j] - y[j]).powi(2)).sum::<f64>().sqrt()
        })
        .collect();
    d.iter().sum::<f64>() / d.len() as f64
}

fn keys_at(keys: &Keys, k: usize) -> Keys {
    let mut out = keys.clone();
    for key in &mut out.keys {
        key.frame *= k;
    }
    out
}

#[test]
fn the_same_motion_at_120_fps_gets_the_camera_it_gets_at_30_fps() {
    let w = weights::committed().unwrap();
    let scene30 = Scene::procedural(11, 301, 30.0);
    let scene120 = upsampled(&scene30, 4);
    let mislabelled = Scene { fps: 30.0, ..scene120.clone() };
    let keys30 = example_keys(&scene30, &[0, 150, 300]);
    let keys120 = keys_at(&keys30, 4);
    for causal in [false, true] {
        for behaviour in [Behaviour::Orbit, Behaviour::Side] {
            let style = w.style(behaviour).unwrap();
            let run = |scene: &Scene, keys: &Keys| {
                let options = GenerateOptions { causal, ..GenerateOptions::default() };
                GenerateJob { options, ..GenerateJob::new(&w.model, scene, keys, &style) }.run().unwrap().toric()
            };
            let (t30, t120, old) = (run(&scene30, &keys30), run(&scene120, &keys120), run(&mislabelled, &keys120));
            assert_eq!((t30.len(), t120.len()), (301, 1201));
            let (now, before) = (apart(&t30, &t120, 4), apart(&t30, &old, 4));
            println!(
                "{} {}: 120 fps against 30 fps, mean Toric distance {now:.4} (stepping every 5 frames as before: {before:.4})",
                behaviour.name(),
                if causal { "causal" } else { "offline" }
            );
            assert!(now < 0.25 * before, "{now} against {before}");
            assert!(now < 0.05, "{now}");
        }
    }
}

#[test]
fn a_reference_at_120_fps_gives_the_style_it_gives_at_30_fps() {
    let w = weights::committed().unwrap();
    let scene30 = Scene::procedural(12, 361, 30.0);
    let scene120 = upsampled(&scene30, 4);
    let lens = Lens::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let params = BehaviourParams::sample(&mut rng);
    let poses = |scene: &Scene| -> Vec<CameraPose> {
        let track = film(scene, 0, 1, true, Behaviour::Orbit, &params, &lens);
        track
            .iter()
            .enumerate()
            .map(|(f, t)| {
                let (a, b) = (scene.characters[0].frame(f), scene.characters[1].frame(f));
                to_pose(t, a.target(), b.target(), &lens).unwrap()
            })
            .collect()
    };
    let code = |scene: &Scene| {
        let clip = ReferenceClip::from_poses(scene, &poses(scene), &lens).unwrap();
        clip.style(&w.model, Path::new("reference")).unwrap()
    };
    let (s30, s120) = (code(&scene30), code(&scene120));
    let mut old = ReferenceClip::from_poses(&scene120, &poses(&scene120), &lens).unwrap();
    old.fps = 30.0;
    let old = old.style(&w.model, Path::new("reference")).unwrap();
    let dist = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>().sqrt();
    let (now, before) = (dist(&s30, &s120), dist(&s30, &old));
    println!("style code of a 120 fps reference against 30 fps: {now:.4} apart (read every 5 frames: {before:.4})");
    assert!(now < 0.25 * before, "{now} against {before}");
}

/// Rates whose network step is not a whole number of frames (25 fps: 4.17 frames; 10 fps: 1.67;
/// 6 fps: one frame, the lowest rate a scene may have): the keys are hit offline, the live camera
/// runs every frame, nothing is left unfilled; 5 fps (a step shorter than a frame) is refused.
#[test]
fn uneven_steps_still_hit_every_key() {
    let w = weights::committed().unwrap();
    let style = w.style(Behaviour::Relative).unwrap();
    let slow = Scene::procedural(13, 121, 5.0);
    let e = GenerateJob::new(&w.model, &slow, &example_keys(&slow, &[0, 120]), &style).run().unwrap_err().to_string();
    assert!(e.contains("5 fps: expected at least 6 fps"), "{e}");
    for fps in [25.0, 10.0, 6.0] {
        let scene = Scene::procedural(13, 121, fps);
        let keys = example_keys(&scene, &[0, 47, 120]);
        for causal in [false, true] {
            let options = GenerateOptions { causal, ..GenerateOptions::default() };
            let track = GenerateJob { options, ..GenerateJob::new(&w.model, &scene, &keys, &style) }.run().unwrap();
            assert_eq!(track.frames.len(), 121, "{fps} fps");
            assert!(track.toric().iter().all(|t| t.to_array().iter().all(|v| v.is_finite())), "{fps} fps");
            if !causal {
                assert!(track.max_corrected_residual < 1e-9, "{fps} fps: {}", track.max_corrected_residual);
            }
        }
    }
}
