//! The runtime pose clip (after ozz-animation's runtime animation and `SamplingJob`): a skeleton's
//! local joint rotations (unit quaternions) and translations, stored as two arrays (structure of
//! arrays, one block of joints per key), at key frames of a fixed frame rate.
//!
//! [`Motion`] stays the raw BVH form (Euler degrees per channel) that io reads and writes; a
//! [`Clip`] is what engines sample, blend and send on. Conversion is explicit and exact:
//! [`Clip::from_motion`] decodes every frame ([`crate::motion::read_pose`]), [`Clip::to_motion`]
//! encodes every frame back ([`crate::motion::write_pose`]) and refuses a pose the skeleton's
//! channels cannot carry instead of dropping part of it. Rotations round-trip to floating-point
//! round-off (an Euler triple outside the principal ranges comes back as the equal principal
//! one), translations bit for bit.
//!
//! A dense clip has a key at every frame; [`Clip::with_keys`] keeps only some (a keyframe set from
//! mocap's selection), and sampling slerps rotations and interpolates translations linearly
//! between the two keys around a time. [`Clip::sample_into`] writes into a [`Pose`] the caller
//! owns and keeps its place in a [`SamplingContext`], so forward playback finds each next segment
//! in constant time and allocates nothing. A clip is a [`Curve<Pose>`] over `[0, duration]`
//! seconds, so the curve adapters (blend, cross-fade, loop, time warp, root placement) apply.
//!
//! ```
//! use inbetween_core::clip::{Clip, SamplingContext};
//! use inbetween_core::curve::Curve;
//! use inbetween_core::{procedural, Pose};
//! let walk = procedural::gait(&procedural::GaitParams::walk());
//! let clip = Clip::from_motion(&walk).unwrap();
//! let (mut ctx, mut pose) = (SamplingContext::default(), Pose::rest(clip.skeleton()));
//! for frame in 0..clip.num_frames() {
//!     clip.sample_into(frame as f64 * clip.frame_time(), &mut ctx, &mut pose).unwrap();
//! }
//! assert_eq!(pose, walk.pose(walk.num_frames() - 1));
//! assert_eq!(clip.to_motion().unwrap().num_frames(), walk.num_frames());
//! assert!(clip.sample(clip.duration() + 1.0).is_none(), "outside the clip");
//! ```

use crate::curve::{Curve, Interval};
use crate::keyframes::KeyframeSet;
use crate::motion::{read_pose, write_pose, Motion, Pose};
use crate::skeleton::{Channel, Skeleton};
use crate::CoreError;
use glam::{DQuat, DVec3};

/// Local joint transforms at key frames of a fixed rate (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    skeleton: Skeleton,
    frame_time: f64,
    /// Frame index of each key, strictly increasing from 0.
    key_frames: Vec<usize>,
    /// `rotations[k * joints + j]`: joint `j`'s local rotation at key `k`.
    rotations: Vec<DQuat>,
    /// `translations[k * joints + j]`: joint `j`'s local translation at key `k`.
    translations: Vec<DVec3>,
}

/// Where the last sample fell (ozz's sampling context): the key segment to try first. One context
/// per playback; it may be reused across clips (a stale cursor only costs a binary search).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SamplingContext {
    segment: usize,
}

impl SamplingContext {
    /// Forgets the cursor (the next sample searches from the start).
    pub fn reset(&mut self) {
        self.segment = 0;
    }
}

impl Clip {
    /// A dense clip, one key per pose at `frame_time` seconds apart. Fails on no poses, a frame
    /// time that is not positive, a pose with the wrong number of joints or a value that is not
    /// finite (naming the frame and joint).
    pub fn from_poses(skeleton: Skeleton, frame_time: f64, poses: &[Pose]) -> Result<Clip, CoreError> {
        Clip::from_keys(skeleton, frame_time, (0..poses.len()).collect(), poses)
    }

