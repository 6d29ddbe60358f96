//! Runtime sampler of `.ibk` version 4 clips, in the shape of ozz-animation's sampling job and
//! ACL's decompression context: [`Clip::open`] borrows the file's bytes (no copy) and checks every
//! field once; a [`Context`] caches the frames it decoded last; [`Clip::sample`] writes local
//! rotations (quaternions x, y, z, w) and translations into the caller's buffers with no
//! allocation. The C ABI (`inbetween_ibk_open`, `_sample`, `_close`; header
//! `include/inbetween_ibk.h`) is [`capi`]. The offline encoder is in the mocap engine
//! (`inbetween_mocap::codec::v4`), which uses this crate to measure what a runtime decodes and
//! to read files back: this crate is the one decoder of the layout ([`read_head`] also reads the
//! head version 3 shares: header fields, skeleton, tracks).
//!
//! Layout (little-endian), version 4:
//! ```text
//! magic "IBK\0" | version u16 = 4 | reserved u16
//! frame_time f64 | num_frames u32 | segment_len u16 | cm_per_unit f64 | bound_cm f64
//! skeleton: as version 3 (raw length u32 | deflated length u32 | deflated joints)
//! tracks: as version 3, one per joint with rotation channels (rotation vector), then one per
//!         joint with position channels (translation): kind u8, 0 animated | 1 constant + 3×f32
//! headers_len u32 | segment headers, one bit stream (LSB first), per segment, per animated
//!         track: step code 8 bits, then per component: width 6 bits (0 to MAX_WIDTH) and the
//!         Rice code (parameter max(width, 1) − 1) of the zig-zagged difference between the
//!         component's least quantised value in the segment and its prediction (the previous
//!         segment's least value × its step / this step, rounded; 0 in the first segment)
//! data_len u32 | data: per segment, from a byte boundary, its frames one after the other, each
//!         frame `frame_bits` = Σ widths long: per animated component in track order, `width`
//!         bits of u = q − q_min; then 8 zero bytes (so that every read is one 8-byte load)
//! crc32 of every byte before it, u32
//! ```
//! A component decodes to `base + u × scale` in f32, with `scale` = [`step`]`(code)` and
//! `base = (q_min as f32) × scale`: every sample of a segment is one load, one shift, one mask and
//! one multiply-add away, whatever its frame (fixed width per track and segment, values of one
//! frame together: ACL's layout). Rotation vectors become quaternions through [`exp_map`], a
//! polynomial in θ² (no square root, no trigonometry). The encoder computes the same f32
//! values, so its error bound is the bound of what this reader returns.

pub mod capi;
mod error;

use error::format_err;
pub use error::{IbkError, Result};

/// The version this crate reads.
pub const VERSION: u16 = 4;
/// Longest segment a file may declare.
pub const MAX_SEGMENT_LEN: usize = 256;
/// Widest packed value (bits).
pub const MAX_WIDTH: u32 = 40;
/// Largest clip a file may describe (frames × joints).
pub const MAX_FRAME_JOINTS: u64 = 1 << 26;
/// Step code bias: step = 2^((code − STEP_BIAS) / 4).
pub const STEP_BIAS: i32 = 192;
const MAGIC: &[u8; 4] = b"IBK\0";
const PAD: usize = 8;

/// 2^(i/4) for i = 0..3, as f32 (the fractional quarter octaves of a step).
const QUARTERS: [f32; 4] = [1.0, 1.189_207_1, std::f32::consts::SQRT_2, 1.681_792_9];

/// The step of a step code, as f32: 2^((code − 192) / 4), exact on every platform (a power of
/// two times one of four constants, no `exp2`).
pub fn step(code: u8) -> f32 {
    let e = (code as i32 - STEP_BIAS).div_euclid(4);
    let q = (code as i32 - STEP_BIAS).rem_euclid(4) as usize;
    QUARTERS[q] * pow2(e)
}

/// 2^e as f32 for −149 ≤ e ≤ 127 (0 below, as subnormals run out).
fn pow2(e: i32) -> f32 {
    if e >= -126 {
        f32::from_bits(((e + 127) as u32) << 23)
    } else if e >= -149 {
        f32::from_bits(1u32 << (e + 149))
    } else {
        0.0
    }
}

