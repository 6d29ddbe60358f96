//! The script as the user writes it (§3.2): sentences, each a scene description (ending in `$`),
//! a character direction, or a verbal command ("camera left").
//!
//! Splitting is lenient because the paper's own captions are (Fig. 1, 5): `\$`, `$.`, quotes
//! around sentences, a `".` where a `$` was meant, sentences broken over lines ("... recorder" /
//! "and pushes ...") and a stray period before "and sings".

use crate::error::SentenceRef;

/// What a sentence asks for (§3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SentenceKind {
    /// Ends in `$`: describes the scene.
    Scene,
    /// Directs a character ("Eve walks to the house").
    Direction,
    /// A verbal command ("camera left", "weather rainy", "time night").
    Command,
}

/// One sentence of the script, with where it is. `at.text` has no terminator, no `$`, no quotes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawSentence {
    pub at: SentenceRef,
    pub kind: SentenceKind,
}

/// Camera views a `camera X` command accepts (§3.2 "camera left").
pub const CAMERA_VIEWS: [&str; 7] = ["left", "front", "right", "back", "top", "close", "wide"];
/// Weathers a `weather X` command accepts.
pub const WEATHERS: [&str; 4] = ["rainy", "sunny", "snowy", "foggy"];
/// Times a `time X` command accepts.
pub const TIMES: [&str; 2] = ["night", "day"];

/// Words that continue the previous line's or sentence's direction ("... recorder" / "and
/// pushes the record button", Fig. 5; "Eve sits on the couch. and sings", Fig. 1).
const CONTINUATIONS: [&str; 3] = ["and", "then", "but"];

/// Titles whose period does not end a sentence.
const ABBREVIATIONS: [&str; 6] = ["mr", "mrs", "ms", "dr", "st", "prof"];

/// A sentence being collected.
#[derive(Default)]
struct Pending {
    text: String,
    line: usize,
}

/// Splits a script into sentences. `#` lines are comments; blank lines are skipped; a line break
/// ends a sentence unless the next line starts with "and"/"then"/"but".
pub fn split(text: &str) -> Vec<RawSentence> {
    // (text, line, ends in $) segments.
    let mut segs: Vec<(String, usize, bool)> = Vec::new();
    let mut cur = Pending::default();
    for (i, line) in text.split('\n').enumerate() {
        let line_no = i + 1;
        let line = line.strip_suffix('\r').unwrap_or(line);
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        // A line break ends the sentence unless this line continues it.
        if !cur.text.trim().is_empty() && !starts_with_continuation(trimmed) {
            push_seg(&mut segs, &mut cur, false);
        }
        let chars: Vec<char> = line.chars().collect();
        let mut k = 0;
        while k < chars.len() {
            let c = chars[k];
            match c {
                '$' => push_seg(&mut segs, &mut cur, true),
                '.' | '!' | '?' => {
                    let prev = chars[..k].iter().rev().find(|c| !c.is_whitespace()).copied();
                    if c == '.' && (is_decimal_point(&chars, k) || ends_with_abbreviation(&cur.text)) {
                        cur.text.push(c);
                    } else if c == '.' && prev == Some('"') && chars[..k].last() == Some(&'"') {
                        // `".` stands for `$".` in the captions (Fig. 5, boxing gym).
                        if cur.text.trim().is_empty() {
                            if let Some(last) = segs.last_mut() {
                                last.2 = true;
                            }
                            cur.text.clear();
                        } else {
                            push_seg(&mut segs, &mut cur, true);
                        }
                    } else {
                        push_seg(&mut segs, &mut cur, false);
                    }
                }
                '\\' if chars.get(k + 1) == Some(&'$') => {}
                '"' | '\u{201c}' | '\u{201d}' | '`' => cur.text.push(' '),
                '\'' | '\u{2018}' | '\u{2019}' => {
                    // An apostrophe inside a word stays ("Eve's"); quote marks go.
                    let inside = k > 0
                        && chars[k - 1].is_alphanumeric()
                        && chars.get(k + 1).is_some_and(|c| c.is_alphanumeric());
                    cur.text.push(if inside { '\'' } else { ' ' });
                }
                _ => {
                    if cur.text.trim().is_empty() && !c.is_whitespace() {
                        cur.line = line_no;
                    }
                    cur.text.push(c);
                }
            }
            k += 1;
        }
        cur.text.push(' ');
    }
    push_seg(&mut segs, &mut cur, false);

    // Merge "and ..." continuations into the direction before them.
    let mut merged: Vec<(String, usize, bool)> = Vec::new();
    for seg in segs {
        let first = seg.0.split_whitespace().next().unwrap_or("");
        let cont = CONTINUATIONS.contains(&first);
        match merged.last_mut() {
            Some(prev) if cont && !prev.2 && command_parts(&prev.0).is_none() => {
                prev.0.push(' ');
                prev.0.push_str(&seg.0);
                prev.2 = seg.2;
            }
            _ => merged.push(seg),
        }
    }

    merged
        .into_iter()
        .enumerate()
        .map(|(i, (text, line, scene))| {
            // A command stays a command even when written with `$` ("camera left$").
            let kind = if command_parts(&text).is_some() {
                SentenceKind::Command
            } else if scene {
                SentenceKind::Scene
            } else {
                SentenceKind::Direction
            };
            RawSentence { at: SentenceRef { line, sentence: i + 1, text }, kind }
        })
        .collect()
}

