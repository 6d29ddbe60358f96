//! Jobs: each panel action (run a story, choose keys, compress) becomes a job that runs an engine
//! call on a blocking thread. The page follows it over server-sent events
//! (`GET /api/jobs/{id}/events`): `progress` events (the stage and its share of the job), then one
//! `result` or `failed` event, or `cancelled` as soon as `POST /api/jobs/{id}/cancel` arrives.
//! Each job holds a cancel token ([`Job::token`]) that engines taking one check in their inner
//! loops (the script story update, face edits, mocap greedy and optimal keys, the video analysis),
//! so those stop soon after the cancel; an engine call without one runs to its end in the
//! background and its result is dropped. Stages after the cancel are skipped.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};

use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde_json::{json, Value};
use tokio::sync::Notify;

use crate::error::StudioError;

/// One job's event log (replayed to every subscriber) and its state.
pub struct Job {
    pub id: u64,
    pub kind: String,
    cancel: Cancel,
    log: Mutex<(Vec<(String, Value)>, bool)>,
    notify: Notify,
    started: Instant,
    /// Milliseconds from the start to when the work itself returned (a cancelled job's engine
    /// call may run on after its `cancelled` event until it checks its token).
    work_ms: Mutex<Option<f64>>,
}

impl Job {
    /// Appends an event; `last` closes the log.
    fn push(&self, event: &str, data: Value, last: bool) {
        let mut log = self.log.lock().unwrap_or_else(|p| p.into_inner());
        if log.1 {
            return;
        }
        log.0.push((event.to_string(), data));
        log.1 = last;
        drop(log);
        self.notify.notify_waiters();
    }

    /// Reports a stage: `fraction` of the job done when it starts.
    pub fn progress(&self, stage: &str, fraction: f64) {
        self.push("progress", json!({"job": self.id, "stage": stage, "fraction": fraction}), false);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancel.is_cancelled()
    }

    /// The job's cancel token, for engine calls that check one.
    pub fn token(&self) -> &Cancel {
        &self.cancel
    }

    /// Milliseconds since the job started.
    pub fn elapsed_ms(&self) -> f64 {
        self.started.elapsed().as_secs_f64() * 1000.0
    }

    /// Waits up to `within` for the job to end; its last event (`result`, `failed` or
    /// `cancelled`) when it did, None while it still runs.
    pub async fn ended_within(&self, within: std::time::Duration) -> Option<(String, Value)> {
        let _ = tokio::time::timeout(within, async {
            loop {
                let seen = {
                    let log = self.log.lock().unwrap_or_else(|p| p.into_inner());
                    if log.1 {
                        return;
                    }
                    log.0.len()
                };
                self.wait_past(seen).await;
            }
        })
        .await;
        let log = self.log.lock().unwrap_or_else(|p| p.into_inner());
        if log.1 {
            log.0.last().cloned()
        } else {
            None
        }
    }

    pub fn cancel(&self) {
        self.cancel.cancel();
        self.push("cancelled", json!({"job": self.id, "kind": self.kind, "ms": self.elapsed_ms()}), true);
    }

    /// The job's state: kind, whether its log is closed (`result`, `failed` or `cancelled`
    /// sent), and whether its work still runs, with the time it took once it returned.
    pub fn status(&self) -> Value {
        let ended = self.log.lock().unwrap_or_else(|p| p.into_inner()).1;
        let work_ms = *self.work_ms.lock().unwrap_or_else(|p| p.into_inner());
        json!({"job": self.id, "kind": self.kind, "ended": ended, "working": work_ms.is_none(),
               "work_ms": work_ms, "cancelled": self.is_cancelled(), "ms": self.elapsed_ms()})
    }

    /// Events from index `from` on, and whether the log is closed.
    pub fn events_from(&self, from: usize) -> (Vec<(String, Value)>, bool) {
        let log = self.log.lock().unwrap_or_else(|p| p.into_inner());
        (log.0[from.min(log.0.len())..].to_vec(), log.1)
    }

    /// Waits until the next event (or returns at once when one arrived after `seen`).
    pub async fn wait_past(&self, seen: usize) {
        loop {
            let notified = self.notify.notified();
            tokio::pin!(notified);
            notified.as_mut().enable();
            {
                let log = self.log.lock().unwrap_or_else(|p| p.into_inner());
                if log.0.len() > seen || log.1 {
                    return;
                }
            }
            notified.await;
        }
    }
}

