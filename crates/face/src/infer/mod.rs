//! Editing a clip: the [`EditJob`] (validate, run) and the keyframe files it reads.

pub mod files;
pub mod job;
pub mod keys;
pub mod plan;
pub mod variants;

pub use job::{EditJob, EditLimits, EditOutcome, Guide, Inpainter, Method};
pub use keys::{read_keys, KeyPose};
pub use variants::{run_variants, Variant, VariantReport};

/// A linear fill of 2 s..3.5 s with seed 7 on `clip`, no guidance: the tests' edit.
#[cfg(test)]
pub(crate) fn linear_test_job(clip: &crate::data::BlendshapeClip) -> EditJob<'_> {
    EditJob {
        clip,
        spans: vec![(2.0, 3.5)],
        channels: None,
        guide: Guide::None,
        method: Method::Linear,
        seed: 7,
        limits: EditLimits::default(),
        cancel: inbetween_core::cancel::Cancel::new(),
        guide_file: None,
        library: None,
    }
}

/// Seconds of procedural motion in the default retrieval library (`face edit --method retrieval`
/// without `--library`).
pub const DEFAULT_LIBRARY_S: f64 = 120.0;
/// Seed of the default retrieval library (fixed, so the library is the same on every run).
pub const DEFAULT_LIBRARY_SEED: u64 = 2025;
