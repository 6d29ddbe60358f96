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
use std::path::Path;
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

impl std::fmt::Display for ScaleRow {
    /// The run's line as a scaling bench prints it while it goes: `10×: 1.234 s, peak 56.7 MiB`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let peak = self.run.peak_mib.unwrap_or(f64::NAN);
        write!(f, "{}×: {:.3} s, peak {peak:.1} MiB", self.scale, self.run.seconds)
    }
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

/// One scale's run as a front end prepares it: the input in words with units, and the command to
/// measure.
pub struct Measured {
    pub input: String,
    pub command: Command,
}

/// A scaling bench: for each of `scales`, `prepare(k, scratch)` writes the input at `k`× into a
/// scratch folder (removed afterwards) and gives the command, which is run and measured as its own
/// process ([`run_measured`]) and told to `each` as its row. Returns the report "`engine` scaling"
/// (file stem `report`) holding the table `<engine>_scale` titled `title`. A run that fails (a limit
/// refusing the input, say) is a row whose result is its first error line; a failure to prepare or
/// start one stops the bench.
pub fn run_scales<E: From<crate::IoError>>(
    engine: &str,
    title: &str,
    scales: &[usize],
    mut prepare: impl FnMut(usize, &Path) -> Result<Measured, E>,
    mut each: impl FnMut(&ScaleRow),
) -> Result<crate::report::Report, E> {
    let io = |path: &Path, source| crate::IoError::Io { path: path.to_path_buf(), source };
    let scratch = std::env::temp_dir().join(format!("inbetween-scale-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).map_err(|e| io(&scratch, e))?;
    let mut rows = Vec::new();
    let result = scales.iter().try_for_each(|&k| -> Result<(), E> {
        let mut m = prepare(k, &scratch)?;
        let program = Path::new(m.command.get_program()).to_path_buf();
        let run = run_measured(&mut m.command).map_err(|e| io(&program, e))?;
        rows.push(ScaleRow { scale: k, input: m.input, run });
        each(rows.last().expect("just pushed"));
        Ok(())
    });
    let _ = std::fs::remove_dir_all(&scratch);
    result?;
    let mut report = crate::report::Report::new("report", &format!("{engine} scaling"));
    report.table(scale_table(&format!("{engine}_scale"), title, &rows));
    Ok(report)
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

    #[cfg(target_os = "linux")]
    #[test]
    fn a_scaling_bench_has_one_row_per_scale_and_a_failed_run_says_why() {
        let mut seen = Vec::new();
        let report = run_scales::<crate::IoError>(
            "sh",
            "sh at multiples",
            &[1, 3],
            |k, scratch| {
                assert!(scratch.is_dir());
                let mut command = Command::new("sh");
                command.args(["-c", if k == 1 { "true" } else { "echo refused >&2; exit 2" }]);
                Ok(Measured { input: format!("{k} lines"), command })
            },
            |row| seen.push(row.scale),
        )
        .unwrap();
        assert_eq!(seen, [1, 3]);
        assert_eq!(report.title, "sh scaling");
        let table = report.find_table("sh_scale").unwrap();
        assert_eq!(table.rows.len(), 2);
        assert_eq!((table.rows[0][5].as_str(), table.rows[1][5].as_str()), ("ok", "refused"));
        assert_eq!(table.rows[1][1], "3 lines");
        let run = ChildRun { seconds: 1.23456, peak_mib: Some(56.72), success: true, stderr: String::new() };
        assert_eq!(ScaleRow { scale: 10, input: "10 lines".into(), run }.to_string(), "10×: 1.235 s, peak 56.7 MiB");
    }
}
