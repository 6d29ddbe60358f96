//! The `scale` subcommands' shared frame: measured runs of this binary at multiples of an engine's
//! example (inputs in a scratch folder removed afterwards), printed and written as one table.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use inbetween_io::scale::{scale_table, ScaleRow};

/// The arguments every engine's `scale` subcommand takes.
#[derive(Args)]
pub struct ScaleArgs {
    /// Folder for the table (CSV, Markdown, text) [default: out/<engine>-scale].
    #[arg(short, long)]
    pub out: Option<PathBuf>,
    /// Multiples of the example to run.
    #[arg(long, value_delimiter = ',', default_value = "1,10,100")]
    pub scales: Vec<usize>,
}

impl ScaleArgs {
    /// `--out`, else `out/<engine>-scale`.
    pub fn out_or(&self, engine: &str) -> PathBuf {
        self.out.clone().unwrap_or_else(|| PathBuf::from(format!("out/{engine}-scale")))
    }
}

/// Runs `rows(exe, scratch)` (one measured run per scale), then prints the table `name` with
/// `title` and writes it into `out` as the report `report_title`.
pub fn run(
    out: &Path,
    name: &str,
    title: &str,
    report_title: &str,
    rows: impl FnOnce(&Path, &Path) -> anyhow::Result<Vec<ScaleRow>>,
) -> anyhow::Result<()> {
    let exe: PathBuf = std::env::current_exe().context("locating the inbetween binary")?;
    let scratch = std::env::temp_dir().join(format!("inbetween-scale-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).with_context(|| format!("creating {}", scratch.display()))?;
    let result = rows(&exe, &scratch);
    let _ = std::fs::remove_dir_all(&scratch);
    let table = scale_table(name, title, &result?);
    let mut report = inbetween_io::report::Report::new("report", report_title);
    print!("{}", table.to_text());
    report.table(table);
    let files = report.write(out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {} files to {}", files.len(), out.display());
    Ok(())
}
