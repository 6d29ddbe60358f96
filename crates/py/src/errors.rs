//! One exception family: every engine error becomes an [`InbetweenError`] carrying the message the
//! CLI prints (the error and its causes, joined by ": "), so a Python caller reads the same file,
//! line/frame and expectation.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::PyErr;

create_exception!(
    inbetween,
    InbetweenError,
    PyException,
    "An engine refused its input or failed; the message is the CLI's."
);
create_exception!(
    inbetween,
    ShapeError,
    InbetweenError,
    "An array of the wrong shape or dtype; the message names the expected one."
);

/// The error and its sources as one line, like the CLI's `Error: a: b: c`.
pub fn message(e: &(dyn std::error::Error + 'static)) -> String {
    inbetween_io::with_causes(e)
}

/// An [`InbetweenError`] from any engine error, with `context` ("reading x.bvh") in front when given.
pub fn engine(context: &str, e: &(dyn std::error::Error + 'static)) -> PyErr {
    let m = message(e);
    if context.is_empty() || m.contains(context) {
        InbetweenError::new_err(m)
    } else {
        InbetweenError::new_err(format!("{context}: {m}"))
    }
}

/// An [`InbetweenError`] with a plain message.
pub fn invalid(m: impl Into<String>) -> PyErr {
    InbetweenError::new_err(m.into())
}

/// A [`ShapeError`] naming what was expected.
pub fn shape(m: impl Into<String>) -> PyErr {
    ShapeError::new_err(m.into())
}

/// Maps an engine error into an [`InbetweenError`] with context (`.map_err(ctx("reading x"))`).
pub fn ctx<E: std::error::Error + 'static>(context: impl Into<String>) -> impl FnOnce(E) -> JobError {
    let context = context.into();
    move |e| JobError::Failed(engine_text(&context, &e))
}

fn engine_text(context: &str, e: &(dyn std::error::Error + 'static)) -> String {
    let m = message(e);
    if context.is_empty() || m.contains(context) {
        m
    } else {
        format!("{context}: {m}")
    }
}

/// Why a job run from Python did not return a value.
#[derive(Debug)]
pub enum JobError {
    /// The engine's error message (becomes [`InbetweenError`]).
    Failed(String),
}

impl JobError {
    pub fn into_py(self) -> PyErr {
        match self {
            JobError::Failed(m) => InbetweenError::new_err(m),
        }
    }
}

impl<E: std::error::Error + 'static> From<E> for JobError {
    fn from(e: E) -> Self {
        JobError::Failed(engine_text("", &e))
    }
}
