//! No viseme-source parser panics: arbitrary text, TextGrid-like token soup, and truncations and
//! single-byte edits of valid files. Whatever parses is valid ([`validate_spans`]) and, for timings,
//! writes back and re-reads to the same spans.

use super::textgrid::tests::{LONG, SHORT};
use super::*;
use crate::test_support::{self, truncated};
use proptest::prelude::*;

fn check_all(text: &str) {
    for tier in [None, Some("phones"), Some("words")] {
        if let Ok(spans) = parse_textgrid(text, "p.TextGrid", tier) {
            validate_spans(&spans).expect("parsed spans are valid");
        }
    }
    if let Ok(spans) = parse_phoneme_csv(text, "p.csv") {
        let again = parse_phoneme_csv(&to_phoneme_csv_string(&spans).expect("writes"), "p.csv").expect("re-reads");
        assert_eq!(again, spans);
    }
    if let Ok(spans) = parse_phoneme_json(text, "p.json") {
        let again = parse_phoneme_json(&to_phoneme_json_string(&spans).expect("writes"), "p.json").expect("re-reads");
        assert_eq!(again, spans);
    }
}

#[test]
fn a_quoted_whitespace_label_reads_back_the_same() {
    // Found by the edit test: `"R"` with R replaced by a carriage return.
    check_all("start,end,phoneme\n0,0.1,B\n0.1,0.2,\"\r\"\n0.2,0.4,AH1\n");
    check_all("start,end,phoneme\n0,0.1,\" \"\n");
}

#[test]
fn arbitrary_text_never_panics() {
    test_support::arbitrary_text_never_panics(check_all);
}

proptest! {
    #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::with_cases(256) })]

    #[test]
    fn token_soup_never_panics(text in "[0-9.\\-e\"<>\\[\\]!=: \r\nxminaxtexsizphonesIntervalTier]{0,300}") {
        check_all(&text);
        check_all(&format!("File type = \"ooTextFile\"\nObject class = \"TextGrid\"\n{text}"));
        check_all(&format!("start,end,phoneme\n{text}"));
    }

    #[test]
    fn truncated_and_edited_files_never_panic(cut in 0usize..4_000, pos in 0usize..4_000, byte in any::<u8>()) {
        let csv = "start,end,phoneme\n0,0.1,B\n0.1,0.2,\"R\"\n0.2,0.4,AH1\n";
        let json = r#"[{"start":0,"end":0.1,"phoneme":"B"},{"start_s":0.1,"end_s":0.3,"phone":"ɪ"}]"#;
        for text in [LONG, SHORT, csv, json] {
            check_all(truncated(text, cut % (text.len() + 1)));
            let mut bytes = text.as_bytes().to_vec();
            let p = pos % bytes.len();
            bytes[p] = byte;
            if let Ok(edited) = decode_text(&bytes, "p") {
                check_all(&edited);
            }
        }
    }

    #[test]
    fn arbitrary_bytes_decode_without_panic(bytes in proptest::collection::vec(any::<u8>(), 0..64), bom in 0usize..4) {
        let prefix: &[u8] = [&[][..], &[0xFF, 0xFE], &[0xFE, 0xFF], &[0xEF, 0xBB, 0xBF]][bom];
        let all: Vec<u8> = prefix.iter().chain(&bytes).copied().collect();
        if let Ok(text) = decode_text(&all, "p") {
            check_all(&text);
        }
    }

    #[test]
    fn text_to_phonemes_never_panics_and_tiles_the_span(text in "(?s).{0,80}", start in -10.0f64..10.0, len in 0.01f64..10.0) {
        if let Ok(got) = text_to_phonemes(&text, start, start + len) {
            validate_spans(&got.spans).expect("valid spans");
            prop_assert_eq!(got.spans[0].start_s, start);
            prop_assert_eq!(got.spans.last().unwrap().end_s, start + len);
        }
    }
}
