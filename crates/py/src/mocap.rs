//! mocap keyframes: `select_keys` (mocap `SelectJob`), `reconstruct` (`ReconstructJob`) and
//! `bezier_handles` (`dcc::bezier_keys`), on a clip prepared once per call (`PreparedClip`). Key poses come back as arrays: rotations and their
//! body-frame angular velocities (the Hermite tangents), root-relative translations and velocities
//! in cm; reports as JSON text (`json.loads` on the Python side) and as the job's own words.

use crate::clip::Clip;
use crate::errors::{ctx, engine, invalid, JobError};
use crate::runner::run_job;
use inbetween_core::cancel::Cancel;
use inbetween_core::KeyframeSet;
use inbetween_core::Motion;
use inbetween_io::Progress;
use inbetween_mocap::dcc::{bezier_keys, BezierKey};
use inbetween_mocap::rotations::KeyPose;
use inbetween_mocap::{
    PreparedClip, ReconstructJob, ReconstructReport, RotationCurve, RotationMotion, SelectJob, SelectReport, Selector,
};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mocap_select, m)?)?;
    m.add_function(wrap_pyfunction!(mocap_reconstruct, m)?)?;
    m.add_function(wrap_pyfunction!(mocap_bezier, m)?)?;
    Ok(())
}

fn prepare(clip: &Clip) -> Result<PreparedClip, JobError> {
    PreparedClip::new(clip.motion.clone(), clip.unit.clone()).map_err(ctx(format!("preparing {}", clip.source)))
}

/// The work of `select_keys`: prepare the clip, run the job (also timed by `inbetween.bench`).
pub fn select(
    clip: &Clip,
    job: &SelectJob,
    cancel: &Cancel,
    progress: &Progress,
) -> Result<(SelectReport, PreparedClip), JobError> {
    let prepared = prepare(clip)?;
    let report = job.run(&prepared, cancel, progress).map_err(ctx(format!("choosing keys of {}", clip.source)))?;
    Ok((report, prepared))
}

/// `[K, J, 4]` / `[K, J, 3]` arrays of the key poses (lengths × `cm`).
fn key_pose_arrays<'py>(py: Python<'py>, poses: &[KeyPose], cm: f64) -> PyResult<Bound<'py, PyDict>> {
    let k = poses.len();
    let j = poses.first().map_or(0, |p| p.rotations.len());
    let quat: Vec<f32> =
        poses.iter().flat_map(|p| p.rotations.iter().flat_map(|q| q.to_array())).map(|v| v as f32).collect();
    let vec3 = |f: &dyn Fn(&KeyPose) -> &Vec<glam::DVec3>, s: f64| -> Vec<f32> {
        poses.iter().flat_map(|p| f(p).iter().flat_map(|v| (*v * s).to_array())).map(|v| v as f32).collect()
    };
    let d = PyDict::new(py);
    d.set_item("rotations", PyArray1::from_vec(py, quat).reshape([k, j, 4])?)?;
    d.set_item(
        "angular_velocities",
        PyArray1::from_vec(py, vec3(&|p| &p.angular_velocities, 1.0)).reshape([k, j, 3])?,
    )?;
    d.set_item("translations_cm", PyArray1::from_vec(py, vec3(&|p| &p.translations, cm)).reshape([k, j, 3])?)?;
    d.set_item("velocities_cm_s", PyArray1::from_vec(py, vec3(&|p| &p.velocities, cm)).reshape([k, j, 3])?)?;
    Ok(d)
}

fn curve(name: Option<&str>) -> PyResult<RotationCurve> {
    name.map_or(Ok(RotationCurve::default()), |c| RotationCurve::parse(c).map_err(|e| engine("", &e)))
}

/// Runs a `SelectJob`: `method` (uniform, greedy, sidql, optimal, error_bounded) with `k` keys or
/// `bound_cm` / `bound_deg`, rotations along `curve` (hermite, quaternion_bezier). Returns (key
/// frames, key pose arrays, report JSON, report text, rebuilt clip).
#[pyfunction]
#[pyo3(signature = (clip, method, k=None, bound_cm=None, max_gap_s=None, progress=None, bound_deg=None, curve=None))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn mocap_select<'py>(
    py: Python<'py>,
    clip: PyRef<'py, Clip>,
    method: &str,
    k: Option<usize>,
    bound_cm: Option<f64>,
    max_gap_s: Option<f64>,
    progress: Option<Bound<'py, PyAny>>,
    bound_deg: Option<f64>,
    curve: Option<&str>,
) -> PyResult<(Vec<usize>, Bound<'py, PyDict>, String, String, Clip)> {
    let method = Selector::parse(method).map_err(|e| engine("", &e))?;
    let defaults = SelectJob::default();
    let job = SelectJob {
        method,
        k,
        bound_cm,
        bound_deg,
        max_gap_s: max_gap_s.unwrap_or(defaults.max_gap_s),
        curve: self::curve(curve)?,
    };
    job.validate(clip.motion.num_frames()).map_err(|e| engine(&clip.source, &e))?;
    let clip_ref: &Clip = &clip;
    let (report, prepared) = run_job(py, progress.as_ref(), |cancel, bar| select(clip_ref, &job, cancel, bar))?;
    let json = serde_json::to_string(&report).map_err(|e| invalid(e.to_string()))?;
    let rebuilt = report.reconstruction.motion(&prepared).map_err(|e| engine("", &e))?;
    let poses = key_pose_arrays(py, &report.key_poses, clip.unit.cm_per_unit())?;
    let out = Clip::new(rebuilt, clip.unit.clone(), clip.source.clone());
    Ok((report.keys().frames().to_vec(), poses, json, report.to_string(), out))
}

