//! The camera part of `inbetween demo`, and the example files of `inbetween camera scene`: a
//! built-in procedural scene, keyframes, the committed weights, one track per behaviour style.

use crate::dataset::{film_sequence, Behaviour, Scene, BEHAVIOURS};
use crate::infer::{example_keys, GenerateJob, GenerateLimits, Keys};
use crate::toric::Lens;
use crate::weights::committed;
use crate::CameraError;
use inbetween_io::{LimitExceeded, OutputSet, Progress};
use std::path::Path;

/// The steps [`run`] counts on its progress bar.
pub const STEPS: u64 = 1;

/// Frames of `camera scene`'s example (15 s at 30 fps).
pub const EXAMPLE_SCENE_FRAMES: usize = 450;

/// Writes `scene.json`, `keys.json` (keys at the start, middle and end) and one
/// `reference-<behaviour>.json` filmed clip per behaviour into `out`: everything `camera generate`
/// needs to try each style. The files appear together in `out` (merged into it when it exists) or
/// none do. A scene of fewer than 2 frames, or over the generate job's `limits.max_frames` (the
/// scene could not be used), is refused before anything is written. Returns the files written.
pub fn write_example_scene(
    out: &Path,
    seed: u64,
    frames: usize,
    limits: &GenerateLimits,
) -> Result<Vec<String>, CameraError> {
    LimitExceeded::check_count("the scene", frames, limits.max_frames, "frames", "max_frames")?;
    if frames < 2 {
        return Err(CameraError::invalid(out, format!("a scene needs at least 2 frames, got {frames}")));
    }
    let mut set = OutputSet::new();
    let dir = set.dir(out).map_err(|source| CameraError::Io { path: out.into(), source })?;
    let scene = Scene::procedural(seed, frames, 30.0);
    scene.save(&dir.join("scene.json"))?;
    let n = frames - 1;
    crate::write_json(&dir.join("keys.json"), &example_keys(&scene, &[0, n / 2, n]))?;
    let mut files = vec!["scene.json".to_string(), "keys.json".to_string()];
    let lens = Lens::default();
    for (i, b) in BEHAVIOURS.into_iter().enumerate() {
        let mut rng = inbetween_core::seed::rng(seed + i as u64);
        let seq = film_sequence(&scene, seed, b, true, &mut rng, &lens);
        let name = format!("reference-{}.json", b.name());
        crate::write_json(&dir.join(&name), &seq)?;
        files.push(name);
    }
    set.commit().map_err(|source| CameraError::Io { path: out.into(), source })?;
    Ok(files)
}

/// The demo's example at `k`× its length (`camera scale`): a 300·k-frame procedural scene at 30 fps
/// with a key every 150 frames and on the last one (3 keys at 1×).
pub fn scaled_example(k: usize) -> (Scene, Keys) {
    let frames = 300 * k;
    let scene = Scene::procedural(3, frames, 30.0);
    let mut at: Vec<usize> = (0..frames).step_by(150).collect();
    if at.last() != Some(&(frames - 1)) {
        at.push(frames - 1);
    }
    let keys = example_keys(&scene, &at);
    (scene, keys)
}

/// The demo: a 300-frame scene with keys at frames 0, 150 and 299, a track per behaviour style
/// with the committed weights (`out/camera/cam-<style>.json`), and the orbit track as
/// `out/cam.json`, `out/cam.gltf` and `out/cam.gif`. Returns one line per result; counts [`STEPS`]
/// step on `progress`.
pub fn run(out: &Path, progress: &Progress) -> Result<Vec<String>, CameraError> {
    let t0 = std::time::Instant::now();
    let w = committed()?;
    let scene = Scene::procedural(3, 300, 30.0);
    let keys = example_keys(&scene, &[0, 150, 299]);
    let dir = out.join("camera");
    std::fs::create_dir_all(&dir).map_err(|source| CameraError::Io { path: dir.clone(), source })?;
    scene.save(&dir.join("scene.json"))?;
    let keys_path = dir.join("keys.json");
    crate::write_json(&keys_path, &keys)?;
    let mut lines = Vec::new();
    for b in BEHAVIOURS {
        let style = w
            .style(b)
            .ok_or_else(|| CameraError::Model(format!("the weights card has no style code for `{}`", b.name())))?;
        let track = GenerateJob { origin: &keys_path, ..GenerateJob::new(&w.model, &scene, &keys, &style) }.run()?;
        let worst = track.worst_key_miss();
        crate::write_json(&dir.join(format!("cam-{}.json", b.name())), &track)?;
        if b == Behaviour::Orbit {
            crate::write_json(&out.join("cam.json"), &track)?;
            crate::gltf::write_gltf(&out.join("cam.gltf"), &track, &scene)?;
            crate::preview::write_preview(&out.join("cam.gif"), &track, &scene, 3)?;
        }
        lines.push(format!(
            "camera {:<8} {} frames, network key miss {worst:.3} (corrected to {:.0e})",
            b.name(),
            track.frames.len(),
            track.max_corrected_residual
        ));
    }
    progress.inc(1);
    lines.push(format!(
        "camera demo: {}, cam.gltf, cam.gif (orbit style; per-style tracks in {}) in {:.1} s",
        out.join("cam.json").display(),
        dir.display(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn example_scene_files_load_back_and_scenes_too_short_or_long_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let limits = GenerateLimits::default();
        let files = write_example_scene(dir.path(), 4, 90, &limits).unwrap();
        assert_eq!(files.len(), 6);
        let scene = Scene::load(&dir.path().join("scene.json")).unwrap();
        assert_eq!(scene.num_frames(), 90);
        let keys: crate::infer::Keys = crate::read_json(&dir.path().join("keys.json")).unwrap();
        assert_eq!(keys.keys.len(), 3);
        let (none, short) = (dir.path().join("none"), GenerateLimits { max_frames: 89, ..limits });
        let err = write_example_scene(&none, 4, 1, &limits).unwrap_err().to_string();
        assert!(err.ends_with("none: a scene needs at least 2 frames, got 1"), "{err}");
        let err = write_example_scene(&none, 4, 90, &short).unwrap_err();
        assert!(matches!(&err, CameraError::Limit(l) if l.field == "max_frames"), "{err}");
        assert!(!none.exists(), "nothing is written for a refused scene");
    }
}
