//! Praat TextGrid, as Montreal Forced Aligner writes its alignments (§3.1: "we use the
//! Montreal-Forced-Aligner"), read into [`PhonemeSpan`]s of one tier.
//!
//! Both text layouts are read: the long one
//!
//! ```text
//! File type = "ooTextFile"
//! Object class = "TextGrid"
//!
//! xmin = 0
//! xmax = 1.5
//! tiers? <exists>
//! size = 2
//! item []:
//!     item [1]:
//!         class = "IntervalTier"
//!         name = "phones"
//!         xmin = 0
//!         xmax = 1.5
//!         intervals: size = 3
//!         intervals [1]:
//!             xmin = 0
//!             xmax = 0.2
//!             text = ""
//!         …
//! ```
//!
//! and the short one, which holds the same values one per line without the labels
//! (`"ooTextFile"`, `"TextGrid"`, `0`, `1.5`, `<exists>`, `2`, `"IntervalTier"`, `"phones"`, …).
//! Like Praat, the reader sees the file as a stream of numbers, `"strings"` (a doubled `""` is a quote
//! inside a string, and strings may span lines) and `<flags>`; `!` starts a comment, `[…]` indices and
//! labels are skipped. Where the long layout names a value (`xmin = …`) the name is checked too, so a
//! misplaced or missing line is reported where it happens. Point tiers (`TextTier`) are read and
//! skipped. Input may be UTF-8 or UTF-16 with a byte-order mark ([`super::decode_text`]), LF or CRLF.
//!
//! The tier used is the one the caller names (case-insensitive), else the one called `phones`,
//! `phonemes` or `phone`, also as Montreal Forced Aligner's per-speaker `<speaker> - phones`. Empty
//! intervals are silence ([`super::SILENCE`]). Every error names the file, the line and what was
//! expected.

use super::labels::SILENCE;
use super::spans::{check_span, read_text_file, shown, PhonemeSpan, SpanField};
use crate::data::FaceError;
use std::path::Path;

/// Tier names (case-insensitive) taken as the phone tier when the caller names none.
pub const PHONE_TIER_NAMES: [&str; 3] = ["phones", "phonemes", "phone"];

/// A value in the token stream.
#[derive(Clone, Debug, PartialEq)]
enum Value {
    /// Anything that starts like a number (`0`, `-1.5e-3`), parsed when used.
    Number(String),
    /// A `"quoted string"`, unescaped.
    Text(String),
    /// `<exists>`, `<absent>`.
    Flag(String),
    /// A bare word standing where a value belongs (after `=`).
    Bare(String),
}

/// One token: its value, the line it starts on, and the label before `=` when the long layout gave one.
#[derive(Clone, Debug)]
struct Token {
    value: Value,
    line: usize,
    key: Option<String>,
}

fn parse_err(file: &str, line: usize, message: impl Into<String>) -> FaceError {
    FaceError::parse(file, line, None, message)
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | 0x0B | 0x0C)
}

fn starts_number(w: &str) -> bool {
    matches!(w.as_bytes().first(), Some(b'0'..=b'9' | b'-' | b'+' | b'.'))
}