/// The quaternion (x, y, z, w) of a rotation vector: `(v · sin(θ/2)/θ, cos(θ/2))` with θ = |v|,
/// both factors as polynomials in h = θ²/4 (Taylor to h⁷: under 1e-10 from the exact value up to
/// θ = π, the largest angle a rotation vector of the encoder has). The encoder measures its
/// error through this very function.
#[inline]
pub fn exp_map(v: [f32; 3]) -> [f32; 4] {
    let h = 0.25 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    let c = 1.0
        - h * (1.0 / 2.0
            - h * (1.0 / 24.0
                - h * (1.0 / 720.0
                    - h * (1.0 / 40320.0
                        - h * (1.0 / 3_628_800.0 - h * (1.0 / 479_001_600.0 - h * (1.0 / 87_178_291_200.0)))))));
    let s = 0.5
        * (1.0
            - h * (1.0 / 6.0
                - h * (1.0 / 120.0
                    - h * (1.0 / 5040.0
                        - h * (1.0 / 362_880.0
                            - h * (1.0 / 39_916_800.0
                                - h * (1.0 / 6_227_020_800.0 - h * (1.0 / 1_307_674_368_000.0))))))));
    [v[0] * s, v[1] * s, v[2] * s, c]
}

/// Joints whose rotations [`exp_map_lanes`] turns into quaternions at once.
const LANES: usize = 8;

/// [`exp_map`] of `LANES` rotation vectors given by component (`v[c][lane]`), as
/// quaternion components `q[c][lane]` (x, y, z, w): the same operations in the same order per
/// lane.
#[inline]
fn exp_map_lanes(v: &[[f32; LANES]; 3]) -> [[f32; LANES]; 4] {
    let mut q = [[0.0f32; LANES]; 4];
    for k in 0..LANES {
        let [x, y, z, w] = exp_map([v[0][k], v[1][k], v[2][k]]);
        q[0][k] = x;
        q[1][k] = y;
        q[2][k] = z;
        q[3][k] = w;
    }
    q
}

/// Zig-zag decoding.
fn unzigzag(u: u64) -> i64 {
    ((u >> 1) as i64) ^ -((u & 1) as i64)
}

/// The prediction of a segment's least value from the previous segment's (module doc).
pub fn predict_min(prev_min: i64, prev_code: u8, code: u8) -> i64 {
    let r = (prev_min as f64) * (step(prev_code) as f64 / step(code) as f64);
    if r.is_finite() {
        r.round().clamp(-(1i64 << 50) as f64, (1i64 << 50) as f64) as i64
    } else {
        0
    }
}

/// One joint as the runtime sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub name: String,
    /// Parent joint, `None` for a root.
    pub parent: Option<usize>,
    /// Rest translation (the file's length unit).
    pub offset: [f64; 3],
    /// Channel codes in file order: 0 to 2 X, Y, Z position, 3 to 5 X, Y, Z rotation (the
    /// order of the rotation codes is the joint's Euler order).
    pub channels: Vec<u8>,
    /// End-site offset (the file's length unit), for a leaf that has one.
    pub end_site: Option<[f64; 3]>,
    /// Rotation track (three Euler channels) and translation track (any position channel).
    pub has_rotation: bool,
    pub has_translation: bool,
}

/// A bounds-checked little-endian reader whose errors name the field and byte.
struct Reader<'a> {
    b: &'a [u8],
    pos: usize,
    /// Added to positions in messages (a sub-reader's start in the file).
    base: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        if self.b.len() - self.pos < n {
            return format_err(format!(
                "truncated: {what} at byte {} needs {n} bytes, {} left",
                self.base + self.pos,
                self.b.len() - self.pos
            ));
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.take(1, what)?[0])
    }
    fn u16(&mut self, what: &str) -> Result<u16> {
        Ok(u16::from_le_bytes(self.take(2, what)?.try_into().expect("2 bytes")))
    }
    fn u32(&mut self, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().expect("4 bytes")))
    }
    fn f32(&mut self, what: &str) -> Result<f32> {
        Ok(f32::from_le_bytes(self.take(4, what)?.try_into().expect("4 bytes")))
    }
    fn f64(&mut self, what: &str) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take(8, what)?.try_into().expect("8 bytes")))
    }
    fn varint(&mut self, what: &str) -> Result<u64> {
        let mut v = 0u64;
        for shift in (0..64).step_by(7) {
            let b = self.u8(what)?;
            v |= ((b & 0x7f) as u64) << shift;
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        format_err(format!("{what} at byte {}: varint longer than 64 bits", self.base + self.pos))
    }
}

/// A bit reader over a byte slice (LSB first) whose reads past the end are errors.
struct Bits<'a> {
    b: &'a [u8],
    bit: usize,
    at: usize,
}

