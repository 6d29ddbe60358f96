//! English text → timed phonemes, for `--text "…"` edits when no forced alignment exists.
//!
//! 1. **Words.** The text is lowercased and split into words (letters, digits and apostrophes; `’` counts
//!    as `'`). Other characters separate words; `,` `;` `:` `—` `–` add a short pause and `.` `!` `?` a
//!    longer one, between words only. Digits are spelled out one by one ("42" → "four two").
//! 2. **Pronunciations.** Each word is looked up in CMUdict (first pronunciation), the dictionary the
//!    `cmudict-fast` package ships: `build.rs` copies it into the build and it is embedded here and
//!    parsed once, on first use. A word missing from it (also after dropping outer apostrophes) gets
//!    our letter-to-sound rules ([`letter_to_sound`]) and is reported in
//!    [`TextPhonemes::guessed_words`].
//! 3. **Durations.** The span `[start_s, end_s)` is shared out in proportion to weights: vowels
//!    [`VOWEL_WEIGHT`], consonants [`CONSONANT_WEIGHT`], pauses [`COMMA_PAUSE_WEIGHT`] or
//!    [`SENTENCE_PAUSE_WEIGHT`] (as [`super::SILENCE`] spans). The spans tile the span exactly.
//!
//! CMUdict is © Carnegie Mellon University under a BSD-style licence (`LICENSE-CMUDICT` in the
//! `cmudict-fast` package).

use super::labels::SILENCE;
use super::spans::PhonemeSpan;
use crate::data::FaceError;
use cmudict_fast::Cmudict;
use std::str::FromStr;
use std::sync::OnceLock;

/// Relative duration of a vowel.
pub const VOWEL_WEIGHT: f64 = 2.0;
/// Relative duration of a consonant.
pub const CONSONANT_WEIGHT: f64 = 1.0;
/// Relative duration of the pause at a comma, semicolon, colon or dash.
pub const COMMA_PAUSE_WEIGHT: f64 = 1.5;
/// Relative duration of the pause between sentences.
pub const SENTENCE_PAUSE_WEIGHT: f64 = 3.0;

/// CMUdict text, copied from the `cmudict-fast` package by `build.rs`.
static DICT_TEXT: &str = include_str!(concat!(env!("OUT_DIR"), "/cmudict.dict"));
static DICT: OnceLock<Result<Cmudict, String>> = OnceLock::new();

/// The embedded CMUdict, parsed on first use (later calls return the same dictionary).
pub fn dictionary() -> Result<&'static Cmudict, FaceError> {
    DICT.get_or_init(|| Cmudict::from_str(DICT_TEXT).map_err(|e| e.to_string())).as_ref().map_err(|e| FaceError::File {
        file: "embedded CMUdict".into(),
        message: format!("cannot parse the dictionary: {e}"),
    })
}

/// A word's phonemes and where they came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pronunciation {
    /// ARPAbet phonemes (vowels with CMUdict stress digits when from the dictionary).
    pub phonemes: Vec<String>,
    /// `true` when CMUdict knew the word, `false` when the letter-to-sound rules guessed.
    pub from_dictionary: bool,
}

/// The pronunciation of one word (any case; outer apostrophes dropped when the dictionary lacks the
/// word with them). Digits are not spelled out here ([`text_to_phonemes`] does that).
pub fn pronounce(word: &str) -> Result<Pronunciation, FaceError> {
    let dict = dictionary()?;
    let lower = word.to_lowercase().replace('’', "'");
    let trimmed = lower.trim_matches('\'');
    for candidate in [lower.as_str(), trimmed] {
        if let Some(rule) = dict.get(candidate).and_then(|rules| rules.first()) {
            let phonemes = rule.pronunciation().iter().map(|s| s.to_string()).collect();
            return Ok(Pronunciation { phonemes, from_dictionary: true });
        }
    }
    Ok(Pronunciation { phonemes: letter_to_sound(trimmed), from_dictionary: false })
}

/// Where a letter-to-sound rule applies.
#[derive(Clone, Copy, Debug)]
enum When {
    Anywhere,
    /// At the start of the word.
    Start,
    /// At the end of the word.
    End,
    /// Before `e`, `i` or `y` (soft `c`, `g`).
    BeforeFrontVowel,
    /// A vowel, one consonant, then the word's final `e` ("make", "time"): the long vowel.
    MagicE,
    /// The word's final `e` after a consonant, in words of three letters or more.
    SilentFinalE,
}

