//! mocap keyframes: `select_keys` (mocap `SelectJob`), `reconstruct` (`ReconstructJob`) and
//! `bezier_handles` (`dcc::bezier_keys`), on a clip prepared once per call (`PreparedClip`). Key poses come back as arrays: rotations and their
//! body-frame angular velocities (the Hermite tangents), root-relative translations and velocities
//! in cm, and for Euler curves the angles and their rates; reports as JSON text (`json.loads` on
//! the Python side) and as the job's own words. Euler playback (`curve="euler_bezier"`) takes each
//! joint's order, pre-rotation and the DCC's own angles as flat lists (`EulerPlayback`).

use crate::clip::Clip;
use crate::errors::{ctx, engine, invalid, JobError};
use crate::report::JobReport;
use crate::runner::run_job;
use inbetween_core::cancel::Cancel;
use inbetween_core::rotation::EulerOrder;
use inbetween_core::KeyframeSet;
use inbetween_core::Motion;
use inbetween_io::Progress;
use inbetween_mocap::dcc::{bezier_keys, BezierKey};
use inbetween_mocap::rotations::{euler_by_axis, EulerKeys, EulerPlayback, KeyPose};
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

/// `[K, J, 4]` / `[K, J, 3]` arrays of the key poses (lengths × `cm`), and with `euler` the Euler
/// angles and rates `(x, y, z)` by axis (NaN for joints without an order).
fn key_pose_arrays<'py>(
    py: Python<'py>,
    poses: &[KeyPose],
    euler: Option<&EulerKeys>,
    cm: f64,
) -> PyResult<Bound<'py, PyDict>> {
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
    if let Some(e) = euler {
        let by_axis = |pick: fn(&inbetween_mocap::rotations::EulerKey) -> glam::DVec3| -> Vec<f32> {
            e.keys
                .iter()
                .flat_map(|row| {
                    row.iter().zip(&e.orders).flat_map(move |(key, o)| match o {
                        Some(o) => euler_by_axis(*o, pick(key)).to_array().map(|v| v as f32),
                        None => [f32::NAN; 3],
                    })
                })
                .collect()
        };
        d.set_item("euler_angles", PyArray1::from_vec(py, by_axis(|k| k.angles)).reshape([k, j, 3])?)?;
        d.set_item("euler_rates", PyArray1::from_vec(py, by_axis(|k| k.rates)).reshape([k, j, 3])?)?;
    }
    Ok(d)
}

/// The Euler playback of `clip` from Python's arguments (`None` when none is given: the job then
/// plays the skeleton's own channels): per joint an order name (the engine's channel order, `ZYX`
/// = Rz·Ry·Rx) or `None`, pre-rotations `[J × 4]` (x, y, z, w), the DCC's angles `[T × J × 3]`
/// radians by axis, all flat.
fn playback(
    clip: &Clip,
    orders: Option<Vec<Option<String>>>,
    pre: Option<Vec<f64>>,
    reference: Option<Vec<f64>>,
) -> PyResult<Option<EulerPlayback>> {
    if orders.is_none() && pre.is_none() && reference.is_none() {
        return Ok(None);
    }
    let sk = &clip.motion.skeleton;
    let nj = sk.len();
    let mut p = EulerPlayback::of_skeleton(sk);
    if let Some(orders) = orders {
        if orders.len() != nj {
            return Err(invalid(format!("{} Euler orders: expected one per joint, {nj}", orders.len())));
        }
        p.orders = orders
            .iter()
            .enumerate()
            .map(|(j, o)| match o {
                None => Ok(None),
                Some(name) => EulerOrder::parse(name).map(Some).ok_or_else(|| {
                    invalid(format!("Euler order '{name}' of joint {j} ({}): expected XYZ, ZYX, …", sk.joint(j).name))
                }),
            })
            .collect::<PyResult<_>>()?;
    }
    if let Some(pre) = pre {
        if pre.len() != nj * 4 {
            return Err(invalid(format!("{} pre-rotation values: expected [{nj}, 4] (x, y, z, w)", pre.len())));
        }
        p.pre = pre.chunks(4).map(|c| glam::DQuat::from_xyzw(c[0], c[1], c[2], c[3])).collect();
    }
    if let Some(r) = reference {
        let n = clip.motion.num_frames();
        if r.len() != n * nj * 3 {
            return Err(invalid(format!("{} reference Euler values: expected [{n}, {nj}, 3]", r.len())));
        }
        p.reference = Some(r.chunks(3).map(|c| glam::DVec3::new(c[0], c[1], c[2])).collect());
    }
    Ok(Some(p))
}

fn curve(name: Option<&str>) -> PyResult<RotationCurve> {
    name.map_or(Ok(RotationCurve::default()), |c| RotationCurve::parse(c).map_err(|e| engine("", &e)))
}