    /// A clip with `poses[k]` at frame `key_frames[k]` (strictly increasing, the first 0); the
    /// frames between keys are interpolated when sampled.
    pub fn from_keys(
        skeleton: Skeleton,
        frame_time: f64,
        key_frames: Vec<usize>,
        poses: &[Pose],
    ) -> Result<Clip, CoreError> {
        let bad = |m: String| Err(CoreError::InvalidMotion(m));
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return bad(format!("frame time {frame_time} s must be a positive number"));
        }
        if poses.is_empty() {
            return bad("a clip needs at least one key".into());
        }
        if key_frames.len() != poses.len() {
            return bad(format!("{} key frames but {} poses", key_frames.len(), poses.len()));
        }
        if key_frames[0] != 0 {
            return bad(format!("the first key is at frame {}; expected frame 0", key_frames[0]));
        }
        if let Some(w) = key_frames.windows(2).find(|w| w[0] >= w[1]) {
            return bad(format!("key frame {} does not come after key frame {}", w[1], w[0]));
        }
        let n = skeleton.len();
        let mut rotations = Vec::with_capacity(n * poses.len());
        let mut translations = Vec::with_capacity(n * poses.len());
        for (k, p) in poses.iter().enumerate() {
            let frame = key_frames[k];
            if p.rotations.len() != n || p.translations.len() != n {
                return bad(format!(
                    "frame {frame}: pose has {} rotations and {} translations; the skeleton has {n} joints",
                    p.rotations.len(),
                    p.translations.len()
                ));
            }
            let finite = |j: usize| p.rotations[j].is_finite() && p.translations[j].is_finite();
            if let Some(j) = (0..n).find(|&j| !finite(j)) {
                return bad(format!("frame {frame}, joint '{}': transform is not finite", skeleton.joint(j).name));
            }
            if let Some(j) = (0..n).find(|&j| (p.rotations[j].length() - 1.0).abs() > 1e-6) {
                return bad(format!(
                    "frame {frame}, joint '{}': rotation has length {}; expected a unit quaternion",
                    skeleton.joint(j).name,
                    p.rotations[j].length()
                ));
            }
            rotations.extend_from_slice(&p.rotations);
            translations.extend_from_slice(&p.translations);
        }
        Ok(Clip { skeleton, frame_time, key_frames, rotations, translations })
    }

    /// Decodes every frame of a BVH-form clip (Euler degrees → quaternions, position channels
    /// over the rest offsets). Fails on a clip with no frames.
    pub fn from_motion(motion: &Motion) -> Result<Clip, CoreError> {
        if motion.num_frames() == 0 {
            return Err(CoreError::InvalidMotion("a clip needs at least one frame; the motion has none".into()));
        }
        let n = motion.skeleton.len();
        let frames = motion.num_frames();
        let mut rotations = Vec::with_capacity(n * frames);
        let mut translations = Vec::with_capacity(n * frames);
        for f in 0..frames {
            let p = read_pose(&motion.skeleton, motion.frame(f));
            rotations.extend_from_slice(&p.rotations);
            translations.extend_from_slice(&p.translations);
        }
        Ok(Clip {
            skeleton: motion.skeleton.clone(),
            frame_time: motion.frame_time,
            key_frames: (0..frames).collect(),
            rotations,
            translations,
        })
    }

    /// Encodes every frame into BVH channel values (each joint's own Euler order, degrees).
    /// Fails, naming the frame and joint, where a pose turns a joint that has no rotation
    /// channels or moves it along an axis it has no position channel for (beyond 1e-9).
    pub fn to_motion(&self) -> Result<Motion, CoreError> {
        let nc = self.skeleton.num_channels();
        let mut data = vec![0.0; nc * self.num_frames()];
        let (mut ctx, mut pose) = (SamplingContext::default(), Pose::rest(&self.skeleton));
        for f in 0..self.num_frames() {
            self.sample_frame(f as f64, &mut ctx, &mut pose);
            self.check_representable(f, &pose)?;
            write_pose(&self.skeleton, &pose, &mut data[f * nc..(f + 1) * nc]);
        }
        Motion::new(self.skeleton.clone(), self.frame_time, data)
    }

    fn check_representable(&self, frame: usize, pose: &Pose) -> Result<(), CoreError> {
        for (j, joint) in self.skeleton.joints().iter().enumerate() {
            if joint.rotation_order().is_none()
                && crate::rotation::angle_between(pose.rotations[j], DQuat::IDENTITY) > 1e-9
            {
                return Err(CoreError::InvalidMotion(format!(
                    "frame {frame}, joint '{}': rotated, but the joint has no rotation channels",
                    joint.name
                )));
            }
            for c in Channel::POSITION_XYZ {
                let axis = c.axis().index();
                if !joint.channels.contains(&c) && (pose.translations[j][axis] - joint.offset[axis]).abs() > 1e-9 {
                    return Err(CoreError::InvalidMotion(format!(
                        "frame {frame}, joint '{}': moved along {} (to {}), but the joint has no {} channel",
                        joint.name,
                        ["x", "y", "z"][axis],
                        pose.translations[j][axis],
                        c.name()
                    )));
                }
            }
        }
        Ok(())
    }

    /// Only the keys at `keys`' frames, which must be keys of this clip (for a dense clip: any
    /// keyframe set of its length). Sampling in between then interpolates.
    pub fn with_keys(&self, keys: &KeyframeSet) -> Result<Clip, CoreError> {
        if keys.num_frames() != self.num_frames() {
            return Err(CoreError::InvalidKeyframes(format!(
                "keyframes for {} frames given to a clip of {} frames",
                keys.num_frames(),
                self.num_frames()
            )));
        }
        let n = self.skeleton.len();
        let mut rotations = Vec::with_capacity(n * keys.len());
        let mut translations = Vec::with_capacity(n * keys.len());
        for &f in keys.frames() {
            let k = self.key_frames.binary_search(&f).map_err(|_| {
                CoreError::InvalidKeyframes(format!("frame {f} is not a key of the clip it is taken from"))
            })?;
            rotations.extend_from_slice(self.key_rotations(k));
            translations.extend_from_slice(self.key_translations(k));
        }
        Ok(Clip {
            skeleton: self.skeleton.clone(),
            frame_time: self.frame_time,
            key_frames: keys.frames().to_vec(),
            rotations,
            translations,
        })
    }

    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Seconds per frame.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// Frames from the first key to the last, both included.
    pub fn num_frames(&self) -> usize {
        self.key_frames[self.key_frames.len() - 1] + 1
    }

    /// Seconds from the first frame to the last.
    pub fn duration(&self) -> f64 {
        (self.num_frames() - 1) as f64 * self.frame_time
    }

    pub fn num_keys(&self) -> usize {
        self.key_frames.len()
    }

    /// Frame index of each key.
    pub fn key_frames(&self) -> &[usize] {
        &self.key_frames
    }

    /// Local rotation of every joint at key `k`.
    pub fn key_rotations(&self, k: usize) -> &[DQuat] {
        let n = self.skeleton.len();
        &self.rotations[k * n..(k + 1) * n]
    }

    /// Local translation of every joint at key `k`.
    pub fn key_translations(&self, k: usize) -> &[DVec3] {
        let n = self.skeleton.len();
        &self.translations[k * n..(k + 1) * n]
    }

    /// The pose at key `k`.
    pub fn key_pose(&self, k: usize) -> Pose {
        Pose { rotations: self.key_rotations(k).to_vec(), translations: self.key_translations(k).to_vec() }
    }

    /// The pose at frame `f` (a key copied, a frame between keys interpolated, the last frame
    /// held past the end): what [`Motion::pose`] gives for a BVH-form clip, without decoding.
    pub fn pose(&self, f: usize) -> Pose {
        let mut p = Pose::rest(&self.skeleton);
        self.pose_into(f, &mut p);
        p
    }

    /// [`Clip::pose`] into a pose the caller owns (no allocation once it has the skeleton's size).
    pub fn pose_into(&self, f: usize, out: &mut Pose) {
        match self.key_frames.get(f) {
            Some(&k) if k == f => self.copy_key_resized(f, out),
            _ => self.sample_frame(f as f64, &mut SamplingContext::default(), out),
        }
    }

    /// Global (world) transforms of every frame, by forward kinematics.
    pub fn globals(&self) -> Vec<crate::fk::GlobalPose> {
        let mut pose = Pose::rest(&self.skeleton);
        (0..self.num_frames())
            .map(|f| {
                self.pose_into(f, &mut pose);
                crate::fk::forward(&self.skeleton, &pose)
            })
            .collect()
    }

    /// The pose of every frame (keys copied, frames between them interpolated).
    pub fn poses(&self) -> Vec<Pose> {
        let mut ctx = SamplingContext::default();
        (0..self.num_frames())
            .map(|f| {
                let mut p = Pose::rest(&self.skeleton);
                self.sample_frame(f as f64, &mut ctx, &mut p);
                p
            })
            .collect()
    }

    /// The pose at `t` seconds into `out` (resized to the skeleton if needed, otherwise no
    /// allocation), starting the key search from `ctx`'s cursor and leaving it on the segment
    /// found. A time within 1e-9 frames of a frame samples that frame exactly. Fails outside
    /// `[0, duration]` or on a NaN time.
    pub fn sample_into(&self, t: f64, ctx: &mut SamplingContext, out: &mut Pose) -> Result<(), CoreError> {
        if !self.domain().contains(t) {
            return Err(CoreError::InvalidMotion(format!(
                "time {t} s is outside the clip's {} (sample a clamped time or a looped clip)",
                self.domain()
            )));
        }
        self.sample_frame(t / self.frame_time, ctx, out);
        Ok(())
    }

    /// The pose at fractional frame `x` (held at the ends outside the clip).
    fn sample_frame(&self, x: f64, ctx: &mut SamplingContext, out: &mut Pose) {
        let n = self.skeleton.len();
        out.rotations.resize(n, DQuat::IDENTITY);
        out.translations.resize(n, DVec3::ZERO);
        let x = if (x - x.round()).abs() < 1e-9 { x.round() } else { x };
        let keys = &self.key_frames;
        if keys.len() == 1 || x <= 0.0 {
            return self.copy_key(0, out);
        }
        let last = keys.len() - 1;
        if x >= keys[last] as f64 {
            return self.copy_key(last, out);
        }
        let k = self.segment(x, ctx);
        let (f0, f1) = (keys[k] as f64, keys[k + 1] as f64);
        let u = (x - f0) / (f1 - f0);
        if u <= 0.0 {
            return self.copy_key(k, out);
        }
        let (r0, r1) = (self.key_rotations(k), self.key_rotations(k + 1));
        let (t0, t1) = (self.key_translations(k), self.key_translations(k + 1));
        for j in 0..n {
            out.rotations[j] = r0[j].slerp(r1[j], u);
            out.translations[j] = t0[j].lerp(t1[j], u);
        }
    }

    /// Segment `k` with `key_frames[k] ≤ x < key_frames[k + 1]` (`x` inside the clip): the
    /// context's segment or the next one (forward playback), otherwise a binary search.
    fn segment(&self, x: f64, ctx: &mut SamplingContext) -> usize {
        let keys = &self.key_frames;
        let segments = keys.len() - 1;
        let inside = |k: usize| k < segments && keys[k] as f64 <= x && x < keys[k + 1] as f64;
        let k = if inside(ctx.segment) {
            ctx.segment
        } else if inside(ctx.segment + 1) {
            ctx.segment + 1
        } else {
            keys.partition_point(|&f| f as f64 <= x).saturating_sub(1).min(segments - 1)
        };
        ctx.segment = k;
        k
    }

    fn copy_key_resized(&self, k: usize, out: &mut Pose) {
        let n = self.skeleton.len();
        out.rotations.resize(n, DQuat::IDENTITY);
        out.translations.resize(n, DVec3::ZERO);
        self.copy_key(k, out);
    }

    fn copy_key(&self, k: usize, out: &mut Pose) {
        out.rotations.copy_from_slice(self.key_rotations(k));
        out.translations.copy_from_slice(self.key_translations(k));
    }
}

