//! Keyframe-stream message decoder (what `mocap stream recv` reads from the network) on arbitrary
//! bytes: must never panic. Every message carries a CRC, so the input is also wrapped as one
//! message of each type with a valid frame and checksum, reaching the payload checks.
#![no_main]

use inbetween_mocap::stream::decode_messages;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = decode_messages(data);
    for kind in 1u8..=3 {
        let mut m = vec![kind];
        m.extend_from_slice(&(data.len() as u32).to_le_bytes());
        m.extend_from_slice(data);
        let crc = crc32fast::hash(&m);
        m.extend_from_slice(&crc.to_le_bytes());
        let _ = decode_messages(&m);
    }
});
