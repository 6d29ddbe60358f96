//! Version 2 of the `.ibk` codec (version 1 still read): a clip's keyframes, from which the whole
//! clip is rebuilt by the rotation reconstruction ([`crate::rotations`]).
//!
//! Layout (little-endian), version 2:
//! ```text
//! magic "IBK\0" | version u16 | reserved u16
//! frame_time f64 | num_frames u32 | num_keys u32 | num_joints u16
//! skeleton: per joint  name_len u16, name bytes, parent i16 (-1 root), offset 3×f64,
//!                      channel count u8, channel codes u8…, end site flag u8 (+ 3×f64)
//! key frames: num_keys × varint of the gap to the previous key (first key is frame 0)
//! key values: per key  angular velocity scale f32, then
//!             per joint with rotation channels
//!                  rotation vector 3×i16 (scale π/32767) and angular velocity 3×i16 (scale/32767),
//!             per joint with position channels
//!                  translation 3×f32 and velocity 3×f32
//! crc32 of every byte before it, u32
//! ```
//! So a key costs 4 bytes plus 12 per rotating joint plus 24 per translating joint: 400 bytes on
//! the 31-joint CMU skeleton (4 + 31 × 12 + 24) against 384 bytes for one raw frame of 96 f32
//! channels. Version 1 (still read) had one angular velocity scale for the whole file, after
//! `num_keys`, and none per key.
//!
//! Each key's scale depends on that key alone, so the value a decoder will see for any frame is
//! known before keys are chosen ([`quantised_model`]): [`compress`] chooses keys against exactly
//! what the decoder rebuilds, and its error bound holds for the decoded file.

use super::{
    check_envelope, read_skeleton_joints, write_skeleton, write_varint, Reader, MAGIC, MAX_FRAME_JOINTS, OLDEST_VERSION,
};
use crate::rotations::{reconstruct_from_keys, KeyPose, RotationMotion};
use crate::{MocapError, Result};
use glam::{DQuat, DVec3};
use inbetween_core::rotation::{quat_to_rotvec, rotvec_to_quat};
use inbetween_core::{KeyframeSet, Motion, Skeleton};
use std::f64::consts::PI;

/// The keyframe version [`encode`] writes ([`v3`] writes version 3, the sampled format).
pub const VERSION: u16 = 2;

/// A decoded `.ibk` file.
#[derive(Clone, Debug)]
pub struct Decoded {
    pub skeleton: Skeleton,
    pub frame_time: f64,
    pub num_frames: usize,
    pub key_frames: Vec<usize>,
    pub keys: Vec<KeyPose>,
}

impl Decoded {
    /// The whole clip rebuilt from the keys.
    pub fn reconstruct(&self) -> Result<Motion> {
        reconstruct_from_keys(&self.skeleton, self.frame_time, &self.key_frames, &self.keys)
    }
}

/// Bytes one key takes on a skeleton (its angular velocity scale included).
pub fn bytes_per_key(skeleton: &Skeleton) -> usize {
    4 + skeleton
        .joints()
        .iter()
        .map(|j| if j.rotation_order().is_some() { 12 } else { 0 } + if j.has_translation() { 24 } else { 0 })
        .sum::<usize>()
}

fn quantize(v: f64, scale: f64) -> i16 {
    (v / scale * 32767.0).round().clamp(-32767.0, 32767.0) as i16
}

fn dequantize(q: i16, scale: f64) -> f64 {
    q as f64 * scale / 32767.0
}

