//! `.ibk` version 3: every sample of every joint, each track quantised with its own step size and
//! entropy coded, for error-bounded compression of dense clips (the protocol of ACL, the Animation
//! Compression Library: virtual vertices 3 cm from each bone, measured in object space).
//!
//! Layout (little-endian), version 3:
//! ```text
//! magic "IBK\0" | version u16 = 3 | reserved u16
//! frame_time f64 | num_frames u32 | segment_len u16 | cm_per_unit f64 | bound_cm f64
//! skeleton: raw length u32 | deflated length u32 | deflated (length format u8: 1 = every
//!           offset a zig-zag varint of micro-units, 0 = f64; then the joints as in version 2)
//! tracks: one per joint with rotation channels (rotation vector), then one per joint with
//!         position channels (translation), in joint order: per track  kind u8:
//!         0 animated | 1 constant, followed by 3×f32
//! segment offsets: ceil(num_frames / segment_len) × u32, byte offsets into the data block
//! data_len u32 | data: one bit stream per segment (see below)
//! crc32 of every byte before it, u32
//! ```
//! A segment (`segment_len` frames) is coded on its own, so decoding one pose reads one segment:
//! ```text
//! per animated track   step code u8 (step = 2^((code − 192)/4): radians of rotation vector or
//!                      length units), then per component  mode 2 bits (0 constant in the segment,
//!                      1 first-order prediction, 2 second-order), Rice parameter 5 bits (modes
//!                      1–2), first value zig-zagged: bit length 6 bits + bits
//! then frames 1.. of the segment, frame-major: per animated track and varying component the
//!      Rice code of the zig-zagged residual  q_f − q_{f−1}  (mode 1) or  q_f − 2q_{f−1} + q_{f−2}
//!      (mode 2; its second frame uses the first-order residual)
//! ```
//! A value decodes to `q × step` exactly as the encoder computed it, so the encoder's error check
//! ([`super::v3_encode`]) is the error of the decoded file. Rotation vectors become quaternions by the
//! exponential map; joints without rotation channels keep the identity, joints without position
//! channels their skeleton offset.

use super::bits::{unzigzag, zigzag, BitReader, BitWriter};
use super::{runtime_error, skeleton_of, write_compact_skeleton, Reader, MAGIC};
use crate::{MocapError, Result};
use glam::{DQuat, DVec3};
use inbetween_core::rotation::rotvec_to_quat;
use inbetween_core::{Motion, Pose, Skeleton};

/// The version this module writes.
pub const VERSION: u16 = 3;
/// Frames per segment written by default: on the CMU takes at 0.05 cm, 32 gave 21.10:1 against
/// 20.27:1 with 16 (ACL's segments hold 16 samples); a pose still decodes from one segment.
pub const DEFAULT_SEGMENT_LEN: usize = 32;
/// Longest segment a file may declare (bounds the work of decoding one pose); the runtime's, as
/// versions 3 and 4 share their head.
pub use inbetween_ibk::MAX_SEGMENT_LEN;
/// Step code bias: step = 2^((code − STEP_BIAS) / 4).
pub use inbetween_ibk::STEP_BIAS;
/// Largest |quantised value| the encoder produces: second-order residuals then stay within
/// [`super::bits::MAX_RICE_VALUE`].
pub const MAX_Q: i64 = 1 << 38;

/// Step size of a step code.
pub fn step(code: u8) -> f64 {
    ((code as i32 - STEP_BIAS) as f64 / 4.0).exp2()
}

/// What a track stores.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackKind {
    /// Local rotation as a rotation vector (radians).
    Rotation,
    /// Local translation (the file's length unit).
    Translation,
}

/// One track of a skeleton.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Track {
    pub joint: usize,
    pub kind: TrackKind,
}