/// Runs a `SelectJob`: `method` (uniform, greedy, sidql, optimal, error_bounded) with `k` keys or
/// `bound_cm` / `bound_deg`, rotations along `curve` (hermite, quaternion_bezier, euler_bezier with
/// its playback: see [`playback`]). Returns (key frames, key pose arrays, report JSON, report text,
/// rebuilt clip, the reconstruction's report text).
#[pyfunction]
#[pyo3(signature = (clip, method, k=None, bound_cm=None, max_gap_s=None, progress=None, bound_deg=None, curve=None, euler_orders=None, pre_rotations=None, euler_reference=None))]
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
    euler_orders: Option<Vec<Option<String>>>,
    pre_rotations: Option<Vec<f64>>,
    euler_reference: Option<Vec<f64>>,
) -> PyResult<(Vec<usize>, Bound<'py, PyDict>, String, String, Clip, String)> {
    let method = Selector::parse(method).map_err(|e| engine("", &e))?;
    let defaults = SelectJob::default();
    let job = SelectJob {
        method,
        k,
        bound_cm,
        bound_deg,
        max_gap_s: max_gap_s.unwrap_or(defaults.max_gap_s),
        curve: self::curve(curve)?,
        euler: playback(&clip, euler_orders, pre_rotations, euler_reference)?,
    };
    job.validate(clip.motion.num_frames()).map_err(|e| engine(&clip.source, &e))?;
    let clip_ref: &Clip = &clip;
    let (report, prepared) = run_job(py, progress.as_ref(), |cancel, bar| select(clip_ref, &job, cancel, bar))?;
    let json = serde_json::to_string(&report).map_err(|e| invalid(e.to_string()))?;
    let rebuilt = report.reconstruction.motion(&prepared).map_err(|e| engine("", &e))?;
    let poses = key_pose_arrays(py, &report.key_poses, report.key_euler.as_ref(), clip.unit.cm_per_unit())?;
    let out = Clip::new(rebuilt, clip.unit.clone(), clip.source.clone());
    Ok((report.keys().frames().to_vec(), poses, json, report.to_string(), out, report.reconstruction.to_string()))
}

/// Runs a `ReconstructJob`: the clip rebuilt from its poses at `keys` (Euler playback as for
/// `mocap_select`). Returns (rebuilt clip, error per frame in cm, mean and max error in cm, the
/// report).
#[pyfunction]
#[pyo3(signature = (clip, keys, progress=None, curve=None, euler_orders=None, pre_rotations=None, euler_reference=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn mocap_reconstruct<'py>(
    py: Python<'py>,
    clip: PyRef<'py, Clip>,
    keys: Vec<usize>,
    progress: Option<Bound<'py, PyAny>>,
    curve: Option<&str>,
    euler_orders: Option<Vec<Option<String>>>,
    pre_rotations: Option<Vec<f64>>,
    euler_reference: Option<Vec<f64>>,
) -> PyResult<(Clip, Bound<'py, PyArray1<f64>>, f64, f64, JobReport)> {
    let euler = playback(&clip, euler_orders, pre_rotations, euler_reference)?;
    let job = ReconstructJob { keys, curve: self::curve(curve)?, euler };
    job.validate(clip.motion.num_frames()).map_err(|e| engine(&clip.source, &e))?;
    let clip_ref: &Clip = &clip;
    let (report, motion) = run_job(py, progress.as_ref(), |cancel, bar| reconstruct(clip_ref, &job, cancel, bar))?;
    let error = &report.error;
    let per_frame = PyArray1::from_slice(py, &error.per_frame_cm);
    let (mean, max) = (error.mean_cm, error.max_cm);
    Ok((Clip::new(motion, clip.unit.clone(), clip.source.clone()), per_frame, mean, max, JobReport::new(report)))
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
    let mut report = job.run(&prepared, cancel, progress).map_err(ctx(format!("reconstructing {}", clip.source)))?;
    let motion = report.motion(&prepared).map_err(ctx("rebuilding the clip"))?;
    // The poses are in `motion` now; the report kept for Python holds the rest.
    report.poses = Vec::new();
    Ok((report, motion))
}

/// The Bezier keys (`dcc::bezier_keys`) of `clip` at `keys` (first and last frames added when
/// missing): a dict of float64 arrays, frames for the handles' times, cm for translations; with
/// `curve="euler_bezier"` (playback as for `mocap_select`) also the Euler curves, radians by axis.
#[pyfunction]
#[pyo3(signature = (clip, keys, curve=None, euler_orders=None, pre_rotations=None, euler_reference=None))]
fn mocap_bezier<'py>(
    py: Python<'py>,
    clip: PyRef<'py, Clip>,
    keys: Vec<usize>,
    curve: Option<&str>,
    euler_orders: Option<Vec<Option<String>>>,
    pre_rotations: Option<Vec<f64>>,
    euler_reference: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = clip.motion.num_frames();
    let set = KeyframeSet::new(keys, n).map_err(|e| engine(&clip.source, &e))?;
    let cm = clip.unit.cm_per_unit();
    let euler = playback(&clip, euler_orders, pre_rotations, euler_reference)?;
    let motion = RotationMotion::from_motion_in(&clip.motion, cm).map_err(|e| engine(&clip.source, &e))?;
    let motion = motion.played(self::curve(curve)?, euler.as_ref()).map_err(|e| engine(&clip.source, &e))?;
    let key_euler = motion.key_euler(&set);
    let bz = bezier_keys(set.frames(), &motion.key_poses(&set), key_euler.as_ref(), clip.motion.frame_time)
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
    if !bz.euler.is_empty() {
        for (name, pick) in [
            ("euler", (|b| b.value) as fn(&BezierKey<3>) -> [f64; 3]),
            ("euler_left", |b| b.left),
            ("euler_right", |b| b.right),
        ] {
            d.set_item(name, PyArray1::from_vec(py, part(&bz.euler, pick, 1.0)).reshape([k, j, 3])?)?;
        }
    }
    Ok(d)
}
