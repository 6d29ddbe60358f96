//! [`PhonemeSpan`]: one phoneme with its time interval, what every viseme source reads into, and the
//! checks every reader applies (finite times, start before end, sorted and non-overlapping, known label).

use super::labels::{phoneme_viseme, EXPECTED_LABEL};
use super::Viseme;
use crate::data::FaceError;
use serde::{Deserialize, Serialize};

/// Slack allowed when one span starts before the previous one ends (text round-off in aligner output).
pub const OVERLAP_TOLERANCE_S: f64 = 1e-9;

/// One phoneme over `[start_s, end_s)` seconds. `phoneme` is an ARPAbet or IPA label, or a silence
/// label (see [`super::phoneme_viseme`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhonemeSpan {
    /// Start time in seconds (inclusive).
    pub start_s: f64,
    /// End time in seconds (exclusive).
    pub end_s: f64,
    /// The phoneme label.
    pub phoneme: String,
}

impl PhonemeSpan {
    /// A span; see [`validate_spans`] for the rules a list of them follows.
    pub fn new(start_s: f64, end_s: f64, phoneme: impl Into<String>) -> Self {
        PhonemeSpan { start_s, end_s, phoneme: phoneme.into() }
    }

    /// `end_s − start_s`.
    pub fn duration_s(&self) -> f64 {
        self.end_s - self.start_s
    }

    /// The viseme class of the label, `None` when the label is unknown.
    pub fn viseme(&self) -> Option<Viseme> {
        phoneme_viseme(&self.phoneme)
    }
}

/// Which field of a span a check failed on (readers turn it into a column).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SpanField {
    Start,
    End,
    Phoneme,
}

/// Checks span `span` against the rules, given the span before it; says which field is wrong and why.
/// `prev_where` names the previous span in the message (e.g. "line 12").
pub(crate) fn check_span(span: &PhonemeSpan, prev: Option<(&PhonemeSpan, String)>) -> Result<(), (SpanField, String)> {
    if !span.start_s.is_finite() {
        return Err((SpanField::Start, format!("expected a finite start time, found {}", span.start_s)));
    }
    if !span.end_s.is_finite() {
        return Err((SpanField::End, format!("expected a finite end time, found {}", span.end_s)));
    }
    if span.end_s <= span.start_s {
        return Err((
            SpanField::End,
            format!("end {} s is not after start {} s; expected start < end", span.end_s, span.start_s),
        ));
    }
    if let Some((p, where_)) = prev {
        if span.start_s < p.end_s - OVERLAP_TOLERANCE_S {
            return Err((
                SpanField::Start,
                format!(
                    "start {} s is before the end {} s of the previous phoneme ({where_}); expected sorted, non-overlapping phonemes",
                    span.start_s, p.end_s
                ),
            ));
        }
    }
    if phoneme_viseme(&span.phoneme).is_none() {
        return Err((
            SpanField::Phoneme,
            format!("unknown phoneme {}; expected {EXPECTED_LABEL}", shown(&span.phoneme)),
        ));
    }
    Ok(())
}

/// Checks a list of spans built in code: finite times, `start < end`, sorted and non-overlapping
/// (within [`OVERLAP_TOLERANCE_S`]), every label known. The error names the span's index.
pub fn validate_spans(spans: &[PhonemeSpan]) -> Result<(), FaceError> {
    for (i, s) in spans.iter().enumerate() {
        let prev = i.checked_sub(1).map(|j| (&spans[j], format!("span {j}")));
        check_span(s, prev).map_err(|(_, m)| FaceError::Invalid(format!("phoneme span {i}: {m}")))?;
    }
    Ok(())
}

/// A field as it appears in an error message: quoted, at most 40 characters.
pub(crate) fn shown(field: &str) -> String {
    let mut s: String = field.chars().take(40).collect();
    if field.chars().count() > 40 {
        s.push('…');
    }
    format!("'{s}'")
}

