//! The `.ibk` keyframe codec: compact, versioned, checksummed binaries of a clip from which the whole
//! clip is rebuilt. What every version shares lives here: the envelope (magic, version, CRC-32), the
//! skeleton sections, the bounds-checked [`Reader`] and [`read`], which reads any version into an
//! [`IbkFile`]. Versions 3 and 4 are read through the runtime crate `inbetween_ibk`, the one
//! decoder of their head (header fields, deflated skeleton, tracks: `read_head`) and of version
//! 4's segments (`Clip`). The versions: [`v2`] (keyframes rebuilt by the rotation reconstruction,
//! [`crate::rotations`]; version 1 still read), [`v3`] (every frame, entropy coded) and [`v4`]
//! (every frame at fixed widths, the runtime layout of `inbetween_ibk`), written by [`v3_encode`].

mod bits;
pub mod job;
pub mod v2;
pub mod v3;
pub mod v3_encode;
pub mod v4;

pub use job::{CompressJob, CompressReport, DecompressJob, DecompressReport, Version};
pub use v2::{
    bytes_per_key, decode, encode, key_scale, quantised_model, read_key, read_scaled_key, round_trip_key, write_key,
    write_scaled_key, Decoded, VERSION,
};

use crate::rotations::RotationMotion;
use crate::{MocapError, Result};
use glam::DVec3;
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::{Channel, Joint, KeyframeSet, Motion, Skeleton};

pub const MAGIC: &[u8; 4] = b"IBK\0";
/// The oldest version [`decode`] reads.
pub const OLDEST_VERSION: u16 = 1;
/// Largest clip a file may describe (frames × joints), so a corrupt or hostile header cannot make
/// the decoder's caller allocate without bound: 2²⁶ joint poses (~4.5 GB of f64 channels at most);
/// the runtime's limit, one for every version.
pub use inbetween_ibk::MAX_FRAME_JOINTS;

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

/// Appends the skeleton section (joint count, then each joint).
pub fn write_skeleton(out: &mut Vec<u8>, sk: &Skeleton) {
    write_skeleton_with(out, sk, |out, v| {
        for x in v.to_array() {
            out.extend_from_slice(&x.to_le_bytes());
        }
    });
}

/// [`write_skeleton`] with lengths (offsets, end sites) written by `vec3`.
fn write_skeleton_with(out: &mut Vec<u8>, sk: &Skeleton, vec3: impl Fn(&mut Vec<u8>, DVec3)) {
    out.extend_from_slice(&(sk.len() as u16).to_le_bytes());
    for j in sk.joints() {
        out.extend_from_slice(&(j.name.len() as u16).to_le_bytes());
        out.extend_from_slice(j.name.as_bytes());
        out.extend_from_slice(&(j.parent.map(|p| p as i16).unwrap_or(-1)).to_le_bytes());
        vec3(out, j.offset);
        out.push(j.channels.len() as u8);
        out.extend(j.channels.iter().map(|c| channel_code(*c)));
        match j.end_site {
            Some(e) => {
                out.push(1);
                vec3(out, e);
            }
            None => out.push(0),
        }
    }
}

// Micro-units per length unit of a compact skeleton's decimal lengths: the runtime's, which reads them.
use inbetween_ibk::DECIMAL_SCALE;

/// `x` as a whole number of micro-units when that reads back as exactly `x` (BVH and ASF
/// lengths are written with a few decimals).
fn as_decimal(x: f64) -> Option<i64> {
    let m = (x * DECIMAL_SCALE).round();
    (m.abs() < 1e15 && m / DECIMAL_SCALE == x).then_some(m as i64)
}

