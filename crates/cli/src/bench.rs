//! The `bench` subcommands' shared frame: every engine's bench is `run(&BenchOptions<E>) ->
//! Result<Report, _>` ([`inbetween_io::report::BenchOptions`]); here it runs under a progress bar,
//! its report is written into `out` and printed.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use inbetween_io::report::{BenchOptions, Report};
use inbetween_io::Progress;

use crate::errors::with_flags;

/// A finished bench: its report and the files written.
pub struct Done {
    pub report: Report,
    pub files: Vec<PathBuf>,
    out: Option<PathBuf>,
    seconds: f64,
}

/// Runs `bench` under a bar labelled `label`, then writes its report into `opts.out`.
pub fn run<E, X: Into<anyhow::Error>>(
    label: &str,
    mut opts: BenchOptions<E>,
    bench: impl FnOnce(&BenchOptions<E>) -> Result<Report, X>,
) -> anyhow::Result<Done> {
    let t = Instant::now();
    opts.progress = Progress::new(0, label);
    let report = bench(&opts).map_err(Into::into);
    opts.progress.finish();
    let report = report?;
    let out = opts.out.clone();
    let shown = out.as_deref().unwrap_or(std::path::Path::new("")).display().to_string();
    let files = opts.write(&report).with_context(|| format!("writing the {label} to {shown}"))?;
    Ok(Done { report, files, out, seconds: t.elapsed().as_secs_f64() })
}

impl Done {
    /// The report (options it names written as flags), then a line per file written.
    pub fn print_files(&self) {
        print!("{}", with_flags(&self.report.to_text()));
        for f in &self.files {
            println!("wrote {}", f.display());
        }
    }

    /// The report, then one line: how many files went where, in how long.
    pub fn print_summary(&self) {
        print!("{}", with_flags(&self.report.to_text()));
        let out = self.out.as_deref().map(|o| o.display().to_string()).unwrap_or_default();
        println!("wrote {} files to {out} ({:.1} s)", self.files.len(), self.seconds);
    }
}
