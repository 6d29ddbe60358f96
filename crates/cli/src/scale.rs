//! The `scale` subcommands' shared frame: measured runs of this binary at multiples of an engine's
//! example (inputs in a scratch folder removed afterwards), printed and written as one table.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use inbetween_io::scale::{run_measured, scale_table, ScaleRow};
use std::process::Command;

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

/// One scale's run, as an engine prepares it: the input in words with units, and the command
/// (this binary) to measure.
pub struct Measured {
    pub input: String,
    pub command: Command,
}

/// Runs `engine`'s scaling bench: for each of `a.scales`, `prepare(k, exe, scratch)` writes the
/// input at `k`× into the scratch folder (removed afterwards) and gives the command, which is run
/// and measured as its own process ([`run_measured`]); then the table `<engine>_scale` titled
/// `title` is printed and written into `--out` as the report "<engine> scaling". A run that fails
/// (a limit refusing the input, say) is a row whose result is its first error line.
pub fn run(
    a: &ScaleArgs,
    engine: &str,
    title: &str,
    mut prepare: impl FnMut(usize, &Path, &Path) -> anyhow::Result<Measured>,
) -> anyhow::Result<()> {
    let exe: PathBuf = std::env::current_exe().context("locating the inbetween binary")?;
    let scratch = std::env::temp_dir().join(format!("inbetween-scale-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).with_context(|| format!("creating {}", scratch.display()))?;
    let mut rows = Vec::new();
    let result = a.scales.iter().try_for_each(|&k| -> anyhow::Result<()> {
        let mut m = prepare(k, &exe, &scratch)?;
        let run = run_measured(&mut m.command).with_context(|| format!("running {engine} at {k}×"))?;
        println!("{k}×: {:.3} s, peak {:.1} MiB", run.seconds, run.peak_mib.unwrap_or(f64::NAN));
        rows.push(ScaleRow { scale: k, input: m.input, run });
        Ok(())
    });
    let _ = std::fs::remove_dir_all(&scratch);
    result?;
    let table = scale_table(&format!("{engine}_scale"), title, &rows);
    let mut report = inbetween_io::report::Report::new("report", &format!("{engine} scaling"));
    print!("{}", table.to_text());
    report.table(table);
    let out = a.out_or(engine);
    let files = report.write(&out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {} files to {}", files.len(), out.display());
    Ok(())
}
