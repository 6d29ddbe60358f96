//! A job's report handed to Python as it is ([`JobReport`]): its words and its JSON are made when
//! asked for, so a call whose caller reads only the arrays converts nothing more (the Python side
//! parses the JSON once, on first use of `.report`).

use crate::errors::invalid;
use pyo3::prelude::*;
use serde::Serialize;
use std::fmt::Display;

/// What a report must do: print, and serialise.
trait Report: Send + Sync {
    fn json(&self) -> serde_json::Result<String>;
    fn text(&self) -> String;
}

impl<T: Serialize + Display + Send + Sync> Report for T {
    fn json(&self) -> serde_json::Result<String> {
        serde_json::to_string(self)
    }
    fn text(&self) -> String {
        self.to_string()
    }
}

/// An engine job's report: `json()` (the CLI's `--json` form) and `str()` (its words).
#[pyclass(frozen, module = "inbetween._native")]
pub struct JobReport(Box<dyn Report>);

impl JobReport {
    pub fn new(report: impl Serialize + Display + Send + Sync + 'static) -> JobReport {
        JobReport(Box::new(report))
    }
}

#[pymethods]
impl JobReport {
    /// The report as JSON text.
    fn json(&self) -> PyResult<String> {
        self.0.json().map_err(|e| invalid(e.to_string()))
    }

    fn __str__(&self) -> String {
        self.0.text()
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<JobReport>()
}
