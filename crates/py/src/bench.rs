//! The Rust side of `python -m inbetween.bench`: the same work each Python function does (the same
//! functions of this crate, minus the Python argument and result conversion and the GIL), timed in
//! Rust, so the bench can put the two side by side on the same input. `pool=True` runs it on a
//! thread of rayon's pool, where the Python functions run their jobs ([`crate::runner::run_job`]):
//! the same thread kind, allocator arena and pool as the Python call, so only the Python side's own
//! work differs; `pool=False` on the calling thread, as the CLI runs a job (the process's main
//! thread, whose allocator hands memory back after a call and faults it in again on the next:
//! 1353 page faults per face edit with a key there, none on a pool thread).

use crate::clip::{Clip, FaceClip};
use crate::errors::{invalid, JobError};
use crate::face::{self, EditRequest, SpanArg};
use crate::video::{self, ResequenceRequest};
use crate::{ibk, mocap};
use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use inbetween_mocap::{ReconstructJob, SelectJob, Selector};
use pyo3::prelude::*;
use std::time::Instant;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_bench_rust, m)?)?;
    m.add_function(wrap_pyfunction!(_bench_sample_rust, m)?)?;
    m.add_function(wrap_pyfunction!(_bench_face_rust, m)?)?;
    m.add_function(wrap_pyfunction!(_bench_video_rust, m)?)?;
    m.add_function(wrap_pyfunction!(_rayon_threads, m)?)?;
    m.add_function(wrap_pyfunction!(_build_profile, m)?)?;
    m.add_function(wrap_pyfunction!(_empty_job, m)?)?;
    Ok(())
}

/// A job that does nothing, run as every long Python call runs its job ([`crate::runner::run_job`]:
/// the hop to a thread of rayon's pool and back, with the GIL released and taken again): what that
/// costs a call, timed from Python.
#[pyfunction]
fn _empty_job(py: Python<'_>) -> PyResult<()> {
    crate::runner::run_job(py, None, |_, _| Ok::<(), JobError>(()))
}

/// The build profile of this extension: `release`, or `dev` (debug assertions on; the workspace's
/// dev profile still optimises, opt-level 2 and 3 for dependencies).
#[pyfunction]
fn _build_profile() -> &'static str {
    if cfg!(debug_assertions) {
        "dev"
    } else {
        "release"
    }
}

/// The threads of rayon's pool (the engines' parallel work and the Python jobs run there; set by
/// `RAYON_NUM_THREADS` before the first job).
#[pyfunction]
fn _rayon_threads() -> usize {
    rayon::current_num_threads()
}

/// Milliseconds of each of `repeats` runs of `run`, with the GIL released: on a thread of rayon's
/// pool when `pool`, else on the calling thread.
fn timed<E: Send>(
    py: Python<'_>,
    repeats: usize,
    pool: bool,
    run: impl Fn() -> Result<(), E> + Send + Sync,
) -> Result<Vec<f64>, E> {
    let all = || {
        (0..repeats)
            .map(|_| {
                let t = Instant::now();
                run().map(|_| t.elapsed().as_secs_f64() * 1e3)
            })
            .collect::<Result<Vec<f64>, E>>()
    };
    py.detach(|| if pool { rayon::scope(|_| all()) } else { all() })
}

/// Milliseconds of each of `repeats` runs of `what` ("read", "select", "reconstruct",
/// "compress") on `clip`, called from Rust.
#[pyfunction]
#[pyo3(signature = (what, clip, repeats, method=None, k=None, bound_cm=None, keys=None, max_error_cm=None, pool=true))]
#[allow(clippy::too_many_arguments)]
fn _bench_rust(
    py: Python<'_>,
    what: &str,
    clip: PyRef<'_, Clip>,
    repeats: usize,
    method: Option<&str>,
    k: Option<usize>,
    bound_cm: Option<f64>,
    keys: Option<Vec<usize>>,
    max_error_cm: Option<f64>,
    pool: bool,
) -> PyResult<Vec<f64>> {
    let clip: &Clip = &clip;
    let (cancel, progress) = (Cancel::new(), Progress::hidden());
    let run: Box<dyn Fn() -> Result<(), JobError> + Send + Sync + '_> = match what {
        "read" => {
            Box::new(|| inbetween_io::load_motion(std::path::Path::new(&clip.source)).map(|_| ()).map_err(Into::into))
        }
        "select" => {
            let method = Selector::parse(method.unwrap_or("optimal")).map_err(|e| invalid(e.to_string()))?;
            let job = SelectJob { method, k, bound_cm, ..SelectJob::default() };
            Box::new(move || mocap::select(clip, &job, &cancel, &progress).map(|_| ()))
        }
        "reconstruct" => {
            let job = ReconstructJob { keys: keys.unwrap_or_default(), ..ReconstructJob::default() };
            Box::new(move || mocap::reconstruct(clip, &job, &cancel, &progress).map(|_| ()))
        }
        "compress" => {
            let job = ibk::compress_job(clip, max_error_cm, None, None, None, 0.5)?;
            Box::new(move || ibk::compress(clip, &job).map(|_| ()))
        }
        other => return Err(invalid(format!("unknown bench job {other:?}"))),
    };
    timed(py, repeats, pool, run).map_err(JobError::into_py)
}

