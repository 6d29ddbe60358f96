//! BVH reader on arbitrary bytes: must never panic, and whatever it accepts must survive
//! write → read with the same layout.
#![no_main]

use inbetween_io::bvh::{parse_bvh, to_bvh_string};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(m) = parse_bvh(&text, "fuzz.bvh") {
        let written = to_bvh_string(&m);
        let back = parse_bvh(&written, "rewritten.bvh").expect("a parsed clip writes back as valid BVH");
        assert_eq!(back.skeleton.len(), m.skeleton.len());
        assert_eq!(back.num_channels(), m.num_channels());
        assert_eq!(back.num_frames(), m.num_frames());
    }
});
