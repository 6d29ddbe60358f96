//! `.ibk` version 4: version 3's samples and step search in a layout made for sampling at run
//! time, as ACL lays out its clips: per segment, every value a fixed number of bits (per track
//! component and segment) after a per-segment least value, all values of one frame together, so
//! one pose at any time is two frames' loads, shifts and multiply-adds, with no entropy decoding
//! and no work that grows with the position in the segment. The byte layout is documented in the
//! runtime crate that reads it ([`inbetween_ibk`], which also has the C ABI); this module writes
//! it and turns files back into clips.
//!
//! Values decode in f32 (`base + u × scale`, rotation vectors through the polynomial
//! [`inbetween_ibk::exp_map`]); the encoder ([`super::v3_encode`] with [`super::v3_encode::Format::V4`])
//! searches its steps on exactly those values, so the bound holds for what the runtime returns
//! (rotations normalised in f64 before the error is measured; the runtime's f32 quaternions are
//! unit to within about 1e-7).
//!
//! Compared with version 3 a file is larger (fixed widths instead of Rice codes of prediction
//! residuals); version 3 stays the format for storage, version 4 for playing back.

use super::runtime_error;
use super::v3::{Header, Quantised, TrackKind};
use crate::Result;
use glam::{DQuat, DVec3};
use inbetween_core::{Motion, Pose};
pub use inbetween_ibk::{exp_map, step, Clip, Context, MAX_WIDTH, VERSION};

/// Frames per segment written by default (see the module doc of the bench for how it was chosen).
pub const DEFAULT_SEGMENT_LEN: usize = 16;

/// The f64 rotation the runtime's f32 exp map gives for a rotation vector (normalised).
pub fn rotation(v: [f32; 3]) -> DQuat {
    let q = exp_map(v);
    DQuat::from_xyzw(q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64).normalize()
}

/// Values of one component over a segment as the runtime decodes them, from quantised values
/// `q` at step code `code`: `(q_min as f32 × scale) + (q − q_min) as f32 × scale`.
pub fn dequantise(q: &[i64], code: u8, out: &mut [f32]) {
    let scale = step(code);
    let q_min = q.iter().copied().min().unwrap_or(0);
    let base = q_min as f32 * scale;
    for (o, &x) in out.iter_mut().zip(q) {
        *o = base + (x - q_min) as f32 * scale;
    }
}

fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

/// Appends bits LSB first.
struct Bits {
    bytes: Vec<u8>,
    acc: u128,
    n: u32,
}

impl Bits {
    fn new() -> Bits {
        Bits { bytes: Vec::new(), acc: 0, n: 0 }
    }
    fn put(&mut self, v: u64, count: u32) {
        if count == 0 {
            return;
        }
        let m = if count >= 64 { u64::MAX } else { (1u64 << count) - 1 };
        self.acc |= ((v & m) as u128) << self.n;
        self.n += count;
        while self.n >= 8 {
            self.bytes.push(self.acc as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }
    /// Rice code with the escape of version 3 (24 ones, 6-bit length, bits).
    fn rice(&mut self, u: u64, k: u32) {
        let q = u >> k;
        if q < 24 {
            for _ in 0..q {
                self.put(1, 1);
            }
            self.put(0, 1);
            self.put(u, k);
        } else {
            for _ in 0..24 {
                self.put(1, 1);
            }
            let len = 64 - u.leading_zeros();
            self.put(len as u64, 6);
            self.put(u, len);
        }
    }
    fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            self.bytes.push(self.acc as u8);
        }
        self.bytes
    }
}

fn width(range: u64) -> u32 {
    64 - range.leading_zeros()
}

