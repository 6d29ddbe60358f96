//! The clip pools the networks train on: procedural clips (with exact viseme labels), or the
//! training split of the real captures ([`crate::data::split::TRAIN_FILES`]; split by file, so the
//! benchmark's held-out takes are never seen).

use std::path::Path;

use crate::data::split::TRAIN_FILES;
use crate::data::{read_live_link, FaceError};
use crate::procedural;
use crate::train::data::{ClipPool, TrainClip};

/// `clips` procedural clips of `seconds` each, seeded.
pub fn procedural_pool(clips: usize, seconds: f64, seed: u64) -> Result<ClipPool, FaceError> {
    let corpus = procedural::generate_corpus(clips, seconds, seed);
    let clips =
        corpus.iter().map(|p| TrainClip::from_clip(&p.clip, Some(p.visemes.clone()))).collect::<Result<Vec<_>, _>>()?;
    Ok(ClipPool::new(
        clips,
        format!("procedural face generator (crate::procedural): {} clips x {seconds} s, seed {seed}", corpus.len()),
    ))
}

/// The training split of the Live Link captures under `captures` (`…/face/neurosync`).
pub fn real_pool(captures: &Path) -> Result<ClipPool, FaceError> {
    let clips = TRAIN_FILES
        .iter()
        .map(|f| TrainClip::from_clip(&read_live_link(&captures.join(f))?, None))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ClipPool::new(clips, format!("real Live Link captures, training split by file: {}", TRAIN_FILES.join(", "))))
}
