//! Phoneme timings as CSV or JSON: the simplest viseme source, for aligners other than MFA or for
//! hand-made timings.
//!
//! CSV (`.csv`): `#` lines are comments, a header naming the columns in any order
//! (`start` or `start_s`, `end` or `end_s`, `phoneme` or `phone`; case-insensitive), then one row per
//! phoneme; LF or CRLF; fields may be wrapped in double quotes; an empty phoneme is silence.
//!
//! ```text
//! start,end,phoneme
//! 0.00,0.10,B
//! 0.10,0.18,R
//! ```
//!
//! JSON (`.json`): an array of objects with `start` (or `start_s`), `end` (or `end_s`) and `phoneme`
//! (or `phone`):
//!
//! ```json
//! [{"start": 0.0, "end": 0.1, "phoneme": "B"}, {"start": 0.1, "end": 0.18, "phoneme": "R"}]
//! ```
//!
//! Both are checked like every source ([`super::validate_spans`]); errors name file, line and column.
//! The writers emit what the readers read back exactly.

use super::labels::SILENCE;
use super::spans::{check_span, read_text_file, shown, validate_spans, PhonemeSpan, SpanField};
use crate::data::{Column, FaceError};
use serde::{Deserialize, Serialize};
use std::path::Path;

const EXPECTED_HEADER: &str = "a header naming the columns 'start,end,phoneme' (or start_s, end_s)";

fn at(file: &str, line: usize, column: Option<Column>, message: impl Into<String>) -> FaceError {
    FaceError::parse(file, line, column, message)
}

/// Non-blank, non-comment lines with 1-based numbers; BOM and `\r` removed.
fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.split('\n').enumerate().filter_map(|(i, l)| {
        let l = l.strip_suffix('\r').unwrap_or(l);
        let t = l.trim();
        (!t.is_empty() && !t.starts_with('#')).then_some((i + 1, l))
    })
}

fn fields(line: &str) -> Vec<&str> {
    line.split(',')
        .map(|f| {
            // Whitespace inside the quotes goes too: `"\r"` is an empty label (silence), as it
            // reads back after writing.
            let f = f.trim();
            f.strip_prefix('"').and_then(|g| g.strip_suffix('"')).map_or(f, str::trim)
        })
        .collect()
}

/// The 0-based field positions of start, end and phoneme in the header.
struct HeaderMap {
    names: Vec<String>,
    pos: [usize; 3],
}

impl HeaderMap {
    fn column(&self, field: SpanField) -> Option<Column> {
        let i = self.pos[field as usize];
        Some(Column { index: i + 1, name: self.names[i].clone() })
    }
}

fn read_header(h: &[&str], file: &str, line: usize) -> Result<HeaderMap, FaceError> {
    let mut pos: [Option<usize>; 3] = [None; 3];
    for (i, name) in h.iter().enumerate() {
        let slot = match name.to_ascii_lowercase().as_str() {
            "start" | "start_s" => SpanField::Start,
            "end" | "end_s" => SpanField::End,
            "phoneme" | "phone" => SpanField::Phoneme,
            _ => {
                return Err(at(
                    file,
                    line,
                    Some(Column { index: i + 1, name: String::new() }),
                    format!("unknown column {}; expected {EXPECTED_HEADER}", shown(name)),
                ))
            }
        };
        if let Some(first) = pos[slot as usize].replace(i) {
            return Err(at(
                file,
                line,
                Some(Column { index: i + 1, name: String::new() }),
                format!(
                    "column {} repeats column {}; expected each of start, end, phoneme once",
                    shown(name),
                    first + 1
                ),
            ));
        }
    }
    let missing: Vec<&str> =
        ["start", "end", "phoneme"].iter().zip(pos).filter(|(_, p)| p.is_none()).map(|(n, _)| *n).collect();
    if !missing.is_empty() {
        return Err(at(
            file,
            line,
            None,
            format!("missing column(s) {}; expected {EXPECTED_HEADER}", missing.join(", ")),
        ));
    }
    Ok(HeaderMap { names: h.iter().map(|s| s.to_string()).collect(), pos: pos.map(|p| p.unwrap_or(0)) })
}

fn time_field(field: &str) -> Result<f64, String> {
    match field.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("expected a finite time in seconds, found {}", shown(field))),
        Err(_) if field.is_empty() => Err("expected a time in seconds, found an empty field".into()),
        Err(_) => Err(format!("expected a time in seconds, found {}", shown(field))),
    }
}