/// Appends a compact skeleton (version 3): a flag (1: every length is a zig-zag varint of
/// micro-units, exact; 0: f64), then the joints as [`write_skeleton`] with those lengths; the
/// whole deflated (`raw length u32 | deflated length u32 | bytes`). Joint names and the
/// mirrored offsets of a body compress well: on a 31-joint CMU skeleton 1443 bytes become a few
/// hundred, a few per cent of a short clip's file.
pub fn write_compact_skeleton(out: &mut Vec<u8>, sk: &Skeleton) {
    let lengths = sk
        .joints()
        .iter()
        .flat_map(|j| j.offset.to_array().into_iter().chain(j.end_site.map(|e| e.to_array()).into_iter().flatten()));
    let decimal = lengths.clone().all(|x| as_decimal(x).is_some());
    let mut raw = vec![decimal as u8];
    write_skeleton_with(&mut raw, sk, |out, v| {
        for x in v.to_array() {
            match as_decimal(x) {
                Some(m) if decimal => write_varint(out, ((m << 1) ^ (m >> 63)) as u64),
                _ => out.extend_from_slice(&x.to_le_bytes()),
            }
        }
    });
    let mut e = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::best());
    std::io::Write::write_all(&mut e, &raw).expect("deflate into memory");
    let packed = e.finish().expect("deflate into memory");
    out.extend_from_slice(&(raw.len() as u32).to_le_bytes());
    out.extend_from_slice(&(packed.len() as u32).to_le_bytes());
    out.extend_from_slice(&packed);
}

/// Reads a skeleton written by [`write_compact_skeleton`], through the runtime's reader (the one
/// decoder of the block for versions 3 and 4).
pub fn read_compact_skeleton(r: &mut Reader) -> Result<Skeleton> {
    let (joints, end) = inbetween_ibk::read_skeleton(r.bytes, r.pos).map_err(runtime_error)?;
    r.pos = end;
    skeleton_of(&joints)
}

/// An error of the runtime reader as the codec's.
pub(crate) fn runtime_error(e: inbetween_ibk::IbkError) -> MocapError {
    MocapError::Codec(e.to_string())
}