/// The tracks of a skeleton in file order: rotations of rotating joints, then translations of
/// translating joints, each in joint order.
pub fn tracks(sk: &Skeleton) -> Vec<Track> {
    let js = sk.joints();
    let rot = (0..js.len())
        .filter(|&j| js[j].rotation_order().is_some())
        .map(|joint| Track { joint, kind: TrackKind::Rotation });
    let trans =
        (0..js.len()).filter(|&j| js[j].has_translation()).map(|joint| Track { joint, kind: TrackKind::Translation });
    rot.chain(trans).collect()
}

/// What a version 3 file says before its segments: the header fields, the skeleton, the tracks
/// and which of them are constant (shared by [`Quantised`] and an opened [`File`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub skeleton: Skeleton,
    pub frame_time: f64,
    pub num_frames: usize,
    pub segment_len: usize,
    /// Centimetres per length unit the file was compressed in (informative).
    pub cm_per_unit: f64,
    /// Error bound (cm) the file was compressed to (informative).
    pub bound_cm: f64,
    pub tracks: Vec<Track>,
    /// Per track: `Some` value for a constant track, `None` for an animated one.
    pub constants: Vec<Option<[f32; 3]>>,
}

impl Header {
    /// The header of the head the runtime read ([`inbetween_ibk::read_head`]: the fields,
    /// skeleton and tracks versions 3 and 4 share), with the engine's skeleton.
    pub fn from_head(head: &inbetween_ibk::Head) -> Result<Header> {
        let skeleton = skeleton_of(&head.joints)?;
        let tracks = tracks(&skeleton);
        let same = tracks.len() == head.tracks.len()
            && tracks.iter().zip(&head.tracks).all(|(a, b)| a.joint == b.0 && (a.kind == TrackKind::Rotation) == b.1);
        if !same {
            return Err(MocapError::Codec("the skeleton's channels do not give the tracks the runtime reads".into()));
        }
        Ok(Header {
            skeleton,
            frame_time: head.frame_time,
            num_frames: head.num_frames,
            segment_len: head.segment_len,
            cm_per_unit: head.cm_per_unit,
            bound_cm: head.bound_cm,
            tracks,
            constants: head.tracks.iter().map(|t| t.2).collect(),
        })
    }

    /// Appends what versions 3 and 4 write before their segments: magic, `version`, the header
    /// fields, the compact skeleton and the tracks (kind, and the value of a constant one).
    pub(crate) fn write_head(&self, out: &mut Vec<u8>, version: u16) {
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&version.to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        out.extend_from_slice(&self.frame_time.to_le_bytes());
        out.extend_from_slice(&(self.num_frames as u32).to_le_bytes());
        out.extend_from_slice(&(self.segment_len as u16).to_le_bytes());
        out.extend_from_slice(&self.cm_per_unit.to_le_bytes());
        out.extend_from_slice(&self.bound_cm.to_le_bytes());
        write_compact_skeleton(out, &self.skeleton);
        for c in &self.constants {
            match c {
                None => out.push(0),
                Some(v) => {
                    out.push(1);
                    for x in v {
                        out.extend_from_slice(&x.to_le_bytes());
                    }
                }
            }
        }
    }
}

/// Everything a version 3 file holds, quantised: what [`encode`] writes and [`decode`] reads back.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantised {
    pub header: Header,
    /// Step codes, `segments × tracks` (ignored for constant tracks).
    pub codes: Vec<u8>,
    /// Quantised values, `frames × tracks` (zero for constant tracks).
    pub q: Vec<[i64; 3]>,
}

impl Quantised {
    pub fn num_segments(&self) -> usize {
        self.header.num_frames.div_ceil(self.header.segment_len)
    }