/// One rule: the letters it consumes, where it applies, the phonemes it gives.
struct Rule {
    letters: &'static str,
    when: When,
    phonemes: &'static [&'static str],
}

const fn r(letters: &'static str, when: When, phonemes: &'static [&'static str]) -> Rule {
    Rule { letters, when, phonemes }
}

/// The ordered rule table: at each position the first rule that matches is applied, so longer
/// spellings come before shorter ones and context rules before the plain letter.
const RULES: &[Rule] = &[
    r("tch", When::Anywhere, &["CH"]),
    r("igh", When::Anywhere, &["AY"]),
    r("kn", When::Start, &["N"]),
    r("wr", When::Start, &["R"]),
    r("th", When::Anywhere, &["TH"]),
    r("sh", When::Anywhere, &["SH"]),
    r("ch", When::Anywhere, &["CH"]),
    r("ph", When::Anywhere, &["F"]),
    r("ck", When::Anywhere, &["K"]),
    r("ng", When::Anywhere, &["NG"]),
    r("wh", When::Anywhere, &["W"]),
    r("qu", When::Anywhere, &["K", "W"]),
    r("gh", When::Anywhere, &[]),
    r("ee", When::Anywhere, &["IY"]),
    r("ea", When::Anywhere, &["IY"]),
    r("oo", When::Anywhere, &["UW"]),
    r("ou", When::Anywhere, &["AW"]),
    r("ow", When::Anywhere, &["OW"]),
    r("ai", When::Anywhere, &["EY"]),
    r("ay", When::Anywhere, &["EY"]),
    r("oi", When::Anywhere, &["OY"]),
    r("oy", When::Anywhere, &["OY"]),
    r("au", When::Anywhere, &["AO"]),
    r("aw", When::Anywhere, &["AO"]),
    r("ew", When::Anywhere, &["UW"]),
    r("er", When::Anywhere, &["ER"]),
    r("ir", When::Anywhere, &["ER"]),
    r("ur", When::Anywhere, &["ER"]),
    r("ar", When::Anywhere, &["AA", "R"]),
    r("or", When::Anywhere, &["AO", "R"]),
    r("a", When::MagicE, &["EY"]),
    r("e", When::MagicE, &["IY"]),
    r("i", When::MagicE, &["AY"]),
    r("o", When::MagicE, &["OW"]),
    r("u", When::MagicE, &["UW"]),
    r("e", When::SilentFinalE, &[]),
    r("c", When::BeforeFrontVowel, &["S"]),
    r("g", When::BeforeFrontVowel, &["JH"]),
    r("y", When::Start, &["Y"]),
    r("y", When::End, &["IY"]),
    r("y", When::Anywhere, &["IH"]),
    r("x", When::Start, &["Z"]),
    r("x", When::Anywhere, &["K", "S"]),
    r("a", When::Anywhere, &["AE"]),
    r("e", When::Anywhere, &["EH"]),
    r("i", When::Anywhere, &["IH"]),
    r("o", When::Anywhere, &["AA"]),
    r("u", When::Anywhere, &["AH"]),
    r("b", When::Anywhere, &["B"]),
    r("c", When::Anywhere, &["K"]),
    r("d", When::Anywhere, &["D"]),
    r("f", When::Anywhere, &["F"]),
    r("g", When::Anywhere, &["G"]),
    r("h", When::Anywhere, &["HH"]),
    r("j", When::Anywhere, &["JH"]),
    r("k", When::Anywhere, &["K"]),
    r("l", When::Anywhere, &["L"]),
    r("m", When::Anywhere, &["M"]),
    r("n", When::Anywhere, &["N"]),
    r("p", When::Anywhere, &["P"]),
    r("q", When::Anywhere, &["K"]),
    r("r", When::Anywhere, &["R"]),
    r("s", When::Anywhere, &["S"]),
    r("t", When::Anywhere, &["T"]),
    r("v", When::Anywhere, &["V"]),
    r("w", When::Anywhere, &["W"]),
    r("z", When::Anywhere, &["Z"]),
];

fn is_vowel_letter(c: u8) -> bool {
    matches!(c, b'a' | b'e' | b'i' | b'o' | b'u')
}

fn applies(rule: &Rule, w: &[u8], i: usize) -> bool {
    let n = rule.letters.len();
    if !w[i..].starts_with(rule.letters.as_bytes()) {
        return false;
    }
    let after = i + n;
    match rule.when {
        When::Anywhere => true,
        When::Start => i == 0,
        When::End => after == w.len(),
        When::BeforeFrontVowel => matches!(w.get(after), Some(b'e' | b'i' | b'y')),
        When::MagicE => {
            after + 2 == w.len()
                && w[after + 1] == b'e'
                && !is_vowel_letter(w[after])
                && w[after] != b'y'
                && w[after] != b'r'
        }
        When::SilentFinalE => after == w.len() && w.len() >= 3 && !is_vowel_letter(w[i - 1]),
    }
}

/// Folds a lowercase letter to `a`–`z` (accents dropped); `None` for anything else.
fn fold_letter(c: char) -> Option<u8> {
    let folded = match c {
        'a'..='z' => c,
        'à' | 'á' | 'â' | 'ã' | 'ä' | 'å' | 'æ' => 'a',
        'ç' => 'c',
        'è' | 'é' | 'ê' | 'ë' => 'e',
        'ì' | 'í' | 'î' | 'ï' => 'i',
        'ñ' => 'n',
        'ò' | 'ó' | 'ô' | 'õ' | 'ö' | 'ø' => 'o',
        'ù' | 'ú' | 'û' | 'ü' => 'u',
        'ý' | 'ÿ' => 'y',
        _ => return None,
    };
    Some(folded as u8)
}

/// Our letter-to-sound rules for words CMUdict lacks: the ordered `RULES` table (see the source), longest spelling
/// first; a doubled consonant letter sounds once; letters outside `a`–`z` (after dropping accents)
/// are skipped. Vowels come out without stress digits.
pub fn letter_to_sound(word: &str) -> Vec<String> {
    let w: Vec<u8> = word.to_lowercase().chars().filter_map(fold_letter).collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < w.len() {
        let Some(rule) = RULES.iter().find(|rule| applies(rule, &w, i)) else {
            i += 1;
            continue;
        };
        out.extend(rule.phonemes.iter().map(|p| p.to_string()));
        i += rule.letters.len();
        let single_consonant = rule.letters.len() == 1 && !is_vowel_letter(w[i - 1]);
        if single_consonant && w.get(i) == Some(&w[i - 1]) {
            i += 1;
        }
    }
    out
}

/// What came between two words.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Pause {
    None,
    Comma,
    Sentence,
}