/// Nanoseconds per pose of `inbetween_ibk::Clip::sample` at each of `times`, in Rust, into
/// buffers made once (what `Reader.sample` does per call, without Python).
#[pyfunction]
fn _bench_sample_rust(py: Python<'_>, data: Vec<u8>, times: Vec<f64>) -> PyResult<f64> {
    py.detach(|| {
        let clip = inbetween_ibk::Clip::open(&data).map_err(|e| e.to_string())?;
        let mut ctx = inbetween_ibk::Context::new(&clip);
        let n = clip.num_joints();
        let (mut r, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
        let t = Instant::now();
        for &time in &times {
            clip.sample(&mut ctx, time, &mut r, &mut tr).map_err(|e| e.to_string())?;
            std::hint::black_box((&r, &tr));
        }
        Ok::<f64, String>(t.elapsed().as_secs_f64() * 1e9 / times.len().max(1) as f64)
    })
    .map_err(invalid)
}

/// Milliseconds of each of `repeats` runs of `face.edit`'s work ([`face::edit`]: the job prepared
/// and run `variants` times from `seed`) on `clip` over `spans` (seconds), unguided or with
/// `keys_json`, called from Rust.
#[pyfunction]
#[pyo3(signature = (clip, spans, repeats, variants=1, seed=1, keys_json=None, pool=true))]
#[allow(clippy::too_many_arguments)]
fn _bench_face_rust(
    py: Python<'_>,
    clip: PyRef<'_, FaceClip>,
    spans: Vec<(f64, f64)>,
    repeats: usize,
    variants: usize,
    seed: u64,
    keys_json: Option<String>,
    pool: bool,
) -> PyResult<Vec<f64>> {
    let request = EditRequest {
        spans: spans.into_iter().map(|(a, b)| SpanArg::Seconds(a, b)).collect(),
        keys_json,
        method: "auto".into(),
        variants,
        seed,
        ..EditRequest::default()
    };
    let input = &clip.clip;
    timed(py, repeats, pool, || face::edit(input, &request, &Cancel::new(), &Progress::hidden()).map(|_| ()))
        .map_err(JobError::into_py)
}

/// Milliseconds of each of `repeats` runs of `video.resequence`'s work ([`video::resequence`]:
/// the clip read and analysed, the metric from its cache once trained, the walk measured and
/// explained) on `path` from `start`, `length` frames, called from Rust.
#[pyfunction]
#[pyo3(signature = (path, repeats, start=0, length=None, seed=1, metric="rsfnet".to_string(), cache_dir=None, pool=true))]
#[allow(clippy::too_many_arguments)]
fn _bench_video_rust(
    py: Python<'_>,
    path: std::path::PathBuf,
    repeats: usize,
    start: usize,
    length: Option<usize>,
    seed: u64,
    metric: String,
    cache_dir: Option<std::path::PathBuf>,
    pool: bool,
) -> PyResult<Vec<f64>> {
    let request = ResequenceRequest {
        path,
        start,
        length,
        seed: Some(seed),
        count: 1,
        transitions: true,
        metric,
        cache_dir,
        ..ResequenceRequest::default()
    };
    timed(py, repeats, pool, || video::resequence(&request, &Cancel::new(), &Progress::hidden()).map(|_| ()))
        .map_err(JobError::into_py)
}