    /// Value of track `t` at frame `f` as the decoder computes it.
    pub fn value(&self, f: usize, t: usize) -> DVec3 {
        match self.header.constants[t] {
            Some(c) => DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64),
            None => {
                let s = step(self.codes[(f / self.header.segment_len) * self.header.tracks.len() + t]);
                let q = self.q[f * self.header.tracks.len() + t];
                DVec3::new(q[0] as f64 * s, q[1] as f64 * s, q[2] as f64 * s)
            }
        }
    }

    /// The local pose of frame `f`.
    pub fn pose(&self, f: usize) -> Pose {
        let mut p = Pose::rest(&self.header.skeleton);
        for t in 0..self.header.tracks.len() {
            set_track(&mut p, self.header.tracks[t], self.value(f, t));
        }
        p
    }

    /// Every frame as local poses.
    pub fn poses(&self) -> Vec<Pose> {
        (0..self.header.num_frames).map(|f| self.pose(f)).collect()
    }

    /// The clip as a motion (BVH channels; rotations through each joint's Euler order).
    pub fn motion(&self) -> Result<Motion> {
        Ok(Motion::from_poses(self.header.skeleton.clone(), self.header.frame_time, &self.poses())?)
    }
}

/// Writes a track's decoded value into a local pose.
pub fn set_track(p: &mut Pose, t: Track, v: DVec3) {
    match t.kind {
        TrackKind::Rotation => p.rotations[t.joint] = rotvec_to_quat(v),
        TrackKind::Translation => p.translations[t.joint] = v,
    }
}

/// `out` as the rest pose, reusing its buffers.
fn reset_pose(out: &mut Pose, sk: &Skeleton) {
    out.rotations.clear();
    out.rotations.resize(sk.len(), DQuat::IDENTITY);
    out.translations.clear();
    out.translations.extend(sk.joints().iter().map(|j| j.offset));
}

/// Per-component coding choices of one segment.
#[derive(Clone, Copy, Debug, Default)]
struct CompCode {
    /// 0 constant in the segment, 1 or 2: prediction order.
    mode: u8,
    k: u32,
}

fn residual(vals: &[i64], i: usize, mode: u8) -> i64 {
    if mode == 1 || i == 1 {
        vals[i] - vals[i - 1]
    } else {
        vals[i] - 2 * vals[i - 1] + vals[i - 2]
    }
}

/// The cheapest mode and Rice parameter for one component's values in a segment, and its bits.
fn choose_code(vals: &[i64]) -> (CompCode, u64) {
    if vals.iter().all(|&v| v == vals[0]) {
        return (CompCode { mode: 0, k: 0 }, 2);
    }
    let mut best = (CompCode::default(), u64::MAX);
    let mut us = Vec::with_capacity(vals.len());
    for mode in [1u8, 2] {
        us.clear();
        us.extend((1..vals.len()).map(|i| zigzag(residual(vals, i, mode))));
        for k in 0..24u32 {
            let bits: u64 = 7 + us.iter().map(|&u| super::bits::rice_bits(u, k)).sum::<u64>();
            if bits < best.1 {
                best = (CompCode { mode, k }, bits);
            }
        }
    }
    best
}

fn bit_len(u: u64) -> u32 {
    64 - u.leading_zeros()
}

/// Encodes one segment's bit stream.
fn encode_segment(qz: &Quantised, seg: usize) -> Vec<u8> {
    let nt = qz.header.tracks.len();
    let start = seg * qz.header.segment_len;
    let end = (start + qz.header.segment_len).min(qz.header.num_frames);
    let animated: Vec<usize> = (0..nt).filter(|&t| qz.header.constants[t].is_none()).collect();
    let mut w = BitWriter::new();
    let mut comps: Vec<(Vec<i64>, CompCode)> = Vec::with_capacity(animated.len() * 3);
    for &t in &animated {
        w.put(qz.codes[seg * nt + t] as u64, 8);
        for c in 0..3 {
            let vals: Vec<i64> = (start..end).map(|f| qz.q[f * nt + t][c]).collect();
            let (code, _) = choose_code(&vals);
            w.put(code.mode as u64, 2);
            if code.mode != 0 {
                w.put(code.k as u64, 5);
            }
            let u0 = zigzag(vals[0]);
            w.put(bit_len(u0) as u64, 6);
            w.put_long(u0, bit_len(u0));
            comps.push((vals, code));
        }
    }
    for i in 1..end - start {
        for (vals, code) in &comps {
            if code.mode != 0 {
                w.rice(zigzag(residual(vals, i, code.mode)), code.k);
            }
        }
    }
    w.finish()
}

