//! The face data readers (Live Link Face CSV, curve CSV, curve JSON) on arbitrary bytes: no panic, and
//! whatever parses writes back and parses again to the same values.
#![no_main]

use inbetween_face::data::{
    parse_curve_csv, parse_curve_json, parse_live_link, to_curve_csv_string, to_curve_json_string, to_live_link_string,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(clip) = parse_live_link(text, "fuzz.csv") {
        let out = to_live_link_string(&clip).expect("a parsed clip writes");
        let back = parse_live_link(&out, "fuzz.csv").expect("written text parses");
        assert_eq!(back.values(), clip.values());
    }
    if let Ok(clip) = parse_curve_csv(text, "fuzz.csv") {
        assert!(parse_curve_csv(&to_curve_csv_string(&clip), "fuzz.csv").expect("re-reads") == clip);
    }
    if let Ok(clip) = parse_curve_json(text, "fuzz.json") {
        assert!(parse_curve_json(&to_curve_json_string(&clip), "fuzz.json").expect("re-reads") == clip);
    }
});
