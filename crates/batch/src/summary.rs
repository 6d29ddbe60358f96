//! `SummaryJob`: every shard's lines in an output folder merged into one report: totals, failures
//! with their errors, the slowest inputs (`inbetween batch summary OUT`).

use crate::results::{self, ResultLine};
use crate::BatchError;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;

/// Merge the result files of one output folder.
#[derive(Clone, Debug)]
pub struct SummaryJob {
    pub out_dir: PathBuf,
    /// How many of the slowest inputs to list.
    pub slowest: usize,
}

impl Default for SummaryJob {
    fn default() -> SummaryJob {
        SummaryJob { out_dir: PathBuf::from("out/batch"), slowest: 10 }
    }
}

/// The merged report.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// The result files read, in name order.
    pub files: Vec<PathBuf>,
    /// Lines read (an input run again after a failure or a change has several).
    pub lines: usize,
    /// Distinct inputs.
    pub inputs: usize,
    /// Inputs whose latest line is ok.
    pub ok: usize,
    /// Inputs whose latest line failed, with the error, by input.
    pub failures: Vec<(String, String)>,
    /// Seconds of work summed over every input's latest line.
    pub seconds: f64,
    /// The slowest inputs (latest lines), slowest first: (input, seconds).
    pub slowest: Vec<(String, f64)>,
}

impl SummaryJob {
    pub fn validate(&self) -> Result<(), BatchError> {
        if !self.out_dir.is_dir() {
            return Err(BatchError::Invalid(format!("{}: expected a batch's output folder", self.out_dir.display())));
        }
        Ok(())
    }

    pub fn run(&self) -> Result<Summary, BatchError> {
        self.validate()?;
        let files = results::files_in(&self.out_dir)?;
        if files.is_empty() {
            return Err(BatchError::Invalid(format!(
                "{}: no results-*.jsonl; run a batch into this folder first",
                self.out_dir.display()
            )));
        }
        // The latest line of each input: within a file the later one; an ok line over a failed one
        // from another shard count (a rerun that fixed it).
        let mut latest: BTreeMap<String, ResultLine> = BTreeMap::new();
        let mut lines = 0;
        for file in &files {
            for line in results::read(file)? {
                lines += 1;
                let keep = match latest.get(&line.input) {
                    None => true,
                    Some(old) => line.ok || !old.ok,
                };
                if keep {
                    latest.insert(line.input.clone(), line);
                }
            }
        }
        let ok = latest.values().filter(|l| l.ok).count();
        let failures =
            latest.values().filter(|l| !l.ok).map(|l| (l.input.clone(), l.error.clone().unwrap_or_default())).collect();
        let mut by_time: Vec<(String, f64)> = latest.values().map(|l| (l.input.clone(), l.seconds)).collect();
        by_time.sort_by(|a, b| b.1.total_cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
        by_time.truncate(self.slowest);
        Ok(Summary {
            files,
            lines,
            inputs: latest.len(),
            ok,
            failures,
            seconds: latest.values().map(|l| l.seconds).sum(),
            slowest: by_time,
        })
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} inputs from {} lines in {} result files: {} ok, {} failed; {:.1} s of work",
            self.inputs,
            self.lines,
            self.files.len(),
            self.ok,
            self.failures.len(),
            self.seconds
        )?;
        if !self.failures.is_empty() {
            writeln!(f, "failures:")?;
            for (input, error) in &self.failures {
                writeln!(f, "  {input}: {error}")?;
            }
        }
        write!(f, "slowest:")?;
        for (input, s) in &self.slowest {
            write!(f, "\n  {s:8.2} s  {input}")?;
        }
        Ok(())
    }
}