/// Writes a version 3 file.
pub fn encode(qz: &Quantised) -> Vec<u8> {
    let mut out = Vec::new();
    qz.header.write_head(&mut out, VERSION);
    let segments: Vec<Vec<u8>> = (0..qz.num_segments()).map(|s| encode_segment(qz, s)).collect();
    let mut offset = 0u32;
    for s in &segments {
        out.extend_from_slice(&offset.to_le_bytes());
        offset += s.len() as u32;
    }
    out.extend_from_slice(&offset.to_le_bytes());
    for s in &segments {
        out.extend_from_slice(s);
    }
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// A parsed version 3 file: header, tracks and segment offsets; segments are decoded on demand.
/// Opening checks the checksum and every header field once; [`File::pose_at`] then decodes one
/// pose from its segment alone.
pub struct File<'a> {
    pub header: Header,
    animated: Vec<usize>,
    offsets: Vec<usize>,
    data: &'a [u8],
    /// Byte of the file where the data block starts (for messages).
    data_at: usize,
    /// The file's checksum (with the data's address, what a [`Scratch`] cursor belongs to).
    crc: u32,
}

/// Decoding state of one component within a segment.
#[derive(Clone, Copy, Debug, Default)]
struct CompState {
    mode: u8,
    k: u32,
    prev: i64,
    prev2: i64,
}

/// Reusable buffers of [`File::pose_at`] (no allocation per call), and where its decoding
/// stopped: a later time in the same segment continues from there, so playing a clip forwards
/// decodes each frame once.
#[derive(Default)]
pub struct Scratch {
    comps: Vec<CompState>,
    codes: Vec<u8>,
    steps: Vec<f64>,
    a: Vec<DVec3>,
    b: Vec<DVec3>,
    cursor: Option<Cursor>,
}

/// The segment and frame whose values `Scratch::comps` hold, and the reader's state after them.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cursor {
    /// The file: its data's address and length and its checksum.
    file: (usize, usize, u32),
    seg: usize,
    frame: usize,
    reader: (usize, u64, u32),
}

impl<'a> File<'a> {
    /// Parses a version 3 file (magic, version, checksum and every header field checked).
    pub fn open(bytes: &'a [u8]) -> Result<File<'a>> {
        let body = super::check_envelope(bytes, VERSION, VERSION)?.1;
        let head = inbetween_ibk::read_head(body, bytes.len()).map_err(runtime_error)?;
        let header = Header::from_head(&head)?;
        let (num_frames, segment_len) = (header.num_frames, header.segment_len);
        let mut r = Reader::new(body);
        r.skip(head.end, "the head")?;
        let segments = num_frames.div_ceil(segment_len);
        if segments * 4 + 4 > r.remaining() {
            return Err(MocapError::Codec(format!(
                "truncated file: {segments} segment offsets announced but only {} bytes remain at byte {}",
                r.remaining(),
                r.pos()
            )));
        }
        let mut offsets = Vec::with_capacity(segments + 1);
        for s in 0..=segments {
            let at = r.pos();
            let o = r.u32("segment offset")? as usize;
            if (s == 0 && o != 0) || offsets.last().is_some_and(|&p| o < p) {
                return Err(MocapError::Codec(format!(
                    "segment {s} at byte {at}: offset {o} does not follow {} (offsets start at 0 and never decrease)",
                    offsets.last().copied().unwrap_or(0)
                )));
            }
            offsets.push(o);
        }
        let data_len = offsets[segments];
        if data_len != r.remaining() {
            return Err(MocapError::Codec(format!(
                "the data block should hold {data_len} bytes after byte {}, but {} remain",
                r.pos(),
                r.remaining()
            )));
        }
        let data_at = r.pos();
        let data = &body[data_at..];
        let animated = (0..header.tracks.len()).filter(|&t| header.constants[t].is_none()).collect();
        let crc = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().expect("the envelope holds a checksum"));
        Ok(File { header, animated, offsets, data, data_at, crc })
    }

