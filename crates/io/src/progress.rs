//! One progress bar for every long job (training, benchmarks, rendering, corpus scans).
//!
//! Library functions that run long take a `&Progress` and call [`Progress::inc`] as work gets
//! done; the CLI makes a visible one with [`Progress::new`], tests and batch callers pass
//! [`Progress::hidden`]; front ends that show progress their own way (the studio's job events, a
//! Python callback) pass [`Progress::observed`]. A bar is drawn on stderr only when stderr is a terminal (never in CI
//! logs or when piped), and never when `INBETWEEN_NO_PROGRESS` is set.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A shareable progress handle (clones report to the same bar).
#[derive(Clone, Debug)]
pub struct Progress {
    bar: ProgressBar,
    /// For [`Progress::after`]: when the bar may appear, and whether it has.
    reveal: Option<Arc<(Instant, AtomicBool)>>,
    /// For [`Progress::observed`]: told the phase's label, position and length at every update.
    observer: Option<Observer>,
}

/// What an observed handle calls: phase label, position, length.
type ObserverFn = dyn Fn(&str, u64, u64) + Send + Sync;

/// The callback of an observed progress handle.
#[derive(Clone)]
struct Observer(Arc<ObserverFn>);

impl std::fmt::Debug for Observer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Observer")
    }
}

/// Whether bars may be drawn at all in this process.
fn drawing_allowed() -> bool {
    std::io::stderr().is_terminal() && std::env::var_os("INBETWEEN_NO_PROGRESS").is_none()
}

impl Progress {
    /// A bar over `len` units labelled `label`, drawn on stderr when it is a terminal.
    pub fn new(len: u64, label: &str) -> Progress {
        let target = if drawing_allowed() { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
        Progress { bar: styled(ProgressBar::with_draw_target(Some(len), target), label), reveal: None, observer: None }
    }

    /// Like [`Progress::new`], but the bar appears only once `delay` has passed (no flicker for
    /// work that is usually quick).
    pub fn after(delay: Duration, len: u64, label: &str) -> Progress {
        let bar = styled(ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden()), label);
        let reveal = drawing_allowed().then(|| Arc::new((Instant::now() + delay, AtomicBool::new(false))));
        Progress { bar, reveal, observer: None }
    }

    /// A handle that counts but never draws.
    pub fn hidden() -> Progress {
        Progress { bar: ProgressBar::hidden(), reveal: None, observer: None }
    }

    /// A handle that never draws and calls `observer(label, position, length)` at every update
    /// (each phase, increment, position or length change): the studio turns the calls into its job
    /// events, a Python caller into its callback.
    pub fn observed(observer: impl Fn(&str, u64, u64) + Send + Sync + 'static) -> Progress {
        let bar = ProgressBar::hidden();
        bar.set_length(0);
        Progress { bar, reveal: None, observer: Some(Observer(Arc::new(observer))) }
    }

    fn notify(&self) {
        if let Some(o) = &self.observer {
            (o.0)(&self.bar.prefix(), self.bar.position(), self.bar.length().unwrap_or(0));
        }
    }

    fn maybe_reveal(&self) {
        if let Some(r) = &self.reveal {
            if Instant::now() >= r.0 && !r.1.swap(true, Ordering::Relaxed) {
                self.bar.set_draw_target(ProgressDrawTarget::stderr());
            }
        }
    }

    /// Starts a new phase on the same bar: new label and length, position 0.
    pub fn phase(&self, len: u64, label: &str) {
        self.bar.set_prefix(label.to_string());
        self.bar.set_length(len);
        self.bar.set_position(0);
        self.bar.set_message("");
        self.notify();
    }

    pub fn inc(&self, n: u64) {
        self.maybe_reveal();
        self.bar.inc(n);
        self.notify();
    }

    pub fn set_position(&self, pos: u64) {
        self.maybe_reveal();
        self.bar.set_position(pos);
        self.notify();
    }

    pub fn position(&self) -> u64 {
        self.bar.position()
    }

    pub fn set_length(&self, len: u64) {
        self.bar.set_length(len);
        self.notify();
    }

    /// Short status after the counts (e.g. the running loss).
    pub fn set_message(&self, message: impl Into<String>) {
        self.bar.set_message(message.into());
    }

    /// Prints a line above the bar (or to stderr when no bar is drawn and stderr is a terminal).
    pub fn println(&self, line: impl AsRef<str>) {
        self.bar.println(line.as_ref());
    }

    /// Redraws the bar every `every` (its elapsed time moves) while a long step reports nothing;
    /// reveals a [`Progress::after`] bar once its delay has passed at a later update.
    pub fn tick_every(&self, every: Duration) {
        self.maybe_reveal();
        self.bar.enable_steady_tick(every);
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }

    /// Leaves the bar where it stopped (after an error).
    pub fn abandon(&self) {
        self.bar.abandon();
    }
}

fn styled(bar: ProgressBar, label: &str) -> ProgressBar {
    if let Ok(style) = ProgressStyle::with_template("{prefix:>12} [{bar:36}] {pos}/{len} ({elapsed} < {eta}) {msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(label.to_string());
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_one_count_and_phases_restart_it() {
        let p = Progress::hidden();
        let q = p.clone();
        p.inc(3);
        q.inc(2);
        assert_eq!(p.position(), 5);
        p.phase(10, "next");
        assert_eq!(q.position(), 0);
        q.set_position(7);
        assert_eq!(p.position(), 7);
        let late = Progress::after(Duration::from_secs(3600), 4, "late");
        late.inc(4);
        assert_eq!(late.position(), 4);
    }

    #[test]
    fn an_observer_sees_every_update_with_its_phase() {
        let seen = Arc::new(std::sync::Mutex::new(Vec::new()));
        let log = seen.clone();
        let p = Progress::observed(move |label, pos, len| log.lock().unwrap().push((label.to_string(), pos, len)));
        p.phase(4, "keys");
        p.inc(1);
        p.clone().set_position(3);
        p.phase(2, "rebuild");
        p.inc(2);
        let seen = seen.lock().unwrap().clone();
        let want = [("keys", 0, 4), ("keys", 1, 4), ("keys", 3, 4), ("rebuild", 0, 2), ("rebuild", 2, 2)];
        assert_eq!(seen, want.map(|(l, p, n)| (l.to_string(), p, n)));
    }
}