/// Splits TextGrid text into tokens (see the module docs).
fn tokenize(text: &str, file: &str) -> Result<Vec<Token>, FaceError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut line = 1;
    let mut i = 0;
    let mut last_word: Option<&str> = None;
    let mut pending_key: Option<String> = None;
    let newline_at = |i: usize| b[i] == b'\n' || (b[i] == b'\r' && b.get(i + 1) != Some(&b'\n'));
    while i < b.len() {
        match b[i] {
            b'\n' | b'\r' => {
                if newline_at(i) {
                    line += 1;
                    last_word = None;
                    pending_key = None;
                }
                i += 1;
            }
            c if is_space(c) => i += 1,
            b'!' => {
                while i < b.len() && b[i] != b'\n' && b[i] != b'\r' {
                    i += 1;
                }
            }
            b'"' => {
                let start_line = line;
                let mut s = String::new();
                i += 1;
                loop {
                    let Some(q) = b[i..].iter().position(|&c| c == b'"').map(|q| q + i) else {
                        return Err(parse_err(
                            file,
                            start_line,
                            "a string opened on this line has no closing '\"'; expected \"text\" (a quote inside is written \"\")",
                        ));
                    };
                    line += (i..q).filter(|&k| newline_at(k)).count();
                    s.push_str(&text[i..q]);
                    if b.get(q + 1) == Some(&b'"') {
                        s.push('"');
                        i = q + 2;
                    } else {
                        i = q + 1;
                        break;
                    }
                }
                out.push(Token { value: Value::Text(s), line: start_line, key: pending_key.take() });
            }
            b'<' => {
                let end = b[i..].iter().position(|&c| c == b'>' || c == b'\n' || c == b'\r').map(|e| e + i);
                match end {
                    Some(e) if b[e] == b'>' => {
                        out.push(Token { value: Value::Flag(text[i..=e].to_string()), line, key: pending_key.take() });
                        i = e + 1;
                    }
                    _ => {
                        return Err(parse_err(
                            file,
                            line,
                            "a '<' without '>' on the same line; expected a flag like <exists>",
                        ))
                    }
                }
            }
            b'[' => {
                while i < b.len() && b[i] != b']' && b[i] != b'\n' && b[i] != b'\r' {
                    i += 1;
                }
                if i < b.len() && b[i] == b']' {
                    i += 1;
                }
            }
            _ => {
                let mut j = i;
                while j < b.len() && !is_space(b[j]) && !matches!(b[j], b'\n' | b'\r' | b'"' | b'<' | b'[' | b'!') {
                    j += 1;
                }
                let w = &text[i..j];
                i = j;
                let key_of = |k: &str| k.trim_end_matches([':', '?']).to_ascii_lowercase();
                if let Some(k) = pending_key.take() {
                    let value = if starts_number(w) { Value::Number(w.into()) } else { Value::Bare(w.into()) };
                    out.push(Token { value, line, key: Some(k) });
                } else if starts_number(w) {
                    out.push(Token { value: Value::Number(w.into()), line, key: None });
                } else if w == "=" {
                    pending_key = last_word.map(key_of);
                    if pending_key.is_none() {
                        pending_key = Some(String::new());
                    }
                } else if let Some((k, v)) = w.split_once('=') {
                    if v.is_empty() {
                        pending_key = Some(key_of(k));
                    } else {
                        let value = if starts_number(v) { Value::Number(v.into()) } else { Value::Bare(v.into()) };
                        out.push(Token { value, line, key: Some(key_of(k)) });
                    }
                } else {
                    last_word = Some(w);
                }
            }
        }
    }
    Ok(out)
}

/// One tier as read: its class, name, line, and (interval tiers only) its intervals.
struct Tier {
    name: String,
    line: usize,
    interval_tier: bool,
    intervals: Vec<Interval>,
}

/// One interval with the lines of its three values.
struct Interval {
    span: PhonemeSpan,
    lines: [usize; 3],
}

/// Walks the token stream, checking labels where the long layout gives them.
struct Reader<'a> {
    tokens: Vec<Token>,
    pos: usize,
    file: &'a str,
}

impl Reader<'_> {
    fn last_line(&self) -> usize {
        self.tokens.last().map_or(1, |t| t.line)
    }

    /// The next token, after checking its label (if it has one) is one of `keys`.
    fn next(&mut self, keys: &[&str], what: &str) -> Result<Token, FaceError> {
        let Some(t) = self.tokens.get(self.pos).cloned() else {
            return Err(parse_err(self.file, self.last_line(), format!("expected {what}, found the end of the file")));
        };
        if let Some(k) = &t.key {
            if !keys.is_empty() && !keys.iter().any(|want| want.eq_ignore_ascii_case(k)) {
                return Err(parse_err(self.file, t.line, format!("expected {what}, found {}", describe(&t))));
            }
        }
        self.pos += 1;
        Ok(t)
    }

    fn number(&mut self, keys: &[&str], what: &str) -> Result<(f64, usize), FaceError> {
        let t = self.next(keys, what)?;
        if let Value::Number(s) = &t.value {
            if let Ok(v) = s.parse::<f64>() {
                if v.is_finite() {
                    return Ok((v, t.line));
                }
            }
        }
        Err(parse_err(self.file, t.line, format!("expected {what} (a finite number), found {}", describe(&t))))
    }

    fn count(&mut self, keys: &[&str], what: &str) -> Result<(usize, usize), FaceError> {
        let t = self.next(keys, what)?;
        if let Value::Number(s) = &t.value {
            if let Ok(v) = s.parse::<usize>() {
                return Ok((v, t.line));
            }
        }
        Err(parse_err(self.file, t.line, format!("expected {what} (a whole number ≥ 0), found {}", describe(&t))))
    }

    fn text(&mut self, keys: &[&str], what: &str) -> Result<(String, usize), FaceError> {
        let t = self.next(keys, what)?;
        match t.value {
            Value::Text(s) => Ok((s, t.line)),
            _ => Err(parse_err(
                self.file,
                t.line,
                format!("expected {what} (a \"quoted string\"), found {}", describe(&t)),
            )),
        }
    }
}

