//! `Clip` (a skeleton's motion: BVH or ASF/AMC) and `FaceClip` (ARKit blendshape weights: Live Link
//! Face CSV, curve CSV/JSON), their arrays, files and previews.
//!
//! A `Clip` keeps the file's own form (`core::Motion`, Euler channels in the file's length unit)
//! and its unit, so reading and writing a file changes nothing; the arrays are made on request
//! through `core::clip::Clip` (local quaternions x, y, z, w) and converted to cm.

use crate::arrays::{f32_array, Dim::Fixed, Dim::Named, Dim::Sized};
use crate::errors::{ctx, engine, invalid, shape, JobError};
use crate::runner::run_job;
use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip as PoseClip;
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::{Channel, EulerOrder, Joint, Motion, Pose, Skeleton};
use inbetween_face::data::BlendshapeClip;
use inbetween_render::stick::{self, StickOptions};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::{Path, PathBuf};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Clip>()?;
    m.add_class::<FaceClip>()?;
    m.add_function(wrap_pyfunction!(read_clip, m)?)?;
    m.add_function(wrap_pyfunction!(read_face_clip, m)?)?;
    Ok(())
}

/// A skeleton's motion. Built by `read`, `Clip.from_arrays` or a job.
#[pyclass(module = "inbetween", frozen)]
#[derive(Clone)]
pub struct Clip {
    pub motion: Motion,
    pub unit: UnitChoice,
    /// Where it came from, for titles and messages.
    pub source: String,
}

impl Clip {
    pub fn new(motion: Motion, unit: UnitChoice, source: impl Into<String>) -> Clip {
        Clip { motion, unit, source: source.into() }
    }

    fn poses(&self) -> PyResult<PoseClip> {
        PoseClip::from_motion(&self.motion).map_err(|e| engine(&self.source, &e))
    }
}

/// Reads a BVH or ASF/AMC file (the ASF beside the AMC); `unit` overrides the inferred length unit.
#[pyfunction]
#[pyo3(signature = (path, unit=None))]
fn read_clip(py: Python<'_>, path: PathBuf, unit: Option<&str>) -> PyResult<Clip> {
    let given = unit.map(|u| u.parse::<LengthUnit>().map_err(|e| invalid(e.to_string()))).transpose()?;
    let motion = py
        .detach(|| inbetween_io::load_motion(&path))
        .map_err(|e| engine(&format!("reading {}", path.display()), &e))?;
    let unit = UnitChoice::resolve(given, &motion.skeleton);
    Ok(Clip::new(motion, unit, path.display().to_string()))
}

/// Reads a face clip: Live Link Face CSV, curve CSV or curve JSON.
#[pyfunction]
fn read_face_clip(py: Python<'_>, path: PathBuf) -> PyResult<FaceClip> {
    let (clip, live_link) = py
        .detach(|| inbetween_face::data::read_clip(&path).map(|c| (c, inbetween_face::data::is_live_link(&path))))
        .map_err(|e| engine("", &e))?;
    Ok(FaceClip { clip, source: path.display().to_string(), live_link })
}

fn stick_options(title: Option<String>, width: u32, height: u32, max_frames: usize) -> StickOptions {
    StickOptions { width, height, max_frames, title, ..StickOptions::default() }
}

fn output_kind(path: &Path) -> PyResult<bool> {
    match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("gif") => Ok(true),
        Some("png") => Ok(false),
        _ => Err(invalid(format!("{}: output must end in .gif (animation) or .png (one frame)", path.display()))),
    }
}

#[pymethods]
impl Clip {
    /// Joint names, in file order.
    #[getter]
    fn joints(&self) -> Vec<String> {
        self.motion.skeleton.joints().iter().map(|j| j.name.clone()).collect()
    }

    /// Parent index of each joint, -1 for a root.
    #[getter]
    fn parents(&self) -> Vec<i64> {
        self.motion.skeleton.joints().iter().map(|j| j.parent.map_or(-1, |p| p as i64)).collect()
    }

