//! Runs a long job from Python: on a worker thread (rayon's pool) with the GIL released, while the calling
//! thread wakes every [`TICK`] to forward progress to the Python callback and to check for
//! signals. Ctrl-C (a `KeyboardInterrupt`) cancels the job's [`Cancel`] token; the job stops at its
//! next check and the interrupt is raised. A panic in the job becomes an [`InbetweenError`]
//! instead of aborting the interpreter.

use crate::errors::{InbetweenError, JobError};
use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

/// How often the waiting thread looks at signals and progress.
const TICK: Duration = Duration::from_millis(50);

/// The last progress update: phase label, position, length.
type Latest = Arc<Mutex<Option<(String, u64, u64)>>>;

/// Runs `job(cancel, progress)` as described in the module doc. `callback(done, total)` (a Python
/// callable or None) is called on the calling thread with the job's latest progress.
pub fn run_job<T, F>(py: Python<'_>, callback: Option<&Bound<'_, PyAny>>, job: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Cancel, &Progress) -> Result<T, JobError> + Send,
{
    let cancel = Cancel::new();
    let latest: Latest = Arc::new(Mutex::new(None));
    let sink = latest.clone();
    let progress = Progress::observed(move |label, pos, len| {
        if let Ok(mut l) = sink.lock() {
            *l = Some((label.to_string(), pos, len));
        }
    });
    let mut reported: Option<(u64, u64)> = None;
    let mut forward = || -> PyResult<()> {
        let Some(cb) = callback else { return Ok(()) };
        let now = latest.lock().ok().and_then(|l| l.as_ref().map(|(_, p, n)| (*p, *n)));
        match now {
            Some(pn) if reported != Some(pn) && pn.1 > 0 => {
                reported = Some(pn);
                cb.call1((pn.0, pn.1)).map(|_| ())
            }
            _ => Ok(()),
        }
    };
    let (cancel_ref, progress_ref) = (&cancel, &progress);
    let mut stopped_by: Option<PyErr> = None;
    // The job runs on a thread of rayon's pool, which lives as long as the process: a thread made
    // per call cost a 13 ms face edit 2.7 ms more (its allocator arena and pages start cold).
    let result: Mutex<Option<std::thread::Result<Result<T, JobError>>>> = Mutex::new(None);
    let result_ref = &result;
    rayon::in_place_scope(|s| {
        let (tx, rx) = mpsc::channel::<()>();
        let rx = Mutex::new(rx);
        s.spawn(move |_| {
            let r = catch_unwind(AssertUnwindSafe(|| job(cancel_ref, progress_ref)));
            *result_ref.lock().unwrap_or_else(|p| p.into_inner()) = Some(r);
            let _ = tx.send(());
        });
        loop {
            // Disconnected counts as finished too (the worker always sends, panics included).
            let finished = py.detach(|| {
                let rx = rx.lock().unwrap_or_else(|p| p.into_inner());
                !matches!(rx.recv_timeout(TICK), Err(mpsc::RecvTimeoutError::Timeout))
            });
            if finished {
                break;
            }
            if stopped_by.is_some() {
                continue;
            }
            // Ctrl-C, or an exception from the callback: cancel and wait for the job to notice.
            if let Err(e) = py.check_signals().and_then(|_| forward()) {
                cancel.cancel();
                stopped_by = Some(e);
            }
        }
    });
    if let Some(e) = stopped_by {
        return Err(e);
    }
    let outcome = result.into_inner().unwrap_or_else(|p| p.into_inner());
    match outcome {
        Some(Ok(Ok(value))) => {
            forward()?;
            Ok(value)
        }
        Some(Ok(Err(e))) => Err(e.into_py()),
        None => Err(InbetweenError::new_err("internal error (a bug in inbetween): the job ended without a result")),
        Some(Err(panic)) => Err(InbetweenError::new_err(format!(
            "internal error (a bug in inbetween; please report it with the input): {}",
            panic_text(&panic)
        ))),
    }
}

fn panic_text(p: &Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "panic".into()
    }
}

/// Panics inside [`run_job`]: the test suite's check that a panic becomes an `InbetweenError`
/// and leaves the interpreter usable (no public operation is known to panic).
#[pyfunction]
pub fn _panic_in_job(py: Python<'_>) -> PyResult<()> {
    run_job(py, None, |_, _| -> Result<(), JobError> { panic!("a deliberate panic for the test suite") })
}