/// The registry of jobs (the last [`KEEP`] are kept).
#[derive(Default)]
pub struct Jobs {
    next: AtomicU64,
    jobs: Mutex<HashMap<u64, Arc<Job>>>,
}

/// Jobs kept for late subscribers.
pub const KEEP: u64 = 64;

/// How long a request that starts a job waits for it before answering with the job's id only: a
/// job done by then (a K change, an incremental story edit) is answered in the same response, so
/// the page does not open an event stream for it.
pub const ANSWER_WITHIN: std::time::Duration = std::time::Duration::from_millis(300);

/// The answer to a request that started job `id`: `{"job": id}`, with `"event"` and `"data"`
/// (the job's last event) when it ended within [`ANSWER_WITHIN`].
pub async fn answer(jobs: &Jobs, id: u64) -> Value {
    let ended = match jobs.get(id) {
        Some(job) => job.ended_within(ANSWER_WITHIN).await,
        None => None,
    };
    match ended {
        Some((event, data)) => json!({"job": id, "event": event, "data": data}),
        None => json!({"job": id}),
    }
}

impl Jobs {
    pub fn get(&self, id: u64) -> Option<Arc<Job>> {
        self.jobs.lock().unwrap_or_else(|p| p.into_inner()).get(&id).cloned()
    }

    /// A progress handle for an engine job run inside job `id`: each update of the engine's
    /// phases becomes a `progress` event, at the share of the job `share(stage, fraction of the
    /// stage)` gives. Hidden (counting only) when the job is gone.
    pub fn engine_progress(&self, id: u64, share: impl Fn(&str, f64) -> f64 + Send + Sync + 'static) -> Progress {
        match self.get(id) {
            Some(job) => Progress::observed(move |stage, pos, len| {
                job.progress(stage, share(stage, pos as f64 / len.max(1) as f64));
            }),
            None => Progress::hidden(),
        }
    }

    /// Starts `work` on a blocking thread as a job of `kind`; returns its id at once. `work`'s
    /// value becomes the `result` event (with `ms` added: the job's wall time), its error the
    /// `failed` event; a panic inside it is caught and reported as `failed`.
    pub fn spawn<F>(&self, kind: &str, work: F) -> u64
    where
        F: FnOnce(&Job) -> Result<Value, StudioError> + Send + 'static,
    {
        let id = self.next.fetch_add(1, Ordering::SeqCst) + 1;
        let job = Arc::new(Job {
            id,
            kind: kind.to_string(),
            cancel: Cancel::new(),
            log: Mutex::new((Vec::new(), false)),
            notify: Notify::new(),
            started: Instant::now(),
            work_ms: Mutex::new(None),
        });
        {
            let mut jobs = self.jobs.lock().unwrap_or_else(|p| p.into_inner());
            jobs.retain(|&k, _| k + KEEP > id);
            jobs.insert(id, job.clone());
        }
        job.progress("queued", 0.0);
        tokio::task::spawn_blocking(move || {
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(&job)));
            let ms = job.elapsed_ms();
            *job.work_ms.lock().unwrap_or_else(|p| p.into_inner()) = Some(ms);
            match outcome {
                Ok(Ok(mut v)) => {
                    if let Some(o) = v.as_object_mut() {
                        o.insert("ms".into(), json!(ms));
                        o.insert("job".into(), json!(job.id));
                        o.insert("kind".into(), json!(job.kind));
                    }
                    job.push("result", v, true);
                }
                Ok(Err(e)) => job.push(
                    "failed",
                    json!({"job": job.id, "kind": job.kind, "ms": ms, "error": e.to_string(), "status": e.status()}),
                    true,
                ),
                Err(p) => {
                    let what = p
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| p.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "unknown panic".into());
                    job.push(
                        "failed",
                        json!({"job": job.id, "kind": job.kind, "ms": ms,
                               "error": format!("internal error in the {} job: {what} (the studio keeps serving)", job.kind)}),
                        true,
                    )
                }
            }
        });
        id
    }
}