/// Parses phoneme-timing CSV text; `file` names it in errors.
pub fn parse_phoneme_csv(text: &str, file: &str) -> Result<Vec<PhonemeSpan>, FaceError> {
    let mut it = content_lines(text);
    let Some((hline, htext)) = it.next() else {
        return Err(FaceError::Empty { file: file.into(), expected: EXPECTED_HEADER.into() });
    };
    let header = read_header(&fields(htext), file, hline)?;
    let mut spans: Vec<PhonemeSpan> = Vec::new();
    let mut prev_line = 0;
    for (line, l) in it {
        let row = fields(l);
        if row.len() != header.names.len() {
            return Err(at(
                file,
                line,
                None,
                format!(
                    "expected {} fields as in the header ({}), found {}",
                    header.names.len(),
                    header.names.join(","),
                    row.len()
                ),
            ));
        }
        let get = |f: SpanField| row[header.pos[f as usize]];
        let start_s =
            time_field(get(SpanField::Start)).map_err(|m| at(file, line, header.column(SpanField::Start), m))?;
        let end_s = time_field(get(SpanField::End)).map_err(|m| at(file, line, header.column(SpanField::End), m))?;
        let label = get(SpanField::Phoneme);
        let phoneme = if label.is_empty() { SILENCE.to_string() } else { label.to_string() };
        let span = PhonemeSpan { start_s, end_s, phoneme };
        check_span(&span, spans.last().map(|p| (p, format!("line {prev_line}"))))
            .map_err(|(f, m)| at(file, line, header.column(f), m))?;
        spans.push(span);
        prev_line = line;
    }
    if spans.is_empty() {
        return Err(at(
            file,
            hline,
            None,
            "no phoneme rows after the header; expected at least one 'start,end,phoneme' row",
        ));
    }
    Ok(spans)
}

/// One element of the JSON form.
#[derive(Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct JsonSpan {
    #[serde(alias = "start_s")]
    start: f64,
    #[serde(alias = "end_s")]
    end: f64,
    #[serde(alias = "phone")]
    phoneme: String,
}

/// Byte offsets where the elements of the top-level JSON array start (the text is valid JSON).
fn element_offsets(text: &str) -> Vec<usize> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let (mut depth, mut in_str, mut escaped, mut expect_elem) = (0usize, false, false, false);
    for (i, &c) in b.iter().enumerate() {
        if in_str {
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, b'\\') => escaped = true,
                (false, b'"') => in_str = false,
                _ => {}
            }
            continue;
        }
        if c.is_ascii_whitespace() {
            continue;
        }
        if expect_elem && depth == 1 && c != b']' {
            out.push(i);
        }
        expect_elem = false;
        match c {
            b'"' => in_str = true,
            b'[' | b'{' => {
                depth += 1;
                expect_elem = depth == 1;
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            b',' => expect_elem = depth == 1,
            _ => {}
        }
    }
    out
}

/// 1-based line and column (in characters) of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Parses phoneme-timing JSON text; `file` names it in errors.
pub fn parse_phoneme_json(text: &str, file: &str) -> Result<Vec<PhonemeSpan>, FaceError> {
    let body = text.strip_prefix('\u{feff}').unwrap_or(text);
    if body.trim().is_empty() {
        return Err(FaceError::Empty {
            file: file.into(),
            expected: "a JSON array of {\"start\", \"end\", \"phoneme\"} objects".into(),
        });
    }
    let raw: Vec<JsonSpan> = serde_json::from_str(body).map_err(|e| {
        let message =
            format!("{e}; expected a JSON array of {{\"start\": <s>, \"end\": <s>, \"phoneme\": \"…\"}} objects");
        let message = message.replacen(&format!(" at line {} column {}", e.line(), e.column()), "", 1);
        at(file, e.line().max(1), Some(Column { index: e.column().max(1), name: String::new() }), message)
    })?;
    let offsets = element_offsets(body);
    let mut spans: Vec<PhonemeSpan> = Vec::with_capacity(raw.len());
    for (i, r) in raw.into_iter().enumerate() {
        let phoneme = if r.phoneme.trim().is_empty() { SILENCE.to_string() } else { r.phoneme.trim().to_string() };
        let span = PhonemeSpan { start_s: r.start, end_s: r.end, phoneme };
        let (line, col) = offsets.get(i).map_or((1, 1), |&o| line_col(body, o));
        let prev = i.checked_sub(1).map(|j| (&spans[j], format!("element {}", j + 1)));
        check_span(&span, prev).map_err(|(_, m)| {
            at(file, line, Some(Column { index: col, name: String::new() }), format!("element {}: {m}", i + 1))
        })?;
        spans.push(span);
    }
    if spans.is_empty() {
        return Err(at(
            file,
            1,
            None,
            "an empty array; expected at least one {\"start\", \"end\", \"phoneme\"} object",
        ));
    }
    Ok(spans)
}

