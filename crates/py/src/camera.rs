//! camera `generate`: the camera engine's `GenerateJob` over two characters (mocap clips) or a
//! scene JSON, through keyframes (Toric coordinates or world camera poses), in a behaviour's style
//! (direct, relative, side, orbit) from the committed weights, as the CLI's `camera generate` runs
//! it, through a lens of the caller's field of view. The track comes back as arrays.

use crate::clip::Clip;
use crate::errors::{ctx, invalid, JobError};
use crate::runner::run_job;
use glam::{DQuat, DVec3};
use inbetween_camera::dataset::{Behaviour, Scene};
use inbetween_camera::infer::{GenerateJob, GenerateOptions, KeyCamera, Keys, ReferenceClip, Style};
use inbetween_camera::toric::{CameraPose, Lens};
use inbetween_camera::weights;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(camera_generate, m)?)?;
    Ok(())
}

/// A reference camera's world positions (metres) and rotations (x, y, z, w), one per frame.
type ReferencePoses = (Vec<[f64; 3]>, Vec<[f64; 4]>);

/// Runs a `GenerateJob`. `keys_json` is the keyframes file's JSON. The lens: `fov_deg` (vertical)
/// and `aspect`, by default the first pose key's `fov_deg` (else the engine's 45°) and 16:9. Writes
/// the track JSON, glTF and preview GIF where paths are given. `names`: the two characters' names
/// (default: the clips' sources), which keys' `targets` and `main` use. `reference`: a reference
/// camera's world positions and rotations (x, y, z, w), one per scene frame from frame 0, whose
/// style (the extractor's code, §4.1) replaces `style`. Returns a dict of arrays and the report.
#[pyfunction]
#[pyo3(signature = (keys_json, characters=None, scene=None, style="relative", exact_keys=true, causal=false, json=None, gltf=None, gif=None, progress=None, fov_deg=None, aspect=None, names=None, reference=None))]
#[allow(clippy::too_many_arguments)]
fn camera_generate<'py>(
    py: Python<'py>,
    keys_json: &str,
    characters: Option<(PyRef<'py, Clip>, PyRef<'py, Clip>)>,
    scene: Option<PathBuf>,
    style: &str,
    exact_keys: bool,
    causal: bool,
    json: Option<PathBuf>,
    gltf: Option<PathBuf>,
    gif: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
    fov_deg: Option<f64>,
    aspect: Option<f64>,
    names: Option<(String, String)>,
    reference: Option<ReferencePoses>,
) -> PyResult<Bound<'py, PyDict>> {
    let keys: Keys = serde_json::from_str(keys_json).map_err(|e| invalid(format!("keys: {e}")))?;
    let poses: Vec<usize> =
        keys.keys.iter().filter(|k| matches!(k.camera, KeyCamera::Pose(_))).map(|k| k.frame).collect();
    let pose_fov = keys.keys.iter().find_map(|k| match &k.camera {
        KeyCamera::Pose(p) => p.fov_deg,
        KeyCamera::Toric(_) => None,
    });
    let default = Lens::default();
    let lens = Lens {
        fovy: fov_deg.or(pose_fov).map_or(default.fovy, f64::to_radians),
        aspect: aspect.unwrap_or(default.aspect),
    };
    lens.validate().map_err(|e| invalid(format!("fov_deg / aspect: {e}")))?;
    let behaviour = Behaviour::parse(style)
        .ok_or_else(|| invalid(format!("unknown style `{style}` (direct, relative, side, orbit)")))?;
    let takes = match (&characters, &scene) {
        (Some((a, b)), None) => {
            let (na, nb) = names.unwrap_or_else(|| (a.source.clone(), b.source.clone()));
            Some([(na, a.motion.clone(), a.unit.unit), (nb, b.motion.clone(), b.unit.unit)])
        }
        (None, Some(_)) => None,
        _ => return Err(invalid("give either characters=(clip_a, clip_b) or scene=PATH (a scene JSON)")),
    };
    let (track, scene, notes) = run_job(py, progress.as_ref(), |cancel, bar| {
        bar.phase(2, "generating the camera");
        let w = weights::committed().map_err(ctx("loading the committed camera weights"))?;
        let (scene, notes) = match (&takes, &scene) {
            (Some(t), _) => {
                // Each clip's own length unit (read from a file, given, or cm for arrays).
                let refs: Vec<(&str, &inbetween_core::Motion)> = t.iter().map(|(n, m, _)| (n.as_str(), m)).collect();
                let units: Vec<_> = t.iter().map(|(_, _, u)| Some(*u)).collect();
                inbetween_camera::dataset::scene_from_motions_in_units(&refs, &units, &Default::default())
                    .map_err(JobError::Failed)?
            }
            (None, Some(p)) => (Scene::load(p).map_err(ctx(""))?, Default::default()),
            (None, None) => unreachable!("checked above"),
        };
        // Pose keys are in the takes' world: a character moved aside is no longer where they frame it.
        if let (Some((c, by)), Some(f)) = (notes.moved, poses.first()) {
            return Err(JobError::Failed(format!(
                "keys: the key at frame {f} is a camera pose in the takes' world, but the two takes stand at one \
                 spot and `{}` was moved {:.2} m aside to frame both; place the characters apart",
                scene.characters[c].name,
                by.length()
            )));
        }
        let style = match &reference {
            // A reference camera's poses over this scene, one per frame from frame 0.
            Some((positions, rotations)) => {
                let poses: Vec<CameraPose> = positions
                    .iter()
                    .zip(rotations)
                    .map(|(p, q)| CameraPose {
                        position: DVec3::from_array(*p),
                        rotation: DQuat::from_array(*q).normalize(),
                    })
                    .collect();
                let clip = ReferenceClip::from_poses(&scene, &poses, &lens)
                    .map_err(|e| JobError::Failed(format!("reference: {e}")))?;
                Style { name: "reference".into(), code: clip.style(&w.model, Path::new("reference")).map_err(ctx(""))? }
            }
            None => w.style(behaviour).ok_or_else(|| {
                JobError::Failed(format!("the weights card has no style code for `{}`", behaviour.name()))
            })?,
        };
        bar.inc(1);
        let options = GenerateOptions { exact_keys, causal, lens, cancel: Some(cancel), ..GenerateOptions::default() };
        let origin = Path::new("keys");
        let job = GenerateJob { model: &w.model, scene: &scene, keys: &keys, style: &style, options, origin };
        let track = job.run().map_err(ctx(""))?;
        bar.inc(1);
        if let Some(p) = &json {
            inbetween_camera::write_json(p, &track).map_err(ctx(""))?;
        }
        if let Some(p) = &gltf {
            inbetween_camera::gltf::write_gltf(p, &track, &scene).map_err(ctx(""))?;
        }
        if let Some(p) = &gif {
            inbetween_camera::preview::write_preview(p, &track, &scene, 3).map_err(ctx(""))?;
        }
        Ok((track, scene, notes))
    })?;
    let n = track.frames.len();
    let flat = |f: &dyn Fn(&inbetween_camera::infer::CameraFrame) -> Vec<f64>| -> Vec<f64> {
        track.frames.iter().flat_map(f).collect()
    };
    let d = PyDict::new(py);
    d.set_item("frames", track.frames.iter().map(|f| f.frame).collect::<Vec<_>>())?;
    d.set_item("positions_m", PyArray1::from_vec(py, flat(&|f| f.pose.position.to_array().to_vec())).reshape([n, 3])?)?;
    d.set_item("rotations", PyArray1::from_vec(py, flat(&|f| f.pose.rotation.to_array().to_vec())).reshape([n, 4])?)?;
    d.set_item("toric", PyArray1::from_vec(py, flat(&|f| f.toric.to_array().to_vec())).reshape([n, 6])?)?;
    d.set_item("targets", track.frames.iter().map(|f| f.targets).collect::<Vec<_>>())?;
    let target_at = |f: &inbetween_camera::infer::CameraFrame| -> Vec<f64> {
        f.targets.iter().flat_map(|&c| scene.characters[c].frame(f.frame).target().to_array()).collect()
    };
    d.set_item("targets_m", PyArray1::from_vec(py, flat(&target_at)).reshape([n, 2, 3])?)?;
    d.set_item("notes", notes.lines)?;
    d.set_item("fov_y_rad", PyArray1::from_vec(py, vec![track.lens.fovy; n]))?;
    d.set_item("aspect", track.lens.aspect)?;
    d.set_item("fps", track.fps)?;
    d.set_item("style", track.style.clone())?;
    d.set_item("characters", scene.characters.iter().map(|c| c.name.clone()).collect::<Vec<_>>())?;
    let residuals: Vec<(usize, f64)> = track.key_residuals.iter().map(|r| (r.frame, r.residual)).collect();
    d.set_item("key_residuals", residuals)?;
    d.set_item("worst_key_miss", track.worst_key_miss())?;
    d.set_item("max_corrected_residual", track.max_corrected_residual)?;
    d.set_item(
        "text",
        format!(
            "{}: {n} frames (network keyframe miss max {:.4}, after correction {:.1e})",
            track.style,
            track.worst_key_miss(),
            track.max_corrected_residual
        ),
    )?;
    Ok(d)
}
