//! Batch runs: one engine job over every input of a folder, split into shards that separate
//! processes (a Slurm job array, a Kubernetes Indexed Job, Dask tasks, or a shell loop) run on their
//! own, with nothing shared but the output folder.
//!
//! - [`manifest`]: the inputs in one stable order;
//! - [`shard`]: which of them one process takes (`--shard i/n`, or the scheduler's variables),
//!   balanced by size;
//! - [`kind`]: the jobs (`mocap-compress`, `mocap-keys`, `video-analyse`, `script-run`,
//!   `face-edit`), each a thin call of an engine's public job;
//! - [`results`]: one JSON line per input in `OUT/results-<i>.jsonl`;
//! - [`BatchJob`]: a shard's run: idempotent (an input whose line has the same input hash and whose
//!   outputs exist is skipped), resumable after a kill (outputs are written atomically, then the
//!   line; a partial last line is cut off), and a bad input fails its line, never the shard;
//! - [`SummaryJob`]: the shards' lines merged into one report.

pub mod bench;
pub mod job;
pub mod kind;
pub mod manifest;
pub mod results;
pub mod shard;
pub mod summary;

pub use job::{input_hash, run_input, BatchJob, BatchReport};
pub use kind::{Kind, Options};
pub use manifest::Input;
pub use results::ResultLine;
pub use shard::Shard;
pub use summary::{Summary, SummaryJob};

use std::path::PathBuf;

/// What can stop a batch as a whole (an input's own failure is a result line, not an error).
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{0}")]
    Invalid(String),
    #[error("{}:{line}: {message}", file.display())]
    Results { file: PathBuf, line: usize, message: String },
    #[error(transparent)]
    Cancelled(#[from] inbetween_core::cancel::Cancelled),
}
