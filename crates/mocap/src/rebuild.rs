//! `ReconstructJob`: a whole clip rebuilt from its key poses (the rotation reconstruction of
//! [`crate::rotations`]: quaternion Hermite rotations and cubic Hermite translations between keys,
//! the engine's BVH output) and its joint position error against the source, per frame.

use crate::metrics::PositionError;
use crate::prepared::PreparedClip;
use crate::rotations::{reconstruct_poses, EulerPlayback, RotationCurve, RotationMotion};
use crate::{MocapError, Result};
use inbetween_core::cancel::Cancel;
use inbetween_core::{forward, KeyframeSet, Motion, Pose};
use inbetween_io::Progress;
use serde::Serialize;
use std::fmt;

/// Rebuild a prepared clip from the poses at `keys`.
#[derive(Clone, Debug, Default)]
pub struct ReconstructJob {
    /// Key frames; the clip's first and last frames are added when missing.
    pub keys: Vec<usize>,
    /// How rotations are interpolated between keys (the engine's Hermite, or what a DCC's
    /// quaternion or Euler Bezier curves play back).
    pub curve: RotationCurve,
    /// How Euler curves play each joint ([`RotationCurve::EulerBezier`]; by default the skeleton's
    /// BVH channels).
    pub euler: Option<EulerPlayback>,
}

/// The rebuilt clip and how far it is from its source.
#[derive(Clone, Debug, Serialize)]
pub struct ReconstructReport {
    pub keys: KeyframeSet,
    pub curve: RotationCurve,
    /// Joint position error against the source, cm.
    pub error: PositionError,
    /// The rebuilt local poses, one per frame (write them with [`ReconstructReport::motion`]).
    #[serde(skip)]
    pub poses: Vec<Pose>,
}

impl ReconstructJob {
    /// The job's keys as a set for a clip of `n` frames (checks every frame is inside it).
    pub fn key_set(&self, n: usize) -> Result<KeyframeSet> {
        Ok(KeyframeSet::new(self.keys.clone(), n)?)
    }

    /// Checks the keys against a clip of `n` frames.
    pub fn validate(&self, n: usize) -> Result<()> {
        crate::rotations::check_playback(self.curve, self.euler.as_ref())?;
        self.key_set(n).map(|_| ())
    }

    /// Rebuilds `clip` from its poses at the job's keys.
    pub fn run(&self, clip: &PreparedClip, cancel: &Cancel, progress: &Progress) -> Result<ReconstructReport> {
        self.validate(clip.num_frames())?;
        let keys = self.key_set(clip.num_frames())?;
        let played = clip.rotations.played(self.curve, self.euler.as_ref())?;
        rebuild(clip, &played, keys, self.curve, cancel, progress)
    }
}

/// [`ReconstructJob::run`] for a key set already made for `clip`, its key poses from `rotations`
/// (the clip's, with Euler keys for [`RotationCurve::EulerBezier`]).
pub(crate) fn rebuild(
    clip: &PreparedClip,
    rotations: &RotationMotion,
    keys: KeyframeSet,
    curve: RotationCurve,
    cancel: &Cancel,
    progress: &Progress,
) -> Result<ReconstructReport> {
    if keys.num_frames() != clip.num_frames() {
        return Err(MocapError::Invalid(format!(
            "keys for {} frames do not fit a clip of {} frames",
            keys.num_frames(),
            clip.num_frames()
        )));
    }
    progress.phase(2, "reconstructing");
    let frames = keys.frames();
    let key_poses: Vec<_> = frames.iter().map(|&f| rotations.frames[f].clone()).collect();
    let euler = rotations.key_euler(&keys);
    let skeleton = &clip.motion.skeleton;
    let poses = reconstruct_poses(skeleton, clip.motion.frame_time, frames, &key_poses, curve, euler.as_ref())?;
    cancel.check()?;
    progress.inc(1);
    use rayon::prelude::*;
    let rebuilt: Vec<_> = poses.par_iter().map(|p| forward(skeleton, p).positions).collect();
    let error = PositionError::between(&clip.positions, &rebuilt, clip.unit.cm_per_unit());
    progress.inc(1);
    Ok(ReconstructReport { keys, curve, error, poses })
}

impl ReconstructReport {
    /// The rebuilt clip on the source's skeleton (Euler channels, as BVH stores them).
    pub fn motion(&self, clip: &PreparedClip) -> Result<Motion> {
        Ok(Motion::from_poses(clip.motion.skeleton.clone(), clip.motion.frame_time, &self.poses)?)
    }
}

impl fmt::Display for ReconstructReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} frames from {} keys: {}", self.keys.num_frames(), self.keys.len(), self.error)
    }
}