/// Reads a file's bytes as text: UTF-8 (BOM optional), or UTF-16 LE/BE with a BOM (Praat writes
/// UTF-16 when a TextGrid holds non-ASCII text).
pub fn decode_text(bytes: &[u8], file: &str) -> Result<String, FaceError> {
    let utf16 = |rest: &[u8], be: bool| -> Result<String, FaceError> {
        if !rest.len().is_multiple_of(2) {
            return Err(FaceError::File {
                file: file.into(),
                message:
                    "UTF-16 text (by its byte-order mark) with an odd number of bytes; expected whole 2-byte units"
                        .into(),
            });
        }
        let units = rest.chunks_exact(2).map(|c| {
            if be {
                u16::from_be_bytes([c[0], c[1]])
            } else {
                u16::from_le_bytes([c[0], c[1]])
            }
        });
        char::decode_utf16(units).enumerate().map(|(i, r)| r.map_err(|_| i)).collect::<Result<String, usize>>().map_err(
            |i| FaceError::File {
                file: file.into(),
                message: format!("invalid UTF-16 (unpaired surrogate at unit {}); expected UTF-16 text", i + 1),
            },
        )
    };
    match bytes {
        [0xFF, 0xFE, rest @ ..] => utf16(rest, false),
        [0xFE, 0xFF, rest @ ..] => utf16(rest, true),
        _ => {
            let bytes = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
            inbetween_io::text::utf8(bytes.to_vec()).map_err(|e| FaceError::File {
                file: file.into(),
                message: format!(
                    "not UTF-8 text (invalid byte at offset {}); expected UTF-8, or UTF-16 with a byte-order mark",
                    e.offset
                ),
            })
        }
    }
}

/// Reads and decodes a text file (see [`decode_text`]).
pub(crate) fn read_text_file(path: &std::path::Path) -> Result<String, FaceError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| FaceError::Io { file: file.clone(), source })?;
    decode_text(&bytes, &file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_span_and_the_rule() {
        let ok = [PhonemeSpan::new(0.0, 0.1, "B"), PhonemeSpan::new(0.1, 0.3, "AH1")];
        validate_spans(&ok).unwrap();
        let cases: [(Vec<PhonemeSpan>, &str); 5] = [
            (vec![PhonemeSpan::new(0.2, 0.1, "B")], "span 0: end 0.1 s is not after start 0.2 s"),
            (vec![PhonemeSpan::new(f64::NAN, 0.1, "B")], "finite start"),
            (vec![PhonemeSpan::new(0.0, f64::INFINITY, "B")], "finite end"),
            (vec![PhonemeSpan::new(0.0, 0.2, "B"), PhonemeSpan::new(0.1, 0.3, "M")], "span 1: start 0.1 s is before"),
            (vec![PhonemeSpan::new(0.0, 0.2, "QQ")], "unknown phoneme 'QQ'"),
        ];
        for (spans, want) in cases {
            let e = validate_spans(&spans).unwrap_err().to_string();
            assert!(e.contains(want), "{e} lacks {want}");
        }
    }

    #[test]
    fn decodes_utf8_utf16_and_rejects_bad_bytes() {
        assert_eq!(decode_text(b"\xEF\xBB\xBFab", "f").unwrap(), "ab");
        let le: Vec<u8> = [0xFF, 0xFE].into_iter().chain("aɹ".encode_utf16().flat_map(|u| u.to_le_bytes())).collect();
        assert_eq!(decode_text(&le, "f").unwrap(), "aɹ");
        let be: Vec<u8> = [0xFE, 0xFF].into_iter().chain("aɹ".encode_utf16().flat_map(|u| u.to_be_bytes())).collect();
        assert_eq!(decode_text(&be, "f").unwrap(), "aɹ");
        assert!(decode_text(&[0xFF, 0xFE, 0x61], "f").unwrap_err().to_string().contains("odd number"));
        assert!(decode_text(&[0xFF, 0xFE, 0x00, 0xD8], "f").unwrap_err().to_string().contains("surrogate"));
        assert!(decode_text(b"a\xC3", "f.TextGrid").unwrap_err().to_string().starts_with("f.TextGrid: not UTF-8"));
    }
}