/// Reads a phoneme-timing file, CSV or JSON by its extension (`.csv`, `.json`, any case).
pub fn read_phoneme_timing(path: &Path) -> Result<Vec<PhonemeSpan>, FaceError> {
    let file = path.display().to_string();
    match extension(path).as_str() {
        "csv" => parse_phoneme_csv(&read_text_file(path)?, &file),
        "json" => parse_phoneme_json(&read_text_file(path)?, &file),
        other => Err(FaceError::File {
            file,
            message: format!("unknown extension {}; expected .csv or .json phoneme timings", shown(other)),
        }),
    }
}

/// The lowercased extension of a path ("" when none).
pub(crate) fn extension(path: &Path) -> String {
    path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default()
}

/// Phoneme-timing CSV text (`start,end,phoneme`, shortest round-trip numbers). Fails on spans that
/// [`validate_spans`] rejects.
pub fn to_phoneme_csv_string(spans: &[PhonemeSpan]) -> Result<String, FaceError> {
    use std::fmt::Write;
    validate_spans(spans)?;
    let mut out = String::from("start,end,phoneme\n");
    for s in spans {
        let _ = writeln!(out, "{},{},{}", s.start_s, s.end_s, s.phoneme);
    }
    Ok(out)
}

/// Phoneme-timing JSON text. Fails on spans that [`validate_spans`] rejects.
pub fn to_phoneme_json_string(spans: &[PhonemeSpan]) -> Result<String, FaceError> {
    validate_spans(spans)?;
    let raw: Vec<JsonSpan> =
        spans.iter().map(|s| JsonSpan { start: s.start_s, end: s.end_s, phoneme: s.phoneme.clone() }).collect();
    serde_json::to_string_pretty(&raw).map_err(|e| FaceError::Invalid(format!("phoneme timings to JSON: {e}")))
}

