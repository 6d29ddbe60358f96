//! One way to save, load and commit trained weights: a burnpack record (`x.bpk`) plus a JSON card
//! (`x.json`) that says what the weights are: which model and architecture version, the model
//! configuration needed to build it, where the training data came from, the training settings,
//! figures measured at save time, and anything else inference needs ([`WeightsCard::extra`]).
//!
//! Committed weights are compiled into the binary with `include_bytes!`/`include_str!` and read
//! through [`Weights::embedded`]; user files through [`Weights::from_path`]. Either way a file
//! for another model, another architecture version or another shape is refused with an error
//! naming the file and what was expected.
//!
//! ```no_run
//! use inbetween_nn::weights::{self, Weights, WeightsCard};
//! # use inbetween_nn::{backend, lstm::FusedLstmConfig};
//! # let device = backend::cpu();
//! # let model = FusedLstmConfig::new(2, 4).init(&device);
//! let card = WeightsCard::new("demo-lstm", 1, serde_json::json!({"input": 2, "hidden": 4}), "sine waves, seed 3");
//! weights::save(&model, &card, std::path::Path::new("out/demo.bpk")).unwrap();
//! // Later, or in another program:
//! let w = Weights::from_path(std::path::Path::new("out/demo.bpk")).unwrap();
//! w.expect_kind("demo-lstm", 1).unwrap();
//! let model = w.load_into(FusedLstmConfig::new(2, 4).init(&device)).unwrap();
//! // Committed weights: Weights::embedded("crates/x/weights/x", include_bytes!("../weights/x.bpk"),
//! //                                      include_str!("../weights/x.json"))
//! # let _ = model;
//! ```

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use burn::module::Module;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::checkpoint::{load_module_bytes, save_module, write_atomic};
use crate::NnError;

/// What a weights file is. Saved as `x.json` beside `x.bpk`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WeightsCard {
    /// The model the weights belong to, e.g. "camera" or "mocap-sidql"; checked on load.
    pub kind: String,
    /// Architecture version of that model; bump it when the parameter layout changes.
    pub format: u32,
    /// The model configuration (what builds the architecture the record fits).
    pub config: serde_json::Value,
    /// Where the training data came from, in words (e.g. "procedural gaits, seed 7").
    pub data: String,
    /// Training settings (e.g. a serialised `TrainConfig`).
    #[serde(default)]
    pub training: serde_json::Value,
    /// Figures measured when the weights were saved (final loss, epochs, seconds, …).
    #[serde(default)]
    pub metrics: BTreeMap<String, f64>,
    /// Whatever else inference needs that training computed (e.g. reference style codes).
    #[serde(default)]
    pub extra: serde_json::Value,
}

impl WeightsCard {
    pub fn new(kind: &str, format: u32, config: serde_json::Value, data: &str) -> WeightsCard {
        WeightsCard {
            kind: kind.into(),
            format,
            config,
            data: data.into(),
            training: serde_json::Value::Null,
            metrics: BTreeMap::new(),
            extra: serde_json::Value::Null,
        }
    }

    /// Parses a card; malformed JSON names `origin`, line and column.
    pub fn parse(text: &str, origin: &Path) -> Result<WeightsCard, NnError> {
        serde_json::from_str(text).map_err(|e| NnError::Metadata {
            path: origin.to_path_buf(),
            line: e.line(),
            column: e.column(),
            message: format!("invalid weights card: {e}"),
        })
    }
}

/// The card's path for a weights file: `x.bpk` → `x.json`.
pub fn card_path(weights: &Path) -> PathBuf {
    weights.with_extension("json")
}

/// Saves `model` to `path` (burnpack) and `card` beside it, each atomically, the card last (a
/// weights file whose card exists is complete).
pub fn save<M: Module>(model: &M, card: &WeightsCard, path: &Path) -> Result<(), NnError> {
    save_module(model, path)?;
    let json = serde_json::to_string_pretty(card)
        .map_err(|e| NnError::Record { path: card_path(path), message: e.to_string() })?;
    write_atomic(&card_path(path), (json + "\n").as_bytes())
}

/// Weights in memory with their card, ready to load into a model.
#[derive(Debug, Clone)]
pub struct Weights {
    origin: PathBuf,
    bytes: Cow<'static, [u8]>,
    card: WeightsCard,
}

impl Weights {
    /// Reads `path` (`x.bpk`) and its card `x.json`.
    pub fn from_path(path: &Path) -> Result<Weights, NnError> {
        let bytes = std::fs::read(path).map_err(|source| NnError::Io { path: path.to_path_buf(), source })?;
        let card_file = card_path(path);
        let text =
            std::fs::read_to_string(&card_file).map_err(|source| NnError::Io { path: card_file.clone(), source })?;
        let card = WeightsCard::parse(&text, &card_file)?;
        Ok(Weights { origin: path.to_path_buf(), bytes: Cow::Owned(bytes), card })
    }

    /// Weights compiled into the binary; `origin` names them in errors (e.g. the repository path).
    pub fn embedded(origin: &str, bpk: &'static [u8], card_json: &str) -> Result<Weights, NnError> {
        let origin = PathBuf::from(origin);
        let card = WeightsCard::parse(card_json, &card_path(&origin))?;
        Ok(Weights { origin, bytes: Cow::Borrowed(bpk), card })
    }

