//! `BatchJob`: one shard of a batch (ozz's job shape: the inputs as fields, `validate`, then `run`)
//! and `run_input`, the same work for one input that a Dask task calls.

use crate::kind::{self, Kind, Options};
use crate::manifest::{self, Input};
use crate::results::{self, ResultLine, ResultsFile};
use crate::shard::Shard;
use crate::BatchError;
use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;
use serde::Serialize;
use sha2::{Digest, Sha256};
use std::fmt;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Run one job on every input of a folder that falls in one shard.
#[derive(Clone, Debug)]
pub struct BatchJob {
    pub kind: Kind,
    /// The folder of inputs (searched recursively).
    pub input_dir: PathBuf,
    /// Where the outputs go, mirroring the inputs' paths, with `results-<shard>.jsonl`.
    pub out_dir: PathBuf,
    pub shard: Shard,
    pub options: Options,
}

/// What one shard did.
#[derive(Clone, Debug, Serialize)]
pub struct BatchReport {
    pub job: Kind,
    pub shard: Shard,
    /// Inputs in the whole manifest.
    pub manifest: usize,
    /// Inputs of this shard.
    pub inputs: usize,
    /// Run now and succeeded.
    pub ok: usize,
    /// Run now and failed (each has its line with the error).
    pub failed: usize,
    /// Skipped: done before with the same input hash, outputs in place.
    pub skipped: usize,
    pub seconds: f64,
    pub results: PathBuf,
    /// (input, error) of each failure, in manifest order.
    pub failures: Vec<(String, String)>,
}

impl fmt::Display for BatchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} shard {}: {} of {} inputs; {} ok, {} failed, {} skipped (done before) in {:.1} s; lines in {}",
            self.job.name(),
            self.shard,
            self.inputs,
            self.manifest,
            self.ok,
            self.failed,
            self.skipped,
            self.seconds,
            self.results.display()
        )?;
        for (input, error) in &self.failures {
            write!(f, "\n  failed: {input}: {error}")?;
        }
        Ok(())
    }
}

impl BatchJob {
    /// Checks the options and folders before any input is read.
    pub fn validate(&self) -> Result<(), BatchError> {
        self.options.validate(self.kind)?;
        if !self.input_dir.is_dir() {
            return Err(BatchError::Invalid(format!("{}: expected a folder of inputs", self.input_dir.display())));
        }
        // Outputs inside the inputs' folder would be read as inputs by the next run.
        let inputs = canonical(&self.input_dir)?;
        let out = canonical_to_be(&self.out_dir)?;
        if out.starts_with(&inputs) {
            return Err(BatchError::Invalid(format!(
                "{}: the output folder is inside the input folder {}; choose one outside it",
                self.out_dir.display(),
                self.input_dir.display()
            )));
        }
        Ok(())
    }

    /// Every input of the batch in its stable order (all shards).
    pub fn manifest(&self) -> Result<Vec<Input>, BatchError> {
        manifest::scan(&self.input_dir, self.kind.extensions())
    }

    /// Runs this shard's inputs one after the other; an input that fails gets a line with its
    /// error and the shard goes on. `cancel` stops between inputs (and inside the engines' jobs
    /// that check it); what was finished keeps its line.
    pub fn run(&self, cancel: &Cancel, progress: &Progress) -> Result<BatchReport, BatchError> {
        self.validate()?;
        let t = Instant::now();
        let all = self.manifest()?;
        let sizes: Vec<u64> = all.iter().map(|i| std::fs::metadata(&i.path).map_or(0, |m| m.len())).collect();
        let mine: Vec<&Input> = self.shard.positions(&sizes).into_iter().map(|p| &all[p]).collect();
        std::fs::create_dir_all(&self.out_dir)
            .map_err(|source| BatchError::Io { path: self.out_dir.clone(), source })?;
        let done = results::done_in(&self.out_dir)?;
        let mut file = ResultsFile::open(&self.out_dir, self.shard.index)?;
        let mut report = BatchReport {
            job: self.kind,
            shard: self.shard,
            manifest: all.len(),
            inputs: mine.len(),
            ok: 0,
            failed: 0,
            skipped: 0,
            seconds: 0.0,
            results: file.path().to_path_buf(),
            failures: Vec::new(),
        };
        progress.phase(mine.len() as u64, &format!("{} {}", self.kind.name(), self.shard));
        for input in mine {
            cancel.check()?;
            let hash = input_hash(self.kind, &self.options, &input.path)?;
            let finished = done.get(&input.rel).is_some_and(|lines| {
                lines.iter().any(|l| l.ok && l.hash == hash && l.outputs.iter().all(|o| self.out_dir.join(o).exists()))
            });
            if finished {
                report.skipped += 1;
                progress.inc(1);
                continue;
            }
            let line = run_hashed(self.kind, input, hash, &self.out_dir, &self.options, cancel);
            if cancel.is_cancelled() && !line.ok {
                // Stopped inside the engine: no line, the input runs again next time.
                cancel.check()?;
            }
            file.append(&line)?;
            if line.ok {
                report.ok += 1;
            } else {
                report.failed += 1;
                report.failures.push((line.input.clone(), line.error.clone().unwrap_or_default()));
            }
            progress.inc(1);
        }
        report.seconds = t.elapsed().as_secs_f64();
        Ok(report)
    }
}

