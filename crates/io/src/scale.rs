//! Scaling runs for benches: how a job's wall time and peak memory grow with its input, measured on
//! a child process (so each run's memory is its own). Peak memory is the kernel's high-water mark of
//! the child's resident set (`VmHWM` in `/proc/<pid>/status`, Linux only), read every 2 ms while it
//! runs; the mark only rises, so the last reading misses at most the growth of the child's final
//! 2 ms.
//!
//! ```no_run
//! let run = inbetween_io::scale::run_measured(std::process::Command::new("true").arg("x")).unwrap();
//! assert!(run.success);
//! println!("{:.3} s, peak {:?} MiB", run.seconds, run.peak_mib);
//! ```

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One measured child run.
#[derive(Debug, Clone, PartialEq)]
pub struct ChildRun {
    /// Wall-clock seconds from spawn to exit.
    pub seconds: f64,
    /// Highest `VmHWM` seen, in MiB (`None` where `/proc` has none, e.g. off Linux).
    pub peak_mib: Option<f64>,
    /// Whether the child exited with status 0.
    pub success: bool,
    /// What the child wrote on stderr (its error, when it failed).
    pub stderr: String,
}

/// `VmHWM` (peak resident set) in KiB from the text of a `/proc/<pid>/status` file.
pub fn vm_hwm_kib(status: &str) -> Option<u64> {
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

/// This process's own peak resident set so far, in MiB (`None` off Linux).
pub fn own_peak_mib() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    vm_hwm_kib(&text).map(|k| k as f64 / 1024.0)
}

/// Runs `cmd` (stdout discarded, stderr kept) and measures its wall time and peak memory.
pub fn run_measured(cmd: &mut Command) -> std::io::Result<ChildRun> {
    cmd.stdin(Stdio::null()).stdout(Stdio::null()).stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn()?;
    let status_path = format!("/proc/{}/status", child.id());
    let mut stderr = child.stderr.take();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        if let Some(s) = stderr.as_mut() {
            let _ = s.read_to_string(&mut text);
        }
        text
    });
    let mut peak_kib: Option<u64> = None;
    let status = loop {
        if let Some(k) = std::fs::read_to_string(&status_path).ok().as_deref().and_then(vm_hwm_kib) {
            peak_kib = Some(peak_kib.map_or(k, |p| p.max(k)));
        }
        if let Some(status) = child.try_wait()? {
            break status;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let seconds = start.elapsed().as_secs_f64();
    let stderr = reader.join().unwrap_or_default();
    Ok(ChildRun { seconds, peak_mib: peak_kib.map(|k| k as f64 / 1024.0), success: status.success(), stderr })
}

/// One row of a scaling bench: the scale factor, what the input was, and the measured run.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleRow {
    /// 1, 10, 100, …: multiples of the built-in example.
    pub scale: usize,
    /// The input at this scale, in words with units ("250 s clip, 75 s mask").
    pub input: String,
    pub run: ChildRun,
}

/// The bench table of a scaling run: time and peak memory per scale, and time relative to the
/// smallest scale (linear work shows ≈ the scale factor, once the fixed start-up cost is small).
pub fn scale_table(name: &str, title: &str, rows: &[ScaleRow]) -> crate::report::Table {
    use crate::report::{num, Table};
    let mut t = Table::new(name, title, &["scale", "input", "seconds", "time vs 1×", "peak MiB", "result"]);
    let base = rows.first().map(|r| r.run.seconds);
    for r in rows {
        let ratio = base.map_or(f64::NAN, |b| r.run.seconds / b);
        let result =
            if r.run.success { "ok".to_string() } else { r.run.stderr.lines().next().unwrap_or("failed").to_string() };
        t.row([
            format!("{}×", r.scale),
            r.input.clone(),
            num(r.run.seconds, 3),
            num(ratio, 1),
            num(r.run.peak_mib.unwrap_or(f64::NAN), 1),
            result,
        ]);
    }
    t.note("one child process per row (start-up and weight loading included); peak MiB = the child's VmHWM");
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_high_water_mark_from_a_status_text() {
        let text = "Name:\tx\nVmPeak:\t  20000 kB\nVmHWM:\t    5120 kB\nVmRSS:\t 4000 kB\n";
        assert_eq!(vm_hwm_kib(text), Some(5120));
        assert_eq!(vm_hwm_kib("Name:\tx\n"), None);
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_child_that_holds_more_memory_shows_a_higher_peak() {
        // `sh` reading 64 MiB into a variable vs doing nothing; both exit 0.
        let small = run_measured(Command::new("sh").args(["-c", "true"])).unwrap();
        let big =
            run_measured(Command::new("sh").args(["-c", "x=$(head -c 67108864 /dev/zero | tr '\\0' a); sleep 0.05"]))
                .unwrap();
        assert!(small.success && big.success, "{} {}", small.stderr, big.stderr);
        let (s, b) = (small.peak_mib.unwrap_or(0.0), big.peak_mib.unwrap());
        assert!(b > s + 32.0, "peak {b} MiB vs {s} MiB");
        assert!(own_peak_mib().unwrap() > 0.0);
        let failed = run_measured(Command::new("sh").args(["-c", "echo oops >&2; exit 3"])).unwrap();
        assert!(!failed.success && failed.stderr.contains("oops"));
    }
}
