use super::*;
use crate::metrics::SegmentModel;
use inbetween_core::positions_clip;
use inbetween_core::procedural::{gait, GaitParams, CM_PER_CMU_UNIT};
use rand::{Rng, SeedableRng};

/// Version 3's skeleton block: exact in both length formats, smaller than version 2's, and
/// a damaged block is refused with a message.
#[test]
fn compact_skeletons_read_back_exactly_in_both_length_formats() {
    let base = gait(&GaitParams::walk()).skeleton;
    let remap = |f: &dyn Fn(f64) -> f64| {
        let joints = base
            .joints()
            .iter()
            .map(|j| Joint { offset: j.offset.map(f), end_site: j.end_site.map(|e| e.map(f)), ..j.clone() })
            .collect();
        Skeleton::new(joints).unwrap()
    };
    let decimal = remap(&|x| (x * 1e4).round() / 1e4);
    let binary = remap(&|x| x / 3.0 + 1e-9);
    assert!(decimal.joints().iter().all(|j| j.offset.to_array().iter().all(|&x| as_decimal(x).is_some())));
    assert!(binary.joints().iter().any(|j| as_decimal(j.offset.x).is_none()));
    let mut sizes = Vec::new();
    for sk in [&decimal, &binary] {
        let mut out = Vec::new();
        write_compact_skeleton(&mut out, sk);
        let back = read_compact_skeleton(&mut Reader::new(&out)).unwrap();
        assert_eq!(&back, sk);
        let mut v2 = Vec::new();
        write_skeleton(&mut v2, sk);
        assert!(out.len() < v2.len(), "{} vs {}", out.len(), v2.len());
        sizes.push(out.len());
        // Every truncation and a damaged deflate stream or length: an error, never a panic.
        for n in 0..out.len() {
            assert!(read_compact_skeleton(&mut Reader::new(&out[..n])).is_err());
        }
        let mut bad = out.clone();
        bad[0..4].copy_from_slice(&(u32::MAX).to_le_bytes());
        let e = read_compact_skeleton(&mut Reader::new(&bad)).unwrap_err().to_string();
        assert!(e.contains("skeleton at byte 0"), "{e}");
        for i in 8..out.len() {
            let mut bad = out.clone();
            bad[i] ^= 0x5a;
            let _ = read_compact_skeleton(&mut Reader::new(&bad));
        }
    }
    assert!(sizes[0] < sizes[1], "decimal lengths are smaller: {sizes:?}");
}

fn clip() -> (Motion, RotationMotion, KeyframeSet) {
    let mut p = GaitParams::run();
    p.frames = 50;
    let m = gait(&p);
    let rm = RotationMotion::from_motion(&m).unwrap();
    let keys = KeyframeSet::new(vec![7, 19, 33, 41], 50).unwrap();
    (m, rm, keys)
}

fn skeleton_bytes(s: &Skeleton) -> usize {
    s.joints()
        .iter()
        .map(|j| 2 + j.name.len() + 2 + 24 + 1 + j.channels.len() + 1 + if j.end_site.is_some() { 24 } else { 0 })
        .sum()
}

#[test]
fn round_trip_rebuilds_exactly_what_the_quantised_model_predicts() {
    let (m, rm, keys) = clip();
    let bytes = encode(&rm, &keys);
    let header = 4 + 4 + 8 + 4 + 4 + 2;
    let expected = header + skeleton_bytes(&m.skeleton) + keys.len() + keys.len() * bytes_per_key(&m.skeleton) + 4;
    assert_eq!(bytes.len(), expected);
    assert_eq!(bytes_per_key(&m.skeleton), 4 + 31 * 12 + 24);
    let d = decode(&bytes).unwrap();
    assert_eq!(d.key_frames, keys.frames());
    assert_eq!(d.skeleton, m.skeleton);
    let rec = d.reconstruct().unwrap();
    assert_eq!(rec.num_frames(), 50);
    // The quantised model predicts the decoded clip: same frames to rounding.
    let q = quantised_model(&rm);
    let predicted = q.reconstruct(&keys).unwrap();
    let e = inbetween_core::position_error(&positions_clip(&predicted), &positions_clip(&rec));
    assert!(e.max * CM_PER_CMU_UNIT < 1e-9, "prediction off by {} cm", e.max * CM_PER_CMU_UNIT);
    // Quantisation moves the clip by well under a millimetre.
    let exact = rm.reconstruct(&keys).unwrap();
    let e = inbetween_core::position_error(&positions_clip(&exact), &positions_clip(&rec));
    assert!(e.max * CM_PER_CMU_UNIT < 0.05, "quantisation costs {} cm", e.max * CM_PER_CMU_UNIT);
    // Four interior keys over 50 frames of a run (gaps up to 14 frames) leave centimetres of
    // error (41 cm at worst), and the model's segment sums say how much the decoded file has.
    let source = positions_clip(&m);
    let decoded = inbetween_core::position_error(&source, &positions_clip(&rec));
    let planned = q.error(&keys);
    assert!(planned.max_cm > 10.0 && planned.max_cm < 60.0, "{planned:?}");
    assert!(planned.mean_cm > 1.0 && planned.mean_cm < 6.0, "{planned:?}");
    assert!((decoded.max * CM_PER_CMU_UNIT - planned.max_cm).abs() < 0.05, "{} vs {planned:?}", decoded.max);
}

