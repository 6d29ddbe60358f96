//! Editing a clip: the [`EditJob`] (validate, run) and the keyframe files it reads.

pub mod files;
pub mod job;
pub mod keys;
pub mod plan;
pub mod variants;

pub use job::{EditJob, EditLimits, EditOutcome, Guide, Inpainter, Method};
pub use keys::{read_keys, KeyPose};
pub use variants::{run_variants, Variant, VariantReport};

/// Seconds of procedural motion in the default retrieval library (`face edit --method retrieval`
/// without `--library`).
pub const DEFAULT_LIBRARY_S: f64 = 120.0;
/// Seed of the default retrieval library (fixed, so the library is the same on every run).
pub const DEFAULT_LIBRARY_SEED: u64 = 2025;
