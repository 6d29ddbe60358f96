//! Motion clips: a skeleton plus frames × channels of raw channel values (BVH units, degrees),
//! and the local poses they describe.

use crate::rotation::EulerOrder;
use crate::skeleton::{Channel, Skeleton};
use crate::CoreError;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// Local transforms of every joint for one frame: rotation and translation relative to the parent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub rotations: Vec<DQuat>,
    pub translations: Vec<DVec3>,
}

impl Pose {
    /// The rest pose: identity rotations, rest offsets.
    pub fn rest(skeleton: &Skeleton) -> Pose {
        Pose {
            rotations: vec![DQuat::IDENTITY; skeleton.len()],
            translations: skeleton.joints().iter().map(|j| j.offset).collect(),
        }
    }
}

/// A motion clip. Channel values are stored as in BVH: positions in the file's length unit,
/// rotations in degrees, frame-major (`frames[f * num_channels + c]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Motion {
    pub skeleton: Skeleton,
    /// Seconds per frame.
    pub frame_time: f64,
    data: Vec<f64>,
}

impl Motion {
    /// Builds a clip from frame-major channel values; the length must be a multiple of the channel count.
    pub fn new(skeleton: Skeleton, frame_time: f64, data: Vec<f64>) -> Result<Motion, CoreError> {
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(CoreError::InvalidMotion(format!("frame time {frame_time} must be a positive number")));
        }
        let nc = skeleton.num_channels();
        if (nc == 0 && !data.is_empty()) || (nc > 0 && !data.len().is_multiple_of(nc)) {
            return Err(CoreError::InvalidMotion(format!(
                "{} values are not a whole number of frames of {nc} channels",
                data.len()
            )));
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::InvalidMotion(format!(
                "frame {}, channel {}: value is not finite",
                i / nc.max(1),
                i % nc.max(1)
            )));
        }
        Ok(Motion { skeleton, frame_time, data })
    }

    /// Builds a clip whose channel values reproduce `poses` (rotations are written in each joint's
    /// own Euler order; joints without rotation channels must have identity rotations).
    pub fn from_poses(skeleton: Skeleton, frame_time: f64, poses: &[Pose]) -> Result<Motion, CoreError> {
        let nc = skeleton.num_channels();
        let mut data = vec![0.0; nc * poses.len()];
        // Frames are independent: in parallel (the same numbers).
        use rayon::prelude::*;
        data.par_chunks_mut(nc.max(1)).zip(poses).for_each(|(frame, pose)| write_pose(&skeleton, pose, frame));
        Motion::new(skeleton, frame_time, data)
    }

    pub fn num_frames(&self) -> usize {
        self.data.len().checked_div(self.skeleton.num_channels()).unwrap_or(0)
    }

    pub fn num_channels(&self) -> usize {
        self.skeleton.num_channels()
    }

    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// Duration from the first to the last frame, in seconds.
    pub fn duration(&self) -> f64 {
        self.num_frames().saturating_sub(1) as f64 * self.frame_time
    }

    pub fn data(&self) -> &[f64] {
        &self.data
    }

    pub fn frame(&self, f: usize) -> &[f64] {
        let nc = self.num_channels();
        &self.data[f * nc..(f + 1) * nc]
    }

    pub fn frame_mut(&mut self, f: usize) -> &mut [f64] {
        let nc = self.num_channels();
        &mut self.data[f * nc..(f + 1) * nc]
    }

    /// Local pose of frame `f`.
    pub fn pose(&self, f: usize) -> Pose {
        read_pose(&self.skeleton, self.frame(f))
    }

    /// Local poses of all frames.
    pub fn poses(&self) -> Vec<Pose> {
        (0..self.num_frames()).map(|f| self.pose(f)).collect()
    }

    /// Frames `start..end` as a new clip.
    pub fn crop(&self, start: usize, end: usize) -> Result<Motion, CoreError> {
        if start >= end || end > self.num_frames() {
            return Err(CoreError::InvalidMotion(format!(
                "crop range {start}..{end} is empty or outside the clip's {} frames",
                self.num_frames()
            )));
        }
        let nc = self.num_channels();
        Motion::new(self.skeleton.clone(), self.frame_time, self.data[start * nc..end * nc].to_vec())
    }

    /// Fixed-length sub-clips `len` frames long, starting every `stride` frames; a tail shorter than
    /// `len` is dropped.
    pub fn windows(&self, len: usize, stride: usize) -> Vec<Motion> {
        if len == 0 || stride == 0 || self.num_frames() < len {
            return Vec::new();
        }
        (0..=self.num_frames() - len)
            .step_by(stride)
            .map(|s| self.crop(s, s + len).expect("window lies inside the clip"))
            .collect()
    }

    /// Keeps only the joints for which `keep` is true (dropping a joint drops its subtree).
    pub fn filter_joints(&self, keep: impl Fn(usize, &crate::skeleton::Joint) -> bool) -> Motion {
        let (skeleton, source) = self.skeleton.filter(keep);
        let mut data = Vec::with_capacity(self.num_frames() * skeleton.num_channels());
        for f in 0..self.num_frames() {
            let frame = self.frame(f);
            for &s in &source {
                let start = self.skeleton.channel_start(s);
                data.extend_from_slice(&frame[start..start + self.skeleton.joint(s).channels.len()]);
            }
        }
        Motion::new(skeleton, self.frame_time, data).expect("filtered data matches the filtered skeleton")
    }

    /// Resamples to `fps`. An integer ratio of rates (120 → 30) keeps every n-th frame exactly;
    /// otherwise rotations are slerped and translations interpolated linearly between the two
    /// nearest source frames.
    pub fn resample(&self, fps: f64) -> Result<Motion, CoreError> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(CoreError::InvalidMotion(format!("target rate {fps} fps must be positive")));
        }
        let n = self.num_frames();
        if n == 0 {
            return Motion::new(self.skeleton.clone(), 1.0 / fps, Vec::new());
        }
        let ratio = self.fps() / fps;
        if (ratio - ratio.round()).abs() < 1e-6 && ratio.round() >= 1.0 {
            let step = ratio.round() as usize;
            let mut data = Vec::new();
            for f in (0..n).step_by(step) {
                data.extend_from_slice(self.frame(f));
            }
            return Motion::new(self.skeleton.clone(), self.frame_time * step as f64, data);
        }
        let out_frames = (self.duration() * fps + 1e-9).floor() as usize + 1;
        let poses = self.poses();
        let resampled: Vec<Pose> = (0..out_frames)
            .map(|i| {
                let src = i as f64 / fps / self.frame_time;
                let f0 = (src.floor() as usize).min(n - 1);
                let f1 = (f0 + 1).min(n - 1);
                let t = src - f0 as f64;
                interpolate_pose(&poses[f0], &poses[f1], t)
            })
            .collect();
        Motion::from_poses(self.skeleton.clone(), 1.0 / fps, &resampled)
    }
}

