//! script `run`: a story in plain English to an animated scene, by the script engine's `RunJob`
//! (`inbetween script run`): the glTF, a clip per character and the scene graph.

use crate::clip::Clip;
use crate::errors::{ctx, invalid, JobError};
use crate::runner::run_job;
use inbetween_core::units::UnitChoice;
use inbetween_script::jobs::{run_story, RunJob};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::path::{Path, PathBuf};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(script_run, m)?)?;
    Ok(())
}

/// Runs a `RunJob` on `text`, writing its files into `out_dir` (a temporary folder when None).
/// Returns a dict: `gltf` (bytes), `characters` ({name: Clip}), `scene_json`, `files`, `notes`,
/// `text` (the report in words).
#[pyfunction]
#[pyo3(signature = (text, out_dir=None, seed=None, optimize=None, shared_motions=None, progress=None))]
fn script_run<'py>(
    py: Python<'py>,
    text: &str,
    out_dir: Option<PathBuf>,
    seed: Option<u64>,
    optimize: Option<bool>,
    shared_motions: Option<bool>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    if text.trim().is_empty() {
        return Err(invalid("the story is empty: give at least one sentence"));
    }
    let temp = match &out_dir {
        Some(_) => None,
        None => Some(tempfile::tempdir().map_err(|e| invalid(format!("making a temporary folder: {e}")))?),
    };
    let dir = out_dir.clone().unwrap_or_else(|| temp.as_ref().expect("made above").path().to_path_buf());
    let defaults = RunJob::default();
    let (report, gltf) = run_job(py, progress.as_ref(), |cancel, bar| {
        let mut job = RunJob { cancel: cancel.clone(), progress: bar.clone(), ..RunJob::default() };
        job.scene.out_dir = dir.clone();
        job.scene.seed = seed.unwrap_or(defaults.scene.seed);
        job.optimize = optimize.unwrap_or(defaults.optimize);
        job.shared_motions = shared_motions.unwrap_or(defaults.shared_motions);
        let report = run_story(text, Path::new("<python>"), &job).map_err(ctx("animating the story"))?;
        // The animated story (the scene job also writes the still `scene.gltf`).
        let gltf_path = report.files.iter().find(|f| f.file_name().is_some_and(|n| n == "story.gltf"));
        let p = gltf_path.ok_or_else(|| JobError::Failed("the story job wrote no story.gltf".into()))?;
        let gltf = std::fs::read(p).map_err(|e| JobError::Failed(format!("reading {}: {e}", p.display())))?;
        Ok((report, gltf))
    })?;
    let d = PyDict::new(py);
    d.set_item("gltf", PyBytes::new(py, &gltf))?;
    let chars = PyDict::new(py);
    for c in &report.animation.characters {
        let motion = c.clip.to_motion().map_err(|e| crate::errors::engine(&c.name, &e))?;
        let unit = UnitChoice::resolve(None, &motion.skeleton);
        chars.set_item(&c.name, Clip::new(motion, unit, format!("{}.bvh", c.name)))?;
    }
    d.set_item("characters", chars)?;
    let scene = serde_json::to_string(&report.animation.scene).map_err(|e| invalid(e.to_string()))?;
    d.set_item("scene_json", scene)?;
    let files: Vec<PathBuf> = if out_dir.is_some() { report.files.clone() } else { Vec::new() };
    d.set_item("files", files)?;
    d.set_item("notes", report.animation.notes.clone())?;
    d.set_item("frames", report.animation.frames())?;
    d.set_item("fps", report.animation.fps)?;
    drop(temp);
    Ok(d)
}