/// Writes phoneme timings atomically, CSV or JSON by extension.
pub fn write_phoneme_timing(path: &Path, spans: &[PhonemeSpan]) -> Result<(), FaceError> {
    let file = path.display().to_string();
    let text = match extension(path).as_str() {
        "csv" => to_phoneme_csv_string(spans)?,
        "json" => to_phoneme_json_string(spans)?,
        other => {
            return Err(FaceError::File {
                file,
                message: format!("unknown extension {}; expected .csv or .json phoneme timings", shown(other)),
            })
        }
    };
    inbetween_io::write_atomic(path, text.as_bytes()).map_err(|source| FaceError::Io { file, source })
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "# aligned by hand\nstart,end,phoneme\n0,0.1,B\n0.1,0.2,R\n\n0.2,0.35,AH1\n";

    #[test]
    fn reads_csv_with_either_header_spelling_and_comments() {
        let got = parse_phoneme_csv(CSV, "t.csv").unwrap();
        assert_eq!(
            got,
            vec![PhonemeSpan::new(0.0, 0.1, "B"), PhonemeSpan::new(0.1, 0.2, "R"), PhonemeSpan::new(0.2, 0.35, "AH1")]
        );
        let alt = "\u{feff}Phoneme,End_s,Start_s\r\n\"B\",0.1,0\r\n,0.3,0.1\r\n";
        let got = parse_phoneme_csv(alt, "t.csv").unwrap();
        assert_eq!(got, vec![PhonemeSpan::new(0.0, 0.1, "B"), PhonemeSpan::new(0.1, 0.3, "sil")]);
    }

    #[test]
    fn csv_errors_name_line_and_column() {
        let cases = [
            ("", "t.csv: empty file; expected a header"),
            ("start,stop,phoneme\n", "t.csv:1: column 2: unknown column 'stop'"),
            ("start,end\n0,1\n", "t.csv:1: missing column(s) phoneme"),
            ("start,end,start_s,phoneme\n", "t.csv:1: column 3: column 'start_s' repeats column 1"),
            ("start,end,phoneme\n", "t.csv:1: no phoneme rows"),
            ("start,end,phoneme\n0,0.1\n", "t.csv:2: expected 3 fields as in the header (start,end,phoneme), found 2"),
            ("start,end,phoneme\n0,x,B\n", "t.csv:2: column 2 (end): expected a time in seconds, found 'x'"),
            ("start,end,phoneme\n0,NaN,B\n", "t.csv:2: column 2 (end): expected a finite time in seconds, found 'NaN'"),
            (
                "start,end,phoneme\n,0.1,B\n",
                "t.csv:2: column 1 (start): expected a time in seconds, found an empty field",
            ),
            ("start,end,phoneme\n0.2,0.1,B\n", "t.csv:2: column 2 (end): end 0.1 s is not after start 0.2 s"),
            (
                "start,end,phoneme\n0,0.2,B\n# c\n0.1,0.3,M\n",
                "t.csv:4: column 1 (start): start 0.1 s is before the end 0.2 s of the previous phoneme (line 2)",
            ),
            (
                "start,end,phoneme\n0,0.2,B\n0.2,0.3,BB\n",
                "t.csv:3: column 3 (phoneme): unknown phoneme 'BB'; expected an ARPAbet phoneme",
            ),
        ];
        for (text, want) in cases {
            let e = parse_phoneme_csv(text, "t.csv").unwrap_err().to_string();
            assert!(e.starts_with(want), "got  {e}\nwant {want}");
        }
    }

    #[test]
    fn reads_json_and_names_the_element_line() {
        let text = "[\n  {\"start\": 0, \"end\": 0.1, \"phoneme\": \"B\"},\n  {\"start_s\": 0.1, \"end_s\": 0.2, \"phone\": \"\"}\n]";
        let got = parse_phoneme_json(text, "t.json").unwrap();
        assert_eq!(got, vec![PhonemeSpan::new(0.0, 0.1, "B"), PhonemeSpan::new(0.1, 0.2, "sil")]);
        let cases = [
            ("", "t.json: empty file"),
            ("[]", "t.json:1: an empty array"),
            ("[\n {\"start\": 0, \"end\": 0.1, \"phoneme\": \"B\"},\n {\"start\": 0.05, \"end\": 0.2, \"phoneme\": \"M\"}\n]", "t.json:3: column 2: element 2: start 0.05 s is before the end 0.1 s of the previous phoneme (element 1)"),
            ("[{\"start\": 0, \"end\": 0.1, \"phoneme\": \"B\"}, {\"start\": 0.1, \"end\": 0.2, \"phoneme\": \"X\"}]", "t.json:1: column 44: element 2: unknown phoneme 'X'"),
            ("[\n {\"start\": 0, \"end\": \"0.1\", \"phoneme\": \"B\"}]", "t.json:2: column 26: invalid type: string \"0.1\", expected f64"),
            ("[\n {\"start\": 0, \"stop\": 1, \"phoneme\": \"B\"}]", "t.json:2: column 20: unknown field `stop`, expected one of"),
            ("{\"start\": 0}", "t.json:1: column 1: invalid type: map, expected a sequence"),
            ("[{\"start\": 0, \"end\": 1e999, \"phoneme\": \"B\"}]", "t.json:1: column 26: number out of range"),
        ];
        for (text, want) in cases {
            let e = parse_phoneme_json(text, "t.json").unwrap_err().to_string();
            assert!(e.starts_with(want), "got  {e}\nwant {want}");
        }
    }

    #[test]
    fn writers_round_trip_through_files_and_refuse_bad_spans() {
        let spans = parse_phoneme_csv(CSV, "t.csv").unwrap();
        let dir = tempfile::tempdir().unwrap();
        for name in ["p.csv", "p.JSON"] {
            let path = dir.path().join(name);
            write_phoneme_timing(&path, &spans).unwrap();
            assert_eq!(read_phoneme_timing(&path).unwrap(), spans);
        }
        let e = write_phoneme_timing(&dir.path().join("p.txt"), &spans).unwrap_err().to_string();
        assert!(e.contains("unknown extension 'txt'"), "{e}");
        let bad = [PhonemeSpan::new(0.0, 0.1, "B,R")];
        assert!(to_phoneme_csv_string(&bad).is_err() && to_phoneme_json_string(&bad).is_err());
        assert!(!dir.path().join("q.csv").exists());
        assert!(matches!(read_phoneme_timing(&dir.path().join("missing.csv")), Err(FaceError::Io { .. })));
    }
}