impl Bits<'_> {
    fn get(&mut self, n: u32, what: &str) -> Result<u64> {
        if self.bit + n as usize > self.b.len() * 8 {
            return format_err(format!(
                "truncated: {what} runs past the segment headers (they start at byte {})",
                self.at
            ));
        }
        let mut v = 0u64;
        for i in 0..n as usize {
            let k = self.bit + i;
            v |= (((self.b[k >> 3] >> (k & 7)) & 1) as u64) << i;
        }
        self.bit += n as usize;
        Ok(v)
    }
    /// A Rice code (escape: 24 ones, then a 6-bit length and the bits), as version 3 writes.
    fn rice(&mut self, k: u32, what: &str) -> Result<u64> {
        let mut q = 0u64;
        while self.get(1, what)? == 1 {
            q += 1;
            if q == 24 {
                let len = self.get(6, what)? as u32;
                return self.get(len.min(63), what);
            }
        }
        Ok((q << k) | self.get(k, what)?)
    }
}

/// Skeleton lengths are micro-units when the format byte says decimal.
pub const DECIMAL_SCALE: f64 = 1e6;

/// Reads the deflated skeleton block (as versions 3 and 4 write it) that starts at byte `at` of
/// `body`: the joints and the byte after the block. Byte positions in errors are `body`'s.
pub fn read_skeleton(body: &[u8], at: usize) -> Result<(Vec<Joint>, usize)> {
    if at > body.len() {
        return format_err(format!("truncated: the skeleton at byte {at} starts past the end ({} bytes)", body.len()));
    }
    let mut r = Reader { b: body, pos: at, base: 0 };
    let joints = read_skeleton_block(&mut r)?;
    Ok((joints, r.pos))
}

fn read_skeleton_block(r: &mut Reader) -> Result<Vec<Joint>> {
    let at = r.base + r.pos;
    let raw_len = r.u32("skeleton length")?;
    let packed_len = r.u32("deflated skeleton length")?;
    if raw_len == 0 || raw_len > 1 << 22 || raw_len as u64 > 1032 * packed_len as u64 + 64 {
        return format_err(format!(
            "skeleton at byte {at}: {raw_len} bytes from {packed_len} deflated bytes, expected 1 to 4194304 and at most 1032 per deflated byte"
        ));
    }
    let packed = r.take(packed_len as usize, "deflated skeleton")?;
    let mut raw = Vec::with_capacity(raw_len as usize);
    let inflated = std::io::Read::read_to_end(
        &mut std::io::Read::take(flate2::read::DeflateDecoder::new(packed), raw_len as u64 + 1),
        &mut raw,
    );
    if inflated.is_err() || raw.len() != raw_len as usize {
        return format_err(format!(
            "skeleton at byte {at}: the deflated bytes do not inflate to the {raw_len} bytes announced"
        ));
    }
    let mut s = Reader { b: &raw, pos: 0, base: 0 };
    let decimal = match s.u8("skeleton length format")? {
        0 => false,
        1 => true,
        f => return format_err(format!("skeleton at byte {at}: length format {f}, expected 0 (f64) or 1 (decimal)")),
    };
    let vec3 = |s: &mut Reader, what: &str| -> Result<[f64; 3]> {
        let mut v = [0.0; 3];
        for x in &mut v {
            *x = if decimal { unzigzag(s.varint(what)?) as f64 / DECIMAL_SCALE } else { s.f64(what)? };
        }
        Ok(v)
    };
    let nj = s.u16("joint count")? as usize;
    if nj == 0 {
        return format_err("skeleton with no joints");
    }
    let mut joints = Vec::with_capacity(nj);
    for i in 0..nj {
        let len = s.u16("joint name length")? as usize;
        let name = String::from_utf8(s.take(len, "joint name")?.to_vec())
            .map_err(|_| IbkError::Format(format!("skeleton joint {i}: name is not UTF-8")))?;
        let parent = s.u16("joint parent")? as i16;
        let offset = vec3(&mut s, "joint offset")?;
        let nch = s.u8("channel count")? as usize;
        let codes = s.take(nch, "channel codes")?;
        if let Some(c) = codes.iter().find(|&&c| c > 5) {
            return format_err(format!("skeleton joint {i} '{name}': unknown channel code {c}"));
        }
        let mut axes = [false; 3];
        let mut rot = 0;
        for &c in codes.iter().filter(|&&c| c >= 3) {
            rot += 1;
            axes[(c - 3) as usize] = true;
        }
        let end_site = if s.u8("end site flag")? == 1 { Some(vec3(&mut s, "end site")?) } else { None };
        let parent = match parent {
            p if p < 0 => None,
            p if (p as usize) < i => Some(p as usize),
            p => return format_err(format!("skeleton joint {i} '{name}': parent {p} does not come before it")),
        };
        joints.push(Joint {
            name,
            parent,
            offset,
            channels: codes.to_vec(),
            end_site,
            has_rotation: rot == 3 && axes.iter().all(|&a| a),
            has_translation: codes.iter().any(|&c| c < 3),
        });
    }
    if s.pos != raw.len() {
        return format_err(format!("skeleton at byte {at}: {} bytes left after its {nj} joints", raw.len() - s.pos));
    }
    Ok(joints)
}