impl TryFrom<&Motion> for Clip {
    type Error = CoreError;
    fn try_from(m: &Motion) -> Result<Clip, CoreError> {
        Clip::from_motion(m)
    }
}

impl TryFrom<&Clip> for Motion {
    type Error = CoreError;
    fn try_from(c: &Clip) -> Result<Motion, CoreError> {
        c.to_motion()
    }
}

impl Curve<Pose> for Clip {
    /// `[0, duration]` seconds.
    fn domain(&self) -> Interval {
        Interval::new(0.0, self.duration()).expect("a clip's duration is finite and not negative")
    }
    /// The pose at `t` (held at the ends outside the domain).
    fn sample_unchecked(&self, t: f64) -> Pose {
        let mut p = Pose::rest(&self.skeleton);
        self.sample_unchecked_into(t, &mut p);
        p
    }
    fn sample_unchecked_into(&self, t: f64, out: &mut Pose) {
        self.sample_frame(t / self.frame_time, &mut SamplingContext::default(), out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::{gait, GaitParams};
    use crate::rotation::{angle_between, EulerOrder};
    use crate::skeleton::Joint;
    use proptest::prelude::*;

    /// A chain with every Euler order and a mix of channel layouts (root with all six, one joint
    /// with a Y position channel only, one with no channels at all).
    fn mixed_skeleton() -> Skeleton {
        let mut joints = Vec::new();
        for (i, order) in EulerOrder::ALL.iter().enumerate() {
            let mut channels = if i == 0 { Channel::POSITION_XYZ.to_vec() } else { vec![] };
            if i == 2 {
                channels.push(Channel::Yposition);
            }
            channels.extend(Channel::rotations(*order));
            joints.push(Joint {
                name: format!("j{i}"),
                parent: i.checked_sub(1),
                offset: DVec3::new(0.5, 1.0 + i as f64, -0.25),
                channels,
                end_site: None,
            });
        }
        joints.push(Joint {
            name: "fixed".into(),
            parent: Some(5),
            offset: DVec3::new(0.0, 2.0, 0.0),
            channels: vec![],
            end_site: Some(DVec3::Y),
        });
        Skeleton::new(joints).unwrap()
    }

    /// Channel values of one frame of `mixed_skeleton`: positions from `pos`, Euler angles in the
    /// principal ranges (the middle one within ±89°) from `ang`.
    fn frame_values(sk: &Skeleton, pos: &[f64], ang: &[f64]) -> Vec<f64> {
        let (mut p, mut a) = (pos.iter().cycle(), ang.iter().cycle());
        let mut out = Vec::new();
        for joint in sk.joints() {
            let mut k = 0;
            for ch in &joint.channels {
                if ch.is_rotation() {
                    let range = if k == 1 { 89.0 } else { 179.0 };
                    out.push(a.next().unwrap() * range);
                    k += 1;
                } else {
                    out.push(*p.next().unwrap());
                }
            }
        }
        out
    }

    #[test]
    fn dense_clip_samples_every_frame_exactly_and_converts_back() {
        let walk = gait(&GaitParams::walk());
        let clip = Clip::from_motion(&walk).unwrap();
        assert_eq!((clip.num_frames(), clip.num_keys()), (walk.num_frames(), walk.num_frames()));
        assert_eq!(clip.duration(), walk.duration());
        let (mut ctx, mut pose) = (SamplingContext::default(), Pose::rest(clip.skeleton()));
        for f in 0..walk.num_frames() {
            clip.sample_into(f as f64 * walk.frame_time, &mut ctx, &mut pose).unwrap();
            assert_eq!(pose, walk.pose(f), "frame {f}");
        }
        let back = clip.to_motion().unwrap();
        for (a, b) in back.data().iter().zip(walk.data()) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        assert!(Clip::from_motion(&Motion::new(walk.skeleton.clone(), 0.1, vec![]).unwrap()).is_err());
    }

    #[test]
    fn sampling_between_frames_slerps_and_lerps_like_interpolate_pose() {
        let clip = Clip::from_motion(&gait(&GaitParams::walk())).unwrap();
        let t = 7.3 * clip.frame_time();
        let got = clip.sample(t).unwrap();
        let want = crate::motion::interpolate_pose(&clip.key_pose(7), &clip.key_pose(8), 0.3);
        for j in 0..clip.skeleton().len() {
            assert!(angle_between(got.rotations[j], want.rotations[j]) < 1e-12);
            assert!((got.translations[j] - want.translations[j]).length() < 1e-12);
        }
    }

    #[test]
    fn the_context_gives_the_same_poses_as_a_search_in_any_order() {
        let dense = Clip::from_motion(&gait(&GaitParams::walk())).unwrap();
        let keys = KeyframeSet::new(vec![5, 9, 30, 31, 60], dense.num_frames()).unwrap();
        let sparse = dense.with_keys(&keys).unwrap();
        assert_eq!(sparse.key_frames(), keys.frames());
        assert_eq!(sparse.num_frames(), dense.num_frames());
        for clip in [&dense, &sparse] {
            let mut ctx = SamplingContext::default();
            let mut pose = Pose::rest(clip.skeleton());
            // Forward at a display rate, then jumps back and forth.
            let mut times: Vec<f64> = (0..200).map(|i| i as f64 * clip.duration() / 199.0).collect();
            times.extend([0.9, 0.1, 0.5, 0.5, 0.0, 1.0].map(|u| u * clip.duration()));
            for t in times {
                clip.sample_into(t, &mut ctx, &mut pose).unwrap();
                assert_eq!(pose, clip.sample_unchecked(t), "t = {t}");
            }
        }
        // Between two keys the sparse clip interpolates; at keys it is the dense clip.
        assert_eq!(sparse.sample(30.0 * sparse.frame_time()), dense.sample(30.0 * dense.frame_time()));
        assert_ne!(sparse.sample(20.0 * sparse.frame_time()), dense.sample(20.0 * dense.frame_time()));
        let bad = KeyframeSet::new(vec![3], 10).unwrap();
        assert!(dense.with_keys(&bad).is_err(), "wrong length");
        let not_keys = KeyframeSet::new(vec![6], sparse.num_frames()).unwrap();
        assert!(sparse.with_keys(&not_keys).is_err(), "frame 6 is not a key of the sparse clip");
    }

    #[test]
    fn sampling_outside_the_clip_is_an_error_or_explicitly_clamped() {
        let clip = Clip::from_motion(&gait(&GaitParams::walk())).unwrap();
        let (mut ctx, mut pose) = (SamplingContext::default(), Pose::rest(clip.skeleton()));
        let e = clip.sample_into(-0.1, &mut ctx, &mut pose).unwrap_err();
        assert!(e.to_string().contains("outside the clip"), "{e}");
        assert!(clip.sample_into(f64::NAN, &mut ctx, &mut pose).is_err());
        assert_eq!(clip.sample(clip.duration() + 0.5), None);
        assert_eq!(clip.sample_clamped(clip.duration() + 0.5), clip.key_pose(clip.num_keys() - 1));
        // An empty pose is sized on first use.
        let mut empty = Pose { rotations: vec![], translations: vec![] };
        clip.sample_into(0.0, &mut ctx, &mut empty).unwrap();
        assert_eq!(empty, clip.key_pose(0));
    }

    #[test]
    fn bad_poses_and_unrepresentable_clips_are_named() {
        let sk = mixed_skeleton();
        let rest = Pose::rest(&sk);
        assert!(Clip::from_poses(sk.clone(), 0.0, std::slice::from_ref(&rest)).is_err());
        assert!(Clip::from_poses(sk.clone(), 0.1, &[]).is_err());
        let short = Pose { rotations: vec![DQuat::IDENTITY], translations: vec![DVec3::ZERO] };
        let e = Clip::from_poses(sk.clone(), 0.1, &[rest.clone(), short]).unwrap_err();
        assert!(e.to_string().contains("frame 1"), "{e}");
        let mut nan = rest.clone();
        nan.translations[3].x = f64::NAN;
        let e = Clip::from_poses(sk.clone(), 0.1, &[nan]).unwrap_err();
        assert!(e.to_string().contains("joint 'j3'"), "{e}");
        assert!(Clip::from_keys(sk.clone(), 0.1, vec![0, 0], &[rest.clone(), rest.clone()]).is_err());
        assert!(Clip::from_keys(sk.clone(), 0.1, vec![1], std::slice::from_ref(&rest)).is_err());
        // The last joint has no channels: turning it cannot be written as BVH.
        let mut turned = rest.clone();
        turned.rotations[6] = DQuat::from_rotation_x(0.2);
        let e = Clip::from_poses(sk.clone(), 0.1, &[rest.clone(), turned]).unwrap().to_motion().unwrap_err();
        assert!(e.to_string().contains("frame 1, joint 'fixed'"), "{e}");
        // Joint 2 has only a Y position channel: moving it along X cannot be written.
        let mut moved = rest.clone();
        moved.translations[2].x += 1.0;
        let e = Clip::from_poses(sk.clone(), 0.1, &[moved]).unwrap().to_motion().unwrap_err();
        assert!(e.to_string().contains("along x"), "{e}");
        let mut lifted = rest;
        lifted.translations[2].y += 1.0;
        assert!(Clip::from_poses(sk, 0.1, &[lifted]).unwrap().to_motion().is_ok());
    }

    #[test]
    fn clips_are_curves_the_adapters_apply_to() {
        let clip = Clip::from_motion(&gait(&GaitParams::walk())).unwrap();
        let turned = (&clip).placed(std::f64::consts::FRAC_PI_2, DVec3::new(10.0, 0.0, 0.0));
        let (a, b) = (clip.sample(0.5).unwrap(), turned.sample(0.5).unwrap());
        let expected_root = DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2) * a.translations[0];
        assert!((b.translations[0] - (expected_root + DVec3::new(10.0, 0.0, 0.0))).length() < 1e-12);
        assert_eq!(a.rotations[1..], b.rotations[1..]);
        let looped = (&clip).looped().unwrap();
        let mut p = Pose::rest(clip.skeleton());
        looped.sample_unchecked_into(clip.duration() + 0.25, &mut p);
        let q = clip.sample(0.25).unwrap();
        for j in 0..p.rotations.len() {
            assert!(angle_between(p.rotations[j], q.rotations[j]) < 1e-9);
        }
        let half = (&clip).cross_fade_to(&turned, Interval::new(0.2, 0.4).unwrap()).unwrap();
        assert_eq!(half.sample(0.1), clip.sample(0.1));
        assert_eq!(half.sample(0.5), turned.sample(0.5));
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(crate::seed::PROPTEST_SEED),
            ..ProptestConfig::with_cases(64)
        })]

        /// Motion → Clip → Motion gives the channel values back (angles in the principal ranges).
        #[test]
        fn motion_to_clip_to_motion_round_trips(
            frames in 1usize..5,
            pos in proptest::collection::vec(-100.0f64..100.0, 8),
            ang in proptest::collection::vec(-1.0f64..1.0, 23),
        ) {
            let sk = mixed_skeleton();
            let mut data = Vec::new();
            for f in 0..frames {
                let shifted: Vec<f64> = ang.iter().map(|a| (a + 0.37 * f as f64 + 1.0).rem_euclid(2.0) - 1.0).collect();
                data.extend(frame_values(&sk, &pos, &shifted));
            }
            let m = Motion::new(sk, 1.0 / 30.0, data).unwrap();
            let back = Clip::from_motion(&m).unwrap().to_motion().unwrap();
            prop_assert_eq!(back.num_frames(), m.num_frames());
            prop_assert_eq!(back.frame_time, m.frame_time);
            for f in 0..m.num_frames() {
                for (c, (a, b)) in back.frame(f).iter().zip(m.frame(f)).enumerate() {
                    let is_rotation = m.skeleton.joints().iter().flat_map(|j| j.channels.iter()).nth(c).unwrap().is_rotation();
                    if is_rotation {
                        prop_assert!((a - b).abs() < 1e-7, "frame {} channel {}: {} vs {}", f, c, a, b);
                    } else {
                        prop_assert_eq!(a, b, "translations are exact");
                    }
                }
            }
        }

        /// Clip → Motion → Clip gives the rotations back to round-off and the translations exactly.
        #[test]
        fn clip_to_motion_to_clip_round_trips(
            pos in proptest::collection::vec(-100.0f64..100.0, 8),
            axes in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, 0.0f64..3.1), 12),
        ) {
            let sk = mixed_skeleton();
            let n = sk.len();
            let poses: Vec<Pose> = (0..2).map(|f| {
                let mut p = Pose::rest(&sk);
                for j in 0..n - 1 {
                    let (x, y, z, angle) = axes[f * 6 + j];
                    let axis = DVec3::new(x, y, z);
                    if axis.length() > 1e-3 {
                        p.rotations[j] = DQuat::from_axis_angle(axis.normalize(), angle);
                    }
                }
                p.translations[0] = DVec3::new(pos[0], pos[1], pos[2 + f]);
                p.translations[2].y = pos[5 + f];
                p
            }).collect();
            let clip = Clip::from_poses(sk, 0.04, &poses).unwrap();
            let back = Clip::from_motion(&clip.to_motion().unwrap()).unwrap();
            prop_assert_eq!(back.key_frames(), clip.key_frames());
            for k in 0..clip.num_keys() {
                for j in 0..n {
                    prop_assert!(angle_between(back.key_rotations(k)[j], clip.key_rotations(k)[j]) < 1e-9);
                    prop_assert_eq!(back.key_translations(k)[j], clip.key_translations(k)[j]);
                }
            }
        }
    }
}
