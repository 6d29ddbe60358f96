//! The `.ibk` keyframe codec: a compact, versioned, checksummed binary of a clip's keyframes from
//! which the whole clip is rebuilt by the rotation reconstruction ([`crate::rotations`]).
//!
//! Layout (little-endian):
//! ```text
//! magic "IBK\0" | version u16 | reserved u16
//! frame_time f64 | num_frames u32 | num_keys u32 | angvel_scale f32 | num_joints u16
//! skeleton: per joint  name_len u16, name bytes, parent i16 (-1 root), offset 3×f64,
//!                      channel count u8, channel codes u8…, end site flag u8 (+ 3×f64)
//! key frames: num_keys × varint of the gap to the previous key (first key is frame 0)
//! key values: per key, per joint with rotation channels
//!                  rotation vector 3×i16 (scale π/32767) and angular velocity 3×i16 (scale angvel_scale/32767),
//!             per joint with position channels
//!                  translation 3×f32 and velocity 3×f32
//! crc32 of every byte before it, u32
//! ```
//! So a key costs 12 bytes per rotating joint plus 24 per translating joint: 396 bytes on the
//! 31-joint CMU skeleton (31 × 12 + 24) against 384 bytes for one raw frame of 96 f32 channels.

use crate::rotations::{reconstruct_from_keys, KeyPose, RotationMotion};
use crate::{MocapError, Result};
use glam::{DQuat, DVec3};
use inbetween_core::rotation::{quat_to_rotvec, rotvec_to_quat};
use inbetween_core::{Channel, Joint, KeyframeSet, Motion, Skeleton};
use std::f64::consts::PI;

pub const MAGIC: &[u8; 4] = b"IBK\0";
pub const VERSION: u16 = 1;

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

/// Bytes one key takes on a skeleton.
pub fn bytes_per_key(skeleton: &Skeleton) -> usize {
    skeleton
        .joints()
        .iter()
        .map(|j| if j.rotation_order().is_some() { 12 } else { 0 } + if j.has_translation() { 24 } else { 0 })
        .sum()
}

fn channel_code(c: Channel) -> u8 {
    match c {
        Channel::Xposition => 0,
        Channel::Yposition => 1,
        Channel::Zposition => 2,
        Channel::Xrotation => 3,
        Channel::Yrotation => 4,
        Channel::Zrotation => 5,
    }
}