/// Splits text into words and the strongest pause before each word.
fn words(text: &str) -> Vec<(Pause, String)> {
    let mut out: Vec<(Pause, String)> = Vec::new();
    let mut current = String::new();
    let mut pause = Pause::None;
    let flush = |current: &mut String, pause: &mut Pause, out: &mut Vec<(Pause, String)>| {
        if !current.is_empty() {
            let p = if out.is_empty() { Pause::None } else { *pause };
            out.push((p, std::mem::take(current)));
            *pause = Pause::None;
        }
    };
    for c in text.chars() {
        let c = if c == '’' { '\'' } else { c };
        if c.is_alphanumeric() || c == '\'' {
            current.extend(c.to_lowercase());
            continue;
        }
        flush(&mut current, &mut pause, &mut out);
        let p = match c {
            ',' | ';' | ':' | '—' | '–' => Pause::Comma,
            '.' | '!' | '?' => Pause::Sentence,
            _ => Pause::None,
        };
        pause = pause.max(p);
    }
    flush(&mut current, &mut pause, &mut out);
    out
}

const DIGITS: [&str; 10] = ["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine"];

/// Splits a word into runs of digits (each digit spelled out) and runs of other characters.
fn spell_digits(word: &str) -> Vec<String> {
    let mut parts = Vec::new();
    let mut rest = String::new();
    for c in word.chars() {
        if let Some(d) = c.to_digit(10) {
            if !rest.is_empty() {
                parts.push(std::mem::take(&mut rest));
            }
            parts.push(DIGITS[d as usize].to_string());
        } else if !c.is_numeric() {
            rest.push(c);
        }
    }
    if !rest.is_empty() {
        parts.push(rest);
    }
    parts
}

/// Whether an ARPAbet phoneme is a vowel.
pub fn is_vowel(phoneme: &str) -> bool {
    let base = phoneme.trim_end_matches(['0', '1', '2']).to_ascii_uppercase();
    matches!(
        base.as_str(),
        "AA" | "AE" | "AH" | "AO" | "AW" | "AY" | "EH" | "ER" | "EY" | "IH" | "IY" | "OW" | "OY" | "UH" | "UW"
    )
}

