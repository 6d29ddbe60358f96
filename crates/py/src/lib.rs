//! `inbetween._native`: the engines' public jobs for Python, numpy arrays in and out.
//!
//! Thin on purpose: every function here converts arrays and arguments into one of the engines' jobs,
//! runs it through [`runner::run_job`] (the GIL released, progress forwarded, Ctrl-C cancelling the
//! job's token, a panic turned into an exception) and converts its report back. No engine rule,
//! constant or metric is written here; the Python package `inbetween` (python/inbetween) adds
//! argument checking with messages that name the expected shapes, and the tqdm bar.

use pyo3::prelude::*;

mod arrays;
mod batch;
mod bench;
mod camera;
mod clip;
mod errors;
mod face;
mod ibk;
mod mocap;
mod report;
mod runner;
mod script;
mod video;

pub use errors::{InbetweenError, ShapeError};

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("InbetweenError", py.get_type::<InbetweenError>())?;
    m.add("ShapeError", py.get_type::<ShapeError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(runner::_panic_in_job, m)?)?;
    clip::register(m)?;
    batch::register(m)?;
    bench::register(m)?;
    camera::register(m)?;
    face::register(m)?;
    ibk::register(m)?;
    mocap::register(m)?;
    report::register(m)?;
    script::register(m)?;
    video::register(m)?;
    Ok(())
}
