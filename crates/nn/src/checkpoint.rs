//! Checkpoints: a module's parameters (burnpack record), the optimizer state (burnpack record)
//! and a small JSON sidecar (epoch, optimizer steps, loss history, config), so a training run
//! can stop and resume.
//!
//! Every file is written atomically (temporary file in the same folder, then rename), and the
//! sidecar is written last: a checkpoint whose sidecar exists is complete, so a crash mid-save
//! never leaves a "latest" checkpoint that cannot be loaded.
//!
//! Layout in a checkpoint folder, for epoch `N` (number of completed epochs):
//! `epoch-0000N.model.bpk`, `epoch-0000N.optim.bpk`, `epoch-0000N.state.bin` (the training
//! objective's own state, e.g. a replay buffer; only when it has any) and `epoch-0000N.json`.

use std::path::{Path, PathBuf};

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use burn::store::ModuleRecord;
use burn::tensor::Bytes;
use serde::{Deserialize, Serialize};

use crate::NnError;

/// [`inbetween_io::write_atomic`] with the error as an [`NnError`] naming the file.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), NnError> {
    inbetween_io::write_atomic(path, bytes).map_err(|source| NnError::Io { path: path.to_path_buf(), source })
}

pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, NnError> {
    std::fs::read(path).map_err(|source| NnError::Io { path: path.to_path_buf(), source })
}

fn record_err(path: &Path, err: impl std::fmt::Display) -> NnError {
    NnError::Record { path: path.to_path_buf(), message: err.to_string() }
}

/// A module's parameters as burnpack bytes (`origin` names them in errors), e.g. to keep a copy
/// of a network inside an objective's checkpointed state.
pub fn module_bytes<M: Module>(module: &M, origin: &Path) -> Result<Vec<u8>, NnError> {
    let bytes = module.clone().into_record().into_bytes().map_err(|e| record_err(origin, e))?;
    Ok(bytes.to_vec())
}

/// Save a module's parameters to `path` (burnpack format), atomically.
pub fn save_module<M: Module>(module: &M, path: &Path) -> Result<(), NnError> {
    write_atomic(path, &module_bytes(module, path)?)
}

/// Load parameters saved by [`save_module`] into `module` (which fixes the architecture and the
/// device). Shape mismatches and missing parameters are errors naming the file and parameter.
pub fn load_module<M: Module>(module: M, path: &Path) -> Result<M, NnError> {
    load_module_bytes(module, read_file(path)?, path)
}

/// Like [`load_module`], from bytes already in memory (weights compiled into a binary); `origin`
/// names them in errors.
pub fn load_module_bytes<M: Module>(module: M, bytes: Vec<u8>, origin: &Path) -> Result<M, NnError> {
    let record = ModuleRecord::from_bytes(Bytes::from_bytes_vec(bytes)).map_err(|e| record_err(origin, e))?;
    module.try_load_record(record).map_err(|e| record_err(origin, e))
}

/// Save an optimizer's state (Adam moments and step counts, keyed by parameter id).
pub fn save_optimizer(optim: &ModuleOptimizer, path: &Path) -> Result<(), NnError> {
    let bytes = optim.into_bytes().map_err(|e| record_err(path, e))?;
    write_atomic(path, &bytes)
}

/// Load optimizer state saved by [`save_optimizer`] into a freshly configured optimizer.
///
/// The state is keyed by parameter id; [`load_module`] restores the ids saved with the model,
/// so load the model from the same checkpoint.
pub fn load_optimizer(optim: ModuleOptimizer, path: &Path) -> Result<ModuleOptimizer, NnError> {
    let bytes = read_file(path)?;
    optim.from_bytes(Bytes::from_bytes_vec(bytes)).map_err(|e| record_err(path, e))
}

/// The JSON sidecar of a checkpoint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckpointMeta {
    /// Completed epochs; training resumes at this epoch index.
    pub epoch: usize,
    /// Optimizer steps taken so far.
    pub optimizer_steps: u64,
    /// Mean loss of every completed epoch, in order (NaN, written as null, for an epoch without a
    /// loss).
    #[serde(deserialize_with = "nan_as_null")]
    pub loss_history: Vec<f64>,
    /// Bit patterns (`f64::to_bits`) of `loss_history`, filled by [`save`](Self::save).
    /// serde_json (without its `float_roundtrip` feature) can parse a float back one ulp off,
    /// which would make a resumed run's history differ from an uninterrupted one; integers
    /// round-trip exactly, so [`load`](Self::load) restores the history from these.
    #[serde(default)]
    pub loss_history_bits: Vec<u64>,
    /// Learning rate used in the last completed epoch.
    pub lr: f64,
    /// Seconds of training so far, over every invocation of the run.
    #[serde(default)]
    pub seconds: f64,
    /// The run's configuration (free-form, e.g. a serialised `TrainConfig` and model config).
    pub config: serde_json::Value,
}

/// JSON has no NaN: serde_json writes it as `null`; read `null` back as NaN.
fn nan_as_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    let values: Vec<Option<f64>> = Deserialize::deserialize(d)?;
    Ok(values.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect())
}