/// Joint poses a file may describe per byte of file (a clip of constant tracks costs almost no
/// bytes per frame; this keeps a hostile header from sizing a huge allocation).
pub const POSES_PER_BYTE: u64 = 1024;

/// What versions 3 and 4 share before their segments, read and checked once for both (the
/// runtime's [`Clip::open`] and the mocap engine's version 3 reader): the header fields, the
/// skeleton and the tracks.
#[derive(Clone, Debug, PartialEq)]
pub struct Head {
    pub frame_time: f64,
    pub num_frames: usize,
    pub segment_len: usize,
    pub cm_per_unit: f64,
    pub bound_cm: f64,
    pub joints: Vec<Joint>,
    /// Per track: joint, whether a rotation, and its value when constant (file order: rotations,
    /// then translations, in joint order).
    pub tracks: Vec<(usize, bool, Option<[f32; 3]>)>,
    /// The byte of `body` after the tracks, where the version's own blocks start.
    pub end: usize,
}

/// Reads [`Head`] from `body` (a version 3 or 4 file less its checksum, whose envelope the caller
/// checked) of a file of `file_len` bytes.
pub fn read_head(body: &[u8], file_len: usize) -> Result<Head> {
    if body.len() < 8 {
        return format_err(format!("truncated file: {} bytes is shorter than the magic and version", body.len()));
    }
    let mut r = Reader { b: body, pos: 8, base: 0 };
    let frame_time = r.f64("frame time")?;
    let num_frames = r.u32("frame count")? as usize;
    let segment_len = r.u16("segment length")? as usize;
    let cm_per_unit = r.f64("cm per unit")?;
    let bound_cm = r.f64("error bound")?;
    let valid = frame_time.is_finite()
        && frame_time > 0.0
        && num_frames > 0
        && (1..=MAX_SEGMENT_LEN).contains(&segment_len)
        && cm_per_unit.is_finite()
        && cm_per_unit > 0.0
        && bound_cm.is_finite()
        && bound_cm >= 0.0;
    if !valid {
        return format_err(format!(
            "invalid header: frame time {frame_time} s, {num_frames} frames, segments of {segment_len} frames (1 to {MAX_SEGMENT_LEN}), {cm_per_unit} cm per unit, bound {bound_cm} cm"
        ));
    }
    let joints = read_skeleton_block(&mut r)?;
    let nj = joints.len();
    let limit = MAX_FRAME_JOINTS.min(POSES_PER_BYTE * file_len as u64);
    if num_frames as u64 * nj as u64 > limit {
        return format_err(format!(
            "invalid header: {num_frames} frames of {nj} joints exceed the {limit} joint poses a file of {file_len} bytes may hold"
        ));
    }
    // Tracks: rotations, then translations, in joint order.
    let order: Vec<(usize, bool)> = (0..nj)
        .filter(|&j| joints[j].has_rotation)
        .map(|j| (j, true))
        .chain((0..nj).filter(|&j| joints[j].has_translation).map(|j| (j, false)))
        .collect();
    let mut tracks = Vec::with_capacity(order.len());
    for (i, &(j, rot)) in order.iter().enumerate() {
        let at = r.pos;
        let constant = match r.u8("track kind")? {
            0 => None,
            1 => {
                let v = [r.f32("constant value")?, r.f32("constant value")?, r.f32("constant value")?];
                if v.iter().any(|x| !x.is_finite()) {
                    return format_err(format!("track {i} (joint {j}) at byte {at}: constant value is not finite"));
                }
                Some(v)
            }
            k => {
                return format_err(format!(
                    "track {i} (joint {j}) at byte {at}: kind {k}, expected 0 (animated) or 1 (constant)"
                ))
            }
        };
        tracks.push((j, rot, constant));
    }
    Ok(Head { frame_time, num_frames, segment_len, cm_per_unit, bound_cm, joints, tracks, end: r.pos })
}

