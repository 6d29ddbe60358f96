//! Editing a clip: the [`EditJob`] (validate, run) and the keyframe files it reads.

pub mod job;
pub mod keys;

pub use job::{EditJob, EditLimits, EditOutcome, Guide, Inpainter, Method};
pub use keys::{read_keys, KeyPose};