impl CheckpointMeta {
    /// Write the sidecar as pretty JSON, atomically.
    pub fn save(&self, path: &Path) -> Result<(), NnError> {
        let exact = Self { loss_history_bits: self.loss_history.iter().map(|l| l.to_bits()).collect(), ..self.clone() };
        let json = serde_json::to_vec_pretty(&exact).map_err(|e| NnError::Metadata {
            path: path.to_path_buf(),
            line: 0,
            column: 0,
            message: e.to_string(),
        })?;
        write_atomic(path, &json)
    }

    /// Read a sidecar; malformed JSON is an error naming the file, line and column.
    pub fn load(path: &Path) -> Result<Self, NnError> {
        let bytes = read_file(path)?;
        let mut meta: Self = serde_json::from_slice(&bytes).map_err(|e| NnError::Metadata {
            path: path.to_path_buf(),
            line: e.line(),
            column: e.column(),
            message: format!("invalid checkpoint metadata: {e}"),
        })?;
        if meta.loss_history_bits.len() == meta.loss_history.len() {
            meta.loss_history = meta.loss_history_bits.iter().map(|&b| f64::from_bits(b)).collect();
        }
        Ok(meta)
    }
}

/// The three files of one checkpoint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CheckpointFiles {
    /// Completed epochs at save time.
    pub epoch: usize,
    /// Module parameters (burnpack).
    pub model: PathBuf,
    /// Optimizer state (burnpack).
    pub optimizer: PathBuf,
    /// The training objective's own state (present only when it had any).
    pub state: PathBuf,
    /// JSON sidecar ([`CheckpointMeta`]).
    pub meta: PathBuf,
}

impl CheckpointFiles {
    /// File names for epoch `epoch` inside `dir`.
    pub fn in_dir(dir: &Path, epoch: usize) -> Self {
        let stem = format!("epoch-{epoch:06}");
        Self {
            epoch,
            model: dir.join(format!("{stem}.model.bpk")),
            optimizer: dir.join(format!("{stem}.optim.bpk")),
            state: dir.join(format!("{stem}.state.bin")),
            meta: dir.join(format!("{stem}.json")),
        }
    }
}

/// Save model, optimizer, the objective's `state` (skipped when empty) and sidecar for
/// `meta.epoch` into `dir` (sidecar last).
pub fn save_checkpoint<M: Module>(
    dir: &Path,
    model: &M,
    optim: &ModuleOptimizer,
    state: &[u8],
    meta: &CheckpointMeta,
) -> Result<CheckpointFiles, NnError> {
    let files = CheckpointFiles::in_dir(dir, meta.epoch);
    save_module(model, &files.model)?;
    save_optimizer(optim, &files.optimizer)?;
    if !state.is_empty() {
        write_atomic(&files.state, state)?;
    }
    meta.save(&files.meta)?;
    Ok(files)
}

/// The most recent complete checkpoint in `dir` (highest epoch whose sidecar exists), or
/// `None` if the folder is missing or holds none.
pub fn latest_checkpoint(dir: &Path) -> Result<Option<CheckpointFiles>, NnError> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => return Err(NnError::Io { path: dir.to_path_buf(), source }),
    };
    let mut best: Option<usize> = None;
    for entry in entries {
        let entry = entry.map_err(|source| NnError::Io { path: dir.to_path_buf(), source })?;
        let name = entry.file_name();
        let epoch = name
            .to_str()
            .and_then(|n| n.strip_prefix("epoch-"))
            .and_then(|n| n.strip_suffix(".json"))
            .and_then(|n| n.parse::<usize>().ok());
        if let Some(epoch) = epoch {
            best = Some(best.map_or(epoch, |b| b.max(epoch)));
        }
    }
    Ok(best.map(|epoch| CheckpointFiles::in_dir(dir, epoch)))
}

/// Load a checkpoint into `model` and `optim` (both freshly built with the run's configuration).
pub fn load_checkpoint<M: Module>(
    files: &CheckpointFiles,
    model: M,
    optim: ModuleOptimizer,
) -> Result<(M, ModuleOptimizer, CheckpointMeta), NnError> {
    let meta = CheckpointMeta::load(&files.meta)?;
    let model = load_module(model, &files.model)?;
    let optim = load_optimizer(optim, &files.optimizer)?;
    Ok((model, optim, meta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidecar_round_trips_losses_bit_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("epoch-000002.json");
        // A value serde_json's default float parser reads back one ulp off.
        let tricky = 0.40024039149284363_f64;
        let meta = CheckpointMeta {
            epoch: 2,
            optimizer_steps: 10,
            loss_history: vec![tricky, 0.1, 1.0 / 3.0, f64::NAN],
            loss_history_bits: Vec::new(),
            lr: 0.01,
            seconds: 1.5,
            config: serde_json::json!({"seed": 1}),
        };
        meta.save(&path).unwrap();
        let back = CheckpointMeta::load(&path).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.loss_history), bits(&meta.loss_history));
        assert_eq!(back.epoch, 2);
        assert_eq!(latest_checkpoint(dir.path()).unwrap().unwrap().epoch, 2);
        assert_eq!(latest_checkpoint(&dir.path().join("absent")).unwrap(), None);
    }
}
