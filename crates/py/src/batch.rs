//! `inbetween.batch`'s native half: one input of a batch job, what a Dask task runs
//! ([`inbetween_batch::run_input`]: the same outputs and result line as `inbetween batch`).

use crate::errors::invalid;
use inbetween_batch::{run_input, Input, Kind, Options};
use inbetween_core::cancel::Cancel;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Runs `job` on the file `path`, writing its outputs below `out` at the file's path relative to
/// `root`; returns the result line as JSON. A failing input is a line with `ok: false`, not an
/// exception; a bad job name, options or a path outside `root` is an `InbetweenError`.
#[pyfunction]
fn batch_run_input(
    py: Python<'_>,
    job: &str,
    path: PathBuf,
    root: PathBuf,
    out: PathBuf,
    options: &str,
) -> PyResult<String> {
    let kind = Kind::parse(job).map_err(|e| invalid(e.to_string()))?;
    let options: Options = serde_json::from_str(options).map_err(|e| invalid(format!("options of {job}: {e}")))?;
    options.validate(kind).map_err(|e| invalid(e.to_string()))?;
    let rel = path
        .strip_prefix(&root)
        .map_err(|_| invalid(format!("{}: not inside the root folder {}", path.display(), root.display())))?;
    let rel = rel
        .components()
        .map(|c| c.as_os_str().to_str().map(str::to_string))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| invalid(format!("{}: a path that is not UTF-8", path.display())))?
        .join("/");
    let input = Input { path, rel };
    let line = py.detach(|| run_input(kind, &input, &out, &options, &Cancel::new()));
    serde_json::to_string(&line).map_err(|e| invalid(e.to_string()))
}

/// The input extensions `job` reads (lower case, no dot).
#[pyfunction]
fn batch_extensions(job: &str) -> PyResult<Vec<&'static str>> {
    Ok(Kind::parse(job).map_err(|e| invalid(e.to_string()))?.extensions().to_vec())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(batch_run_input, m)?)?;
    m.add_function(wrap_pyfunction!(batch_extensions, m)?)?;
    Ok(())
}
