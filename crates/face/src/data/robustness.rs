//! No input makes a reader panic: arbitrary text, and truncations and single-byte edits of valid files.
//! Whatever parses writes back and parses to the same clip.

use super::livelink::tests::generated;
use super::*;
use crate::test_support::{self, truncated};
use proptest::prelude::*;

fn check_all(text: &str) {
    if let Ok(c) = parse_live_link(text, "p.csv") {
        let again =
            parse_live_link(&to_live_link_string(&c).expect("a parsed clip writes"), "p.csv").expect("re-reads");
        assert_eq!(again.values(), c.values());
    }
    if let Ok(c) = parse_curve_csv(text, "p.csv") {
        assert_eq!(parse_curve_csv(&to_curve_csv_string(&c), "p.csv").expect("re-reads"), c);
    }
    if let Ok(c) = parse_curve_json(text, "p.json") {
        assert_eq!(parse_curve_json(&to_curve_json_string(&c), "p.json").expect("re-reads"), c);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::with_cases(256) })]

    #[test]
    fn csv_like_text_never_panics(text in "[0-9:.,\\-eE+naNIf#=\r\n ]{0,300}") {
        check_all(&text);
        let header = format!("Timecode,BlendshapeCount,{}\n", ARKIT_NAMES.join(","));
        check_all(&(header + &text));
        let header = format!("time_s,{}\n", ARKIT_NAMES.join(","));
        check_all(&(header + &text));
    }

    #[test]
    fn truncated_and_edited_files_never_panic(cut in 0usize..40_000, pos in 0usize..40_000, byte in any::<u8>(), head in any::<bool>(), emo in any::<bool>()) {
        let clip = generated(12, head, emo, 7.0);
        for text in [to_live_link_string(&clip).unwrap(), to_curve_csv_string(&clip), to_curve_json_string(&clip)] {
            let cut_text = truncated(&text, cut % (text.len() + 1));
            check_all(cut_text);
            let mut bytes = text.into_bytes();
            let p = pos % bytes.len();
            bytes[p] = byte;
            if let Ok(edited) = std::str::from_utf8(&bytes) {
                check_all(edited);
            }
        }
    }
}

#[test]
fn arbitrary_text_never_panics() {
    test_support::arbitrary_text_never_panics(check_all);
}