#[test]
fn version_1_files_still_decode() {
    let (_, rm, keys) = clip();
    let v2 = decode(&encode(&rm, &keys)).unwrap();
    // Version 1: one file-wide scale after the key count, none per key.
    let scale = keys.frames().iter().map(|&f| key_scale(&rm.frames[f])).fold(0.0f32, f32::max);
    let mut v1 = Vec::new();
    v1.extend_from_slice(MAGIC);
    v1.extend_from_slice(&1u16.to_le_bytes());
    v1.extend_from_slice(&0u16.to_le_bytes());
    v1.extend_from_slice(&rm.frame_time.to_le_bytes());
    v1.extend_from_slice(&(rm.num_frames() as u32).to_le_bytes());
    v1.extend_from_slice(&(keys.len() as u32).to_le_bytes());
    v1.extend_from_slice(&scale.to_le_bytes());
    write_skeleton(&mut v1, &rm.skeleton);
    let mut prev = 0;
    for &f in keys.frames() {
        write_varint(&mut v1, (f - prev) as u64);
        prev = f;
    }
    for &f in keys.frames() {
        write_key(&mut v1, &rm.skeleton, &rm.frames[f], scale as f64);
    }
    let crc = crc32fast::hash(&v1);
    v1.extend_from_slice(&crc.to_le_bytes());
    let old = decode(&v1).unwrap();
    assert_eq!(old.key_frames, v2.key_frames);
    for (a, b) in old.keys.iter().zip(&v2.keys) {
        assert_eq!(a.rotations, b.rotations);
        for (wa, wb) in a.angular_velocities.iter().zip(&b.angular_velocities) {
            assert!((*wa - *wb).abs().max_element() <= 2.0 * scale as f64 / 32767.0);
        }
    }
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
    let mut v9 = bytes.clone();
    v9[4] = 9;
    assert!(msg(&v9).contains("version 9"));
    // A truncated body with a valid checksum still fails on lengths, naming the byte.
    let mut cut = bytes[..bytes.len() - 40].to_vec();
    let crc = crc32fast::hash(&cut);
    cut.extend_from_slice(&crc.to_le_bytes());
    assert!(msg(&cut).contains("truncated"), "{}", msg(&cut));
    for n in 0..bytes.len() {
        assert!(decode(&bytes[..n]).is_err(), "prefix of {n} bytes decoded");
    }
}

/// With its checksum fixed up, `body` reaches the structural checks.
fn with_crc(mut body: Vec<u8>) -> Vec<u8> {
    let crc = crc32fast::hash(&body);
    body.extend_from_slice(&crc.to_le_bytes());
    body
}

/// What the fuzz target (`fuzz/fuzz_targets/ibk.rs`) does, on seeded random inputs, so that CI
/// runs it: random bytes, and valid files with random bytes changed, cut or a huge header
/// value, all behind a valid checksum. Decoding must return, never panic or allocate wildly.
#[test]
fn decoding_arbitrary_bytes_never_panics() {
    let (_, rm, keys) = clip();
    let good = encode(&rm, &keys);
    let body = &good[..good.len() - 4];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let mut accepted = 0;
    for case in 0..3000 {
        let bytes = match case % 4 {
            0 => {
                let n = rng.random_range(0..200);
                let mut b: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                if n >= 6 && rng.random_bool(0.5) {
                    b[..4].copy_from_slice(MAGIC);
                    b[4] = 2;
                    b[5] = 0;
                }
                with_crc(b)
            }
            1 => {
                let mut b = body.to_vec();
                for _ in 0..rng.random_range(1..6) {
                    let i = rng.random_range(6..b.len());
                    b[i] = rng.random();
                }
                with_crc(b)
            }
            2 => with_crc(body[..rng.random_range(0..body.len())].to_vec()),
            _ => {
                let mut b = body.to_vec();
                let at = rng.random_range(8..24);
                b[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
                with_crc(b)
            }
        };
        if let Ok(d) = decode(&bytes) {
            accepted += 1;
            if d.num_frames * d.skeleton.len() <= 100_000 {
                let _ = d.reconstruct();
            }
        }
    }
    assert!(accepted > 0, "some single-byte changes (e.g. in key values) still decode");
}