/// Runs a `ReconstructJob`: the clip rebuilt from its poses at `keys`. Returns (rebuilt clip,
/// report JSON, report text).
#[pyfunction]
#[pyo3(signature = (clip, keys, progress=None, curve=None))]
fn mocap_reconstruct<'py>(
    py: Python<'py>,
    clip: PyRef<'py, Clip>,
    keys: Vec<usize>,
    progress: Option<Bound<'py, PyAny>>,
    curve: Option<&str>,
) -> PyResult<(Clip, String, String)> {
    let job = ReconstructJob { keys, curve: self::curve(curve)? };
    job.validate(clip.motion.num_frames()).map_err(|e| engine(&clip.source, &e))?;
    let clip_ref: &Clip = &clip;
    let (report, motion) = run_job(py, progress.as_ref(), |cancel, bar| reconstruct(clip_ref, &job, cancel, bar))?;
    let json = serde_json::to_string(&report).map_err(|e| invalid(e.to_string()))?;
    Ok((Clip::new(motion, clip.unit.clone(), clip.source.clone()), json, report.to_string()))
}

/// The work of `reconstruct`: prepare the clip, run the job, rebuild the BVH form (also timed by
/// `inbetween.bench`).
pub fn reconstruct(
    clip: &Clip,
    job: &ReconstructJob,
    cancel: &Cancel,
    progress: &Progress,
) -> Result<(ReconstructReport, Motion), JobError> {
    let prepared = prepare(clip)?;
    let report = job.run(&prepared, cancel, progress).map_err(ctx(format!("reconstructing {}", clip.source)))?;
    let motion = report.motion(&prepared).map_err(ctx("rebuilding the clip"))?;
    Ok((report, motion))
}

/// The Bezier keys (`dcc::bezier_keys`) of `clip` at `keys` (first and last frames added when
/// missing): a dict of float64 arrays, frames for the handles' times, cm for translations.
#[pyfunction]
fn mocap_bezier<'py>(py: Python<'py>, clip: PyRef<'py, Clip>, keys: Vec<usize>) -> PyResult<Bound<'py, PyDict>> {
    let n = clip.motion.num_frames();
    let set = KeyframeSet::new(keys, n).map_err(|e| engine(&clip.source, &e))?;
    let cm = clip.unit.cm_per_unit();
    let motion = RotationMotion::from_motion_in(&clip.motion, cm).map_err(|e| engine(&clip.source, &e))?;
    let bz = bezier_keys(set.frames(), &motion.key_poses(&set), clip.motion.frame_time)
        .map_err(|e| engine(&clip.source, &e))?;
    let (k, j) = (bz.frames.len(), clip.motion.skeleton.len());
    let d = PyDict::new(py);
    d.set_item("frames", bz.frames.clone())?;
    d.set_item("left_frames", PyArray1::from_vec(py, bz.left_frames.clone()))?;
    d.set_item("right_frames", PyArray1::from_vec(py, bz.right_frames.clone()))?;
    fn part<const N: usize>(keys: &[Vec<BezierKey<N>>], pick: fn(&BezierKey<N>) -> [f64; N], s: f64) -> Vec<f64> {
        keys.iter().flat_map(|row| row.iter().flat_map(move |b| pick(b).map(|v| v * s))).collect()
    }
    for (name, pick) in [
        ("rotations", (|b| b.value) as fn(&BezierKey<4>) -> [f64; 4]),
        ("rotations_left", |b| b.left),
        ("rotations_right", |b| b.right),
    ] {
        d.set_item(name, PyArray1::from_vec(py, part(&bz.rotations, pick, 1.0)).reshape([k, j, 4])?)?;
    }
    for (name, pick) in [
        ("translations_cm", (|b| b.value) as fn(&BezierKey<3>) -> [f64; 3]),
        ("translations_left_cm", |b| b.left),
        ("translations_right_cm", |b| b.right),
    ] {
        d.set_item(name, PyArray1::from_vec(py, part(&bz.translations, pick, cm)).reshape([k, j, 3])?)?;
    }
    Ok(d)
}