/// Writes a version 4 file of a quantised clip (steps and values chosen by the encoder for
/// version 4; constant tracks as in version 3).
pub fn encode(qz: &Quantised) -> Vec<u8> {
    let h = &qz.header;
    let nt = h.tracks.len();
    let animated: Vec<usize> = (0..nt).filter(|&t| h.constants[t].is_none()).collect();
    let segments = qz.num_segments();
    let mut out = Vec::new();
    h.write_head(&mut out, VERSION);
    let mut headers = Bits::new();
    let mut data = Vec::new();
    let mut prev: Vec<(i64, u8)> = vec![(0, 0); 3 * animated.len()];
    for s in 0..segments {
        let start = s * h.segment_len;
        let end = (start + h.segment_len).min(h.num_frames);
        // Per component: least value and width.
        let mut comps: Vec<(i64, u32)> = Vec::with_capacity(3 * animated.len());
        for (a, &t) in animated.iter().enumerate() {
            let code = qz.codes[s * nt + t];
            headers.put(code as u64, 8);
            for c in 0..3 {
                let vals = (start..end).map(|f| qz.q[f * nt + t][c]);
                let (lo, hi) = vals.fold((i64::MAX, i64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
                let w = width((hi - lo) as u64);
                let k = 3 * a + c;
                let pred = if s == 0 { 0 } else { inbetween_ibk::predict_min(prev[k].0, prev[k].1, code) };
                headers.put(w as u64, 6);
                headers.rice(zigzag(lo - pred), w.max(1) - 1);
                prev[k] = (lo, code);
                comps.push((lo, w));
            }
        }
        let mut seg = Bits::new();
        for f in start..end {
            for (a, &t) in animated.iter().enumerate() {
                for c in 0..3 {
                    let (lo, w) = comps[3 * a + c];
                    seg.put((qz.q[f * nt + t][c] - lo) as u64, w);
                }
            }
        }
        data.extend(seg.finish());
    }
    data.extend_from_slice(&[0u8; 8]);
    let headers = headers.finish();
    out.extend_from_slice(&(headers.len() as u32).to_le_bytes());
    out.extend_from_slice(&headers);
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(&data);
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// The values of frame `f` (6 per joint: rotation vector, translation) as the encoder computes
/// them from its quantised clip, without a file: rest values, constant tracks, and each animated
/// component dequantised over its segment ([`dequantise`]). The runtime must return exactly these.
pub fn encoder_frame(qz: &Quantised, f: usize) -> Vec<f32> {
    let h = &qz.header;
    let nt = h.tracks.len();
    let mut out: Vec<f32> = h
        .skeleton
        .joints()
        .iter()
        .flat_map(|j| [0.0, 0.0, 0.0].into_iter().chain(j.offset.to_array().map(|x| x as f32)))
        .collect();
    let seg = f / h.segment_len;
    let (start, end) = (seg * h.segment_len, ((seg + 1) * h.segment_len).min(h.num_frames));
    let (mut q, mut v) = (vec![0i64; end - start], vec![0f32; end - start]);
    for (t, tr) in h.tracks.iter().enumerate() {
        let at = 6 * tr.joint + if tr.kind == TrackKind::Rotation { 0 } else { 3 };
        match h.constants[t] {
            Some(c) => out[at..at + 3].copy_from_slice(&c),
            None => {
                for c in 0..3 {
                    q.iter_mut().enumerate().for_each(|(i, x)| *x = qz.q[(start + i) * nt + t][c]);
                    dequantise(&q, qz.codes[seg * nt + t], &mut v);
                    out[at + c] = v[f - start];
                }
            }
        }
    }
    out
}

/// A decoded version 4 file: its header (skeleton, tracks, constants) and every frame's local
/// pose as the runtime decodes it (rotations normalised in f64).
#[derive(Clone, Debug)]
pub struct Decoded {
    pub header: Header,
    pub poses: Vec<Pose>,
}

impl Decoded {
    /// The clip as a motion (BVH channels; rotations through each joint's Euler order).
    pub fn motion(&self) -> Result<Motion> {
        Ok(Motion::from_poses(self.header.skeleton.clone(), self.header.frame_time, &self.poses)?)
    }
}

/// The local pose of frame `f` of an opened clip, as [`Decoded`] holds it.
pub fn frame_pose(clip: &Clip, f: usize, vals: &mut Vec<f32>, out: &mut Pose) {
    clip.frame_values(f, vals);
    let nj = clip.num_joints();
    out.rotations.resize(nj, DQuat::IDENTITY);
    out.translations.resize(nj, DVec3::ZERO);
    for j in 0..nj {
        let v = &vals[6 * j..6 * j + 6];
        out.rotations[j] = rotation([v[0], v[1], v[2]]);
        out.translations[j] = DVec3::new(v[3] as f64, v[4] as f64, v[5] as f64);
    }
}

/// Decodes a whole version 4 file: the runtime opens it (every check, the one reader of the
/// layout) and decodes every frame; the engine's skeleton is made from the joints it read.
pub fn decode(bytes: &[u8]) -> Result<Decoded> {
    let clip = Clip::open(bytes).map_err(runtime_error)?;
    let header = Header::from_head(clip.head())?;
    let mut vals = Vec::new();
    let poses = (0..clip.num_frames())
        .map(|f| {
            let mut p = Pose { rotations: Vec::new(), translations: Vec::new() };
            frame_pose(&clip, f, &mut vals, &mut p);
            p
        })
        .collect();
    Ok(Decoded { header, poses })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codec::v3_encode::{compress, Format, Options};
    use inbetween_core::procedural::{gait, GaitParams};
    use rand::{Rng, SeedableRng};

    fn walk() -> Motion {
        let mut p = GaitParams::walk();
        p.frames = 61;
        p.fps = 24.0;
        gait(&p)
    }

    /// Every frame sampled from the file is the encoder's, and between frames the sample lies
    /// between them (normalised lerp of the two frames' rotations, lerp of translations).
    #[test]
    fn the_runtime_returns_the_encoders_values_and_interpolates_between_frames() {
        let m = walk();
        for seg in [1, 7, 16, 64] {
            let c = compress(&m, &Options { segment_len: seg, ..Options::with_format(0.05, Format::V4) }).unwrap();
            assert_eq!(&c.bytes[4..6], &4u16.to_le_bytes());
            let clip = Clip::open(&c.bytes).unwrap();
            let mut vals = Vec::new();
            for f in 0..clip.num_frames() {
                clip.frame_values(f, &mut vals);
                assert_eq!(vals, encoder_frame(&c.quantised, f), "segments of {seg}, frame {f}");
            }
            let n = clip.num_joints();
            let mut ctx = Context::new(&clip);
            let (mut rot, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
            let t = 10.5 * clip.frame_time();
            clip.sample(&mut ctx, t, &mut rot, &mut tr).unwrap();
            let (a, b) = (encoder_frame(&c.quantised, 10), encoder_frame(&c.quantised, 11));
            for j in 0..n {
                for k in 0..3 {
                    let mid = (a[6 * j + 3 + k] + b[6 * j + 3 + k]) / 2.0;
                    assert!((tr[j][k] - mid).abs() <= 1e-5 * (1.0 + mid.abs()));
                }
                let (qa, qb) =
                    (exp_map([a[6 * j], a[6 * j + 1], a[6 * j + 2]]), exp_map([b[6 * j], b[6 * j + 1], b[6 * j + 2]]));
                let dot = (0..4).map(|k| qa[k] * qb[k]).sum::<f32>().signum();
                let mid: Vec<f32> = (0..4).map(|k| qa[k] + dot * qb[k]).collect();
                let norm = mid.iter().map(|x| x * x).sum::<f32>().sqrt();
                for k in 0..4 {
                    assert!((rot[j][k] - mid[k] / norm).abs() < 1e-6, "joint {j}");
                }
            }
            // Wrong buffer sizes are an error, not a panic.
            assert!(clip.sample(&mut ctx, 0.0, &mut rot[..n - 1], &mut tr).is_err());
        }
    }

    /// The sampler works on eight joints at a time; each sample is the one-joint formula's (the
    /// frames' values through `exp_map`, normalised lerp, lerp of translations), bit for bit,
    /// on skeletons whose joint counts do and do not fill whole lanes.
    #[test]
    fn samples_are_the_one_joint_formulas_bit_for_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for joints in [None, Some(9), Some(16), Some(17)] {
            let mut m = walk();
            if let Some(keep) = joints {
                m = inbetween_core::Motion::from_poses(
                    inbetween_core::Skeleton::new(m.skeleton.joints()[..keep].to_vec()).unwrap(),
                    m.frame_time,
                    &(0..m.num_frames())
                        .map(|f| {
                            let p = m.pose(f);
                            inbetween_core::Pose {
                                rotations: p.rotations[..keep].to_vec(),
                                translations: p.translations[..keep].to_vec(),
                            }
                        })
                        .collect::<Vec<_>>(),
                )
                .unwrap();
            }
            let c = compress(&m, &Options::with_format(0.05, Format::V4)).unwrap();
            let clip = Clip::open(&c.bytes).unwrap();
            let n = clip.num_joints();
            let mut ctx = Context::new(&clip);
            let (mut rot, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for _ in 0..200 {
                let t = rng.random::<f64>() * clip.duration();
                clip.sample(&mut ctx, t, &mut rot, &mut tr).unwrap();
                let x = t / clip.frame_time();
                let f0 = x as usize;
                let f1 = (f0 + 1).min(clip.num_frames() - 1);
                let u = (x - f0 as f64) as f32;
                clip.frame_values(f0, &mut a);
                clip.frame_values(f1, &mut b);
                for j in 0..n {
                    let p = exp_map([a[6 * j], a[6 * j + 1], a[6 * j + 2]]);
                    let q = exp_map([b[6 * j], b[6 * j + 1], b[6 * j + 2]]);
                    let (want_r, want_t) = if u == 0.0 || f1 == f0 {
                        (p, [a[6 * j + 3], a[6 * j + 4], a[6 * j + 5]])
                    } else {
                        let dot = p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3];
                        let w1 = if dot < 0.0 { -u } else { u };
                        let w0 = 1.0 - u;
                        let r = [0, 1, 2, 3].map(|k| p[k] * w0 + q[k] * w1);
                        let norm = 1.0 / (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]).sqrt();
                        let lerp = |k: usize| a[6 * j + 3 + k] + (b[6 * j + 3 + k] - a[6 * j + 3 + k]) * u;
                        (r.map(|v| v * norm), [lerp(0), lerp(1), lerp(2)])
                    };
                    assert_eq!(rot[j].map(f32::to_bits), want_r.map(f32::to_bits), "{n} joints, time {t}, joint {j}");
                    assert_eq!(tr[j].map(f32::to_bits), want_t.map(f32::to_bits), "{n} joints, time {t}, joint {j}");
                }
            }
        }
    }

    /// A context reused across random times and playback gives what a fresh one gives.
    #[test]
    fn a_reused_context_gives_the_samples_of_a_fresh_one() {
        let c = compress(&walk(), &Options::with_format(0.1, Format::V4)).unwrap();
        let clip = Clip::open(&c.bytes).unwrap();
        let n = clip.num_joints();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let forwards = (0..).map(|k| k as f64 / 60.0).take_while(|&t| t <= clip.duration() + 0.05);
        let random: Vec<f64> = (0..300).map(|_| rng.random::<f64>() * clip.duration()).collect();
        let mut ctx = Context::new(&clip);
        let (mut rot, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
        let (mut rot1, mut tr1) = (rot.clone(), tr.clone());
        for t in forwards.chain(random).chain([-1.0, f64::NAN, f64::INFINITY, 1e12]) {
            clip.sample(&mut ctx, t, &mut rot, &mut tr).unwrap();
            clip.sample(&mut Context::new(&clip), t, &mut rot1, &mut tr1).unwrap();
            assert_eq!((&rot, &tr), (&rot1, &tr1), "time {t}");
        }
    }

    /// Truncated and bit-flipped files: a clear error naming what is wrong, never a panic; with
    /// the checksum fixed up, the structural checks answer.
    #[test]
    fn truncated_and_damaged_files_are_refused_with_a_message() {
        let good = compress(&walk(), &Options::with_format(0.05, Format::V4)).unwrap().bytes;
        for n in 0..good.len() {
            let e = Clip::open(&good[..n]).err().unwrap_or_else(|| panic!("a prefix opens"));
            assert!(!e.to_string().is_empty());
            assert!(crate::codec::read(&good[..n]).is_err());
        }
        for i in 0..good.len() {
            let mut b = good.clone();
            b[i] ^= 0x04;
            let e = Clip::open(&b).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(e.contains("checksum") || e.contains("magic") || e.contains("version"), "byte {i}: {e}");
        }
        let body = &good[..good.len() - 4];
        let fix = |mut b: Vec<u8>| {
            let crc = crc32fast::hash(&b);
            b.extend_from_slice(&crc.to_le_bytes());
            b
        };
        for n in 8..body.len() {
            let e =
                Clip::open(&fix(body[..n].to_vec())).err().unwrap_or_else(|| panic!("a cut body opens")).to_string();
            assert!(e.contains("truncated") || e.contains("byte") || e.contains("segment"), "cut at {n}: {e}");
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let mut accepted = 0;
        for _ in 0..3000 {
            let mut b = body.to_vec();
            for _ in 0..rng.random_range(1..4) {
                let i = rng.random_range(6..b.len());
                b[i] ^= 1 << rng.random_range(0..8);
            }
            let file = fix(b);
            if let Ok(clip) = Clip::open(&file) {
                accepted += 1;
                let n = clip.num_joints();
                let mut ctx = Context::new(&clip);
                let (mut rot, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
                for t in [0.0, 0.77, 1e9] {
                    clip.sample(&mut ctx, t, &mut rot, &mut tr).unwrap();
                }
                let _ = decode(&file);
            }
        }
        assert!(accepted > 0, "flips inside the packed values still open");
    }
}
