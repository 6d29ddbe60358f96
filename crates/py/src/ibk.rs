//! `.ibk` files: `compress` (mocap `CompressJob`), `decompress` (the codec's reader) and `Reader`,
//! the runtime sampler of version 4 files (`inbetween_ibk`) writing into a caller's numpy buffers.

use crate::clip::Clip;
use crate::errors::{ctx, engine, invalid, shape, JobError};
use crate::runner::run_job;
use inbetween_core::units::UnitChoice;
use inbetween_mocap::codec::{self, job::CompressJob, job::Version, Budget};
use numpy::{PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(ibk_compress, m)?)?;
    m.add_function(wrap_pyfunction!(ibk_decompress, m)?)?;
    m.add_class::<Reader>()?;
    Ok(())
}

/// Compresses a clip as the CLI's `mocap compress` does (same job, same defaults): `max_error_cm`
/// (version 4 unless `version` says otherwise) or `k` keys (version 2). Returns the file's bytes
/// and the job's report text.
#[pyfunction]
#[pyo3(signature = (clip, max_error_cm=None, k=None, version=None, segment_len=None, max_gap_s=0.5, progress=None))]
#[allow(clippy::too_many_arguments)]
fn ibk_compress<'py>(
    py: Python<'py>,
    clip: PyRef<'py, Clip>,
    max_error_cm: Option<f64>,
    k: Option<usize>,
    version: Option<&str>,
    segment_len: Option<usize>,
    max_gap_s: f64,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyBytes>, String)> {
    let job = compress_job(&clip, max_error_cm, k, version, segment_len, max_gap_s)?;
    let clip_ref: &Clip = &clip;
    let (bytes, text) = run_job(py, progress.as_ref(), |_, _| compress(clip_ref, &job))?;
    Ok((PyBytes::new(py, &bytes), text))
}

/// The work of `ibk.compress`: the file's bytes and the report text (also timed by `inbetween.bench`).
pub fn compress(clip: &Clip, job: &CompressJob) -> Result<(Vec<u8>, String), JobError> {
    let report = job.run(&clip.motion).map_err(ctx(format!("compressing {}", clip.source)))?;
    Ok((report.bytes().to_vec(), report.to_string()))
}

/// The job `ibk.compress` runs for these arguments (the CLI's defaults where none is given).
pub fn compress_job(
    clip: &Clip,
    max_error_cm: Option<f64>,
    k: Option<usize>,
    version: Option<&str>,
    segment_len: Option<usize>,
    max_gap_s: f64,
) -> PyResult<CompressJob> {
    let budget = match (max_error_cm, k) {
        (Some(cm), None) => Budget::MaxErrorCm(cm),
        (None, Some(k)) => Budget::Keys(k),
        _ => return Err(invalid("give either k=N or max_error_cm=LENGTH (e.g. max_error_cm=1.0)")),
    };
    if !(max_gap_s.is_finite() && max_gap_s > 0.0) {
        return Err(invalid(format!("max_gap_s {max_gap_s}: expected a positive number of seconds")));
    }
    let job = CompressJob {
        budget,
        version: version.map(Version::parse).transpose().map_err(|e| engine("", &e))?,
        segment_len,
        max_gap: inbetween_mocap::select::job::max_gap_frames(max_gap_s, clip.motion.frame_time),
        unit: clip.unit.clone(),
    };
    job.validate().map_err(|e| engine("", &e))?;
    Ok(job)
}

/// Decodes an `.ibk` file of any version into a clip (in the file's length unit).
#[pyfunction]
fn ibk_decompress(py: Python<'_>, data: &[u8]) -> PyResult<Clip> {
    let motion =
        py.detach(|| codec::read(data).and_then(|d| d.motion())).map_err(|e| engine("decoding the .ibk bytes", &e))?;
    let unit = UnitChoice::resolve(None, &motion.skeleton);
    Ok(Clip::new(motion, unit, ".ibk"))
}

