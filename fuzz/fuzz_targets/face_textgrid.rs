//! The viseme sources (Praat TextGrid, phoneme-timing CSV and JSON) on arbitrary bytes, decoded as a
//! file would be (UTF-8, or UTF-16 with a byte-order mark): no panic; whatever parses is a valid span
//! list, and timings write back and parse again to the same spans.
#![no_main]

use inbetween_face::visemes::{
    decode_text, parse_phoneme_csv, parse_phoneme_json, parse_textgrid, to_phoneme_csv_string, to_phoneme_json_string,
    validate_spans, viseme_frames,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = decode_text(data, "fuzz.TextGrid") else { return };
    for tier in [None, Some("phones")] {
        if let Ok(spans) = parse_textgrid(&text, "fuzz.TextGrid", tier) {
            validate_spans(&spans).expect("parsed spans are valid");
            viseme_frames(&spans, 25.0, 0.0, 50).expect("valid spans give frames");
        }
    }
    if let Ok(spans) = parse_phoneme_csv(&text, "fuzz.csv") {
        let back = parse_phoneme_csv(&to_phoneme_csv_string(&spans).expect("writes"), "fuzz.csv").expect("re-reads");
        assert!(back == spans);
    }
    if let Ok(spans) = parse_phoneme_json(&text, "fuzz.json") {
        let back = parse_phoneme_json(&to_phoneme_json_string(&spans).expect("writes"), "fuzz.json").expect("re-reads");
        assert!(back == spans);
    }
});