    pub fn num_segments(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Reads segment `seg`'s header into `sc` and returns a reader placed at its first residual.
    fn segment_header(&self, seg: usize, sc: &mut Scratch) -> Result<BitReader<'a>> {
        let (a, b) = (self.offsets[seg], self.offsets[seg + 1]);
        let mut r = BitReader::new(&self.data[a..b], self.data_at + a);
        sc.cursor = None;
        sc.comps.clear();
        sc.steps.clear();
        sc.codes.clear();
        for _ in &self.animated {
            let code = r.get(8, "step code")? as u8;
            sc.codes.push(code);
            sc.steps.push(step(code));
            for _ in 0..3 {
                let mode = r.get(2, "component mode")? as u8;
                if mode == 3 {
                    return Err(MocapError::Codec(format!("segment {seg}: component mode 3, expected 0 to 2")));
                }
                let k = if mode != 0 { r.get(5, "Rice parameter")? as u32 } else { 0 };
                let len = r.get(6, "first value length")? as u32;
                if len > 40 {
                    return Err(MocapError::Codec(format!("segment {seg}: first value of {len} bits, at most 40")));
                }
                let v = unzigzag(r.get_long(len, "first value")?);
                sc.comps.push(CompState { mode, k, prev: v, prev2: v });
            }
        }
        Ok(r)
    }

    /// Decodes one more frame of a segment into `sc` (after its header or a previous frame);
    /// `i` is the frame's index in the segment (≥ 1).
    fn next_frame(&self, r: &mut BitReader, i: usize, sc: &mut Scratch) -> Result<()> {
        for c in sc.comps.iter_mut() {
            if c.mode == 0 {
                continue;
            }
            let d = unzigzag(r.rice(c.k, "residual")?);
            let pred = if c.mode == 1 || i == 1 { c.prev } else { 2 * c.prev - c.prev2 };
            let v = pred.checked_add(d).filter(|v| v.abs() <= 4 * MAX_Q).ok_or_else(|| {
                MocapError::Codec(format!("a residual near byte {} takes a value out of range", self.data_at))
            })?;
            c.prev2 = c.prev;
            c.prev = v;
        }
        Ok(())
    }

