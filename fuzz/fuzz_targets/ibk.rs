//! `.ibk` decoders on arbitrary bytes: must never panic. The checksum rejects almost every random
//! input, so each input is also tried as a body with its valid CRC appended, reaching the
//! structural checks. Keyframe files (versions 1–2) are rebuilt into a clip when small; sampled
//! files (versions 3 and 4) are read whole and sought at a time taken from the input; version 4
//! through the runtime sampler (`inbetween_ibk::Clip`, what the C ABI calls) as well.
#![no_main]

use inbetween_mocap::codec::{decode, read, v3, v4};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = decode(data);
    let _ = read(data);
    let mut file = data.to_vec();
    file.extend_from_slice(&crc32fast::hash(data).to_le_bytes());
    if let Ok(d) = decode(&file) {
        assert!(d.key_frames.len() >= 2 && d.key_frames.len() == d.keys.len());
        assert_eq!(*d.key_frames.last().unwrap(), d.num_frames - 1);
        if d.num_frames * d.skeleton.len() <= 20_000 {
            let _ = d.reconstruct();
        }
    }
    if let Ok(f) = read(&file) {
        if f.num_frames() * f.skeleton().len() <= 20_000 {
            let _ = f.motion();
        }
    }
    if let Ok(f) = v3::File::open(&file) {
        let time = data.first().map_or(0.0, |&b| b as f64 * f.header.frame_time * 0.37);
        let (mut pose, mut scratch) = (inbetween_core::Pose::rest(&f.header.skeleton), v3::Scratch::default());
        let _ = f.pose_at(time, &mut pose, &mut scratch);
    }
    if let Ok(clip) = v4::Clip::open(&file) {
        let time = data.first().map_or(0.0, |&b| b as f64 * clip.frame_time() * 0.37);
        let mut ctx = v4::Context::new(&clip);
        let n = clip.num_joints();
        let (mut rot, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
        for t in [time, 0.0, f64::NAN, 1e30, time * 0.5] {
            clip.sample(&mut ctx, t, &mut rot, &mut tr).expect("buffers of the clip's size");
        }
    }
});