fn channel_from_code(c: u8) -> Option<Channel> {
    Some(match c {
        0 => Channel::Xposition,
        1 => Channel::Yposition,
        2 => Channel::Zposition,
        3 => Channel::Xrotation,
        4 => Channel::Yrotation,
        5 => Channel::Zrotation,
        _ => return None,
    })
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
    let poses = model.key_poses(keys);
    let max_w =
        poses.iter().flat_map(|p| p.angular_velocities.iter()).map(|w| w.abs().max_element()).fold(1e-6, f64::max);
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    out.extend_from_slice(&model.frame_time.to_le_bytes());
    out.extend_from_slice(&(model.num_frames() as u32).to_le_bytes());
    out.extend_from_slice(&(keys.len() as u32).to_le_bytes());
    out.extend_from_slice(&(max_w as f32 * 1.0001).to_le_bytes());
    let w_scale = f32::from_le_bytes(out[out.len() - 4..].try_into().expect("4 bytes")) as f64;
    write_skeleton(&mut out, sk);
    let mut prev = 0;
    for &f in keys.frames() {
        write_varint(&mut out, (f - prev) as u64);
        prev = f;
    }
    for p in &poses {
        write_key(&mut out, sk, p, w_scale);
    }
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// Appends the skeleton section (joint count, then each joint).
pub fn write_skeleton(out: &mut Vec<u8>, sk: &Skeleton) {
    out.extend_from_slice(&(sk.len() as u16).to_le_bytes());
    for j in sk.joints() {
        out.extend_from_slice(&(j.name.len() as u16).to_le_bytes());
        out.extend_from_slice(j.name.as_bytes());
        out.extend_from_slice(&(j.parent.map(|p| p as i16).unwrap_or(-1)).to_le_bytes());
        for v in j.offset.to_array() {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.push(j.channels.len() as u8);
        out.extend(j.channels.iter().map(|c| channel_code(*c)));
        match j.end_site {
            Some(e) => {
                out.push(1);
                for v in e.to_array() {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
            None => out.push(0),
        }
    }
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

fn write_varint(out: &mut Vec<u8>, mut v: u64) {
    loop {
        let byte = (v & 0x7f) as u8;
        v >>= 7;
        if v == 0 {
            out.push(byte);
            return;
        }
        out.push(byte | 0x80);
    }
}

/// A bounds-checked reader whose errors say what was expected at which byte.
pub struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    pub fn new(bytes: &'a [u8]) -> Reader<'a> {
        Reader { bytes, pos: 0 }
    }
    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        if self.bytes.len() - self.pos < n {
            return Err(MocapError::Codec(format!(
                "truncated file: expected {what} ({n} bytes) at byte {}, but only {} bytes remain",
                self.pos,
                self.bytes.len() - self.pos
            )));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn arr<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        Ok(self.take(N, what)?.try_into().expect("length checked"))
    }
    pub fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.take(1, what)?[0])
    }
    pub fn u16(&mut self, what: &str) -> Result<u16> {
        Ok(u16::from_le_bytes(self.arr(what)?))
    }
    pub fn i16(&mut self, what: &str) -> Result<i16> {
        Ok(i16::from_le_bytes(self.arr(what)?))
    }
    pub fn u32(&mut self, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(self.arr(what)?))
    }
    pub fn f32(&mut self, what: &str) -> Result<f64> {
        Ok(f32::from_le_bytes(self.arr(what)?) as f64)
    }
    pub fn f64(&mut self, what: &str) -> Result<f64> {
        Ok(f64::from_le_bytes(self.arr(what)?))
    }
    fn vec3_f64(&mut self, what: &str) -> Result<DVec3> {
        Ok(DVec3::new(self.f64(what)?, self.f64(what)?, self.f64(what)?))
    }
    pub fn varint(&mut self, what: &str) -> Result<u64> {
        let mut v = 0u64;
        for shift in (0..64).step_by(7) {
            let b = self.u8(what)?;
            v |= ((b & 0x7f) as u64) << shift;
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err(MocapError::Codec(format!("{what} at byte {}: varint longer than 64 bits", self.pos)))
    }
}

/// Reads `nj` joints written by [`write_skeleton`] (after its joint count).
pub fn read_skeleton_joints(r: &mut Reader, nj: usize) -> Result<Skeleton> {
    let mut joints = Vec::with_capacity(nj);
    for i in 0..nj {
        let len = r.u16("joint name length")? as usize;
        let name = String::from_utf8(r.take(len, "joint name")?.to_vec())
            .map_err(|_| MocapError::Codec(format!("joint {i}: name is not UTF-8")))?;
        let parent = r.i16("joint parent")?;
        let offset = r.vec3_f64("joint offset")?;
        let nch = r.u8("channel count")? as usize;
        let channels = (0..nch)
            .map(|_| {
                let c = r.u8("channel code")?;
                channel_from_code(c)
                    .ok_or_else(|| MocapError::Codec(format!("joint {i} '{name}': unknown channel code {c}")))
            })
            .collect::<Result<Vec<_>>>()?;
        let end_site = if r.u8("end site flag")? == 1 { Some(r.vec3_f64("end site")?) } else { None };
        let parent = if parent < 0 { None } else { Some(parent as usize) };
        joints.push(Joint { name, parent, offset, channels, end_site });
    }
    Skeleton::new(joints).map_err(|e| MocapError::Codec(format!("skeleton: {e}")))
}

/// Reads a skeleton written by [`write_skeleton`].
pub fn read_skeleton(r: &mut Reader) -> Result<Skeleton> {
    let nj = r.u16("joint count")? as usize;
    if nj == 0 {
        return Err(MocapError::Codec("skeleton with no joints".into()));
    }
    read_skeleton_joints(r, nj)
}

/// Reads one key written by [`write_key`].
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

/// Decodes an `.ibk` file, checking magic, version, checksum and every length.
pub fn decode(bytes: &[u8]) -> Result<Decoded> {
    if bytes.len() < 4 || &bytes[..4] != MAGIC {
        return Err(MocapError::Codec("not an .ibk file: expected the magic bytes \"IBK\\0\" at byte 0".into()));
    }
    if bytes.len() < 12 {
        return Err(MocapError::Codec(format!("truncated file: {} bytes is shorter than the header", bytes.len())));
    }
    let body = &bytes[..bytes.len() - 4];
    let stored = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().expect("4 bytes"));
    let mut r = Reader { bytes: body, pos: 4 };
    let version = r.u16("version")?;
    if version != VERSION {
        return Err(MocapError::Codec(format!(
            "unsupported .ibk version {version}; this build reads version {VERSION}"
        )));
    }
    if crc32fast::hash(body) != stored {
        return Err(MocapError::Codec(format!(
            "checksum mismatch (stored {stored:08x}, computed {:08x}): the file is corrupt or truncated",
            crc32fast::hash(body)
        )));
    }
    r.u16("reserved")?;
    let frame_time = r.f64("frame time")?;
    let num_frames = r.u32("frame count")? as usize;
    let num_keys = r.u32("key count")? as usize;
    let w_scale = r.f32("angular velocity scale")?;
    let nj = r.u16("joint count")? as usize;
    if !(frame_time.is_finite() && frame_time > 0.0) || num_keys < 2 || num_keys > num_frames || nj == 0 {
        return Err(MocapError::Codec(format!(
            "invalid header: frame time {frame_time}, {num_frames} frames, {num_keys} keys, {nj} joints"
        )));
    }
    let skeleton = read_skeleton_joints(&mut r, nj)?;
    let mut key_frames = Vec::with_capacity(num_keys);
    let mut f = 0u64;
    for k in 0..num_keys {
        let gap = r.varint("key frame gap")?;
        f += gap;
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
    let mut keys = Vec::with_capacity(num_keys);
    for _ in 0..num_keys {
        let p = read_key(&mut r, &skeleton, w_scale)?;
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

/// Raw size of a clip as f32 channel values (the comparison baseline).
pub fn raw_bytes(motion: &Motion) -> usize {
    motion.num_frames() * motion.num_channels() * 4
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::SegmentModel;
    use inbetween_core::positions_clip;
    use inbetween_core::procedural::{gait, GaitParams, CM_PER_CMU_UNIT};

    fn clip() -> (Motion, RotationMotion, KeyframeSet) {
        let mut p = GaitParams::run();
        p.frames = 50;
        let m = gait(&p);
        let rm = RotationMotion::from_motion(&m).unwrap();
        let keys = KeyframeSet::new(vec![7, 19, 33, 41], 50).unwrap();
        (m, rm, keys)
    }

    #[test]
    fn round_trip_matches_the_unquantised_reconstruction() {
        let (m, rm, keys) = clip();
        let bytes = encode(&rm, &keys);
        assert_eq!(
            bytes.len(),
            4 + 4
                + 8
                + 4
                + 4
                + 4
                + 2
                + skeleton_bytes(&m.skeleton)
                + keys.len()
                + keys.len() * bytes_per_key(&m.skeleton)
                + 4
        );
        let d = decode(&bytes).unwrap();
        assert_eq!(d.key_frames, keys.frames());
        assert_eq!(d.skeleton, m.skeleton);
        let rec = d.reconstruct().unwrap();
        assert_eq!(rec.num_frames(), 50);
        let exact = rm.reconstruct(&keys).unwrap();
        let e = inbetween_core::position_error(&positions_clip(&exact), &positions_clip(&rec));
        assert!(e.max * CM_PER_CMU_UNIT < 0.1, "quantisation costs {} cm", e.max * CM_PER_CMU_UNIT);
        assert!(rm.error(&keys).max_cm > 0.0);
    }

    fn skeleton_bytes(s: &Skeleton) -> usize {
        s.joints()
            .iter()
            .map(|j| 2 + j.name.len() + 2 + 24 + 1 + j.channels.len() + 1 + if j.end_site.is_some() { 24 } else { 0 })
            .sum()
    }

    #[test]
    fn corrupt_and_truncated_files_give_clear_errors() {
        let (_, rm, keys) = clip();
        let bytes = encode(&rm, &keys);
        let msg = |b: &[u8]| decode(b).unwrap_err().to_string();
        assert!(msg(b"hello world!").contains("magic"));
        assert!(msg(&bytes[..bytes.len() / 2]).contains("checksum"));
        let mut flipped = bytes.clone();
        flipped[100] ^= 0x40;
        assert!(msg(&flipped).contains("checksum"));
        let mut v2 = bytes.clone();
        v2[4] = 9;
        assert!(msg(&v2).contains("version 9"));
        // A truncated body with a valid checksum still fails on lengths, naming the byte.
        let mut cut = bytes[..bytes.len() - 40].to_vec();
        let crc = crc32fast::hash(&cut);
        cut.extend_from_slice(&crc.to_le_bytes());
        assert!(msg(&cut).contains("truncated"), "{}", msg(&cut));
        for n in 0..bytes.len() {
            assert!(decode(&bytes[..n]).is_err(), "prefix of {n} bytes decoded");
        }
    }
}

/// How many keys a compression may use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// Exactly this many keys, placed to minimise the mean position error.
    Keys(usize),
    /// The fewest keys keeping every joint of every frame within this many cm (before quantisation).
    MaxErrorCm(f64),
}

/// The outcome of [`compress`].
#[derive(Clone, Debug)]
pub struct Compressed {
    pub keys: KeyframeSet,
    pub bytes: Vec<u8>,
    /// Error of the exact (unquantised) reconstruction, as the selector saw it.
    pub planned: crate::ReconstructionError,
    /// Mean and max position error in cm of the decoded file against the source.
    pub decoded_mean_cm: f64,
    pub decoded_max_cm: f64,
}

/// Picks keys with the exact selectors over segments of at most `max_gap` frames, encodes them and
/// measures the decoded result. In `Keys(k)` mode the gap is widened to at least twice the average
/// spacing so that `k` keys can cover the clip.
pub fn compress(motion: &Motion, budget: Budget, max_gap: usize) -> Result<Compressed> {
    use crate::error::{Objective, SegmentModel, SegmentTable};
    let model = RotationMotion::from_motion(motion)?;
    let n = model.num_frames();
    let keys = match budget {
        Budget::Keys(k) => {
            crate::select::check_k(n, k)?;
            let gap = max_gap.max((2 * (n - 1)).div_ceil(k - 1));
            crate::select::optimal(&SegmentTable::banded(&model, gap), k, Objective::Position)?
        }
        Budget::MaxErrorCm(cm) => {
            if !(cm.is_finite() && cm >= 0.0) {
                return Err(MocapError::Invalid(format!("max error {cm} cm must be a non-negative number")));
            }
            crate::select::error_bounded(&SegmentTable::bounded(&model, max_gap, cm), cm, Objective::Position)?
        }
    };
    let planned = model.error(&keys);
    let bytes = encode(&model, &keys);
    let decoded = decode(&bytes)?.reconstruct()?;
    let e = inbetween_core::position_error(
        &inbetween_core::positions_clip(motion),
        &inbetween_core::positions_clip(&decoded),
    );
    Ok(Compressed {
        keys,
        bytes,
        planned,
        decoded_mean_cm: e.mean * model.cm_per_unit,
        decoded_max_cm: e.max * model.cm_per_unit,
    })
}

/// Parses an error bound such as `1cm`, `0.5 cm`, `10mm` or `0.01m` (a bare number is cm).
pub fn parse_length_cm(s: &str) -> Result<f64> {
    let t = s.trim().to_ascii_lowercase();
    let (num, scale) = if let Some(v) = t.strip_suffix("mm") {
        (v, 0.1)
    } else if let Some(v) = t.strip_suffix("cm") {
        (v, 1.0)
    } else if let Some(v) = t.strip_suffix('m') {
        (v, 100.0)
    } else {
        (t.as_str(), 1.0)
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| MocapError::Invalid(format!("'{s}' is not a length; expected e.g. 1cm, 5mm or 0.01m")))?;
    if !(v.is_finite() && v >= 0.0) {
        return Err(MocapError::Invalid(format!("'{s}': a length must be non-negative")));
    }
    Ok(v * scale)
}

#[cfg(test)]
mod compress_tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn max_error_mode_meets_its_bound_and_k_mode_uses_k_keys() {
        let mut p = GaitParams::walk();
        p.frames = 60;
        let m = gait(&p);
        let c = compress(&m, Budget::MaxErrorCm(1.0), 30).unwrap();
        assert!(c.planned.max_cm <= 1.0 + 1e-9);
        assert!(c.decoded_max_cm < 1.1, "decoded max {}", c.decoded_max_cm);
        assert!(c.keys.len() < 30, "{} keys", c.keys.len());
        let tight = compress(&m, Budget::MaxErrorCm(0.1), 30).unwrap();
        assert!(tight.keys.len() > c.keys.len());
        let k = compress(&m, Budget::Keys(6), 10).unwrap();
        assert_eq!(k.keys.len(), 6);
        assert_eq!(decode(&k.bytes).unwrap().key_frames, k.keys.frames());
        assert_eq!(parse_length_cm("10mm").unwrap(), 1.0);
        assert_eq!(parse_length_cm("0.5 cm").unwrap(), 0.5);
        assert!(parse_length_cm("fast").is_err());
    }
}
