//! Camera engine: style-aware camera keyframing in Toric space, after Jiang, Christie, Wang, Liu,
//! Wang & Chen, "Camera Keyframing with Style and Control" (ACM TOG 40(6), 2021).
//!
//! Pipeline (one module per stage): [`toric`] space ↔ camera poses, cinematic [`features`] (Eq. 1–2),
//! the synthetic [`dataset`] (scenes + four behaviours), the three networks in [`model`], [`train`]
//! (run as a [`TrainJob`]),
//! loading trained [`weights`], inference with keyframes in [`infer`] (plain-Rust networks, one
//! [`infer::Rollout`], [`infer::GenerateJob`], the causal mode), exports ([`gltf`], [`preview`]) and
//! the [`bench`](mod@bench).

/// Toric space lives in core (the script engine frames two-shots in it too); re-exported here.
pub use inbetween_core::toric;

pub mod bench;
pub mod dataset;
pub mod demo;
mod error;
pub mod features;
pub mod generate_files;
pub mod gltf;
pub mod infer;
pub mod model;
pub mod preview;
pub mod train;
pub mod train_job;
pub mod weights;

pub use error::CameraError;
pub use train_job::{TrainJob, TrainReport};

use std::path::Path;

/// Reads a JSON file; syntax and shape errors give file:line:column.
pub fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, CameraError> {
    let text = std::fs::read_to_string(path).map_err(|source| CameraError::Io { path: path.into(), source })?;
    serde_json::from_str(&text).map_err(|e| CameraError::Parse {
        path: path.into(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })
}

/// Writes compact JSON atomically (temp file, then rename).
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<(), CameraError> {
    let bytes = serde_json::to_vec(value).map_err(|e| CameraError::invalid(path, e.to_string()))?;
    inbetween_io::write_atomic(path, &bytes).map_err(|source| CameraError::Io { path: path.into(), source })
}