    pub fn card(&self) -> &WeightsCard {
        &self.card
    }

    /// Where the weights came from (file path, or the name given to [`Weights::embedded`]).
    pub fn origin(&self) -> &Path {
        &self.origin
    }

    /// Refuses weights of another model or architecture version.
    pub fn expect_kind(&self, kind: &str, format: u32) -> Result<&Weights, NnError> {
        if self.card.kind != kind || self.card.format != format {
            return Err(NnError::Mismatch {
                path: self.origin.clone(),
                message: format!(
                    "holds {} weights (format {}), expected {kind} weights (format {format})",
                    self.card.kind, self.card.format
                ),
            });
        }
        Ok(self)
    }

    /// The card's model configuration as `T`.
    pub fn config<T: DeserializeOwned>(&self) -> Result<T, NnError> {
        self.card_field("config", &self.card.config)
    }

    /// The card's `extra` field as `T`.
    pub fn extra<T: DeserializeOwned>(&self) -> Result<T, NnError> {
        self.card_field("extra", &self.card.extra)
    }

    fn card_field<T: DeserializeOwned>(&self, name: &str, value: &serde_json::Value) -> Result<T, NnError> {
        serde_json::from_value(value.clone()).map_err(|e| NnError::Mismatch {
            path: card_path(&self.origin),
            message: format!("field \"{name}\" does not fit this model: {e}"),
        })
    }

    /// Loads the parameters into `module` (built with the card's configuration). A record that
    /// does not fit (missing parameter, other shape) is an error naming the file and parameter.
    pub fn load_into<M: Module>(&self, module: M) -> Result<M, NnError> {
        load_module_bytes(module, self.bytes.to_vec(), &self.origin)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend;
    use crate::lstm::FusedLstmConfig;
    use burn::tensor::Tensor;

    fn card() -> WeightsCard {
        let mut c = WeightsCard::new("test-lstm", 2, serde_json::json!({"input": 2, "hidden": 4}), "nothing, seed 1");
        c.metrics.insert("final_loss".into(), 0.25);
        c.extra = serde_json::json!({"codes": [[0.5, -1.0]]});
        c
    }

    fn outputs(m: &crate::lstm::FusedLstm) -> Vec<f32> {
        let x = Tensor::<2>::ones([1, 2], &backend::cpu());
        m.step(x, None).h.into_data().try_to_vec::<f32>().unwrap()
    }

    #[test]
    fn saved_weights_load_back_identically_from_file_and_memory() {
        let device = backend::cpu();
        let model = backend::seeded_module(&device, 5, |d| FusedLstmConfig::new(2, 4).init(d));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.bpk");
        save(&model, &card(), &path).unwrap();
        let w = Weights::from_path(&path).unwrap();
        assert_eq!(w.card(), &card());
        let fresh = || backend::seeded_module(&device, 99, |d| FusedLstmConfig::new(2, 4).init(d));
        assert_ne!(outputs(&fresh()), outputs(&model));
        assert_eq!(outputs(&w.expect_kind("test-lstm", 2).unwrap().load_into(fresh()).unwrap()), outputs(&model));
        // The same bytes compiled in (leaked here to get 'static, as include_bytes! gives).
        let bytes: &'static [u8] = Box::leak(std::fs::read(&path).unwrap().into_boxed_slice());
        let text = std::fs::read_to_string(card_path(&path)).unwrap();
        let e = Weights::embedded("weights/w", bytes, &text).unwrap();
        assert_eq!(outputs(&e.load_into(fresh()).unwrap()), outputs(&model));
        let codes: serde_json::Value = e.extra().unwrap();
        assert_eq!(codes["codes"][0][1], -1.0);
    }

    #[test]
    fn mismatched_files_are_refused_with_the_file_named() {
        let device = backend::cpu();
        let model = FusedLstmConfig::new(2, 4).init(&device);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.bpk");
        save(&model, &card(), &path).unwrap();
        let w = Weights::from_path(&path).unwrap();
        let err = w.expect_kind("camera", 1).unwrap_err().to_string();
        assert!(
            err.contains("w.bpk")
                && err.contains("holds test-lstm weights (format 2)")
                && err.contains("expected camera"),
            "{err}"
        );
        let err = w.expect_kind("test-lstm", 3).unwrap_err().to_string();
        assert!(err.contains("format 3"), "{err}");
        // Another shape: burn names the parameter.
        let err = w.load_into(FusedLstmConfig::new(3, 4).init(&device)).unwrap_err().to_string();
        assert!(err.contains("w.bpk"), "{err}");
        // A config that does not fit the caller's type.
        let err = w.config::<Vec<u32>>().unwrap_err().to_string();
        assert!(err.contains("w.json") && err.contains("config"), "{err}");
        // A broken card names file and line; a missing card names the card.
        std::fs::write(card_path(&path), "{\n \"kind\": \"x\",\n oops\n}").unwrap();
        let err = Weights::from_path(&path).unwrap_err().to_string();
        assert!(err.contains("w.json") && err.contains("line 3"), "{err}");
        std::fs::remove_file(card_path(&path)).unwrap();
        let err = Weights::from_path(&path).unwrap_err().to_string();
        assert!(err.contains("w.json"), "{err}");
    }
}