/// Encodes the keys `keys` of `model` (a [`RotationMotion`] of the clip to store).
pub fn encode(model: &RotationMotion, keys: &KeyframeSet) -> Vec<u8> {
    let sk = &model.skeleton;
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    out.extend_from_slice(&model.frame_time.to_le_bytes());
    out.extend_from_slice(&(model.num_frames() as u32).to_le_bytes());
    out.extend_from_slice(&(keys.len() as u32).to_le_bytes());
    write_skeleton(&mut out, sk);
    let mut prev = 0;
    for &f in keys.frames() {
        write_varint(&mut out, (f - prev) as u64);
        prev = f;
    }
    for &f in keys.frames() {
        write_scaled_key(&mut out, sk, &model.frames[f]);
    }
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// The angular velocity scale of one key: its largest component (rad/s), a little over so that
/// it quantises to ±32767 at most, as the f32 that is stored.
pub fn key_scale(p: &KeyPose) -> f32 {
    let max_w = p.angular_velocities.iter().map(|w| w.abs().max_element()).fold(1e-6, f64::max);
    max_w as f32 * 1.0001
}

/// Appends one key: its angular velocity scale ([`key_scale`]) and its values ([`write_key`]).
pub fn write_scaled_key(out: &mut Vec<u8>, sk: &Skeleton, p: &KeyPose) {
    let scale = key_scale(p);
    out.extend_from_slice(&scale.to_le_bytes());
    write_key(out, sk, p, scale as f64);
}

/// Appends one key's values (quantised rotations and angular velocities, f32 translations).
pub fn write_key(out: &mut Vec<u8>, sk: &Skeleton, p: &KeyPose, w_scale: f64) {
    for (j, joint) in sk.joints().iter().enumerate() {
        if joint.rotation_order().is_some() {
            for v in quat_to_rotvec(p.rotations[j]).to_array() {
                out.extend_from_slice(&quantize(v, PI).to_le_bytes());
            }
            for v in p.angular_velocities[j].to_array() {
                out.extend_from_slice(&quantize(v, w_scale).to_le_bytes());
            }
        }
        if joint.has_translation() {
            for v in p.translations[j].to_array().into_iter().chain(p.velocities[j].to_array()) {
                out.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
    }
}

/// The key pose a decoder reads back for `p` (written by [`write_scaled_key`]).
pub fn round_trip_key(sk: &Skeleton, p: &KeyPose) -> KeyPose {
    let mut bytes = Vec::with_capacity(bytes_per_key(sk));
    write_scaled_key(&mut bytes, sk, p);
    read_scaled_key(&mut Reader::new(&bytes), sk).expect("a key written for this skeleton reads back")
}

/// `model` with every frame replaced by what a decoder reads back for it as a key (quantised
/// rotations and angular velocities, f32 translations); positions stay the source's. Errors of
/// this model's in-betweens are the errors of the decoded file.
pub fn quantised_model(model: &RotationMotion) -> RotationMotion {
    let frames = model.frames.iter().map(|p| round_trip_key(&model.skeleton, p)).collect();
    RotationMotion { frames, ..model.clone() }
}

/// Reads one key's values written by [`write_key`] with scale `w_scale`.
pub fn read_key(r: &mut Reader, skeleton: &Skeleton, w_scale: f64) -> Result<KeyPose> {
    let nj = skeleton.len();
    let mut p = KeyPose {
        rotations: vec![DQuat::IDENTITY; nj],
        angular_velocities: vec![DVec3::ZERO; nj],
        translations: skeleton.joints().iter().map(|j| j.offset).collect(),
        velocities: vec![DVec3::ZERO; nj],
    };
    for (j, joint) in skeleton.joints().iter().enumerate() {
        if joint.rotation_order().is_some() {
            let mut v = [0.0; 6];
            for (i, x) in v.iter_mut().enumerate() {
                let q = r.i16("key rotation")?;
                *x = if i < 3 { dequantize(q, PI) } else { dequantize(q, w_scale) };
            }
            p.rotations[j] = rotvec_to_quat(DVec3::new(v[0], v[1], v[2]));
            p.angular_velocities[j] = DVec3::new(v[3], v[4], v[5]);
        }
        if joint.has_translation() {
            let mut v = [0.0; 6];
            for x in &mut v {
                *x = r.f32("key translation")?;
            }
            p.translations[j] = DVec3::new(v[0], v[1], v[2]);
            p.velocities[j] = DVec3::new(v[3], v[4], v[5]);
        }
    }
    Ok(p)
}

/// Reads one key written by [`write_scaled_key`], refusing a scale that is not a finite,
/// non-negative number.
pub fn read_scaled_key(r: &mut Reader, skeleton: &Skeleton) -> Result<KeyPose> {
    let at = r.pos;
    let scale = r.f32("angular velocity scale")?;
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(MocapError::Codec(format!(
            "angular velocity scale {scale} at byte {at} is not a finite, non-negative number"
        )));
    }
    read_key(r, skeleton, scale)
}

/// Decodes a keyframe `.ibk` file (version 1 or 2), checking magic, version, checksum and every
/// length. Version 3 files hold samples: [`read`] reads every version.
pub fn decode(bytes: &[u8]) -> Result<Decoded> {
    let body = check_envelope(bytes, OLDEST_VERSION, VERSION)?.1;
    let mut r = Reader { bytes: body, pos: 6 };
    let version = u16::from_le_bytes([bytes[4], bytes[5]]);
    r.u16("reserved")?;
    let frame_time = r.f64("frame time")?;
    let num_frames = r.u32("frame count")? as usize;
    let num_keys = r.u32("key count")? as usize;
    let file_scale = if version == 1 { Some(r.f32("angular velocity scale")?) } else { None };
    let nj = r.u16("joint count")? as usize;
    if !(frame_time.is_finite() && frame_time > 0.0) || num_keys < 2 || num_keys > num_frames || nj == 0 {
        return Err(MocapError::Codec(format!(
            "invalid header: frame time {frame_time}, {num_frames} frames, {num_keys} keys, {nj} joints"
        )));
    }
    if num_frames as u64 * nj as u64 > MAX_FRAME_JOINTS {
        return Err(MocapError::Codec(format!(
            "invalid header: {num_frames} frames of {nj} joints exceed the {MAX_FRAME_JOINTS} joint poses a file may hold"
        )));
    }
    if file_scale.is_some_and(|s| !(s.is_finite() && s >= 0.0)) {
        return Err(MocapError::Codec(format!("invalid header: angular velocity scale {}", file_scale.unwrap_or(0.0))));
    }
    let skeleton = read_skeleton_joints(&mut r, nj)?;
    // Every key takes at least one byte of gap and one of values: a count beyond the bytes left
    // is corrupt (and must not size an allocation).
    if num_keys > r.remaining() {
        return Err(MocapError::Codec(format!(
            "truncated file: {num_keys} keys announced but only {} bytes remain at byte {}",
            r.remaining(),
            r.pos
        )));
    }
    let key_frames = read_key_frames(&mut r, num_keys, num_frames)?;
    let mut keys = Vec::with_capacity(num_keys);
    for _ in 0..num_keys {
        let p = match file_scale {
            Some(s) => read_key(&mut r, &skeleton, s)?,
            None => read_scaled_key(&mut r, &skeleton)?,
        };
        keys.push(p);
    }
    if r.pos != body.len() {
        return Err(MocapError::Codec(format!(
            "{} unexpected bytes after the key values at byte {}",
            body.len() - r.pos,
            r.pos
        )));
    }
    Ok(Decoded { skeleton, frame_time, num_frames, key_frames, keys })
}

/// The varint gaps of the key frames: strictly increasing from frame 0 to the clip's last frame.
fn read_key_frames(r: &mut Reader, num_keys: usize, num_frames: usize) -> Result<Vec<usize>> {
    let mut key_frames = Vec::with_capacity(num_keys);
    let mut f = 0u64;
    for k in 0..num_keys {
        let gap = r.varint("key frame gap")?;
        f = f.saturating_add(gap);
        if (k > 0 && gap == 0) || (k == 0 && gap != 0) || f >= num_frames as u64 {
            return Err(MocapError::Codec(format!("key {k}: frame {f} is out of order or outside 0..{num_frames}")));
        }
        key_frames.push(f as usize);
    }
    if key_frames[num_keys - 1] != num_frames - 1 {
        return Err(MocapError::Codec(format!(
            "the last key is frame {}, expected the clip's last frame {}",
            key_frames[num_keys - 1],
            num_frames - 1
        )));
    }
    Ok(key_frames)
}