    /// Rest offsets from the parent, cm, float32 `[J, 3]`.
    #[getter]
    fn offsets_cm<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let s = self.unit.cm_per_unit();
        let rows: Vec<Vec<f32>> = self
            .motion
            .skeleton
            .joints()
            .iter()
            .map(|j| j.offset.to_array().iter().map(|v| (v * s) as f32).collect())
            .collect();
        Ok(PyArray2::from_vec2(py, &rows).expect("rows of 3"))
    }

    /// Frames per second.
    #[getter]
    fn fps(&self) -> f64 {
        self.motion.fps()
    }

    #[getter]
    fn num_frames(&self) -> usize {
        self.motion.num_frames()
    }

    /// Seconds from the first frame to the last.
    #[getter]
    fn duration_s(&self) -> f64 {
        self.motion.duration()
    }

    /// cm per unit of the file, and the reason it was chosen.
    #[getter]
    fn cm_per_unit(&self) -> f64 {
        self.unit.cm_per_unit()
    }

    #[getter]
    fn unit(&self) -> String {
        self.unit.to_string()
    }

    #[getter]
    fn source(&self) -> String {
        self.source.clone()
    }

    /// Local joint rotations, unit quaternions (x, y, z, w), float32 `[T, J, 4]` (a new array).
    #[getter]
    fn rotations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let clip = self.poses()?;
        let (t, j) = (clip.num_frames(), clip.skeleton().len());
        let mut out = Vec::with_capacity(t * j * 4);
        for f in 0..t {
            for q in clip.key_rotations(f) {
                out.extend(q.to_array().map(|v| v as f32));
            }
        }
        PyArray1::from_vec(py, out).reshape([t, j, 4])
    }

    /// The root's translation (offset plus position channels), cm, float32 `[T, 3]` (a new array).
    #[getter]
    fn translations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let clip = self.poses()?;
        let s = self.unit.cm_per_unit();
        let t = clip.num_frames();
        let out: Vec<f32> =
            (0..t).flat_map(|f| (clip.key_translations(f)[0] * s).to_array().map(|v| v as f32)).collect();
        PyArray1::from_vec(py, out).reshape([t, 3])
    }

    /// Global joint positions (forward kinematics), cm, float32 `[T, J, 3]` (a new array).
    fn positions_cm<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let clip = self.poses()?;
        let s = self.unit.cm_per_unit();
        let (t, j) = (clip.num_frames(), clip.skeleton().len());
        let globals = py.detach(|| clip.globals());
        let out: Vec<f32> = globals
            .iter()
            .flat_map(|g| g.positions.iter().flat_map(|p| (*p * s).to_array().map(|v| v as f32)))
            .collect();
        PyArray1::from_vec(py, out).reshape([t, j, 3])
    }

    /// A clip from arrays: `joints` names, `parents` (-1 for the root), `offsets_cm` `[J, 3]`,
    /// `fps`, `rotations` `[T, J, 4]` unit quaternions (x, y, z, w) and `translations` `[T, 3]` of
    /// the root in cm. Every joint gets Z-Y-X Euler channels, the root also position channels; the
    /// unit is cm.
    #[staticmethod]
    #[pyo3(signature = (joints, parents, offsets_cm, fps, rotations, translations))]
    fn from_arrays(
        py: Python<'_>,
        joints: Vec<String>,
        parents: Vec<i64>,
        offsets_cm: &Bound<'_, PyAny>,
        fps: f64,
        rotations: &Bound<'_, PyAny>,
        translations: &Bound<'_, PyAny>,
    ) -> PyResult<Clip> {
        let n = joints.len();
        if parents.len() != n {
            return Err(shape(format!("parents: {} entries; expected one per joint ({n})", parents.len())));
        }
        let (off, _) = f32_array("offsets_cm", offsets_cm, &[Sized("J", n), Fixed(3)])?;
        let (r, rs) = f32_array("rotations", rotations, &[Named("T"), Sized("J", n), Fixed(4)])?;
        let t = rs[0];
        let (tr, _) = f32_array("translations", translations, &[Sized("T", t), Fixed(3)])?;
        if !(fps.is_finite() && fps > 0.0) {
            return Err(invalid(format!("fps {fps}: expected a positive number of frames per second")));
        }
        let mut skeleton_joints = Vec::with_capacity(n);
        for (j, name) in joints.iter().enumerate() {
            let parent = match parents[j] {
                -1 => None,
                p if p >= 0 && (p as usize) < j => Some(p as usize),
                p => {
                    return Err(invalid(format!(
                        "parents[{j}] = {p}: expected -1 (a root) or the index of an earlier joint (0..{j})"
                    )))
                }
            };
            let mut channels = Vec::new();
            if parent.is_none() {
                channels.extend(Channel::POSITION_XYZ);
            }
            channels.extend(Channel::rotations(EulerOrder::Zyx));
            let offset = DVec3::new(off[3 * j] as f64, off[3 * j + 1] as f64, off[3 * j + 2] as f64);
            skeleton_joints.push(Joint { name: name.clone(), parent, offset, channels, end_site: None });
        }
        let skeleton = Skeleton::new(skeleton_joints).map_err(|e| engine("", &e))?;
        let poses: Vec<Pose> = (0..t)
            .map(|f| {
                let mut p = Pose::rest(&skeleton);
                for j in 0..n {
                    let q = &r[4 * (f * n + j)..4 * (f * n + j) + 4];
                    let q = DQuat::from_xyzw(q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64);
                    // float32 quaternions are unit to ~1e-7; the clip wants 1e-6.
                    p.rotations[j] = if q.length() > 0.5 { q.normalize() } else { q };
                }
                for (j, joint) in skeleton.joints().iter().enumerate() {
                    if joint.parent.is_none() {
                        p.translations[j] = DVec3::new(tr[3 * f] as f64, tr[3 * f + 1] as f64, tr[3 * f + 2] as f64);
                    }
                }
                p
            })
            .collect();
        let motion = py
            .detach(|| PoseClip::from_poses(skeleton, 1.0 / fps, &poses).and_then(|c| c.to_motion()))
            .map_err(|e| engine("Clip.from_arrays", &e))?;
        Ok(Clip::new(motion, UnitChoice::given(LengthUnit::Centimetre), "arrays"))
    }

    /// Frames `start..end` (end exclusive).
    #[pyo3(signature = (start, end=None))]
    fn crop(&self, start: usize, end: Option<usize>) -> PyResult<Clip> {
        let end = end.unwrap_or(self.motion.num_frames());
        let m = self.motion.crop(start, end).map_err(|e| engine(&format!("cropping {}", self.source), &e))?;
        Ok(Clip::new(m, self.unit.clone(), self.source.clone()))
    }

    /// Writes a BVH file (atomically; the file's unit is the clip's).
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| inbetween_io::write_bvh(&path, &self.motion)).map_err(|e| engine("", &e))
    }

    /// The clip as BVH text.
    fn to_bvh(&self) -> String {
        inbetween_io::to_bvh_string(&self.motion)
    }

    /// A stick-figure preview: `.gif` (the animation) or `.png` (one frame), optionally with
    /// `compare` overlaid in another colour. Returns the path.
    #[pyo3(signature = (path, frame=None, compare=None, width=480, height=360, max_frames=150, title=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn preview(
        &self,
        py: Python<'_>,
        path: PathBuf,
        frame: Option<usize>,
        compare: Option<PyRef<'_, Clip>>,
        width: u32,
        height: u32,
        max_frames: usize,
        title: Option<String>,
        progress: Option<Bound<'_, PyAny>>,
    ) -> PyResult<PathBuf> {
        let is_gif = output_kind(&path)?;
        let other = compare.map(|c| c.motion.clone());
        let mut opts = stick_options(title.or_else(|| Some(file_label(&self.source))), width, height, max_frames);
        if other.is_some() {
            opts.labels = vec!["clip".into(), "compare".into()];
        }
        let main = &self.motion;
        run_job(py, progress.as_ref(), |_, bar| {
            let mut motions = vec![main];
            motions.extend(other.as_ref());
            if is_gif {
                stick::render_motion_gif_with_progress(&path, &motions, &opts, &mut |done, all| {
                    bar.set_length(all as u64);
                    bar.set_position(done as u64);
                })
                .map_err(ctx(format!("writing {}", path.display())))
            } else {
                let f = frame.unwrap_or(0);
                stick::render_motion_png(&path, &motions, f, &opts)
                    .map_err(ctx(format!("rendering frame {f} of {}", path.display())))
            }
        })?;
        Ok(path)
    }

    /// PNG bytes of the middle frame (Jupyter shows a clip as this picture).
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let opts = stick_options(Some(file_label(&self.source)), 480, 360, 150);
        let frame = self.motion.num_frames() / 2;
        let img = stick::try_render_motion_frame(&[&self.motion], frame, &opts).map_err(|e| engine("", &e))?;
        let bytes = inbetween_render::png_bytes(&img).map_err(|e| engine("", &e))?;
        Ok(PyBytes::new(py, &bytes))
    }

    fn __len__(&self) -> usize {
        self.motion.num_frames()
    }

    fn __repr__(&self) -> String {
        format!(
            "<inbetween.Clip {}: {} joints, {} frames at {:.3} fps ({:.3} s), {}>",
            file_label(&self.source),
            self.motion.skeleton.len(),
            self.motion.num_frames(),
            self.motion.fps(),
            self.motion.duration(),
            self.unit.unit.describe()
        )
    }
}