/// Where one animated component of one segment lives and how it dequantises.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Comp {
    base: f32,
    scale: f32,
    mask: u64,
    /// Bit offset inside a frame.
    off: u32,
}

/// An opened version 4 file: the borrowed bytes and the tables made once at open.
pub struct Clip<'a> {
    data: &'a [u8],
    /// The header fields, the skeleton and the tracks.
    head: Head,
    /// Animated components per segment (3 × animated tracks).
    ncomp: usize,
    /// segments × ncomp.
    comps: Vec<Comp>,
    /// Per segment: first byte in `data` and bits per frame.
    seg_start: Vec<usize>,
    frame_bits: Vec<usize>,
    /// Per animated component: its slot in a frame's joint values (6 per joint: rotation vector,
    /// translation).
    slot: Vec<usize>,
    /// Frame values before the animated slots are written: rotation vector 0 or a constant
    /// track's value, translation the rest offset or a constant track's value.
    rest: Vec<f32>,
    /// Joints whose rotation has an animated component: the only ones whose quaternion a decoded
    /// frame recomputes.
    animated_rot: Vec<usize>,
    /// Quaternion of every joint's rest (or constant) rotation vector.
    rest_rot: Vec<[f32; 4]>,
}

impl<'a> Clip<'a> {
    /// Parses a version 4 file: magic, version, checksum and every header field and segment
    /// header checked, tables of every segment made (the only allocation; sampling makes none).
    pub fn open(bytes: &'a [u8]) -> Result<Clip<'a>> {
        if bytes.len() < 4 || &bytes[..4] != MAGIC {
            return format_err("not an .ibk file: expected the magic bytes \"IBK\\0\" at byte 0");
        }
        if bytes.len() < 12 {
            return format_err(format!("truncated file: {} bytes is shorter than the header", bytes.len()));
        }
        let version = u16::from_le_bytes([bytes[4], bytes[5]]);
        if version != VERSION {
            return format_err(format!(
                "unsupported .ibk version {version}: the runtime reads version {VERSION} (versions 1 to 3 are read by the mocap engine's codec::read)"
            ));
        }
        let body = &bytes[..bytes.len() - 4];
        let stored = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().expect("4 bytes"));
        let computed = crc32fast::hash(body);
        if computed != stored {
            return format_err(format!(
                "checksum mismatch (stored {stored:08x}, computed {computed:08x}): the file is corrupt or truncated"
            ));
        }
        let head = read_head(body, bytes.len())?;
        let Head { num_frames, segment_len, ref joints, ref tracks, end, .. } = head;
        let nj = joints.len();
        let mut r = Reader { b: body, pos: end, base: 0 };
        let mut rest = Vec::with_capacity(6 * nj);
        for jt in joints {
            rest.extend([0.0, 0.0, 0.0]);
            rest.extend(jt.offset.map(|x| x as f32));
        }
        let mut slot = Vec::new();
        for &(j, rot, c) in tracks {
            let s = 6 * j + if rot { 0 } else { 3 };
            match c {
                Some(v) => rest[s..s + 3].copy_from_slice(&v),
                None => slot.extend([s, s + 1, s + 2]),
            }
        }
        let ncomp = slot.len();
        let segments = num_frames.div_ceil(segment_len);
        let headers_at = r.pos;
        let headers_len = r.u32("segment headers length")? as usize;
        let headers = r.take(headers_len, "segment headers")?;
        let mut bits = Bits { b: headers, bit: 0, at: headers_at + 4 };
        // Every component takes at least 7 header bits: the headers bound what is allocated.
        let mut comps = Vec::with_capacity((segments * ncomp).min(headers.len() * 8 / 7 + 1));
        let mut frame_bits = Vec::with_capacity(segments.min(headers.len() + 1));
        let mut prev: Vec<(i64, u8)> = vec![(0, STEP_BIAS as u8); ncomp];
        for s in 0..segments {
            let mut off = 0u32;
            for t in 0..ncomp / 3 {
                let code = bits.get(8, "step code")? as u8;
                let scale = step(code);
                if scale == 0.0 || !scale.is_finite() {
                    return format_err(format!(
                        "segment {s}, animated track {t}: step code {code} gives no usable step"
                    ));
                }
                for c in 0..3 {
                    let k = 3 * t + c;
                    let width = bits.get(6, "value width")? as u32;
                    if width > MAX_WIDTH {
                        return format_err(format!(
                            "segment {s}, animated track {t}, component {c}: width {width} bits, expected at most {MAX_WIDTH}"
                        ));
                    }
                    let d = unzigzag(bits.rice(width.max(1) - 1, "least value")?);
                    let (pm, pc) = prev[k];
                    let q_min = if s == 0 { 0 } else { predict_min(pm, pc, code) }.saturating_add(d);
                    if q_min.unsigned_abs() > 1 << 50 {
                        return format_err(format!(
                            "segment {s}, animated track {t}, component {c}: least value {q_min} out of range"
                        ));
                    }
                    prev[k] = (q_min, code);
                    comps.push(Comp {
                        base: q_min as f32 * scale,
                        scale,
                        mask: if width == 0 { 0 } else { (1u64 << width) - 1 },
                        off,
                    });
                    off += width;
                }
            }
            frame_bits.push(off as usize);
        }
        if bits.bit.div_ceil(8) != headers.len() {
            return format_err(format!(
                "segment headers at byte {}: {} bytes announced, {} used",
                headers_at + 4,
                headers.len(),
                bits.bit.div_ceil(8)
            ));
        }
        let data_at = r.pos + 4;
        let data_len = r.u32("data length")? as usize;
        let data = r.take(data_len, "segment data")?;
        let mut seg_start = Vec::with_capacity(segments);
        let mut at = 0usize;
        for (s, &fb) in frame_bits.iter().enumerate() {
            seg_start.push(at);
            let frames = segment_len.min(num_frames - s * segment_len);
            at += (frames * fb).div_ceil(8);
        }
        if at + PAD != data.len() {
            return format_err(format!(
                "segment data at byte {data_at}: {} bytes, the segment headers need {} and {PAD} of padding",
                data.len(),
                at
            ));
        }
        if r.pos != body.len() {
            return format_err(format!("{} bytes after the segment data (at byte {})", body.len() - r.pos, r.pos));
        }
        let mut animated_rot: Vec<usize> = slot.iter().filter(|&&s| s % 6 < 3).map(|&s| s / 6).collect();
        animated_rot.sort_unstable();
        animated_rot.dedup();
        let rest_rot = (0..joints.len()).map(|j| exp_map([rest[6 * j], rest[6 * j + 1], rest[6 * j + 2]])).collect();
        Ok(Clip { data, head, ncomp, comps, seg_start, frame_bits, slot, rest, animated_rot, rest_rot })
    }

