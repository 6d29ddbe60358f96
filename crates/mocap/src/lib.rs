//! Mocap engine: the SIDQL paper's spherical keyframe reconstruction (Eq. 1–13), its error metrics
//! (Eq. 15–18, 24), keyframe selectors (random, uniform, greedy, the exact optimum, error-bounded and
//! the SIDQL deep Q-network), a compact keyframe codec and a live keyframe stream.
//!
//! Pipeline: [`representation`] turns a clip into per-bone spherical angles plus angular velocities,
//! [`reconstruct`] rebuilds the in-between frames from keyframes with cubic Hermite segments,
//! [`error`] scores a reconstruction and tabulates per-segment costs, and [`select`] picks keyframes.

pub mod bench;
pub mod codec;
pub mod corpus;
pub mod demo;
pub mod dqn;
pub mod error;
pub mod reconstruct;
pub mod representation;
pub mod rotations;
pub mod select;
pub mod stream;

pub use error::{Objective, ReconstructionError, SegmentCost, SegmentTable};
pub use reconstruct::{reconstruct_spherical, SphericalReconstruction};
pub use representation::{JointFilter, SphericalMotion};
pub use rotations::RotationMotion;

/// Errors of the mocap engine.
#[derive(Debug, thiserror::Error)]
pub enum MocapError {
    #[error("invalid input: {0}")]
    Invalid(String),
    #[error(transparent)]
    Core(#[from] inbetween_core::CoreError),
    #[error("codec: {0}")]
    Codec(String),
    #[error("i/o error on {path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error(transparent)]
    Format(#[from] inbetween_io::IoError),
    #[error("model: {0}")]
    Model(String),
    /// Weights or training (files named in the message).
    #[error(transparent)]
    Nn(#[from] inbetween_nn::NnError),
    #[error("stream: {0}")]
    Stream(String),
}

pub type Result<T> = std::result::Result<T, MocapError>;