pub fn file_label(source: &str) -> String {
    Path::new(source).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| source.to_string())
}

/// ARKit blendshape weights over time.
#[pyclass(module = "inbetween", frozen)]
#[derive(Clone)]
pub struct FaceClip {
    pub clip: BlendshapeClip,
    pub source: String,
    /// Written as Live Link Face CSV by default (read from one, made from arrays or by an edit of one).
    pub live_link: bool,
}

#[pymethods]
impl FaceClip {
    /// The 52 ARKit shape names, in the column order of `weights`.
    #[getter]
    fn names(&self) -> Vec<String> {
        inbetween_face::data::ARKIT_NAMES.iter().map(|s| s.to_string()).collect()
    }

    /// Nominal frames per second.
    #[getter]
    fn fps(&self) -> f64 {
        self.clip.fps()
    }

    /// Time of each frame, seconds, float64 `[T]`.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.clip.times())
    }

    #[getter]
    fn num_frames(&self) -> usize {
        self.clip.num_frames()
    }

    #[getter]
    fn source(&self) -> String {
        self.source.clone()
    }

    /// ARKit weights, float32 `[T, 52]` (a new array).
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let frames = self.clip.arkit_frames();
        let t = frames.len();
        let flat: Vec<f32> = frames.into_iter().flatten().collect();
        PyArray1::from_vec(py, flat).reshape([t, inbetween_face::data::NUM_ARKIT])
    }

    /// A face clip from `weights` `[T, 52]` (ARKit order, see `names`) at `fps` (times `i / fps`).
    #[staticmethod]
    fn from_arrays(weights: &Bound<'_, PyAny>, fps: f64) -> PyResult<FaceClip> {
        let n = inbetween_face::data::NUM_ARKIT;
        let (values, s) = f32_array("weights", weights, &[Named("T"), Fixed(n)])?;
        if !(fps.is_finite() && fps > 0.0) {
            return Err(invalid(format!("fps {fps}: expected a positive number of frames per second")));
        }
        let times: Vec<f64> = (0..s[0]).map(|i| i as f64 / fps).collect();
        let clip = BlendshapeClip::new(fps, times, false, Vec::new(), values)
            .map_err(|e| engine("FaceClip.from_arrays", &e))?;
        Ok(FaceClip { clip, source: "arrays".into(), live_link: true })
    }

    /// Writes the clip (atomically): Live Link Face CSV when `live_link`, else curve CSV or JSON by
    /// extension. By default (`None`) a `.json` path gets curve JSON, a CSV path the layout the clip
    /// came in (Live Link for a Live Link capture, an edit of one, or arrays; curve CSV for a curve file).
    #[pyo3(signature = (path, live_link=None))]
    fn write(&self, py: Python<'_>, path: PathBuf, live_link: Option<bool>) -> PyResult<()> {
        let json = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
        let live_link = live_link.unwrap_or(self.live_link && !json);
        py.detach(|| inbetween_face::data::write_clip(&path, &self.clip, live_link)).map_err(|e| engine("", &e))
    }

    /// Every channel's name, in the column order of `values`: the 52 ARKit shapes, then the 9 head
    /// and eye rotations when the capture has them, then any extra columns.
    #[getter]
    fn channel_names(&self) -> Vec<String> {
        self.clip.channel_names().iter().map(|s| s.to_string()).collect()
    }

    /// Every channel, float32 `[T, C]` (a new array; `weights` is its first 52 columns).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let (t, c) = (self.clip.num_frames(), self.clip.num_channels());
        PyArray1::from_vec(py, self.clip.values().to_vec()).reshape([t, c])
    }

    /// Seconds from the first frame to the last.
    #[getter]
    fn duration_s(&self) -> f64 {
        self.clip.duration()
    }

    /// A face-drawing GIF of the clip (or, with `compare`, both side by side). Returns the path.
    #[pyo3(signature = (path, compare=None, progress=None))]
    fn preview(
        &self,
        py: Python<'_>,
        path: PathBuf,
        compare: Option<PyRef<'_, FaceClip>>,
        progress: Option<Bound<'_, PyAny>>,
    ) -> PyResult<PathBuf> {
        if !output_kind(&path)? {
            return Err(invalid(format!("{}: a face preview is an animation; give a .gif path", path.display())));
        }
        let mine = self.clip.arkit_frames();
        let other = compare.map(|c| c.clip.arkit_frames());
        let (label, fps) = (file_label(&self.source), self.clip.fps());
        run_job(py, progress.as_ref(), |_, bar| {
            let mut columns: Vec<(&str, &[[f32; 52]])> = vec![(label.as_str(), &mine)];
            if let Some(o) = &other {
                if o.len() != mine.len() {
                    return Err(JobError::Failed(format!(
                        "compare has {} frames; expected {} like the clip",
                        o.len(),
                        mine.len()
                    )));
                }
                columns.push(("compare", o));
            }
            let highlight = vec![false; mine.len()];
            inbetween_face::preview::write_edit_gif(&path, fps, &columns, None, &highlight, bar)
                .map_err(ctx(format!("writing {}", path.display())))
        })?;
        Ok(path)
    }

    /// PNG bytes of the middle frame's face (Jupyter shows a face clip as this picture).
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let frames = self.clip.arkit_frames();
        let pose = inbetween_face::preview::pose_from_arkit(&frames[frames.len() / 2], None);
        let label = file_label(&self.source);
        let img =
            inbetween_render::face::render_face_panels(&[(label.as_str(), &pose)], 256).map_err(|e| engine("", &e))?;
        let bytes = inbetween_render::png_bytes(&img).map_err(|e| engine("", &e))?;
        Ok(PyBytes::new(py, &bytes))
    }

    fn __len__(&self) -> usize {
        self.clip.num_frames()
    }

    fn __repr__(&self) -> String {
        format!(
            "<inbetween.FaceClip {}: {} frames at {:.3} fps, {} channels>",
            file_label(&self.source),
            self.clip.num_frames(),
            self.clip.fps(),
            self.clip.num_channels()
        )
    }
}
