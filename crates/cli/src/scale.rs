//! The `scale` subcommands' shared arguments and lines: the bench itself (measured runs of this binary
//! at multiples of an engine's example, one table) is [`inbetween_io::scale::run_scales`].

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
pub use inbetween_io::scale::Measured;

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

/// Runs `engine`'s scaling bench, `prepare(k, exe, scratch)` writing the input at `k`× and giving
/// the command; prints a line per run and the table, and writes the report into `--out`.
pub fn run(
    a: &ScaleArgs,
    engine: &str,
    title: &str,
    mut prepare: impl FnMut(usize, &Path, &Path) -> anyhow::Result<Measured>,
) -> anyhow::Result<()> {
    let exe: PathBuf = std::env::current_exe().context("locating the inbetween binary")?;
    let each = |r: &inbetween_io::scale::ScaleRow| println!("{r}");
    let report = inbetween_io::scale::run_scales(engine, title, &a.scales, |k, work| prepare(k, &exe, work), each)?;
    report.tables().for_each(|t| print!("{}", t.to_text()));
    let out = a.out.clone().unwrap_or_else(|| PathBuf::from(format!("out/{engine}-scale")));
    let files = report.write(&out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {} files to {}", files.len(), out.display());
    Ok(())
}
