//! Mocap engine: the SIDQL paper's spherical keyframe reconstruction (Eq. 1–13), its error metrics
//! (Eq. 15–18, 24), keyframe selectors (random, uniform, greedy, the exact optimum, error-bounded and
//! the SIDQL deep Q-network), a compact keyframe codec and a live keyframe stream.
//!
//! Pipeline: [`representation`] turns a clip into per-bone spherical angles plus angular velocities,
//! [`reconstruct`] rebuilds the in-between frames from keyframes with cubic Hermite segments,
//! [`metrics`] scores a reconstruction and tabulates per-segment costs, and [`select`] picks keyframes.
//!
//! Every user-facing operation is a job (inputs as fields, `validate`, `run`, a report that is
//! `Display` and `serde::Serialize`): [`SelectJob`] (keys by one [`Selector`]) and
//! [`ReconstructJob`] on a [`PreparedClip`], [`CompressJob`] and [`DecompressJob`] for `.ibk` files.

pub mod bench;
pub mod codec;
pub mod corpus;
pub mod dcc;
pub mod demo;
pub mod dqn;
mod error;
pub mod metrics;
pub mod prepared;
pub mod protocol;
pub mod rebuild;
pub mod reconstruct;
pub mod representation;
pub mod rotations;
pub mod select;
pub mod stream;

pub use codec::job::{
    CompressJob, CompressReport, DecompressJob, DecompressReport, PreviewJob, PreviewReport, Rebuilt,
};
pub use error::{MocapError, Result};
pub use metrics::{ErrorMeasure, PositionError, ReconstructionError, SegmentCost, SegmentTable};
pub use prepared::PreparedClip;
pub use rebuild::{ReconstructJob, ReconstructReport};
pub use reconstruct::{reconstruct_spherical, SphericalReconstruction};
pub use representation::{JointFilter, SphericalMotion};
pub use rotations::{RotationCurve, RotationMotion};
pub use select::job::{SelectJob, SelectReport, Selector};