/// Runs `kind` on one input and returns its result line (never an error: a failure, a bad file or
/// a panic in an engine is a line with `ok: false`). Dask tasks call this for each path.
pub fn run_input(kind: Kind, input: &Input, out: &Path, options: &Options, cancel: &Cancel) -> ResultLine {
    match input_hash(kind, options, &input.path) {
        Ok(hash) => run_hashed(kind, input, hash, out, options, cancel),
        Err(e) => ResultLine {
            input: input.rel.clone(),
            hash: String::new(),
            ok: false,
            error: Some(e.to_string()),
            outputs: Vec::new(),
            report: serde_json::Value::Null,
            seconds: 0.0,
        },
    }
}

fn run_hashed(kind: Kind, input: &Input, hash: String, out: &Path, options: &Options, cancel: &Cancel) -> ResultLine {
    let t = Instant::now();
    let outcome =
        catch_unwind(AssertUnwindSafe(|| kind::run(kind, input, out, options, cancel))).unwrap_or_else(|panic| {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            Err(format!("{}: internal error (a bug; please report it): {what}", input.path.display()))
        });
    let seconds = t.elapsed().as_secs_f64();
    match outcome {
        Ok(p) => ResultLine {
            input: input.rel.clone(),
            hash,
            ok: true,
            error: None,
            outputs: p.outputs,
            report: p.report,
            seconds,
        },
        Err(error) => ResultLine {
            input: input.rel.clone(),
            hash,
            ok: false,
            error: Some(error),
            outputs: Vec::new(),
            report: serde_json::Value::Null,
            seconds,
        },
    }
}

/// SHA-256 (hex) of the job's name, its options and the input's bytes, with the `.asf` an `.amc`
/// reads: the same input under the same options hashes the same on every machine.
pub fn input_hash(kind: Kind, options: &Options, path: &Path) -> Result<String, BatchError> {
    let mut h = Sha256::new();
    h.update(b"inbetween batch 1\0");
    h.update(kind.name().as_bytes());
    h.update(b"\0");
    h.update(serde_json::to_string(options).expect("options serialise").as_bytes());
    h.update(b"\0");
    let read = |p: &Path| std::fs::read(p).map_err(|source| BatchError::Io { path: p.to_path_buf(), source });
    h.update(read(path)?);
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("amc")) {
        if let Ok(asf) = inbetween_io::asf::find_asf_for(path) {
            h.update(b"\0");
            h.update(read(&asf)?);
        }
    }
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

fn canonical(p: &Path) -> Result<PathBuf, BatchError> {
    p.canonicalize().map_err(|source| BatchError::Io { path: p.to_path_buf(), source })
}

/// The canonical form of a folder that may not exist yet: its nearest existing ancestor's, with
/// the rest appended.
fn canonical_to_be(p: &Path) -> Result<PathBuf, BatchError> {
    let abs = if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir().map_err(|source| BatchError::Io { path: p.to_path_buf(), source })?.join(p)
    };
    let mut rest = Vec::new();
    let mut cur = abs.as_path();
    loop {
        if let Ok(c) = cur.canonicalize() {
            return Ok(rest.iter().rev().fold(c, |acc, part| acc.join(part)));
        }
        match (cur.parent(), cur.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_os_string());
                cur = parent;
            }
            _ => return Ok(abs),
        }
    }
}
