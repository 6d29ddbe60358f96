//! Result lines: one JSON object per input, appended to `OUT/results-<shard>.jsonl` once the input's
//! outputs are in place (so a line never names an output that is not there).
//!
//! A process killed while appending leaves at most one partial last line; [`ResultsFile::open`]
//! cuts it off before appending, so a rerun never duplicates nor corrupts a line.

use crate::BatchError;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// What happened to one input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResultLine {
    /// The input's path relative to the batch's folder (`/` separators).
    pub input: String,
    /// SHA-256 of the job's name, its options and the input's bytes (hex): an input whose line has
    /// the same hash and whose outputs exist is not run again.
    pub hash: String,
    pub ok: bool,
    /// The error with its causes (file, line or frame, what was expected), when not ok.
    pub error: Option<String>,
    /// The outputs written, relative to the output folder.
    pub outputs: Vec<String>,
    /// The job's report (fields of its own; `null` on failure).
    pub report: serde_json::Value,
    /// Wall-clock seconds the input took.
    pub seconds: f64,
}

/// The file name of shard `index`'s lines.
pub fn file_name(index: usize) -> String {
    format!("results-{index}.jsonl")
}

/// Every result file in `out` (`results-*.jsonl`), sorted by name.
pub fn files_in(out: &Path) -> Result<Vec<PathBuf>, BatchError> {
    let mut files = Vec::new();
    let entries = match std::fs::read_dir(out) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(files),
        Err(source) => return Err(BatchError::Io { path: out.to_path_buf(), source }),
    };
    for entry in entries {
        let entry = entry.map_err(|source| BatchError::Io { path: out.to_path_buf(), source })?;
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with("results-") && name.ends_with(".jsonl") {
            files.push(entry.path());
        }
    }
    files.sort();
    Ok(files)
}

/// The complete lines of one result file, in order. A last line without its newline (a process
/// killed while writing it) is not counted; any other line that is not a result is an error naming
/// the file and line.
pub fn read(path: &Path) -> Result<Vec<ResultLine>, BatchError> {
    let text = std::fs::read_to_string(path).map_err(|source| BatchError::Io { path: path.to_path_buf(), source })?;
    let complete = text.rfind('\n').map_or("", |end| &text[..end]);
    let mut lines = Vec::new();
    for (i, line) in complete.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let parsed = serde_json::from_str(line).map_err(|e| BatchError::Results {
            file: path.to_path_buf(),
            line: i + 1,
            message: format!(
                "expected a result line (JSON with input, hash, ok, error, outputs, report, seconds): {e}"
            ),
        })?;
        lines.push(parsed);
    }
    Ok(lines)
}

/// The lines of every result file in `out`, by input: the inputs done before, for skipping.
pub fn done_in(out: &Path) -> Result<HashMap<String, Vec<ResultLine>>, BatchError> {
    let mut done: HashMap<String, Vec<ResultLine>> = HashMap::new();
    for file in files_in(out)? {
        for line in read(&file)? {
            done.entry(line.input.clone()).or_default().push(line);
        }
    }
    Ok(done)
}

/// One shard's result file, open for appending.
pub struct ResultsFile {
    file: File,
    path: PathBuf,
}

impl ResultsFile {
    /// Opens (or creates) shard `index`'s file in `out`, cutting off a partial last line.
    pub fn open(out: &Path, index: usize) -> Result<ResultsFile, BatchError> {
        let path = out.join(file_name(index));
        let io = |source| BatchError::Io { path: path.clone(), source };
        let mut file =
            OpenOptions::new().create(true).read(true).write(true).truncate(false).open(&path).map_err(io)?;
        let bytes = std::fs::read(&path).map_err(io)?;
        let keep = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        if keep < bytes.len() {
            file.set_len(keep as u64).map_err(io)?;
        }
        file.seek(SeekFrom::End(0)).map_err(io)?;
        Ok(ResultsFile { file, path })
    }

    /// Appends one line and syncs it to disk.
    pub fn append(&mut self, line: &ResultLine) -> Result<(), BatchError> {
        let mut text = serde_json::to_string(line).map_err(|e| BatchError::Invalid(e.to_string()))?;
        text.push('\n');
        let io = |source| BatchError::Io { path: self.path.clone(), source };
        self.file.write_all(text.as_bytes()).map_err(io)?;
        self.file.sync_data().map_err(io)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(input: &str) -> ResultLine {
        ResultLine {
            input: input.into(),
            hash: "ab".into(),
            ok: true,
            error: None,
            outputs: vec![format!("{input}.out")],
            report: serde_json::json!({"frames": 3}),
            seconds: 0.5,
        }
    }

    #[test]
    fn a_partial_last_line_is_cut_before_appending() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = ResultsFile::open(dir.path(), 0).unwrap();
        f.append(&line("a")).unwrap();
        drop(f);
        // A kill in the middle of the second line.
        let path = dir.path().join(file_name(0));
        let mut text = std::fs::read_to_string(&path).unwrap();
        text.push_str("{\"input\":\"b\",\"ha");
        std::fs::write(&path, text).unwrap();
        assert_eq!(read(&path).unwrap(), vec![line("a")]);
        let mut f = ResultsFile::open(dir.path(), 0).unwrap();
        f.append(&line("b")).unwrap();
        assert_eq!(read(&path).unwrap(), vec![line("a"), line("b")]);
        let done = done_in(dir.path()).unwrap();
        assert_eq!(done.len(), 2);
    }

    #[test]
    fn a_corrupt_line_names_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(file_name(2));
        std::fs::write(&path, format!("{}\nnot json\n", serde_json::to_string(&line("a")).unwrap())).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("results-2.jsonl:2"), "{e}");
    }
}
