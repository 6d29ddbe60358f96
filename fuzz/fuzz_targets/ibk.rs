//! `.ibk` keyframe decoder on arbitrary bytes: must never panic. The checksum rejects almost every
//! random input, so each input is also tried as a body with its valid CRC appended, reaching the
//! structural checks; whatever decodes is rebuilt into a clip when it is small.
#![no_main]

use inbetween_mocap::codec::decode;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = decode(data);
    let mut file = data.to_vec();
    file.extend_from_slice(&crc32fast::hash(data).to_le_bytes());
    if let Ok(d) = decode(&file) {
        assert!(d.key_frames.len() >= 2 && d.key_frames.len() == d.keys.len());
        assert_eq!(*d.key_frames.last().unwrap(), d.num_frames - 1);
        if d.num_frames * d.skeleton.len() <= 20_000 {
            let _ = d.reconstruct();
        }
    }
});