    /// Values of every track from the current state (`prev`, or `prev2` when `older`).
    fn values_into(&self, sc: &Scratch, older: bool, out: &mut Vec<DVec3>) {
        out.clear();
        let mut a = 0;
        for (t, c) in self.header.constants.iter().enumerate() {
            out.push(match c {
                Some(v) => DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64),
                None => {
                    let s = sc.steps[a];
                    let cs = &sc.comps[3 * a..3 * a + 3];
                    let g = |c: &CompState| if older { c.prev2 } else { c.prev } as f64 * s;
                    a += 1;
                    debug_assert_eq!(self.animated[a - 1], t);
                    DVec3::new(g(&cs[0]), g(&cs[1]), g(&cs[2]))
                }
            });
        }
    }

    /// Track values of frame `f` (and of frame `f + 1` into `next` when it lies in the same
    /// segment; `next` is left empty otherwise).
    fn frame_values(&self, f: usize, sc: &mut Scratch, want_next: bool) -> Result<(Vec<DVec3>, Vec<DVec3>)> {
        let seg = f / self.header.segment_len;
        let i = f - seg * self.header.segment_len;
        let seg_end = ((seg + 1) * self.header.segment_len).min(self.header.num_frames);
        let last = if want_next && f + 1 < seg_end { i + 1 } else { i };
        let key = (self.data.as_ptr() as usize, self.data.len(), self.crc);
        let (a0, b0) = (self.offsets[seg], self.offsets[seg + 1]);
        // Continue where the last call stopped when it stopped in this segment at or before
        // the last frame wanted (its state then holds that frame's predecessor too).
        let (mut r, from) = match sc.cursor.filter(|c| c.file == key && c.seg == seg && c.frame <= last) {
            Some(c) => (BitReader::resume(&self.data[a0..b0], self.data_at + a0, c.reader), c.frame + 1),
            None => (self.segment_header(seg, sc)?, 1),
        };
        sc.cursor = None;
        for j in from..=last {
            self.next_frame(&mut r, j, sc)?;
        }
        sc.cursor = Some(Cursor { file: key, seg, frame: last, reader: r.state() });
        let (mut a, mut b) = (std::mem::take(&mut sc.a), std::mem::take(&mut sc.b));
        if last > i {
            self.values_into(sc, true, &mut a);
            self.values_into(sc, false, &mut b);
        } else {
            self.values_into(sc, false, &mut a);
            b.clear();
        }
        Ok((a, b))
    }

    /// The local pose at `time` seconds (clamped to the clip): the two frames around it, rotations
    /// by spherical linear interpolation and translations linearly (as ACL samples). Decodes at
    /// most one segment and the header of the next: O(joints × segment length), whatever the
    /// clip's length; with the same `sc`, a later time in the same segment only decodes the
    /// frames after the last one decoded (playback forwards: O(joints) per pose).
    pub fn pose_at(&self, time: f64, out: &mut Pose, sc: &mut Scratch) -> Result<()> {
        let x = if time.is_finite() {
            (time / self.header.frame_time).clamp(0.0, (self.header.num_frames - 1) as f64)
        } else {
            0.0
        };
        let f = (x.floor() as usize).min(self.header.num_frames - 1);
        let u = x - f as f64;
        let interpolate = u > 0.0 && f + 1 < self.header.num_frames;
        let (a, mut b) = self.frame_values(f, sc, interpolate)?;
        if interpolate && b.is_empty() {
            // Frame f + 1 starts the next segment: its values are the segment's first values.
            let _ = self.segment_header(f / self.header.segment_len + 1, sc)?;
            self.values_into(sc, false, &mut b);
        }
        reset_pose(out, &self.header.skeleton);
        for (t, &track) in self.header.tracks.iter().enumerate() {
            set_track(out, track, a[t]);
            if interpolate {
                match track.kind {
                    TrackKind::Rotation => {
                        let q1 = rotvec_to_quat(b[t]);
                        let q0 = out.rotations[track.joint];
                        let q1 = if q0.dot(q1) < 0.0 { -q1 } else { q1 };
                        out.rotations[track.joint] = q0.slerp(q1, u);
                    }
                    TrackKind::Translation => out.translations[track.joint] = a[t].lerp(b[t], u),
                }
            }
        }
        sc.a = a;
        sc.b = b;
        Ok(())
    }

    /// Decodes every segment into the quantised clip, checking that each segment's bits are used
    /// exactly (to its last byte).
    pub fn decode_all(&self) -> Result<Quantised> {
        let nt = self.header.tracks.len();
        let mut q = vec![[0i64; 3]; self.header.num_frames * nt];
        let mut codes = vec![0u8; self.num_segments() * nt];
        let mut sc = Scratch::default();
        for seg in 0..self.num_segments() {
            let mut r = self.segment_header(seg, &mut sc)?;
            let start = seg * self.header.segment_len;
            let end = (start + self.header.segment_len).min(self.header.num_frames);
            for (a, &t) in self.animated.iter().enumerate() {
                codes[seg * nt + t] = sc.codes[a];
            }
            for f in start..end {
                if f > start {
                    self.next_frame(&mut r, f - start, &mut sc)?;
                }
                for (a, &t) in self.animated.iter().enumerate() {
                    let c = &sc.comps[3 * a..3 * a + 3];
                    q[f * nt + t] = [c[0].prev, c[1].prev, c[2].prev];
                }
            }
            let used = r.bytes_used();
            let size = self.offsets[seg + 1] - self.offsets[seg];
            if used != size {
                return Err(MocapError::Codec(format!(
                    "segment {seg} at byte {}: its values take {used} bytes but it is {size} bytes long",
                    self.data_at + self.offsets[seg]
                )));
            }
        }
        Ok(Quantised { header: self.header.clone(), codes, q })
    }
}

