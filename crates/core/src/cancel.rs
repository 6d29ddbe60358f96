//! Cooperative cancellation for long library jobs: one [`Cancel`] token, cheap to clone, checked in
//! the jobs' inner loops.
//!
//! A caller (the CLI's `--time-limit`, the studio's cancel button, a test) makes a token, hands
//! clones to the job and keeps one. The job calls [`Cancel::check`] between units of work (a
//! training step, a generated frame) and returns the [`Cancelled`] error it gives, so the caller
//! receives an ordinary error and nothing half-done is written. A time limit is the same mechanism:
//! a token with a deadline ([`Cancel::with_time_limit`]) reports itself cancelled once the deadline
//! has passed, so a job needs only one check for both.
//!
//! ```
//! use inbetween_core::cancel::Cancel;
//! let token = Cancel::new();
//! let job_side = token.clone();
//! assert!(job_side.check().is_ok());
//! token.cancel();
//! assert!(job_side.is_cancelled());
//! assert_eq!(job_side.check().unwrap_err().to_string(), "cancelled");
//! ```

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A shareable cancellation token; clones observe the same state.
///
/// `Cancel::default()` (= [`Cancel::new`]) is never cancelled unless [`Cancel::cancel`] is called,
/// so jobs without a caller-side token pass `&Cancel::new()`.
#[derive(Clone, Debug, Default)]
pub struct Cancel {
    inner: Arc<Inner>,
}

#[derive(Debug, Default)]
struct Inner {
    requested: AtomicBool,
    /// When the token counts as cancelled by itself, and the limit (in seconds) it came from.
    deadline: Option<(Instant, f64)>,
}

/// Why a job stopped early: the error a job returns when its token is cancelled.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum Cancelled {
    /// [`Cancel::cancel`] was called (a cancel button, a signal, a test).
    #[error("cancelled")]
    Requested,
    /// The token's time limit passed; `limit_s` is the limit the token was made with, in seconds.
    #[error("time limit of {limit_s} s reached")]
    TimeLimit { limit_s: f64 },
}

impl Cancel {
    /// A token that is cancelled only by [`Cancel::cancel`].
    pub fn new() -> Cancel {
        Cancel::default()
    }

    /// A token that also cancels itself `limit` from now (`--time-limit`).
    pub fn with_time_limit(limit: Duration) -> Cancel {
        let deadline = Instant::now().checked_add(limit).map(|at| (at, limit.as_secs_f64()));
        Cancel { inner: Arc::new(Inner { requested: AtomicBool::new(false), deadline }) }
    }

    /// [`Cancel::with_time_limit`] when `limit_s` is given, else [`Cancel::new`]. `limit_s` must be
    /// a finite number of seconds > 0; anything else is refused with a message naming the value.
    pub fn with_optional_limit_s(limit_s: Option<f64>) -> Result<Cancel, String> {
        match limit_s {
            None => Ok(Cancel::new()),
            Some(s) if s.is_finite() && s > 0.0 && s < 1e12 => Ok(Cancel::with_time_limit(Duration::from_secs_f64(s))),
            Some(s) => Err(format!("time limit {s} s: expected a number of seconds > 0")),
        }
    }

    /// Asks every holder of this token (and its clones) to stop.
    pub fn cancel(&self) {
        self.inner.requested.store(true, Ordering::Relaxed);
    }

    /// Whether the job should stop: cancelled, or past the deadline.
    pub fn is_cancelled(&self) -> bool {
        self.reason().is_some()
    }

    /// Why the token is cancelled, or `None` while the job may go on. An explicit
    /// [`Cancel::cancel`] wins over a passed deadline.
    pub fn reason(&self) -> Option<Cancelled> {
        if self.inner.requested.load(Ordering::Relaxed) {
            return Some(Cancelled::Requested);
        }
        match self.inner.deadline {
            Some((at, limit_s)) if Instant::now() >= at => Some(Cancelled::TimeLimit { limit_s }),
            _ => None,
        }
    }

    /// `Err` once cancelled: the inner-loop check (`cancel.check()?`).
    pub fn check(&self) -> Result<(), Cancelled> {
        match self.reason() {
            Some(r) => Err(r),
            None => Ok(()),
        }
    }

    /// The time left before the deadline (`None` without one; zero once it has passed).
    pub fn remaining(&self) -> Option<Duration> {
        self.inner.deadline.map(|(at, _)| at.saturating_duration_since(Instant::now()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresh_token_runs_and_clones_share_cancellation() {
        let a = Cancel::new();
        let b = a.clone();
        assert!(!a.is_cancelled());
        assert_eq!(b.check(), Ok(()));
        assert_eq!(a.remaining(), None);
        b.cancel();
        assert!(a.is_cancelled());
        assert_eq!(a.check(), Err(Cancelled::Requested));
        assert_eq!(a.reason().unwrap().to_string(), "cancelled");
    }

    #[test]
    fn passed_deadline_cancels_and_names_the_limit() {
        let t = Cancel::with_time_limit(Duration::ZERO);
        assert_eq!(t.check(), Err(Cancelled::TimeLimit { limit_s: 0.0 }));
        assert_eq!(t.remaining(), Some(Duration::ZERO));
        let t = Cancel::with_optional_limit_s(Some(2.5)).unwrap();
        assert!(!t.is_cancelled(), "2.5 s have not passed yet");
        assert!(t.remaining().unwrap() > Duration::ZERO);
        assert_eq!(Cancelled::TimeLimit { limit_s: 2.5 }.to_string(), "time limit of 2.5 s reached");
        // An explicit cancel wins over a deadline still ahead.
        t.cancel();
        assert_eq!(t.reason(), Some(Cancelled::Requested));
    }

    #[test]
    fn bad_limits_are_refused_with_the_value() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = Cancel::with_optional_limit_s(Some(bad)).unwrap_err();
            assert!(e.contains("expected a number of seconds > 0"), "{e}");
        }
        assert!(!Cancel::with_optional_limit_s(None).unwrap().is_cancelled());
    }

    #[test]
    fn cancellation_crosses_threads() {
        let t = Cancel::new();
        // The job loops until it sees the cancel made on another thread (the test hangs otherwise).
        let seen = std::thread::scope(|s| {
            let job = s.spawn(|| {
                while t.check().is_ok() {
                    std::thread::yield_now();
                }
                t.reason()
            });
            t.cancel();
            job.join().unwrap()
        });
        assert_eq!(seen, Some(Cancelled::Requested));
    }
}