/// `("camera", "left")` when the sentence is a verbal command (§3.2): two words, the first
/// `camera`/`weather`, or `time` followed by a known time of day.
pub fn command_parts(text: &str) -> Option<(String, String)> {
    let words: Vec<String> = text
        .split(|c: char| c.is_whitespace() || c == ':' || c == ',')
        .filter(|w| !w.is_empty())
        .map(str::to_lowercase)
        .collect();
    if words.len() != 2 {
        return None;
    }
    let ok = match words[0].as_str() {
        "camera" | "weather" => true,
        "time" => TIMES.contains(&words[1].as_str()),
        _ => false,
    };
    ok.then(|| (words[0].clone(), words[1].clone()))
}

fn push_seg(segs: &mut Vec<(String, usize, bool)>, cur: &mut Pending, scene: bool) {
    let text = cur.text.split_whitespace().collect::<Vec<_>>().join(" ");
    let text = text.trim_matches(|c: char| c == ',' || c == ';' || c == ':' || c.is_whitespace()).to_string();
    if !text.is_empty() && text.chars().any(char::is_alphanumeric) {
        segs.push((text, cur.line.max(1), scene));
    }
    cur.text.clear();
}

fn starts_with_continuation(line: &str) -> bool {
    let first = line
        .trim_start_matches(|c: char| !c.is_alphanumeric())
        .split(|c: char| !c.is_alphanumeric())
        .next()
        .unwrap_or("");
    CONTINUATIONS.contains(&first)
}

fn is_decimal_point(chars: &[char], k: usize) -> bool {
    k > 0 && chars[k - 1].is_ascii_digit() && chars.get(k + 1).is_some_and(|c| c.is_ascii_digit())
}

fn ends_with_abbreviation(text: &str) -> bool {
    let last = text.rsplit(|c: char| !c.is_alphanumeric()).next().unwrap_or("");
    !last.is_empty() && ABBREVIATIONS.contains(&last.to_lowercase().as_str())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dollar_variants_mark_scenes() {
        let s = split("A desk is near a bed\\$. Eve walks to the desk.");
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].kind, SentenceKind::Scene);
        assert_eq!(s[0].at.text, "A desk is near a bed");
        assert_eq!(s[1].kind, SentenceKind::Direction);
        assert_eq!(s[1].at.sentence, 2);
    }

    #[test]
    fn decimals_and_titles_do_not_split() {
        let s = split("Mr. Smith walks 2.5 metres to the desk.");
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].at.text, "Mr. Smith walks 2.5 metres to the desk");
    }
}