    pub fn joints(&self) -> &[Joint] {
        &self.head.joints
    }
    pub fn num_joints(&self) -> usize {
        self.head.joints.len()
    }
    pub fn num_frames(&self) -> usize {
        self.head.num_frames
    }
    /// Seconds per frame.
    pub fn frame_time(&self) -> f64 {
        self.head.frame_time
    }
    /// Seconds from the first frame to the last.
    pub fn duration(&self) -> f64 {
        (self.head.num_frames - 1) as f64 * self.head.frame_time
    }
    pub fn segment_len(&self) -> usize {
        self.head.segment_len
    }
    /// Centimetres per length unit of the translations.
    pub fn cm_per_unit(&self) -> f64 {
        self.head.cm_per_unit
    }
    /// The virtual-vertex error bound (cm) the file was compressed to.
    pub fn bound_cm(&self) -> f64 {
        self.head.bound_cm
    }
    /// Per track: joint, whether a rotation, and its value when constant (file order).
    pub fn tracks(&self) -> &[(usize, bool, Option<[f32; 3]>)] {
        &self.head.tracks
    }
    /// The header fields, the skeleton and the tracks, as [`read_head`] read them.
    pub fn head(&self) -> &Head {
        &self.head
    }

    /// Decodes frame `f` into `vals` (6 per joint: rotation vector, translation), from the rest
    /// values and the animated components.
    #[inline]
    fn decode_frame(&self, f: usize, vals: &mut [f32]) {
        let seg = f / self.head.segment_len;
        let i = f - seg * self.head.segment_len;
        let comps = &self.comps[seg * self.ncomp..(seg + 1) * self.ncomp];
        let bit0 = self.seg_start[seg] * 8 + i * self.frame_bits[seg];
        let data = self.data;
        for (c, &s) in comps.iter().zip(&self.slot) {
            let bit = bit0 + c.off as usize;
            let at = bit >> 3;
            debug_assert!(at + 8 <= data.len());
            // SAFETY: `Clip::open` checked that every component of every frame lies in the data,
            // which ends with 8 padding bytes, so `at + 8 <= data.len()` (asserted in debug builds).
            let word = u64::from_le(unsafe { data.as_ptr().add(at).cast::<u64>().read_unaligned() });
            let u = (word >> (bit & 7)) & c.mask;
            // u < 2^MAX_WIDTH: as a signed integer it converts to the same f32 in one instruction.
            vals[s] = c.base + (u as i64) as f32 * c.scale;
        }
    }