/// A token as an error message shows it, with its label when it has one.
fn describe(t: &Token) -> String {
    let v = match &t.value {
        Value::Number(s) | Value::Flag(s) | Value::Bare(s) => s.clone(),
        Value::Text(s) => format!("\"{s}\""),
    };
    match &t.key {
        Some(k) if !k.is_empty() => shown(&format!("{k} = {v}")),
        _ => shown(&v),
    }
}

/// Reads the file header and every tier.
fn read_tiers(reader: &mut Reader) -> Result<Vec<Tier>, FaceError> {
    let file = reader.file;
    let head = "a Praat text file starting 'File type = \"ooTextFile\"'";
    let (kind, line) = reader.text(&["type"], head)?;
    if !kind.starts_with("ooTextFile") {
        return Err(parse_err(file, line, format!("expected {head}, found file type {}", shown(&kind))));
    }
    let class_what = "'Object class = \"TextGrid\"'";
    let (class, line) = reader.text(&["class"], class_what)?;
    if !class.starts_with("TextGrid") {
        return Err(parse_err(file, line, format!("expected {class_what}, found object class {}", shown(&class))));
    }
    reader.number(&["xmin"], "the TextGrid's start 'xmin = <number>'")?;
    reader.number(&["xmax"], "the TextGrid's end 'xmax = <number>'")?;
    let t = reader.next(&[], "'tiers? <exists>'")?;
    let n_tiers = match &t.value {
        Value::Flag(f) if f == "<exists>" => reader.count(&["size"], "the number of tiers 'size = <count>'")?.0,
        Value::Flag(f) if f == "<absent>" => 0,
        _ => return Err(parse_err(file, t.line, format!("expected 'tiers? <exists>', found {}", describe(&t)))),
    };
    let mut tiers = Vec::new();
    for k in 1..=n_tiers {
        tiers.push(read_tier(reader, k)?);
    }
    Ok(tiers)
}

fn read_tier(reader: &mut Reader, k: usize) -> Result<Tier, FaceError> {
    let file = reader.file;
    let what = format!("tier {k}'s class 'class = \"IntervalTier\"' or \"TextTier\"");
    let (class, line) = reader.text(&["class"], &what)?;
    let interval_tier = match class.as_str() {
        "IntervalTier" => true,
        "TextTier" => false,
        _ => return Err(parse_err(file, line, format!("expected {what}, found {}", shown(&class)))),
    };
    let (name, line) = reader.text(&["name"], &format!("tier {k}'s name 'name = \"…\"'"))?;
    reader.number(&["xmin"], &format!("tier {k}'s start 'xmin = <number>'"))?;
    reader.number(&["xmax"], &format!("tier {k}'s end 'xmax = <number>'"))?;
    let item = if interval_tier { "intervals" } else { "points" };
    let (n, _) = reader.count(&["size"], &format!("tier {k}'s number of {item} '{item}: size = <count>'"))?;
    let mut intervals = Vec::new();
    for j in 1..=n {
        if interval_tier {
            let (start, l0) =
                reader.number(&["xmin"], &format!("interval {j}'s start 'xmin = <number>' (tier {k})"))?;
            let (end, l1) = reader.number(&["xmax"], &format!("interval {j}'s end 'xmax = <number>' (tier {k})"))?;
            let (label, l2) = reader.text(&["text"], &format!("interval {j}'s label 'text = \"…\"' (tier {k})"))?;
            let label = label.trim();
            let phoneme = if label.is_empty() { SILENCE.to_string() } else { label.to_string() };
            intervals.push(Interval { span: PhonemeSpan { start_s: start, end_s: end, phoneme }, lines: [l0, l1, l2] });
        } else {
            reader.number(&["number", "time"], &format!("point {j}'s time 'number = <number>' (tier {k})"))?;
            reader.text(&["mark", "text"], &format!("point {j}'s label 'mark = \"…\"' (tier {k})"))?;
        }
    }
    Ok(Tier { name, line, interval_tier, intervals })
}