/// The engine's skeleton of the joints the runtime read (channel codes as [`write_skeleton`]
/// writes them).
pub(crate) fn skeleton_of(joints: &[inbetween_ibk::Joint]) -> Result<Skeleton> {
    let joints = joints
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let channels = j
                .channels
                .iter()
                .map(|&c| {
                    channel_from_code(c)
                        .ok_or_else(|| MocapError::Codec(format!("joint {i} '{}': unknown channel code {c}", j.name)))
                })
                .collect::<Result<Vec<_>>>()?;
            Ok(Joint {
                name: j.name.clone(),
                parent: j.parent,
                offset: DVec3::from_array(j.offset),
                channels,
                end_site: j.end_site.map(DVec3::from_array),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Skeleton::new(joints).map_err(|e| MocapError::Codec(format!("skeleton: {e}")))
}

pub(crate) fn write_varint(out: &mut Vec<u8>, mut v: u64) {
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
    /// Bytes read so far.
    pub fn pos(&self) -> usize {
        self.pos
    }
    pub fn skip(&mut self, n: usize, what: &str) -> Result<()> {
        self.take(n, what).map(|_| ())
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

/// Checks what every `.ibk` file shares: the magic bytes, a version in `oldest..=newest` and the
/// checksum. Returns the version and the body (the file less its checksum).
pub(crate) fn check_envelope(bytes: &[u8], oldest: u16, newest: u16) -> Result<(u16, &[u8])> {
    if bytes.len() < 4 || &bytes[..4] != MAGIC {
        return Err(MocapError::Codec("not an .ibk file: expected the magic bytes \"IBK\\0\" at byte 0".into()));
    }
    if bytes.len() < 12 {
        return Err(MocapError::Codec(format!("truncated file: {} bytes is shorter than the header", bytes.len())));
    }
    let body = &bytes[..bytes.len() - 4];
    let stored = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().expect("4 bytes"));
    let version = u16::from_le_bytes([bytes[4], bytes[5]]);
    if !(oldest..=newest).contains(&version) {
        let hint = if version == v3::VERSION {
            " (a version 3 file holds samples, not keys: read it with codec::read)"
        } else {
            ""
        };
        return Err(MocapError::Codec(format!(
            "unsupported .ibk version {version}; this reader reads versions {oldest} to {newest}{hint}"
        )));
    }
    if crc32fast::hash(body) != stored {
        return Err(MocapError::Codec(format!(
            "checksum mismatch (stored {stored:08x}, computed {:08x}): the file is corrupt or truncated",
            crc32fast::hash(body)
        )));
    }
    Ok((version, body))
}

/// Any `.ibk` file: keys (versions 1 and 2) or samples (versions 3 and 4).
#[derive(Clone, Debug)]
pub enum IbkFile {
    Keys(Decoded),
    Samples(v3::Quantised),
    Runtime(v4::Decoded),
}

impl IbkFile {
    /// The whole clip.
    pub fn motion(&self) -> Result<Motion> {
        match self {
            IbkFile::Keys(d) => d.reconstruct(),
            IbkFile::Samples(q) => q.motion(),
            IbkFile::Runtime(d) => d.motion(),
        }
    }

    pub fn skeleton(&self) -> &Skeleton {
        match self {
            IbkFile::Keys(d) => &d.skeleton,
            IbkFile::Samples(q) => &q.header.skeleton,
            IbkFile::Runtime(d) => &d.header.skeleton,
        }
    }

    pub fn num_frames(&self) -> usize {
        match self {
            IbkFile::Keys(d) => d.num_frames,
            IbkFile::Samples(q) => q.header.num_frames,
            IbkFile::Runtime(d) => d.header.num_frames,
        }
    }

    /// The poses the file stores: its keys (versions 1 and 2) or every frame (versions 3 and 4).
    pub fn stored_poses(&self) -> usize {
        match self {
            IbkFile::Keys(d) => d.key_frames.len(),
            IbkFile::Samples(q) => q.header.num_frames,
            IbkFile::Runtime(r) => r.poses.len(),
        }
    }

    /// What the file holds, in words (for the command line).
    pub fn describe(&self) -> String {
        match self {
            IbkFile::Keys(d) => format!("version 2 or older: {} keys of {} frames", d.key_frames.len(), d.num_frames),
            IbkFile::Samples(q) => format!(
                "version 3: {} frames in segments of {}, compressed to {} cm (virtual vertices 3 cm from each bone)",
                q.header.num_frames, q.header.segment_len, q.header.bound_cm
            ),
            IbkFile::Runtime(d) => format!(
                "version 4: {} frames in segments of {} at fixed widths (runtime layout), compressed to {} cm (virtual vertices 3 cm from each bone)",
                d.header.num_frames, d.header.segment_len, d.header.bound_cm
            ),
        }
    }
}

/// Reads any `.ibk` file this build knows (versions 1 to 4).
pub fn read(bytes: &[u8]) -> Result<IbkFile> {
    let (version, _) = check_envelope(bytes, OLDEST_VERSION, v4::VERSION)?;
    if version == v4::VERSION {
        Ok(IbkFile::Runtime(v4::decode(bytes)?))
    } else if version == v3::VERSION {
        Ok(IbkFile::Samples(v3::decode(bytes)?))
    } else {
        Ok(IbkFile::Keys(decode(bytes)?))
    }
}

/// Raw bytes per bone per sample: quaternion, translation, scale as f32 (ACL's raw size).
pub const RAW_BYTES_PER_BONE: usize = 40;

/// Raw size of a clip as f32 channel values (the comparison baseline).
pub fn raw_bytes(motion: &Motion) -> usize {
    motion.num_frames() * motion.num_channels() * 4
}

#[cfg(test)]
mod tests;

/// How many keys a compression may use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// Exactly this many keys, placed to minimise the mean position error of the decoded file.
    Keys(usize),
    /// The fewest keys keeping every joint of every frame of the decoded file within this many cm.
    MaxErrorCm(f64),
}

/// The outcome of [`compress`].
#[derive(Clone, Debug)]
pub struct Compressed {
    pub keys: KeyframeSet,
    pub bytes: Vec<u8>,
    /// Error of the in-between frames as the selector saw them (the decoder's quantised keys).
    pub planned: crate::ReconstructionError,
    /// Mean and max position error in cm of the decoded file against the source, key frames
    /// (quantised) included.
    pub decoded_mean_cm: f64,
    pub decoded_max_cm: f64,
    /// Frame of the largest decoded error.
    pub worst_frame: usize,
    /// The length unit errors were measured in, and why.
    pub unit: UnitChoice,
    /// Bound (cm) the keys were finally chosen with: the requested bound, or a tighter one when
    /// rounding on the way through Euler angles pushed a frame over it. `None` for `Keys`.
    pub selection_bound_cm: Option<f64>,
}

/// [`compress_in`] with the length unit inferred from the clip's skeleton.
pub fn compress(motion: &Motion, budget: Budget, max_gap: usize) -> Result<Compressed> {
    compress_in(motion, LengthUnit::infer(&motion.skeleton), budget, max_gap)
}

/// Picks keys with the exact selectors over segments of at most `max_gap` frames, against the
/// clip as the decoder will rebuild it ([`quantised_model`]), encodes them and measures the decoded
/// file. In `Keys(k)` mode the gap is widened to at least twice the average spacing so that `k`
/// keys can cover the clip. In `MaxErrorCm` mode the decoded file is checked against the bound;
/// should a frame still exceed it (rounding), the keys are chosen again with a tighter bound, and a
/// bound below what the format stores (a key frame's own quantisation error) is an error.
pub fn compress_in(motion: &Motion, unit: UnitChoice, budget: Budget, max_gap: usize) -> Result<Compressed> {
    use crate::metrics::{ErrorMeasure, SegmentTable};
    let exact = RotationMotion::from_motion_in(motion, unit.cm_per_unit())?;
    let model = quantised_model(&exact);
    let n = model.num_frames();
    let bound = match budget {
        Budget::Keys(k) => {
            crate::select::check_k(n, k)?;
            let gap = max_gap.max((2 * (n - 1)).div_ceil(k - 1));
            let keys = crate::select::optimal(&SegmentTable::banded(&model, gap), k, ErrorMeasure::Position)?;
            return finish(&exact, &model, keys, unit, None);
        }
        Budget::MaxErrorCm(cm) => cm,
    };
    if !(bound.is_finite() && bound >= 0.0) {
        return Err(MocapError::Invalid(format!("max error {bound} cm must be a non-negative number")));
    }
    let mut select_at = bound;
    for _ in 0..6 {
        let table = SegmentTable::bounded(&model, max_gap, select_at);
        let keys = crate::select::error_bounded(&table, select_at, ErrorMeasure::Position)?;
        let c = finish(&exact, &model, keys, unit.clone(), Some(select_at))?;
        if c.decoded_max_cm <= bound {
            return Ok(c);
        }
        if c.keys.frames().contains(&c.worst_frame) {
            return Err(MocapError::Invalid(format!(
                "max error {bound} cm is below what the .ibk format stores: quantising key frame {} alone moves a joint by {:.4} cm",
                c.worst_frame, c.decoded_max_cm
            )));
        }
        select_at = (select_at - 2.0 * (c.decoded_max_cm - bound)).min(select_at * (1.0 - 1e-9));
    }
    Err(MocapError::Invalid(format!("could not keep the decoded file within {bound} cm")))
}

/// Encodes `keys` of `exact`, decodes the file and measures it against the source; `model` is
/// `exact` quantised, for the planned error.
fn finish(
    exact: &RotationMotion,
    model: &RotationMotion,
    keys: KeyframeSet,
    unit: UnitChoice,
    selection_bound_cm: Option<f64>,
) -> Result<Compressed> {
    use crate::metrics::SegmentModel;
    let bytes = encode(exact, &keys);
    let decoded = decode(&bytes)?.reconstruct()?;
    let nj = model.skeleton.len();
    let (mut sum, mut max, mut worst_frame) = (0.0, 0.0f64, 0);
    for (f, frame) in inbetween_core::positions_clip(&decoded).iter().enumerate() {
        for (j, p) in frame.iter().enumerate() {
            let d = p.distance(model.positions[f * nj + j]) * model.cm_per_unit;
            sum += d;
            if d > max {
                (max, worst_frame) = (d, f);
            }
        }
    }
    let planned = model.error(&keys);
    Ok(Compressed {
        keys,
        bytes,
        planned,
        decoded_mean_cm: sum / (model.num_frames() * nj) as f64,
        decoded_max_cm: max,
        worst_frame,
        unit,
        selection_bound_cm,
    })
}

/// Parses an error bound such as `1cm`, `0.5 cm`, `10mm` or `0.01m`; a bare number is refused
/// (its unit would be a guess), with a message showing it with each unit.
pub fn parse_length_cm(s: &str) -> Result<f64> {
    let t = s.trim().to_ascii_lowercase();
    let (num, scale) = if let Some(v) = t.strip_suffix("mm") {
        (v, 0.1)
    } else if let Some(v) = t.strip_suffix("cm") {
        (v, 1.0)
    } else if let Some(v) = t.strip_suffix('m') {
        (v, 100.0)
    } else if t.parse::<f64>().is_err() {
        (t.as_str(), 1.0)
    } else {
        return Err(MocapError::Invalid(format!(
            "'{s}' has no length unit; write it with one, e.g. {}cm, {}mm or {}m",
            s.trim(),
            s.trim(),
            s.trim()
        )));
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
mod compress_tests;