/// Decodes a whole version 3 file.
pub fn decode(bytes: &[u8]) -> Result<Quantised> {
    File::open(bytes)?.decode_all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    /// A hand-made quantised clip: every mode (constant, smooth, noisy), escapes and extreme values.
    fn quantised() -> Quantised {
        let mut p = GaitParams::walk();
        p.frames = 37;
        let m = gait(&p);
        let tracks = tracks(&m.skeleton);
        let nt = tracks.len();
        let n = 37;
        let segment_len = 8;
        let constants: Vec<Option<[f32; 3]>> =
            (0..nt).map(|t| if t % 5 == 4 { Some([0.25, -1.5, t as f32]) } else { None }).collect();
        let q = (0..n * nt)
            .map(|i| {
                let (f, t) = ((i / nt) as i64, (i % nt) as i64);
                if constants[(i % nt) as usize].is_some() {
                    return [0; 3];
                }
                match t % 5 {
                    0 => [f * f - 40 * f + t, 7, -f],
                    1 => [((f * 7919 + t * 104729) % 2001) - 1000, 0, f * 3],
                    2 => [if f == 20 { MAX_Q } else { -MAX_Q + f }, 1 << 30, -(1 << 20) * f],
                    _ => [t, -t, 0],
                }
            })
            .collect();
        let segments = n.div_ceil(segment_len);
        // Step codes over the whole range; constant tracks have none (read back as 0).
        let codes =
            (0..segments * nt).map(|i| if constants[i % nt].is_some() { 0 } else { (i * 37 % 256) as u8 }).collect();
        let header = Header {
            skeleton: m.skeleton,
            frame_time: 1.0 / 24.0,
            num_frames: n,
            segment_len,
            cm_per_unit: 5.6444,
            bound_cm: 0.05,
            tracks,
            constants,
        };
        Quantised { header, codes, q }
    }

    #[test]
    fn encode_then_decode_is_the_identity() {
        let qz = quantised();
        let bytes = encode(&qz);
        let d = decode(&bytes).unwrap();
        assert_eq!(d.codes, qz.codes);
        if let Some(i) = (0..qz.q.len()).find(|&i| d.q[i] != qz.q[i]) {
            panic!(
                "value {i} (frame {}, track {}): {:?} vs {:?}",
                i / qz.header.tracks.len(),
                i % qz.header.tracks.len(),
                d.q[i],
                qz.q[i]
            );
        }
        assert_eq!(d, qz);
        assert_eq!(&bytes[4..6], &3u16.to_le_bytes());
    }

    #[test]
    fn pose_at_matches_the_decoded_frames_and_interpolates_between_them() {
        let qz = quantised();
        let bytes = encode(&qz);
        let file = File::open(&bytes).unwrap();
        let (mut pose, mut sc) = (Pose::rest(&qz.header.skeleton), Scratch::default());
        for f in 0..qz.header.num_frames {
            file.pose_at(f as f64 * qz.header.frame_time, &mut pose, &mut sc).unwrap();
            let want = qz.pose(f);
            for j in 0..qz.header.skeleton.len() {
                assert!(
                    inbetween_core::rotation::angle_between(pose.rotations[j], want.rotations[j]) < 1e-9,
                    "frame {f}, joint {j}"
                );
                assert!(
                    (pose.translations[j] - want.translations[j]).length()
                        < 1e-9 * (1.0 + want.translations[j].length())
                );
            }
        }
        // Halfway between frames 7 and 8 (the second starts a segment): the slerp midpoint.
        file.pose_at(7.5 * qz.header.frame_time, &mut pose, &mut sc).unwrap();
        let (a, b) = (qz.pose(7), qz.pose(8));
        for j in 0..qz.header.skeleton.len() {
            let (qa, qb) = (a.rotations[j], b.rotations[j]);
            let mid = qa.slerp(if qa.dot(qb) < 0.0 { -qb } else { qb }, 0.5);
            assert!(inbetween_core::rotation::angle_between(pose.rotations[j], mid) < 1e-9);
            assert!((pose.translations[j] - (a.translations[j] + b.translations[j]) / 2.0).length() < 1e-6);
        }
        // Times outside the clip clamp to its ends.
        file.pose_at(-3.0, &mut pose, &mut sc).unwrap();
        assert_eq!(pose.translations, qz.pose(0).translations);
        file.pose_at(f64::INFINITY, &mut pose, &mut sc).unwrap();
        file.pose_at(1e9, &mut pose, &mut sc).unwrap();
        assert_eq!(pose.translations, qz.pose(qz.header.num_frames - 1).translations);
    }

    /// A scratch that continues from its last frame gives the poses a fresh one gives, for
    /// playback forwards at 60 Hz and for times in random order.
    #[test]
    fn a_reused_scratch_gives_the_poses_of_a_fresh_one() {
        use rand::{Rng, SeedableRng};
        let qz = quantised();
        let bytes = encode(&qz);
        let file = File::open(&bytes).unwrap();
        let duration = (qz.header.num_frames - 1) as f64 * qz.header.frame_time;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let forwards = (0..).map(|k| k as f64 / 60.0).take_while(|&t| t <= duration + 0.05);
        let random: Vec<f64> = (0..200).map(|_| rng.random::<f64>() * duration).collect();
        let (mut pose, mut sc) = (Pose::rest(&qz.header.skeleton), Scratch::default());
        let mut fresh = Pose::rest(&qz.header.skeleton);
        for t in forwards.chain(random) {
            file.pose_at(t, &mut pose, &mut sc).unwrap();
            file.pose_at(t, &mut fresh, &mut Scratch::default()).unwrap();
            assert_eq!(pose, fresh, "time {t}");
        }
        // A scratch used on another file starts over there.
        let mut other = qz.clone();
        other.q.iter_mut().for_each(|v| v[0] += 1);
        let other_bytes = encode(&other);
        let other_file = File::open(&other_bytes).unwrap();
        other_file.pose_at(0.1, &mut pose, &mut sc).unwrap();
        other_file.pose_at(0.1, &mut fresh, &mut Scratch::default()).unwrap();
        assert_eq!(pose, fresh);
    }

    #[test]
    fn every_truncated_prefix_and_every_corrupted_byte_is_refused() {
        let bytes = encode(&quantised());
        for n in 0..bytes.len() {
            assert!(decode(&bytes[..n]).is_err(), "prefix of {n} bytes decoded");
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            let e = decode(&b).unwrap_err().to_string();
            assert!(e.contains("checksum") || e.contains("magic") || e.contains("version"), "byte {i}: {e}");
        }
    }

    /// With the checksum fixed up, structural checks still refuse damaged files with a message.
    #[test]
    fn damaged_bodies_behind_a_valid_checksum_give_clear_errors() {
        let qz = quantised();
        let good = encode(&qz);
        let body = &good[..good.len() - 4];
        let fix = |mut b: Vec<u8>| {
            let crc = crc32fast::hash(&b);
            b.extend_from_slice(&crc.to_le_bytes());
            b
        };
        // Truncated at every length: an error, never a panic.
        for n in 0..body.len() {
            assert!(decode(&fix(body[..n].to_vec())).is_err(), "body cut at {n}");
        }
        // Hostile frame count: refused before any allocation.
        let mut b = body.to_vec();
        b[16..20].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = decode(&fix(b)).unwrap_err().to_string();
        assert!(e.contains("joint poses a file of"), "{e}");
        let mut b = body.to_vec();
        b[20..22].copy_from_slice(&0u16.to_le_bytes());
        assert!(decode(&fix(b)).unwrap_err().to_string().contains("segments of 0 frames"));
        // Every single byte changed in turn (behind a valid checksum): decodes or errs, no panic.
        let mut accepted = 0;
        for i in 6..body.len() {
            for x in [0x01u8, 0x80, 0xff] {
                let mut b = body.to_vec();
                b[i] ^= x;
                if let Ok(d) = decode(&fix(b)) {
                    accepted += 1;
                    let _ = d.motion();
                }
            }
        }
        assert!(accepted > 0, "changes inside the value bits still decode");
    }
}