self_cell::self_cell!(
    /// The file's bytes and the runtime clip that borrows them.
    struct OwnedClip {
        owner: Vec<u8>,
        #[covariant]
        dependent: RuntimeClip,
    }
);

type RuntimeClip<'a> = inbetween_ibk::Clip<'a>;

/// The runtime sampler of an `.ibk` version 4 file: `sample(t, rotations, translations)` writes the
/// local pose at `t` seconds into the caller's float32 buffers (`[J, 4]` quaternions x, y, z, w and
/// `[J, 3]` translations in cm) without allocating.
#[pyclass(module = "inbetween.ibk", unsendable)]
pub struct Reader {
    clip: OwnedClip,
    ctx: inbetween_ibk::Context,
    cm_per_unit: f32,
}

#[pymethods]
impl Reader {
    #[new]
    fn new(data: Vec<u8>) -> PyResult<Reader> {
        let clip = OwnedClip::try_new(data, |b| inbetween_ibk::Clip::open(b))
            .map_err(|e| engine("opening the .ibk bytes (version 4)", &e))?;
        let ctx = inbetween_ibk::Context::new(clip.borrow_dependent());
        let cm_per_unit = clip.borrow_dependent().cm_per_unit() as f32;
        Ok(Reader { clip, ctx, cm_per_unit })
    }

    #[getter]
    fn num_joints(&self) -> usize {
        self.clip.borrow_dependent().num_joints()
    }

    #[getter]
    fn num_frames(&self) -> usize {
        self.clip.borrow_dependent().num_frames()
    }

    #[getter]
    fn duration_s(&self) -> f64 {
        self.clip.borrow_dependent().duration()
    }

    #[getter]
    fn fps(&self) -> f64 {
        1.0 / self.clip.borrow_dependent().frame_time()
    }

    /// The file's error bound, cm.
    #[getter]
    fn bound_cm(&self) -> f64 {
        self.clip.borrow_dependent().bound_cm()
    }

    #[getter]
    fn joints(&self) -> Vec<String> {
        self.clip.borrow_dependent().joints().iter().map(|j| j.name.clone()).collect()
    }

    #[getter]
    fn parents(&self) -> Vec<i64> {
        self.clip.borrow_dependent().joints().iter().map(|j| j.parent.map_or(-1, |p| p as i64)).collect()
    }

    /// Writes the pose at `t` seconds (clamped to the clip) into `rotations` (float32 `[J, 4]`,
    /// x, y, z, w) and `translations` (float32 `[J, 3]`, cm). Both must be C-contiguous.
    fn sample(
        &mut self,
        t: f64,
        rotations: &Bound<'_, PyArray2<f32>>,
        translations: &Bound<'_, PyArray2<f32>>,
    ) -> PyResult<()> {
        let nj = self.clip.borrow_dependent().num_joints();
        if rotations.shape() != [nj, 4] || translations.shape() != [nj, 3] {
            return Err(shape(format!(
                "rotations {:?} and translations {:?}: expected float32 [J, 4] and [J, 3] with J = {nj}",
                rotations.shape(),
                translations.shape()
            )));
        }
        let mut r = rotations.try_readwrite().map_err(|e| invalid(format!("rotations: {e}")))?;
        let mut tr = translations.try_readwrite().map_err(|e| invalid(format!("translations: {e}")))?;
        let r = r.as_slice_mut().map_err(|_| shape("rotations: expected a C-contiguous float32 [J, 4] array"))?;
        let tr = tr.as_slice_mut().map_err(|_| shape("translations: expected a C-contiguous float32 [J, 3] array"))?;
        let (r4, _) = r.as_chunks_mut::<4>();
        let (t3, _) = tr.as_chunks_mut::<3>();
        self.clip.borrow_dependent().sample(&mut self.ctx, t, r4, t3).map_err(|e| engine("", &e))?;
        let s = self.cm_per_unit;
        for v in t3.iter_mut().flatten() {
            *v *= s;
        }
        Ok(())
    }
}