/// Whether a tier name is a phone tier: `phones`, or `<speaker> - phones` (MFA, several speakers).
fn phone_tier_match(name: &str) -> Option<bool> {
    let n = name.trim();
    let exact = PHONE_TIER_NAMES.iter().any(|p| n.eq_ignore_ascii_case(p));
    if exact {
        return Some(true);
    }
    let suffix = n.rsplit_once(" - ").map(|(_, s)| s.trim())?;
    PHONE_TIER_NAMES.iter().any(|p| suffix.eq_ignore_ascii_case(p)).then_some(false)
}

fn tier_list(tiers: &[Tier]) -> String {
    if tiers.is_empty() {
        return "none".into();
    }
    tiers.iter().map(|t| format!("{} (line {})", shown(&t.name), t.line)).collect::<Vec<_>>().join(", ")
}

/// Picks the tier: the named one, else the phone tier.
fn choose_tier<'t>(tiers: &'t [Tier], wanted: Option<&str>, file: &str) -> Result<&'t Tier, FaceError> {
    let err = |message: String| FaceError::File { file: file.into(), message };
    if let Some(w) = wanted {
        return tiers
            .iter()
            .find(|t| t.name.trim().eq_ignore_ascii_case(w.trim()))
            .ok_or_else(|| err(format!("no tier named {}; tiers found: {}", shown(w), tier_list(tiers))));
    }
    let exact: Vec<&Tier> = tiers.iter().filter(|t| phone_tier_match(&t.name) == Some(true)).collect();
    let any: Vec<&Tier> = tiers.iter().filter(|t| phone_tier_match(&t.name).is_some()).collect();
    let pick = if exact.is_empty() { any } else { exact };
    match pick.as_slice() {
        [one] => Ok(one),
        [] => Err(err(format!(
            "no phone tier (named 'phones', 'phonemes' or 'phone'); tiers found: {}; name the tier to use",
            tier_list(tiers)
        ))),
        several => Err(err(format!(
            "several phone tiers: {}; name the tier to use",
            several.iter().map(|t| format!("{} (line {})", shown(&t.name), t.line)).collect::<Vec<_>>().join(", ")
        ))),
    }
}

/// Parses TextGrid text (see the module docs) and returns the phonemes of `tier` (or of the phone
/// tier when `None`), checked: finite, start < end, sorted, non-overlapping, known labels.
/// `file` names the source in errors.
pub fn parse_textgrid(text: &str, file: &str, tier: Option<&str>) -> Result<Vec<PhonemeSpan>, FaceError> {
    let tokens = tokenize(text, file)?;
    if tokens.is_empty() {
        return Err(FaceError::Empty {
            file: file.into(),
            expected: "a Praat TextGrid ('File type = \"ooTextFile\"')".into(),
        });
    }
    let mut reader = Reader { tokens, pos: 0, file };
    let tiers = read_tiers(&mut reader)?;
    let chosen = choose_tier(&tiers, tier, file)?;
    if !chosen.interval_tier {
        return Err(parse_err(
            file,
            chosen.line,
            format!("tier {} is a point tier (TextTier); expected an IntervalTier of phonemes", shown(&chosen.name)),
        ));
    }
    for (j, iv) in chosen.intervals.iter().enumerate() {
        let prev =
            j.checked_sub(1).map(|p| (&chosen.intervals[p].span, format!("line {}", chosen.intervals[p].lines[0])));
        check_span(&iv.span, prev).map_err(|(field, m)| {
            let line = match field {
                SpanField::Start => iv.lines[0],
                SpanField::End => iv.lines[1],
                SpanField::Phoneme => iv.lines[2],
            };
            parse_err(file, line, format!("tier {}, interval {}: {m}", shown(&chosen.name), j + 1))
        })?;
    }
    Ok(chosen.intervals.iter().map(|iv| iv.span.clone()).collect())
}