    /// The rotation vectors and translations of frame `f` (6 values per joint), as every
    /// sample of it decodes: what the encoder checks its bound on.
    pub fn frame_values(&self, f: usize, out: &mut Vec<f32>) {
        out.clear();
        out.extend_from_slice(&self.rest);
        self.decode_frame(f.min(self.head.num_frames - 1), out);
    }

    /// Decodes frame `f` into a slot of `ctx` (values, then quaternions). Joints with a constant
    /// rotation keep the quaternion [`Context::bind`] set from the rest values.
    fn fill(&self, f: usize, slot: &mut Frame) {
        self.decode_frame(f, &mut slot.vals);
        // Eight joints at a time in lanes (the compiler vectorises the lane loops): the same
        // operations on each as `exp_map`, so the same quaternions.
        for chunk in self.animated_rot.chunks(LANES) {
            let mut v = [[0.0f32; LANES]; 3];
            for (k, &j) in chunk.iter().enumerate() {
                for (c, lane) in v.iter_mut().enumerate() {
                    lane[k] = slot.vals[6 * j + c];
                }
            }
            let q = exp_map_lanes(&v);
            for (k, &j) in chunk.iter().enumerate() {
                for (c, lane) in q.iter().enumerate() {
                    slot.rot[c][j] = lane[k];
                }
            }
        }
        slot.frame = f;
    }

    /// The local pose at `time` seconds (clamped to the clip; not finite: the first frame):
    /// the two frames around it, rotations by normalised linear interpolation (shortest way),
    /// translations linearly, as ACL samples. Writes `rotations` (x, y, z, w) and `translations`
    /// of every joint; both must hold [`Clip::num_joints`] entries. A frame decoded by the
    /// previous call with the same context is not decoded again, so playing forwards decodes
    /// each frame once.
    pub fn sample(
        &self,
        ctx: &mut Context,
        time: f64,
        rotations: &mut [[f32; 4]],
        translations: &mut [[f32; 3]],
    ) -> Result<()> {
        let nj = self.head.joints.len();
        if rotations.len() != nj || translations.len() != nj {
            return Err(IbkError::Buffer(format!(
                "pose buffers hold {} rotations and {} translations; the clip has {nj} joints",
                rotations.len(),
                translations.len()
            )));
        }
        ctx.bind(self);
        let x = if time.is_finite() {
            (time / self.head.frame_time).clamp(0.0, (self.head.num_frames - 1) as f64)
        } else {
            0.0
        };
        let f0 = (x as usize).min(self.head.num_frames - 1);
        let f1 = (f0 + 1).min(self.head.num_frames - 1);
        let u = (x - f0 as f64) as f32;
        // Reuse what the last call decoded: the same frames, or its second frame as our first.
        if ctx.a.frame != f0 {
            if ctx.b.frame == f0 {
                std::mem::swap(&mut ctx.a, &mut ctx.b);
            } else {
                self.fill(f0, &mut ctx.a);
            }
        }
        if u == 0.0 || f1 == f0 {
            let r = &ctx.a.rot;
            for j in 0..nj {
                rotations[j] = [r[0][j], r[1][j], r[2][j], r[3][j]];
                let t = &ctx.a.vals[6 * j + 3..6 * j + 6];
                translations[j] = [t[0], t[1], t[2]];
            }
            return Ok(());
        }
        if ctx.b.frame != f1 {
            self.fill(f1, &mut ctx.b);
        }
        let (a, b) = (&ctx.a, &ctx.b);
        // Rotations by normalised linear interpolation, `LANES` joints at a time (the rotation
        // buffers are padded to whole lanes; the same operations on each lane as one at a time).
        let w0 = 1.0 - u;
        for j0 in (0..nj).step_by(LANES) {
            let lane = |r: &[Vec<f32>; 4], c: usize| -> [f32; LANES] {
                r[c][j0..j0 + LANES].try_into().expect("rotation buffers hold whole lanes")
            };
            let (p, q) = ([0, 1, 2, 3].map(|c| lane(&a.rot, c)), [0, 1, 2, 3].map(|c| lane(&b.rot, c)));
            let mut out = [[0.0f32; LANES]; 4];
            for k in 0..LANES {
                let dot = p[0][k] * q[0][k] + p[1][k] * q[1][k] + p[2][k] * q[2][k] + p[3][k] * q[3][k];
                let w1 = if dot < 0.0 { -u } else { u };
                let r = [0, 1, 2, 3].map(|c| p[c][k] * w0 + q[c][k] * w1);
                let n = 1.0 / (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]).sqrt();
                for c in 0..4 {
                    out[c][k] = r[c] * n;
                }
            }
            for (k, rot) in rotations[j0..(j0 + LANES).min(nj)].iter_mut().enumerate() {
                *rot = [out[0][k], out[1][k], out[2][k], out[3][k]];
            }
        }
        for (j, t) in translations.iter_mut().enumerate() {
            let (ta, tb) = (&a.vals[6 * j + 3..6 * j + 6], &b.vals[6 * j + 3..6 * j + 6]);
            *t = [ta[0] + (tb[0] - ta[0]) * u, ta[1] + (tb[1] - ta[1]) * u, ta[2] + (tb[2] - ta[2]) * u];
        }
        Ok(())
    }
}