/// Phonemes from text, timed over a span, and the words the rules had to guess.
#[derive(Clone, Debug, PartialEq)]
pub struct TextPhonemes {
    /// Consecutive spans tiling `[start_s, end_s)`.
    pub spans: Vec<PhonemeSpan>,
    /// Words CMUdict lacks (lowercase, each once, in order of appearance), pronounced by the rules.
    pub guessed_words: Vec<String>,
}

/// English text spoken over `[start_s, end_s)` → timed phonemes (see the module docs).
/// Errors: non-finite times, `end_s <= start_s`, or text without a pronounceable word.
pub fn text_to_phonemes(text: &str, start_s: f64, end_s: f64) -> Result<TextPhonemes, FaceError> {
    if !start_s.is_finite() || !end_s.is_finite() || end_s <= start_s {
        return Err(FaceError::Invalid(format!(
            "text span {start_s} s .. {end_s} s; expected finite times with start < end"
        )));
    }
    let mut labels: Vec<(String, f64)> = Vec::new();
    let mut guessed: Vec<String> = Vec::new();
    for (pause, word) in words(text) {
        let mut phonemes = Vec::new();
        for part in spell_digits(&word) {
            let p = pronounce(&part)?;
            if !p.from_dictionary && !p.phonemes.is_empty() && !guessed.contains(&part) {
                guessed.push(part.clone());
            }
            phonemes.extend(p.phonemes);
        }
        if phonemes.is_empty() {
            continue;
        }
        let pause_weight = match pause {
            Pause::None => 0.0,
            Pause::Comma => COMMA_PAUSE_WEIGHT,
            Pause::Sentence => SENTENCE_PAUSE_WEIGHT,
        };
        if pause_weight > 0.0 && !labels.is_empty() {
            labels.push((SILENCE.to_string(), pause_weight));
        }
        for p in phonemes {
            let w = if is_vowel(&p) { VOWEL_WEIGHT } else { CONSONANT_WEIGHT };
            labels.push((p, w));
        }
    }
    if labels.is_empty() {
        return Err(FaceError::Invalid(format!(
            "no pronounceable word in the text {:?}; expected English words",
            text.chars().take(60).collect::<String>()
        )));
    }
    Ok(TextPhonemes { spans: spread(&labels, start_s, end_s), guessed_words: guessed })
}