/// Reads a TextGrid file (UTF-8 or UTF-16 with BOM); see [`parse_textgrid`].
pub fn read_textgrid(path: &Path, tier: Option<&str>) -> Result<Vec<PhonemeSpan>, FaceError> {
    let text = read_text_file(path)?;
    parse_textgrid(&text, &path.display().to_string(), tier)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A long-format TextGrid as Montreal Forced Aligner writes it: "brother" then silence.
    pub(crate) const LONG: &str = r#"File type = "ooTextFile"
Object class = "TextGrid"

xmin = 0
xmax = 1.0
tiers? <exists>
size = 2
item []:
    item [1]:
        class = "IntervalTier"
        name = "words"
        xmin = 0
        xmax = 1.0
        intervals: size = 2
        intervals [1]:
            xmin = 0
            xmax = 0.5
            text = "brother"
        intervals [2]:
            xmin = 0.5
            xmax = 1.0
            text = ""
    item [2]:
        class = "IntervalTier"
        name = "phones"
        xmin = 0
        xmax = 1.0
        intervals: size = 6
        intervals [1]:
            xmin = 0
            xmax = 0.1
            text = "B"
        intervals [2]:
            xmin = 0.1
            xmax = 0.2
            text = "R"
        intervals [3]:
            xmin = 0.2
            xmax = 0.3
            text = "AH1"
        intervals [4]:
            xmin = 0.3
            xmax = 0.4
            text = "DH"
        intervals [5]:
            xmin = 0.4
            xmax = 0.5
            text = "ER0"
        intervals [6]:
            xmin = 0.5
            xmax = 1.0
            text = ""
"#;

    /// The same alignment in the short layout, with a point tier and IPA labels on the phone tier.
    pub(crate) const SHORT: &str = "File type = \"ooTextFile\"\nObject class = \"TextGrid\"\n\n0\n0.6\n<exists>\n2\n\
\"TextTier\"\n\"events\"\n0\n0.6\n1\n0.3\n\"click\"\n\
\"IntervalTier\"\n\"Phones\"\n0\n0.6\n3\n0\n0.1\n\"\"\n0.1\n0.35\n\"tʃ\"\n0.35\n0.6\n\"iː\"\n";

    fn spans(list: &[(f64, f64, &str)]) -> Vec<PhonemeSpan> {
        list.iter().map(|&(a, b, p)| PhonemeSpan::new(a, b, p)).collect()
    }

    #[test]
    fn reads_the_long_layout_phone_tier() {
        let got = parse_textgrid(LONG, "a.TextGrid", None).unwrap();
        let want = spans(&[
            (0.0, 0.1, "B"),
            (0.1, 0.2, "R"),
            (0.2, 0.3, "AH1"),
            (0.3, 0.4, "DH"),
            (0.4, 0.5, "ER0"),
            (0.5, 1.0, "sil"),
        ]);
        assert_eq!(got, want);
        // CRLF and a UTF-8 BOM read the same.
        let crlf = format!("\u{feff}{}", LONG.replace('\n', "\r\n"));
        assert_eq!(parse_textgrid(&crlf, "a.TextGrid", None).unwrap(), want);
    }

    #[test]
    fn reads_the_short_layout_skipping_point_tiers() {
        let got = parse_textgrid(SHORT, "s.TextGrid", None).unwrap();
        assert_eq!(got, spans(&[(0.0, 0.1, "sil"), (0.1, 0.35, "tʃ"), (0.35, 0.6, "iː")]));
        let e = parse_textgrid(SHORT, "s.TextGrid", Some("events")).unwrap_err().to_string();
        assert_eq!(e, "s.TextGrid:9: tier 'events' is a point tier (TextTier); expected an IntervalTier of phonemes");
    }

    #[test]
    fn reads_utf16_files_with_a_bom() {
        let dir = tempfile::tempdir().unwrap();
        for be in [false, true] {
            let mut bytes = if be { vec![0xFE, 0xFF] } else { vec![0xFF, 0xFE] };
            for u in SHORT.replace('\n', "\r\n").encode_utf16() {
                bytes.extend(if be { u.to_be_bytes() } else { u.to_le_bytes() });
            }
            let path = dir.path().join("u16.TextGrid");
            std::fs::write(&path, bytes).unwrap();
            let got = read_textgrid(&path, None).unwrap();
            assert_eq!(got[1].phoneme, "tʃ");
            assert_eq!(got.len(), 3);
        }
    }

    #[test]
    fn picks_named_tiers_and_lists_tiers_when_none_fits() {
        let words = parse_textgrid(LONG, "a.TextGrid", Some("WORDS"));
        // The words tier holds "brother", not a phoneme: the label check names its line.
        let e = words.unwrap_err().to_string();
        assert!(e.starts_with("a.TextGrid:18: tier 'words', interval 1: unknown phoneme 'brother'"), "{e}");
        let e = parse_textgrid(LONG, "a.TextGrid", Some("syllables")).unwrap_err().to_string();
        assert_eq!(e, "a.TextGrid: no tier named 'syllables'; tiers found: 'words' (line 11), 'phones' (line 25)");
        let no_phones = LONG.replace("\"phones\"", "\"segments\"");
        let e = parse_textgrid(&no_phones, "a.TextGrid", None).unwrap_err().to_string();
        assert!(e.contains("no phone tier") && e.contains("'words' (line 11), 'segments' (line 25)"), "{e}");
        // MFA with several speakers: "<speaker> - phones".
        let speaker = LONG.replace("\"phones\"", "\"anna - phones\"");
        assert_eq!(parse_textgrid(&speaker, "a.TextGrid", None).unwrap().len(), 6);
        let two = LONG.replace("\"phones\"", "\"anna - phones\"").replace("\"words\"", "\"bob - phones\"");
        let e = parse_textgrid(&two, "a.TextGrid", None).unwrap_err().to_string();
        assert!(e.contains("several phone tiers"), "{e}");
    }

    #[test]
    fn errors_name_the_line_and_what_was_expected() {
        let cases: Vec<(String, &str)> = vec![
            (LONG.replace("xmax = 0.3", "xmax = 0.3x"), "a.TextGrid:39: expected interval 3's end 'xmax = <number>' (tier 2) (a finite number), found 'xmax = 0.3x'"),
            (LONG.replace("            xmax = 0.2\n", ""), "a.TextGrid:35: expected interval 2's end 'xmax = <number>' (tier 2), found 'text = \"R\"'"),
            (LONG[..LONG.find("ER0").unwrap() + 2].to_string(), "a.TextGrid:48: a string opened on this line has no closing"),
            (LONG.replace("xmin = 0.3\n", "xmin = 0.25\n"), "a.TextGrid:42: tier 'phones', interval 4: start 0.25 s is before the end 0.3 s of the previous phoneme (line 38)"),
            (LONG.replace("xmax = 0.5\n            text = \"ER0\"", "xmax = 0.4\n            text = \"ER0\""), "a.TextGrid:47: tier 'phones', interval 5: end 0.4 s is not after start 0.4 s"),
            (LONG.replace("\"DH\"", "\"DHX\""), "a.TextGrid:44: tier 'phones', interval 4: unknown phoneme 'DHX'"),
            (LONG.replace("intervals: size = 6", "intervals: size = 7"), "a.TextGrid:52: expected interval 7's start 'xmin = <number>' (tier 2), found the end of the file"),
            (LONG.replace("size = 2\n", "size = two\n"), "a.TextGrid:7: expected the number of tiers 'size = <count>' (a whole number ≥ 0), found 'size = two'"),
            (LONG.replace("\"TextGrid\"", "\"Sound\""), "a.TextGrid:2: expected 'Object class = \"TextGrid\"', found object class 'Sound'"),
            (LONG.replace("\"IntervalTier\"\n        name = \"phones\"", "\"Tier\"\n        name = \"phones\""), "a.TextGrid:24: expected tier 2's class"),
            ("start,end,phoneme\n0,1,B\n".to_string(), "a.TextGrid:2: expected a Praat text file starting 'File type = \"ooTextFile\"' (a \"quoted string\"), found '0,1,B'"),
            (SHORT.replace("0.35\n0.6\n\"iː\"", "0.35\n0.6\n0.7"), "a.TextGrid:28: expected interval 3's label 'text = \"…\"' (tier 2) (a \"quoted string\"), found '0.7'"),
        ];
        for (text, want) in cases {
            let e = parse_textgrid(&text, "a.TextGrid", None).unwrap_err().to_string();
            assert!(e.starts_with(want), "got  {e}\nwant {want}");
        }
        assert!(matches!(parse_textgrid(" \n! only a comment\n", "e.TextGrid", None), Err(FaceError::Empty { .. })));
    }

    #[test]
    fn strings_unescape_doubled_quotes_and_span_lines() {
        let text =
            "\"ooTextFile\" \"TextGrid\" 0 1 <exists> 1 \"IntervalTier\" \"say \"\"hi\"\"\n again\" 0 1 1 0 1 \"sil\"";
        let e = parse_textgrid(text, "q", None).unwrap_err().to_string();
        assert!(e.contains("'say \"hi\"\n again' (line 1)"), "{e}");
        let got = parse_textgrid(text, "q", Some("say \"hi\"\n again")).unwrap();
        assert_eq!(got, spans(&[(0.0, 1.0, "sil")]));
    }
}