/// One decoded frame: values (6 per joint) and rotation quaternions by component (x, y, z, w),
/// each padded with identities to a whole number of `LANES`.
#[derive(Clone, Debug)]
struct Frame {
    frame: usize,
    vals: Vec<f32>,
    rot: [Vec<f32>; 4],
}

/// What [`Clip::sample`] keeps between calls: the two frames it decoded last. Made once per
/// playing instance (its buffers are the only allocation); used with another clip, it starts
/// over there.
#[derive(Clone, Debug)]
pub struct Context {
    clip: (usize, usize),
    a: Frame,
    b: Frame,
}

impl Context {
    /// A context sized for `clip`.
    pub fn new(clip: &Clip) -> Context {
        let mut c = Context {
            clip: (0, 0),
            a: Frame { frame: usize::MAX, vals: Vec::new(), rot: Default::default() },
            b: Frame { frame: usize::MAX, vals: Vec::new(), rot: Default::default() },
        };
        c.bind(clip);
        c
    }

    /// Resets the cached frames when `clip` is not the one they came from.
    fn bind(&mut self, clip: &Clip) {
        let key = (clip.data.as_ptr() as usize, clip.data.len());
        if self.clip != key || self.a.vals.len() != clip.rest.len() {
            self.clip = key;
            for f in [&mut self.a, &mut self.b] {
                f.frame = usize::MAX;
                f.vals.clear();
                f.vals.extend_from_slice(&clip.rest);
                let padded = clip.rest_rot.len().div_ceil(LANES) * LANES;
                for (c, comp) in f.rot.iter_mut().enumerate() {
                    comp.clear();
                    comp.extend(clip.rest_rot.iter().map(|q| q[c]));
                    comp.resize(padded, if c == 3 { 1.0 } else { 0.0 });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_quarter_octaves_and_exact_powers_of_two_at_multiples_of_four() {
        assert_eq!(step(192), 1.0);
        assert_eq!(step(196), 2.0);
        assert_eq!(step(188), 0.5);
        assert_eq!(step(0), 2f32.powi(-48));
        for c in 1..=255u8 {
            let r = step(c) as f64 / step(c - 1) as f64;
            assert!((r - 2f64.powf(0.25)).abs() < 1e-6, "code {c}: ratio {r}");
        }
    }

    #[test]
    fn the_exp_map_polynomial_is_the_exact_quaternion_within_f32_rounding() {
        for i in 0..=400 {
            let theta = std::f64::consts::PI * i as f64 / 400.0;
            let axis = [0.48f64, -0.6, 0.64];
            let v = axis.map(|a| (a * theta) as f32);
            let q = exp_map(v);
            let th = (v.iter().map(|&x| (x as f64).powi(2)).sum::<f64>()).sqrt();
            let (s, c) = ((th / 2.0).sin(), (th / 2.0).cos());
            let want = [axis[0] * s, axis[1] * s, axis[2] * s, c];
            for k in 0..4 {
                assert!((q[k] as f64 - want[k]).abs() < 3e-7, "θ = {theta}: {q:?} vs {want:?}");
            }
        }
    }
}