/// Shares `[start_s, end_s)` out in proportion to the weights; the last span ends exactly at `end_s`.
fn spread(labels: &[(String, f64)], start_s: f64, end_s: f64) -> Vec<PhonemeSpan> {
    let total: f64 = labels.iter().map(|(_, w)| w).sum();
    let mut acc = 0.0;
    let mut t = start_s;
    labels
        .iter()
        .enumerate()
        .map(|(i, (p, w))| {
            acc += w;
            let end = if i + 1 == labels.len() { end_s } else { start_s + (end_s - start_s) * acc / total };
            let span = PhonemeSpan::new(t, end, p.clone());
            t = end;
            span
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::{validate_spans, viseme_frames, Viseme};
    use super::*;

    fn strs(v: &[String]) -> Vec<&str> {
        v.iter().map(String::as_str).collect()
    }

    #[test]
    fn dictionary_loads_once_and_knows_common_words() {
        let t = std::time::Instant::now();
        let d1 = dictionary().unwrap();
        let first = t.elapsed();
        let d2 = dictionary().unwrap();
        eprintln!("CMUdict first dictionary() call: {:.1} ms ({} bytes embedded; the parse time when no other test ran first)", first.as_secs_f64() * 1e3, DICT_TEXT.len());
        assert!(std::ptr::eq(d1, d2), "parsed once");
        let brother = pronounce("Brother").unwrap();
        assert!(brother.from_dictionary);
        assert_eq!(strs(&brother.phonemes), ["B", "R", "AH1", "DH", "ER0"]);
        assert_eq!(strs(&pronounce("don't").unwrap().phonemes), ["D", "OW1", "N", "T"]);
        assert_eq!(strs(&pronounce("never").unwrap().phonemes), ["N", "EH1", "V", "ER0"]);
    }

    #[test]
    fn brother_becomes_the_expected_visemes() {
        // Weights 1,1,2,1,2 over 0.875 s (binary-exact): 0.125 s per consonant, 0.25 s per vowel.
        let got = text_to_phonemes("Brother", 0.0, 0.875).unwrap();
        assert!(got.guessed_words.is_empty());
        let labels: Vec<&str> = got.spans.iter().map(|s| s.phoneme.as_str()).collect();
        assert_eq!(labels, ["B", "R", "AH1", "DH", "ER0"]);
        let durations: Vec<f64> = got.spans.iter().map(|s| s.duration_s()).collect();
        assert_eq!(durations, [0.125, 0.125, 0.25, 0.125, 0.25]);
        // Frames every 0.125 s, one past the end (uncovered → silence).
        let frames = viseme_frames(&got.spans, 8.0, 0.0, 8).unwrap();
        use Viseme::*;
        assert_eq!(frames, [MBP, R, AhEr, AhEr, ThDh, AhEr, AhEr, Sil]);
    }

    #[test]
    fn unknown_words_use_the_rules_and_are_reported() {
        assert_eq!(strs(&letter_to_sound("inbetweenx")), ["IH", "N", "B", "EH", "T", "W", "IY", "N", "K", "S"]);
        assert_eq!(strs(&letter_to_sound("shoop")), ["SH", "UW", "P"]);
        assert_eq!(strs(&letter_to_sound("blake")), ["B", "L", "EY", "K"]);
        assert_eq!(strs(&letter_to_sound("phatch")), ["F", "AE", "CH"]);
        assert_eq!(strs(&letter_to_sound("zelling")), ["Z", "EH", "L", "IH", "NG"]);
        assert_eq!(strs(&letter_to_sound("cigy")), ["S", "IH", "JH", "IY"]);
        assert_eq!(strs(&letter_to_sound("Zoë")), ["Z", "AA", "EH"]);
        let got = text_to_phonemes("Hello, glorptastic brother. Glorptastic!", 1.0, 4.0).unwrap();
        assert_eq!(got.guessed_words, ["glorptastic"]);
        validate_spans(&got.spans).unwrap();
        let labels: Vec<&str> = got.spans.iter().map(|s| s.phoneme.as_str()).collect();
        assert_eq!(labels.iter().filter(|l| **l == SILENCE).count(), 2, "{labels:?}");
        assert_eq!(labels[..5], ["HH", "AH0", "L", "OW1", SILENCE]);
        for s in &got.spans {
            assert!(s.viseme().is_some(), "{s:?}");
        }
    }

    #[test]
    fn spans_tile_the_given_span_and_pauses_scale() {
        let got = text_to_phonemes("Stop. Now, 42 times!", 2.5, 5.25).unwrap();
        assert_eq!(got.spans.first().unwrap().start_s, 2.5);
        assert_eq!(got.spans.last().unwrap().end_s, 5.25);
        for w in got.spans.windows(2) {
            assert_eq!(w[0].end_s, w[1].start_s);
        }
        let total: f64 = got.spans.iter().map(PhonemeSpan::duration_s).sum();
        assert!((total - 2.75).abs() < 1e-12);
        let sils: Vec<f64> = got.spans.iter().filter(|s| s.phoneme == SILENCE).map(|s| s.duration_s()).collect();
        assert_eq!(sils.len(), 2);
        assert!((sils[0] / sils[1] - SENTENCE_PAUSE_WEIGHT / COMMA_PAUSE_WEIGHT).abs() < 1e-9);
        // "42" spelled digit by digit: four (F AO1 R) two (T UW1).
        let labels: Vec<&str> = got.spans.iter().map(|s| s.phoneme.as_str()).collect();
        let n = labels.iter().position(|l| *l == "F").unwrap();
        assert_eq!(labels[n..n + 5], ["F", "AO1", "R", "T", "UW1"]);
        assert!(got.guessed_words.is_empty());
    }

    #[test]
    fn bad_text_or_span_is_an_error() {
        for (text, a, b) in [
            ("hi", 1.0, 1.0),
            ("hi", 1.0, 0.5),
            ("hi", f64::NAN, 1.0),
            ("", 0.0, 1.0),
            (" ,.!? ", 0.0, 1.0),
            ("''", 0.0, 1.0),
        ] {
            assert!(matches!(text_to_phonemes(text, a, b), Err(FaceError::Invalid(_))), "{text:?} {a} {b}");
        }
    }
}