/// Slerp of rotations, lerp of translations.
pub fn interpolate_pose(a: &Pose, b: &Pose, t: f64) -> Pose {
    Pose {
        rotations: a.rotations.iter().zip(&b.rotations).map(|(qa, qb)| qa.slerp(*qb, t)).collect(),
        translations: a.translations.iter().zip(&b.translations).map(|(pa, pb)| pa.lerp(*pb, t)).collect(),
    }
}

/// Decodes one frame of channel values. Position channels replace the matching component of the
/// joint's rest offset (the Blender/MotionBuilder reading of BVH).
pub fn read_pose(skeleton: &Skeleton, frame: &[f64]) -> Pose {
    let mut pose = Pose::rest(skeleton);
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let start = skeleton.channel_start(j);
        let mut angles = [0.0; 3];
        let mut k = 0;
        for (c, ch) in joint.channels.iter().enumerate() {
            let v = frame[start + c];
            if ch.is_rotation() {
                angles[k] = v.to_radians();
                k += 1;
            } else {
                pose.translations[j][ch.axis().index()] = v;
            }
        }
        if let Some(order) = joint.rotation_order() {
            pose.rotations[j] = order.to_quat(angles);
        }
    }
    pose
}

/// Encodes a pose into one frame of channel values (inverse of [`read_pose`]).
pub fn write_pose(skeleton: &Skeleton, pose: &Pose, frame: &mut [f64]) {
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let start = skeleton.channel_start(j);
        let angles = joint.rotation_order().map(|o: EulerOrder| o.from_quat(pose.rotations[j])).unwrap_or([0.0; 3]);
        let mut k = 0;
        for (c, ch) in joint.channels.iter().enumerate() {
            frame[start + c] = if ch.is_rotation() {
                k += 1;
                angles[k - 1].to_degrees()
            } else {
                pose.translations[j][ch.axis().index()]
            };
        }
    }
}

/// True when every joint's rotation channels exist or its pose rotation is the identity, i.e.
/// `write_pose` loses nothing. Useful before writing reconstructed poses back as BVH.
pub fn pose_is_representable(skeleton: &Skeleton, pose: &Pose) -> bool {
    skeleton.joints().iter().enumerate().all(|(j, joint)| {
        joint.rotation_order().is_some() || crate::rotation::angle_between(pose.rotations[j], DQuat::IDENTITY) < 1e-9
    }) && skeleton.joints().iter().enumerate().all(|(j, joint)| {
        Channel::POSITION_XYZ.iter().all(|c| {
            joint.channels.contains(c)
                || (pose.translations[j][c.axis().index()] - joint.offset[c.axis().index()]).abs() < 1e-9
        })
    })
}
